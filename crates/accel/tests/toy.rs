//! The toy structure (`src/toy/`, feature `toy`) follows `docs/extending.md` once more:
//! its folder and one registry line, nothing else, and every generic part of the crate
//! takes it: the kinds and their names, the saved-tree format, `Structures`, `TreeSet`,
//! validation, statistics and the oracle's per-ray check.
//!
//! `cargo test --release -p dualsplit-accel --features toy --test toy`
#![cfg(feature = "toy")]

use dualsplit_accel::math::{Ray, Vec3};
use dualsplit_accel::toy::ToyTree;
use dualsplit_accel::{
    AccelKind, AnyTree, BuildConfig, Bvh2Tree, NoObserver, Structures, TraversalSet, TreeKind,
    TreeSet,
};
use dualsplit_geometry::Pcg32;
use dualsplit_testkit::oracle::{check_rays, hit_bits};
use dualsplit_testkit::rays::random_rays;
use dualsplit_testkit::scenes::random_scene;

fn toy_kind() -> TreeKind {
    TreeKind::parse("toy").expect("the registry line names the toy `toy`")
}

#[test]
fn the_registry_lists_the_toy() {
    let kind = toy_kind();
    assert!(TreeKind::ALL.contains(&kind));
    let a = AccelKind::parse("toy").expect("its traversal is `toy`");
    assert_eq!(kind.accel_kinds(), [a]);
    assert_eq!(a.tree_kind(), kind);
    assert!(
        AccelKind::names().ends_with("toy"),
        "{}",
        AccelKind::names()
    );
    assert!(kind.rust_type().contains("toy"));
}

#[test]
fn every_set_answers_each_ray_as_the_oracle() {
    let tris = random_scene(5, 300, 0, 1.0);
    let s = Structures::build(&tris, &BuildConfig::default());
    let b = s.tree(TreeKind::REFERENCE).scene_box();
    let rays = random_rays(&mut Pcg32::new(11, 3), &tris, &b, 400);
    // Every kind of the registry, the toy's included.
    check_rays(&s, &tris, &rays);
    let toy = AccelKind::parse("toy").unwrap();
    let set = TreeSet::build(&tris[..], &BuildConfig::default(), &[toy]).unwrap();
    assert_eq!(set.kinds(), [toy]);
    for r in &rays {
        assert_eq!(
            hit_bits(TraversalSet::closest_hit(&set, toy, r, &mut NoObserver)),
            hit_bits(s.closest_hit(AccelKind::REFERENCE, r, &mut NoObserver))
        );
    }
    let miss = Ray::new(Vec3::splat(100.0), Vec3::X);
    assert!(!s.any_hit(toy, &miss, &mut NoObserver));
}

#[test]
fn validation_and_statistics_cover_the_toy() {
    let tris = random_scene(6, 100, 1, 1.0);
    let s = Structures::build(&tris, &BuildConfig::default());
    let reps = s.validate();
    assert_eq!(reps.len(), TreeKind::ALL.len());
    assert!(reps.iter().all(|r| r.is_ok()), "{reps:?}");
    let toy = reps
        .iter()
        .find(|r| r.structure == "toy")
        .expect("a toy report");
    assert_eq!(toy.triangles_referenced, tris.len());
    let stats = s.stats();
    let row = stats.iter().find(|r| r.name == "toy").expect("a toy row");
    assert_eq!(row.bytes_indices, 4 * tris.len() as u64);
    assert_eq!(row.leaves, 1);
}

#[test]
fn the_toy_saves_loads_and_refuses_forged_files() {
    let tris = random_scene(7, 50, 2, 1.0);
    let bvh2 = Bvh2Tree::build(&tris[..], &BuildConfig::default()).unwrap();
    let tree = AnyTree::derive(&bvh2, toy_kind()).unwrap().unwrap();
    assert!(tree.get::<ToyTree>().is_some());
    let bytes = tree.to_bytes();
    let back = AnyTree::from_bytes(&bytes, Some(&tris)).expect("the toy loads back");
    assert_eq!(back.kind(), toy_kind());
    assert_eq!(back.to_bytes(), bytes);
    assert_eq!(back.image().words, tree.image().words);
    // One index word changed, the checksum recomputed: the toy's own check refuses it.
    let mut forged = bytes.clone();
    let at = dualsplit_accel::saved::WORDS_OFFSET as usize;
    forged[at] ^= 1;
    let n = forged.len() - 32;
    use sha2::Digest;
    let sum: [u8; 32] = sha2::Sha256::digest(&forged[..n]).into();
    forged[n..].copy_from_slice(&sum);
    let e = AnyTree::from_bytes(&forged, Some(&tris)).expect_err("a forged toy is refused");
    assert!(e.to_string().contains("toy"), "{e}");
}
