//! Conversion speed bar: converting `dragon_box.ply.gz` (871K triangles) into a
//! DST must take at most 10 % of its BVH2 build time. Both are timed here.
//!
//! `cargo bench -p dualsplit-accel --bench dst_convert`

use dualsplit_accel::dst::{Dst, DstConfig, Partitioning};
use dualsplit_accel::image::Words;
use dualsplit_accel::{BuildConfig, Bvh2, BvhImage, SharedTriangles, WideBvh};
use dualsplit_geometry::Aabb;
use dualsplit_testkit::scenes::shipped_triangles;
use std::sync::OnceLock;

struct Input {
    tris: SharedTriangles,
    boxes: Vec<Aabb>,
    bvh: Bvh2,
}

fn input() -> &'static Input {
    static INPUT: OnceLock<Input> = OnceLock::new();
    INPUT.get_or_init(|| {
        let tris: SharedTriangles = shipped_triangles(&scene_name())
            .expect("the benchmark needs this mesh")
            .into();
        let boxes: Vec<Aabb> = tris.iter().map(|t| t.bounds()).collect();
        let bvh = Bvh2::build(&boxes, &BuildConfig::default());
        Input { tris, boxes, bvh }
    })
}

/// The mesh: `dragon_box.ply.gz` unless `DST_BENCH_SCENE` names another shipped mesh (for
/// quick callgrind runs on a small one).
/// Under `cargo test --benches` (no `--bench` argument) the small `dragon_res4` is used.
fn scene_name() -> String {
    std::env::var("DST_BENCH_SCENE").unwrap_or_else(|_| {
        if !std::env::args().any(|a| a == "--bench") {
            "dragon_res4.ply.gz".into()
        } else {
            "dragon_box.ply.gz".into()
        }
    })
}

fn main() {
    // Correctness before timing: the converted trees validate against their BVH2.
    let i = input();
    for cfg in [DstConfig::hardware(), DstConfig::software()] {
        let dst = Dst::from_bvh2(&i.bvh, i.tris.clone(), &cfg).expect("conversion");
        dst.validate(&i.bvh).expect("valid DST");
        let s = dst.stats();
        eprintln!(
            "{} {cfg:?}: {s:?}\n  DST {:.2} MiB = {:.1} % of BVH2 {:.2} MiB",
            scene_name(),
            s.total_bytes as f64 / 1048576.0,
            s.percent_of_bvh2(),
            s.bvh2_bytes as f64 / 1048576.0
        );
    }
    divan::main();
}

#[divan::bench(sample_count = 5, sample_size = 1)]
fn bvh2_build() -> Bvh2 {
    let i = input();
    Bvh2::build(divan::black_box(&i.boxes), &BuildConfig::default())
}

/// The BVH2 build up to its byte-exact memory image (52-byte nodes, index runs, a copy of the
/// triangles): the same kind of output as the conversion, which also writes an image with
/// its own copy of the triangles.
#[divan::bench(sample_count = 5, sample_size = 1)]
fn bvh2_build_and_image() -> BvhImage {
    let i = input();
    let cfg = BuildConfig::default();
    let boxes: Vec<Aabb> = divan::black_box(&i.tris)
        .iter()
        .map(|t| t.bounds())
        .collect();
    let bvh = Bvh2::build(&boxes, &cfg);
    let wide = WideBvh::from_bvh2(&bvh);
    BvhImage::encode(&wide, &bvh, i.tris.clone(), &cfg, std::time::Duration::ZERO)
        .expect("encoding")
}

/// Words the hardware DST's image allocates (nodes and index runs; the triangles are shared).
fn image_words() -> usize {
    static WORDS: OnceLock<usize> = OnceLock::new();
    *WORDS.get_or_init(|| {
        let i = input();
        Dst::from_bvh2(&i.bvh, i.tris.clone(), &DstConfig::hardware())
            .expect("conversion")
            .image()
            .words
            .len()
    })
}

/// The page-fault floor of writing the converter's image: a fresh [`Words::zeroed`] (a
/// mapping with the transparent-huge-page advice) the size of the hardware DST's node and
/// index regions, one word written per 4 KiB page, so the first touch is timed alone. (A
/// plain `Vec` of that size is no floor: glibc serves it from memory the previous sample
/// freed.)
#[divan::bench(sample_count = 10, sample_size = 1)]
fn image_first_touch_words() -> Words {
    let mut words = Words::zeroed(divan::black_box(image_words()));
    for w in words.iter_mut().step_by(1024) {
        *w = 1;
    }
    words
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn dst_convert_hardware() -> Dst {
    let i = input();
    Dst::from_bvh2(
        divan::black_box(&i.bvh),
        i.tris.clone(),
        &DstConfig::hardware(),
    )
    .unwrap()
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn dst_convert_software() -> Dst {
    let i = input();
    Dst::from_bvh2(
        divan::black_box(&i.bvh),
        i.tris.clone(),
        &DstConfig::software(),
    )
    .unwrap()
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn dst_convert_similar() -> Dst {
    let i = input();
    let cfg = DstConfig::hardware().with_partitioning(Partitioning::Similar);
    Dst::from_bvh2(divan::black_box(&i.bvh), i.tris.clone(), &cfg).unwrap()
}
