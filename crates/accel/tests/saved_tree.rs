//! Saved trees: a saved and reloaded tree answers every ray exactly as the built one; the
//! same tree always gives the same bytes; every single-byte corruption, every truncation,
//! an appended byte, another format version and another scene are rejected with a typed
//! error, never a panic.

use dualsplit_accel::math::{Hit, Ray, Triangle};
use dualsplit_accel::saved::{FORMAT_VERSION, SavedError, WORDS_OFFSET};
use dualsplit_accel::{
    AccelKind, AnyTree, BuildConfig, Bvh2Tree, BvhTree, DstConfig, DstTree, NoObserver, RayQuery,
    TreeKind,
};
use dualsplit_geometry::{Aabb, Pcg32};
use dualsplit_testkit::rays::random_rays;

fn bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.prim.0, h.u.to_bits(), h.v.to_bits()))
}

fn trees(tris: &[Triangle]) -> Vec<AnyTree> {
    let bvh2 = Bvh2Tree::build(tris, &BuildConfig::default()).expect("bvh2");
    let mut out: Vec<AnyTree> = [TreeKind::Bvh2, TreeKind::Bvh4, TreeKind::Bvh8]
        .into_iter()
        .map(|k| {
            BvhTree::from_bvh2(&bvh2, k)
                .expect("bvh")
                .expect("encode")
                .into()
        })
        .collect();
    out.push(
        DstTree::from_bvh2(&bvh2, &DstConfig::hardware())
            .expect("dst")
            .into(),
    );
    out.push(
        DstTree::from_bvh2(&bvh2, &DstConfig::software())
            .expect("dst")
            .into(),
    );
    out
}

fn scene(spec: &str) -> Vec<Triangle> {
    dualsplit_scene::load(spec).expect("builtin").triangles
}

fn rays(tris: &[Triangle], n: usize) -> Vec<Ray> {
    let b = tris.iter().fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
    random_rays(&mut Pcg32::new(5, 3), tris, &b, n)
}

#[test]
fn a_reloaded_tree_answers_every_ray_as_the_built_one() {
    let tris = scene("builtin:forest?triangles=20000");
    let rays = rays(&tris, if cfg!(debug_assertions) { 500 } else { 20_000 });
    let dir = tempfile::tempdir().expect("tempdir");
    for (i, tree) in trees(&tris).into_iter().enumerate() {
        let path = dir.path().join(format!("t{i}.dstree"));
        tree.save(&path).expect("save");
        let back = AnyTree::load(&path, Some(&tris)).expect("load");
        assert_eq!(back.kind(), tree.kind());
        assert_eq!(back.image().words, tree.image().words);
        assert_eq!(back.image().nodes, tree.image().nodes);
        assert_eq!(back.image().indices, tree.image().indices);
        assert_eq!(back.triangles(), &tris[..]);
        assert_eq!(back.config(), tree.config());
        assert_eq!(back.stats().bytes_total(), tree.stats().bytes_total());
        assert_eq!(back.stats().build_ms, 0.0);
        if let (AnyTree::Dst(a), AnyTree::Dst(b)) = (&back, &tree) {
            assert_eq!(a.dst().scene_box(), b.dst().scene_box());
            assert_eq!(a.dst().config(), b.dst().config());
            assert_eq!(a.dst().stats(), b.dst().stats());
        }
        let mut hits = 0;
        for (j, r) in rays.iter().enumerate() {
            for &k in tree.kind().accel_kinds() {
                let want = tree.closest_hit(k, r, &mut NoObserver).expect("kind");
                hits += want.is_some() as usize;
                let got = back.closest_hit(k, r, &mut NoObserver).expect("kind");
                assert_eq!(bits(got), bits(want), "{} {k:?} ray {j}", tree.kind());
                assert_eq!(
                    back.any_hit(k, r, &mut NoObserver),
                    tree.any_hit(k, r, &mut NoObserver),
                    "{} {k:?} shadow ray {j}",
                    tree.kind()
                );
            }
        }
        assert!(hits > rays.len() / 10, "too few hits ({hits})");
        // Saving the reloaded tree gives the same file.
        assert_eq!(back.to_bytes(), std::fs::read(&path).expect("read"));
    }
}

#[test]
fn the_same_tree_gives_the_same_bytes() {
    let tris = scene("builtin:atrium?triangles=15000");
    let a: Vec<Vec<u8>> = trees(&tris).iter().map(AnyTree::to_bytes).collect();
    let b: Vec<Vec<u8>> = trees(&tris).iter().map(AnyTree::to_bytes).collect();
    assert_eq!(a, b);
    for (bytes, kind) in a.iter().zip([
        TreeKind::Bvh2,
        TreeKind::Bvh4,
        TreeKind::Bvh8,
        TreeKind::Dst,
        TreeKind::Dst,
    ]) {
        assert_eq!(
            AnyTree::from_bytes(bytes, Some(&tris))
                .expect("load")
                .kind(),
            kind
        );
    }
}

