//! The fast converter decides exactly what the original one did: for fixed scenes and every
//! preset, the converted tree's stats (node counts by kind, bytes) and an FNV-1a hash of the
//! whole memory image equal the values recorded from the converter *before* the speed work
//! (branch `dstfast`, commit 8363980, by running this test once with the old `from_bvh2.rs`
//! / `encode.rs` and copying its output). Any changed decision (another chain, another
//! child order, another layout) changes the hash. (The BVH2 builder is part of the input: if its output changes, the
//! values must be re-recorded from the old converter on the new BVH.)

mod dst_common;

use dst_common::{build, load_shipped};
use dualsplit_accel::MemoryImage;
use dualsplit_accel::dst::{DstConfig, Partitioning};

/// FNV-1a of the whole image's bytes (nodes, indices, triangles: the same byte string as
/// when the triangles were a copy at the end of the image's words).
fn fnv1a(img: &MemoryImage) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in img.to_bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

fn presets() -> [(&'static str, DstConfig); 4] {
    [
        ("hardware", DstConfig::hardware()),
        ("software", DstConfig::software()),
        (
            "hardware-similar",
            DstConfig::hardware().with_partitioning(Partitioning::Similar),
        ),
        (
            "software-similar",
            DstConfig::software().with_partitioning(Partitioning::Similar),
        ),
    ]
}

/// `(splitting, single, dual, leaves, carving_leaves, index_entries, node_bytes, hash)`.
type Golden = (u64, u64, u64, u64, u64, u64, u64, u64);

fn check(scene: &str, expected: &[Golden; 4]) {
    let tris = load_shipped(scene);
    let mut all = Vec::new();
    for (name, cfg) in presets() {
        let b = build(&tris, &cfg);
        let s = b.dst.stats();
        let got = (
            s.splitting,
            s.single_carving,
            s.dual_carving,
            s.leaves,
            s.carving_leaves,
            s.index_entries,
            s.node_bytes,
            fnv1a(b.dst.image()),
        );
        println!("{scene} {name}: {got:?}");
        all.push((name, got));
    }
    for ((name, got), want) in all.iter().zip(expected) {
        assert_eq!(got, want, "{scene} {name}: stats or image changed");
    }
}

#[test]
fn dragon_res4_unchanged() {
    check("dragon_res4.ply.gz", &GOLDEN_RES4);
}

#[test]
fn bunny_unchanged() {
    check("bunny.ply.gz", &GOLDEN_BUNNY);
}

/// Recorded from the converter before the speed work (commit 8363980); presets in the order
/// of [`presets`].
const GOLDEN_RES4: [Golden; 4] = [
    (
        5557,
        5829,
        5183,
        731,
        4827,
        11102,
        201752,
        8161748869877617883,
    ),
    (
        5557,
        8544,
        3189,
        698,
        4860,
        11102,
        210272,
        8532281034258634742,
    ),
    (
        5557,
        3491,
        3908,
        3842,
        1716,
        11102,
        170840,
        9164611358340817780,
    ),
    (
        5557,
        6846,
        1865,
        2917,
        2641,
        11102,
        182884,
        17840876450810734692,
    ),
];
/// Recorded as [`GOLDEN_RES4`].
const GOLDEN_BUNNY: [Golden; 4] = [
    (
        37367,
        28581,
        48864,
        2599,
        34769,
        69451,
        1388140,
        18311695276340556155,
    ),
    (
        37367,
        39470,
        40409,
        2594,
        34774,
        69451,
        1417328,
        8720189899266357446,
    ),
    (
        37367,
        16432,
        31121,
        30182,
        7186,
        69451,
        1139768,
        8046536055577755576,
    ),
    (
        37367,
        35129,
        21432,
        22936,
        14432,
        69451,
        1218880,
        8513990613833046186,
    ),
];

/// The image does not depend on the thread count (the parallel subtrees are appended in a
/// fixed depth-first order).
#[test]
fn same_image_for_any_thread_count() {
    use dualsplit_accel::dst::Dst;
    let tris = load_shipped("bunny.ply.gz");
    let b = build(&tris, &DstConfig::hardware());
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        let dst = pool.install(|| Dst::from_bvh2(&b.bvh, &tris[..], &DstConfig::hardware()));
        let dst = dst.expect("conversion");
        assert_eq!(
            dst.image().words,
            b.dst.image().words,
            "{threads} threads: image differs"
        );
    }
}
