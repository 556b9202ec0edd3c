//! Saved trees: a saved and reloaded tree answers every ray exactly as the built one; the
//! same tree always gives the same bytes; every single-byte corruption, every truncation,
//! an appended byte, another format version and another scene are rejected with a typed
//! error, never a panic.

use dualsplit_accel::dstq::DstQConfig;
use dualsplit_accel::image::RUN_END;
use dualsplit_accel::math::{Hit, Ray, Triangle};
use dualsplit_accel::saved::{FORMAT_VERSION, SavedError, WORDS_OFFSET};
use dualsplit_accel::{
    AccelKind, AnyTree, BuildConfig, Bvh2Tree, BvhTree, CwbvhTree, DstConfig, DstQTree, DstTree,
    NoObserver, RayQuery, TreeKind,
};
use dualsplit_geometry::{Aabb, Pcg32};
use dualsplit_testkit::rays::random_rays;

fn bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.prim.0, h.u.to_bits(), h.v.to_bits()))
}

fn trees(tris: &[Triangle]) -> Vec<AnyTree> {
    trees_of(&Bvh2Tree::build(tris, &BuildConfig::default()).expect("bvh2"))
}

/// Every kind of tree from `bvh2`: BVH2, BVH4, BVH8, both DST presets, the compressed BVH8
/// and the quantized DST.
fn trees_of(bvh2: &Bvh2Tree) -> Vec<AnyTree> {
    let mut out: Vec<AnyTree> = [TreeKind::Bvh2, TreeKind::Bvh4, TreeKind::Bvh8]
        .into_iter()
        .map(|k| {
            BvhTree::from_bvh2(bvh2, k)
                .expect("bvh")
                .expect("encode")
                .into()
        })
        .collect();
    out.push(
        DstTree::from_bvh2(bvh2, &DstConfig::hardware())
            .expect("dst")
            .into(),
    );
    out.push(
        DstTree::from_bvh2(bvh2, &DstConfig::software())
            .expect("dst")
            .into(),
    );
    out.push(CwbvhTree::from_bvh2(bvh2).expect("cwbvh").into());
    out.push(
        DstQTree::from_bvh2(bvh2, &DstQConfig::default())
            .expect("dst-q")
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
        if let (AnyTree::DstQ(a), AnyTree::DstQ(b)) = (&back, &tree) {
            assert_eq!(a.dstq().scene_box(), b.dstq().scene_box());
            assert_eq!(a.dstq().config(), b.dstq().config());
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
        TreeKind::Cwbvh,
        TreeKind::DstQ,
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
    let names = [
        "bvh2",
        "bvh4",
        "bvh8",
        "dst",
        "dst_software",
        "cwbvh",
        "dst_q",
    ];
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

// ---- Forged files: a recomputed checksum, a structural error ----------------------------

/// Rewrites the checksum at the end of `file` to match its contents, as a forger would.
fn reseal(file: &mut [u8]) {
    use sha2::{Digest, Sha256};
    let n = file.len() - 32;
    let sum: [u8; 32] = Sha256::digest(&file[..n]).into();
    file[n..].copy_from_slice(&sum);
}

/// Byte offset of image word `w` in a saved file.
fn at(w: usize) -> usize {
    WORDS_OFFSET as usize + 4 * w
}

fn word(file: &[u8], w: usize) -> u32 {
    u32::from_le_bytes(file[at(w)..at(w) + 4].try_into().expect("4 bytes"))
}

fn set_word(file: &mut [u8], w: usize, v: u32) {
    file[at(w)..at(w) + 4].copy_from_slice(&v.to_le_bytes());
}

/// `good` with `change` applied to its words and the checksum recomputed.
fn forge(good: &[u8], change: impl FnOnce(&mut Vec<u8>)) -> Vec<u8> {
    let mut f = good.to_vec();
    change(&mut f);
    reseal(&mut f);
    f
}

/// Loads a forged file: it must fail with [`SavedError::Structure`] at `want_word`, naming
/// `want` in its message.
#[track_caller]
fn expect_structure(file: &[u8], want_word: usize, want: &str, case: &str) {
    match AnyTree::from_bytes(file, None) {
        Err(SavedError::Structure {
            structure,
            word,
            what,
        }) => {
            assert_eq!(word, want_word as u64, "{case}: {structure}: {what}");
            assert!(what.contains(want), "{case}: {structure}: {what}");
            let e = AnyTree::from_bytes(file, None).expect_err("same");
            assert!(
                e.to_string().contains(&format!("at word {want_word}")),
                "{e}"
            );
        }
        r => panic!(
            "{case}: expected a structure error, got {:?}",
            r.map(|t| t.kind())
        ),
    }
}

/// The offset word of a BVH root node and its offset field's mask.
fn bvh_offset_word(kind: TreeKind) -> (usize, u32) {
    match kind {
        TreeKind::Bvh2 => (12, (1 << 30) - 1),
        TreeKind::Bvh4 => (24, (1 << 28) - 1),
        _ => (48, u32::MAX),
    }
}

#[test]
fn forged_bvh_files_are_structure_errors() {
    let tris = scene("builtin:cornell");
    for tree in trees(&tris).into_iter().take(3) {
        let kind = tree.kind();
        let good = tree.to_bytes();
        let img = tree.image();
        let (nodes, indices) = (img.nodes.clone(), img.indices.clone());
        let (ow, mask) = bvh_offset_word(kind);
        let root = word(&good, ow);
        let case = |s: &str| format!("{kind} {s}");
        // A child block beyond the node region.
        let f = forge(&good, |f| set_word(f, ow, root | mask));
        expect_structure(&f, 0, "leaves the node region", &case("offset"));
        // The root's children are the root itself: a cycle.
        let f = forge(&good, |f| set_word(f, ow, root & !mask));
        expect_structure(&f, 0, "in the layout it is at word", &case("cycle"));
        // A triangle id beyond the triangle count (the run end bit kept).
        let e = word(&good, indices.start);
        let f = forge(&good, |f| {
            set_word(f, indices.start, (e & RUN_END) | tris.len() as u32)
        });
        let want = format!("names triangle {}", tris.len());
        expect_structure(&f, indices.start, &want, &case("id"));
        // The last run's end removed: it would run off the index region. The error names
        // the leaf word of that run (the node-region word that starts it).
        let last = indices.end - 1;
        let last_start = (indices.start..last)
            .rev()
            .find(|&j| word(&good, j) & RUN_END != 0)
            .map_or(indices.start, |j| j + 1);
        let last_leaf = (nodes.clone())
            .rev()
            .find(|&w| word(&good, w) as usize == last_start)
            .expect("the last leaf word");
        let f = forge(&good, |f| set_word(f, last, word(&good, last) & !RUN_END));
        expect_structure(&f, last_leaf, "does not end", &case("run end"));
        // The first run's end removed: it runs into the next run.
        let first_end = (indices.start..indices.end)
            .find(|&j| word(&good, j) & RUN_END != 0)
            .expect("a run");
        assert!(first_end < last, "{kind}: one run only");
        let f = forge(&good, |f| {
            set_word(f, first_end, word(&good, first_end) & !RUN_END)
        });
        match AnyTree::from_bytes(&f, None) {
            Err(SavedError::Structure { what, .. }) => {
                assert!(what.contains("the next run is at word"), "{kind}: {what}")
            }
            r => panic!("{kind}: overlapping runs: {:?}", r.map(|t| t.kind())),
        }
        // A leaf word pointing outside the index region (the first leaf word found in a
        // node region of boxes and leaf words: a word whose value starts a run).
        let leaf = (nodes.clone())
            .find(|&w| word(&good, w) as usize == indices.start)
            .expect("the first leaf word");
        let f = forge(&good, |f| set_word(f, leaf, indices.end as u32));
        match AnyTree::from_bytes(&f, None) {
            Err(SavedError::Structure { word, what, .. }) => {
                assert_eq!(word, leaf as u64, "{kind}: {what}");
                assert!(what.contains("the next run is at word"), "{kind}: {what}");
            }
            r => panic!("{kind}: leaf word: {:?}", r.map(|t| t.kind())),
        }
        // The header's counts must be the tree's.
        let mut f = good.clone();
        let leaves_at = header_bvh_leaves(&good, &tree);
        f[leaves_at] ^= 1;
        reseal(&mut f);
        expect_structure(&f, 0, "its header says", &case("counts"));
        // A byte in the zero padding (found by the fuzz target: it loaded, and wrote back
        // a file without it).
        let f = forge(&good, |f| f[2595] = 1);
        match AnyTree::from_bytes(&f, None) {
            Err(SavedError::Malformed(m)) => assert!(m.contains("header byte 2595"), "{m}"),
            r => panic!("{kind}: padding: {:?}", r.map(|t| t.kind())),
        }
        // The untouched file still loads.
        AnyTree::from_bytes(&good, Some(&tris)).expect("the good file loads");
    }
}

/// Byte offset of the header's BVH leaf count (found by its value, after the internal-node
/// count).
fn header_bvh_leaves(file: &[u8], tree: &AnyTree) -> usize {
    let (n, l) = (tree.stats().internal_nodes, tree.stats().leaves);
    let mut want = n.to_le_bytes().to_vec();
    want.extend(l.to_le_bytes());
    let at = file[..512]
        .windows(16)
        .position(|w| w == want)
        .expect("the counts in the header");
    at + 8
}

#[test]
fn forged_dst_files_are_structure_errors() {
    let tris = scene("builtin:cornell");
    // The two DSTs (hardware and software presets).
    for tree in trees(&tris).into_iter().skip(3).take(2) {
        let good = tree.to_bytes();
        let img = tree.image();
        let (nodes, indices) = (img.nodes.clone(), img.indices.clone());
        let root = word(&good, 0);
        let h = dualsplit_accel::dst::HeaderOffset::from_bits(root);
        assert!(
            h.is_split() || (h.is_carving() && !h.is_leaf_flag()),
            "{h:?}"
        );
        let off = (1u32 << 26) - 1;
        // A child beyond the node region.
        let f = forge(&good, |f| set_word(f, 0, root | off));
        expect_structure(&f, 0, "outside the node region", "dst offset");
        // The root's child is the root: a cycle.
        let f = forge(&good, |f| set_word(f, 0, root & !off));
        expect_structure(&f, 0, "in the layout it is at word", "dst cycle");
        // An invalid header code (C = 0, L = 0, A = 11: no splitting axis 3).
        let f = forge(&good, |f| set_word(f, 0, (0b011010 << 26) | (root & off)));
        expect_structure(&f, 0, "invalid node header", "dst header");
        // A triangle id beyond the triangle count.
        let e = word(&good, indices.start);
        let f = forge(&good, |f| {
            set_word(f, indices.start, (e & RUN_END) | 1_000_000)
        });
        expect_structure(&f, indices.start, "names triangle 1000000", "dst id");
        // The last run's end removed.
        let last = indices.end - 1;
        let f = forge(&good, |f| set_word(f, last, word(&good, last) & !RUN_END));
        match AnyTree::from_bytes(&f, None) {
            Err(SavedError::Structure { what, .. }) => {
                assert!(what.contains("does not end"), "dst run end: {what}")
            }
            r => panic!("dst run end: {:?}", r.map(|t| t.kind())),
        }
        // A plain leaf whose run starts beyond the index region.
        let leaf = (nodes.clone())
            .find(|&w| {
                let h = dualsplit_accel::dst::HeaderOffset::from_bits(word(&good, w));
                h.is_plain_leaf() && h.offset() == 0
            })
            .or_else(|| {
                (nodes.clone()).find(|&w| {
                    let h = dualsplit_accel::dst::HeaderOffset::from_bits(word(&good, w));
                    h.is_carving() && h.is_leaf_flag() && h.offset() == 0
                })
            })
            .expect("the leaf of run 0");
        let f = forge(&good, |f| {
            set_word(f, leaf, word(&good, leaf) | (indices.len() as u32))
        });
        expect_structure(&f, leaf, "the next run is at word", "dst leaf run");
        AnyTree::from_bytes(&good, Some(&tris)).expect("the good file loads");
    }
}

#[test]
fn tiny_trees_load() {
    let all = scene("builtin:cornell");
    for n in [0, 1, 2, 3] {
        let tris = &all[..n];
        let Ok(bvh2) = Bvh2Tree::build(tris, &BuildConfig::default()) else {
            assert!(n == 0, "{n} triangles do not build");
            continue;
        };
        let ts = trees_of(&bvh2);
        for t in ts {
            let back = AnyTree::from_bytes(&t.to_bytes(), Some(tris))
                .unwrap_or_else(|e| panic!("{} of {n} triangles: {e}", t.kind()));
            assert_eq!(back.kind(), t.kind());
        }
    }
}

/// Many random word changes of every kind's file, each with a recomputed checksum: the load
/// is a tree or a typed error, never a panic, and a loaded tree answers rays through every
/// traversal in bounded time (a cycle or an exponential walk would time out).
#[test]
fn random_forgeries_load_or_fail_typed_and_traverse_in_bounded_time() {
    let tris = scene("builtin:cornell");
    let trials = if cfg!(debug_assertions) { 300 } else { 4000 };
    let rays = rays(&tris, 8);
    let (tx, rx) = std::sync::mpsc::channel();
    for (i, tree) in trees(&tris).into_iter().enumerate() {
        let (tx, tris, rays) = (tx.clone(), tris.clone(), rays.clone());
        std::thread::spawn(move || {
            let good = tree.to_bytes();
            let words = tree.image().indices.end;
            let mut rng = Pcg32::new(77, i as u64);
            let (mut ok, mut structure, mut other) = (0usize, 0usize, 0usize);
            for _ in 0..trials {
                let mut f = good.clone();
                for _ in 0..1 + rng.next_u32() % 3 {
                    let w = rng.next_u32() as usize % words;
                    let old = word(&f, w);
                    let new = match rng.next_u32() % 4 {
                        0 => old ^ (1 << (rng.next_u32() % 32)),
                        1 => rng.next_u32(),
                        // A plausible offset or index, keeping the high bits (types, header).
                        2 => (old & 0xfc00_0000) | (rng.next_u32() % words as u32),
                        _ => old & !(rng.next_u32() % 64),
                    };
                    set_word(&mut f, w, new);
                }
                reseal(&mut f);
                match AnyTree::from_bytes(&f, None) {
                    Ok(t) => {
                        ok += 1;
                        // An accepted file is the file its tree writes (the header's
                        // triangle hash, bytes 56–87, is not checked without a scene).
                        let back = t.to_bytes();
                        let n = f.len() - 32;
                        assert!(
                            back[..56] == f[..56] && back[88..n] == f[88..n],
                            "{}: an accepted forgery writes back other bytes",
                            t.kind()
                        );
                        for r in &rays {
                            for &k in t.kind().accel_kinds() {
                                let _ = t.closest_hit(k, r, &mut NoObserver);
                                let _ = t.any_hit(k, r, &mut NoObserver);
                            }
                            let _ = t.intersect(r);
                            let _ = t.occluded(r);
                            if let AnyTree::Dst(d) = &t {
                                let _ = d.pipeline().intersect(r);
                                let _ = d.pipeline().occluded(r);
                            }
                        }
                    }
                    Err(SavedError::Structure { .. }) => structure += 1,
                    Err(_) => other += 1,
                }
            }
            let _ = tris;
            tx.send((tree.kind(), ok, structure, other)).expect("send");
        });
    }
    drop(tx);
    let mut seen = 0;
    while seen < 7 {
        let (kind, ok, structure, other) = rx
            .recv_timeout(std::time::Duration::from_secs(120))
            .expect("a forgery thread panicked or did not finish in 120 s");
        assert_eq!(ok + structure + other, trials);
        // Box and plane words are not checked, so some forgeries load; offsets, runs and
        // ids are, so many do not.
        assert!(ok > trials / 20, "{kind}: {ok} of {trials} loaded");
        assert!(
            structure > trials / 5,
            "{kind}: {structure} of {trials} structure errors"
        );
        assert_eq!(other, 0, "{kind}: errors other than structure errors");
        seen += 1;
    }
}

/// `file` with the little-endian `bytes` at header byte `at`, resealed.
fn forge_header(file: &[u8], at: usize, bytes: &[u8]) -> Vec<u8> {
    forge(file, |f| f[at..at + bytes.len()].copy_from_slice(bytes))
}

#[test]
fn forged_header_settings_and_scene_boxes_are_refused() {
    let tris = scene("builtin:cornell");
    for tree in trees(&tris) {
        let good = tree.to_bytes();
        let name = tree.kind().name();
        AnyTree::from_bytes(&good, Some(&tris)).expect("the good file loads");
        // Build settings (bytes 88–107) once loaded unchecked.
        for (at, bytes, says) in [
            (88, 0u32.to_le_bytes(), "max_leaf_size is 0"),
            (100, 0u32.to_le_bytes(), "bins is 0"),
            (100, u32::MAX.to_le_bytes(), "bins is 4294967295"),
            (92, f32::NAN.to_le_bytes(), "cost_traversal is NaN"),
            (96, (-1.0f32).to_le_bytes(), "cost_triangle is -1"),
        ] {
            let e =
                AnyTree::from_bytes(&forge_header(&good, at, &bytes), Some(&tris)).expect_err(name);
            assert!(matches!(e, SavedError::Malformed(_)), "{name}: {e}");
            assert!(e.to_string().contains(says), "{name}: {e}");
        }
        // The DST's costs, and the scene box where the DST and DST-Q traversals start: a
        // DST-Q box of x = ±inf once passed `check` and simulated differently.
        let box_at = match tree.kind() {
            TreeKind::Dst => {
                let e = AnyTree::from_bytes(
                    &forge_header(&good, 112, &f32::INFINITY.to_le_bytes()),
                    Some(&tris),
                )
                .expect_err(name);
                assert!(
                    e.to_string().contains("DST cost single_carve is inf"),
                    "{e}"
                );
                128
            }
            TreeKind::DstQ => 116,
            _ => continue,
        };
        for (off, v) in [
            (0, f32::NEG_INFINITY),
            (12, f32::INFINITY),
            (4, -1e30),
            (16, 0.5),
        ] {
            let f = forge_header(&good, box_at + off, &v.to_le_bytes());
            let e = AnyTree::from_bytes(&f, Some(&tris)).expect_err(name);
            assert!(
                e.to_string()
                    .contains("is not the bounds of the file's triangles"),
                "{name}: {e}"
            );
        }
    }
}

#[test]
fn settings_a_load_would_refuse_are_not_saved() {
    let tris = scene("builtin:cornell");
    let odd = BuildConfig {
        bins: 0,
        max_leaf_size: 0,
        ..BuildConfig::default()
    };
    // The builder clamps these, and the file records what it used.
    let bvh2 = Bvh2Tree::build(&tris[..], &odd).expect("bvh2");
    let any: AnyTree = BvhTree::from_bvh2(&bvh2, TreeKind::Bvh2)
        .expect("bvh")
        .expect("encode")
        .into();
    AnyTree::from_bytes(&any.to_bytes(), Some(&tris)).expect("clamped settings load");
    let nan = BuildConfig {
        cost_traversal: f32::NAN,
        ..BuildConfig::default()
    };
    let bvh2 = Bvh2Tree::build(&tris[..], &nan).expect("bvh2");
    let any: AnyTree = BvhTree::from_bvh2(&bvh2, TreeKind::Bvh2)
        .expect("bvh")
        .expect("encode")
        .into();
    let e = any
        .write_to(Vec::new())
        .expect_err("a NaN cost is not saved");
    assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
    assert!(any.to_bytes().is_empty());
}
