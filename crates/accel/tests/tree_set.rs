//! `TreeSet`: the trees of some traversals only. Each traversal answers every ray (closest
//! hit and shadow) exactly as the same traversal of `Structures`, reads the same memory
//! image word for word, and the set holds no tree it was not asked for.

use dualsplit_accel::math::{Hit, Ray, Triangle};
use dualsplit_accel::{
    AccelKind, BuildConfig, NoObserver, Structures, TraversalSet, TreeKind, TreeSet,
};
use dualsplit_geometry::{Aabb, Pcg32};
use dualsplit_testkit::rays::random_rays;

fn bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.prim.0, h.u.to_bits(), h.v.to_bits()))
}

fn rays(tris: &[Triangle], n: usize) -> Vec<Ray> {
    let b = tris.iter().fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
    random_rays(&mut Pcg32::new(11, 7), tris, &b, n)
}

#[test]
fn a_tree_set_answers_every_ray_as_the_structures_do() {
    let tris = dualsplit_scene::load("builtin:forest?triangles=20000")
        .expect("builtin")
        .triangles;
    let cfg = BuildConfig::default();
    let all = Structures::build(&tris, &cfg);
    let rays = rays(&tris, if cfg!(debug_assertions) { 300 } else { 5_000 });
    let asked: [&[AccelKind]; 4] = [
        &[AccelKind::Bvh2],
        &[AccelKind::Dst, AccelKind::Bvh8],
        &[AccelKind::DstQ, AccelKind::Cwbvh, AccelKind::Bvh4],
        &AccelKind::ALL,
    ];
    for kinds in asked {
        let set = TreeSet::build(&tris[..], &cfg, kinds).expect("build");
        // Exactly the trees asked for, each with every traversal of its image.
        let want_trees: Vec<TreeKind> = TreeKind::ALL
            .into_iter()
            .filter(|t| kinds.iter().any(|&k| TreeKind::of_accel(k) == *t))
            .collect();
        let got_trees: Vec<TreeKind> = set.trees().iter().map(|t| t.kind()).collect();
        assert_eq!(got_trees, want_trees, "{kinds:?}");
        for &k in kinds {
            assert!(set.supports(k), "{kinds:?} lacks {k:?}");
        }
        assert_eq!(set.scene_box(), TraversalSet::scene_box(&all), "{kinds:?}");
        for &k in set.kinds() {
            let (a, b) = (TraversalSet::image(&set, k), all.image(k));
            assert_eq!(a.words, b.words, "{k:?} image words");
            assert_eq!(a.nodes, b.nodes, "{k:?} node region");
            for (j, r) in rays.iter().enumerate() {
                assert_eq!(
                    bits(TraversalSet::closest_hit(&set, k, r, &mut NoObserver)),
                    bits(all.closest_hit(k, r, &mut NoObserver)),
                    "{k:?} ray {j}"
                );
                assert_eq!(
                    TraversalSet::any_hit(&set, k, r, &mut NoObserver),
                    all.any_hit(k, r, &mut NoObserver),
                    "{k:?} shadow ray {j}"
                );
            }
        }
        // A traversal whose tree was not built misses every ray.
        for k in AccelKind::ALL.into_iter().filter(|k| !set.supports(*k)) {
            assert!(
                rays.iter()
                    .all(|r| TraversalSet::closest_hit(&set, k, r, &mut NoObserver).is_none()),
                "{k:?} outside {kinds:?} answered"
            );
        }
    }
}