/// Every single-byte change of every kind's file is rejected (each byte flipped in one bit
/// and in all bits), and so is every truncation and an appended byte.
#[test]
fn every_corruption_and_truncation_is_rejected() {
    let tris = scene("builtin:cornell");
    for tree in trees(&tris) {
        let good = tree.to_bytes();
        assert!(good.len() as u64 > WORDS_OFFSET);
        AnyTree::from_bytes(&good, Some(&tris)).expect("the good file loads");
        let mut bad = good.clone();
        for i in 0..good.len() {
            for flip in [0x01u8, 0xff] {
                bad[i] ^= flip;
                let r = AnyTree::from_bytes(&bad, None);
                assert!(r.is_err(), "{}: byte {i} ^ {flip:#x} accepted", tree.kind());
                bad[i] ^= flip;
            }
        }
        for n in 0..good.len() {
            let r = AnyTree::from_bytes(&good[..n], None);
            assert!(
                r.is_err(),
                "{}: truncation to {n} bytes accepted",
                tree.kind()
            );
        }
        let mut long = good.clone();
        long.push(0);
        assert!(matches!(
            AnyTree::from_bytes(&long, None),
            Err(SavedError::Length { .. })
        ));
    }
}

#[test]
fn wrong_magic_version_and_scene_are_named() {
    let tris = scene("builtin:cornell");
    let tree = trees(&tris).remove(3);
    let good = tree.to_bytes();

    let mut v = good.clone();
    v[8..12].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    match AnyTree::from_bytes(&v, None) {
        Err(SavedError::UnsupportedVersion { found, supported }) => {
            assert_eq!((found, supported), (FORMAT_VERSION + 1, FORMAT_VERSION));
        }
        r => panic!("expected UnsupportedVersion, got {r:?}"),
    }

    let mut m = good.clone();
    m[0] = b'X';
    assert!(matches!(
        AnyTree::from_bytes(&m, None),
        Err(SavedError::NotATree)
    ));
    assert!(matches!(
        AnyTree::from_bytes(b"hello", None),
        Err(SavedError::NotATree)
    ));

    let mut c = good.clone();
    let last = c.len() - 1;
    c[last] ^= 0x80;
    assert!(matches!(
        AnyTree::from_bytes(&c, None),
        Err(SavedError::Checksum)
    ));

    let other = scene("builtin:cornell?subdiv=2");
    let e = AnyTree::from_bytes(&good, Some(&other)).expect_err("wrong scene");
    assert!(matches!(e, SavedError::WrongScene { .. }), "{e}");

    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("t.dstree");
    std::fs::write(&path, &good[..good.len() / 2]).expect("write");
    let e = AnyTree::load(&path, None).expect_err("truncated");
    assert!(e.to_string().contains("t.dstree"), "{e}");
    assert!(matches!(e.cause(), SavedError::Length { .. }), "{e}");
    let e = AnyTree::load(dir.path().join("missing"), None).expect_err("missing");
    assert!(matches!(e, SavedError::Io { .. }), "{e}");
}

#[test]
fn both_dst_decodings_read_a_loaded_dst() {
    let tris = scene("builtin:cornell");
    let tree = trees(&tris).remove(3);
    let back = AnyTree::from_bytes(&tree.to_bytes(), Some(&tris)).expect("load");
    let AnyTree::Dst(d) = &back else {
        panic!("a DST");
    };
    for r in rays(&tris, 2000) {
        assert_eq!(bits(d.intersect(&r)), bits(d.pipeline().intersect(&r)));
        assert_eq!(
            bits(
                back.closest_hit(AccelKind::DST_PIPELINE, &r, &mut NoObserver)
                    .expect("dst")
            ),
            bits(d.intersect(&r))
        );
    }
}

/// The seeds of the `tree` fuzz target (`fuzz/seeds/tree`) are the files this code writes
/// for 12 triangles of the Cornell box, one of each kind (both DST presets), so they stay
/// valid when the format changes: `DUALSPLIT_WRITE_SEEDS=1 cargo test -p dualsplit-accel
/// --test saved_tree fuzz_seeds` rewrites them.
#[test]
fn fuzz_seeds_are_the_files_this_code_writes() {
    let tris = &scene("builtin:cornell")[..12];
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/tree");
    let write = std::env::var_os("DUALSPLIT_WRITE_SEEDS").is_some();
    let names = ["bvh2", "bvh4", "bvh8", "dst", "dst_software"];
    for (tree, name) in trees(tris).iter().zip(names) {
        let bytes = tree.to_bytes();
        let path = dir.join(name);
        if write {
            std::fs::create_dir_all(&dir).expect("seed folder");
            std::fs::write(&path, &bytes).expect("write seed");
        }
        let seed = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            seed == bytes,
            "{} is not the file this code writes; rerun with DUALSPLIT_WRITE_SEEDS=1",
            path.display()
        );
        assert!(seed.len() < 8 << 10, "{name}: {} bytes", seed.len());
        let back = AnyTree::from_bytes(&seed, Some(tris)).expect("a seed loads");
        assert_eq!(back.to_bytes(), seed);
    }
}
