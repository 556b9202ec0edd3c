//! One tree instead of every structure (`TraversalSet` for `AnyTree`, what `--tree` uses):
//! a DST or BVH8 tree renders the same frame as `Structures`, records the same ray sets,
//! and a traversal it does not hold is refused before anything is traced.

use dualsplit_accel::{
    AccelKind, AnyTree, BuildConfig, Bvh2Tree, BvhTree, DstConfig, DstTree, Structures,
    TraversalSet,
};
use dualsplit_render::bench::{MeasureConfig, measure, ray_sets};
use dualsplit_render::{RenderError, RenderSettings, Workload, render};
use dualsplit_testkit::scenes::room;

#[test]
fn one_tree_renders_the_frame_of_every_structure() {
    let scene = room(false, 8);
    let all = Structures::build(&scene.triangles, &BuildConfig::default());
    let bvh2 = Bvh2Tree::build(&scene.triangles[..], &BuildConfig::default()).unwrap();
    let dst = AnyTree::from(DstTree::from_bvh2(&bvh2, &DstConfig::hardware()).unwrap());
    let bvh8 = AnyTree::from(BvhTree::bvh8_from(&bvh2).unwrap());
    assert_eq!(dst.scene_box(), all.scene_box());
    assert_eq!(bvh8.scene_box(), all.scene_box());
    let settings = RenderSettings::new(24, 18, Workload::Path);
    let want = render(&scene, &all, AccelKind::Bvh2, &settings, &|| {}).unwrap();
    assert!(want.counts.hits() > 0);
    for (tree, kinds) in [
        (&dst, &[AccelKind::DstSw, AccelKind::Dst][..]),
        (&bvh8, &[AccelKind::Bvh8]),
    ] {
        assert_eq!(tree.kinds(), kinds);
        for &kind in kinds {
            let got = render(&scene, tree, kind, &settings, &|| {}).unwrap();
            assert_eq!(got.image.pixels.len(), want.image.pixels.len());
            assert!(
                got.image
                    .pixels
                    .iter()
                    .zip(&want.image.pixels)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "{kind:?}: the frame differs"
            );
            assert_eq!(got.counts, want.counts, "{kind:?}");
        }
        // Ray sets recorded on the tree's own first traversal are BVH2's.
        let sets = ray_sets(&scene, tree, &settings).unwrap();
        let reference = ray_sets(&scene, &all, &settings).unwrap();
        for (a, b) in sets.iter().zip(&reference) {
            assert_eq!(a.rays.len(), b.rays.len());
            assert!(a.expected.iter().zip(&b.expected).all(|(x, y)| x.bit_eq(y)));
        }
    }
}

#[test]
fn a_traversal_the_tree_lacks_is_refused() {
    let scene = room(false, 4);
    let bvh2 = Bvh2Tree::build(&scene.triangles[..], &BuildConfig::default()).unwrap();
    let dst = AnyTree::from(DstTree::from_bvh2(&bvh2, &DstConfig::hardware()).unwrap());
    let settings = RenderSettings::new(4, 4, Workload::Cast);
    for kind in [AccelKind::Bvh2, AccelKind::Bvh4, AccelKind::Bvh8] {
        match render(&scene, &dst, kind, &settings, &|| {}) {
            Err(RenderError::Unsupported { accel, available }) => {
                assert_eq!(accel, kind.name());
                assert_eq!(available, "dst-sw, dst");
            }
            other => panic!("{kind:?}: {:?}", other.map(|f| f.counts)),
        }
    }
    let sets = ray_sets(&scene, &dst, &settings).unwrap();
    let cfg = MeasureConfig {
        min_seconds: 0.0,
        min_repeats: 1,
    };
    assert!(matches!(
        measure(&dst, AccelKind::Bvh4, &sets[0], &cfg),
        Err(RenderError::Unsupported { .. })
    ));
    assert!(measure(&dst, AccelKind::Dst, &sets[0], &cfg).is_ok());
}
