//! Build benchmarks on `dragon_box.ply.gz` (871K triangles): the BVH2 build (speed bar:
//! ≤ 1.0 s on the 2-core machine) and the BVH4/BVH8 collapses.
//!
//! Run: `cargo bench -p dualsplit-accel --bench build`. Before timing it prints the size
//! table of the three structures (the paper's Table 3) once.

use dualsplit_accel::{BuildConfig, Bvh2, CollapseConfig, Structures, WideBvh};
use dualsplit_geometry::Aabb;
use dualsplit_testkit::scenes::shipped;
use std::sync::OnceLock;

fn boxes() -> &'static Vec<Aabb> {
    static B: OnceLock<Vec<Aabb>> = OnceLock::new();
    B.get_or_init(|| {
        let scene = shipped("dragon_box.ply.gz").expect("the benchmark needs this mesh");
        scene.triangles.iter().map(|t| t.bounds()).collect()
    })
}

fn bvh() -> &'static Bvh2 {
    static B: OnceLock<Bvh2> = OnceLock::new();
    B.get_or_init(|| Bvh2::build(boxes(), &BuildConfig::default()))
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn bvh2_build_dragon_box() -> Bvh2 {
    Bvh2::build(divan::black_box(boxes()), &BuildConfig::default())
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn bvh4_collapse_dragon_box() -> WideBvh {
    WideBvh::collapse_bvh4(divan::black_box(bvh()))
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn bvh8_collapse_dragon_box() -> WideBvh {
    WideBvh::collapse_bvh8(divan::black_box(bvh()), &CollapseConfig::default())
}

/// CPU seconds (user + system) of this process so far, from `/proc/self/stat` (100 Hz ticks).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = rest
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    if f.len() > 13 {
        (f[11] + f[12]) / 100.0
    } else {
        0.0
    }
}

fn main() {
    // The shared machine is loaded; CPU time tells what the build would take on idle cores.
    let (t, c) = (std::time::Instant::now(), cpu_seconds());
    let b = Bvh2::build(boxes(), &BuildConfig::default());
    eprintln!(
        "one BVH2 build: wall {:.3} s, CPU {:.3} s ({} nodes)",
        t.elapsed().as_secs_f64(),
        cpu_seconds() - c,
        b.nodes.len()
    );
    let scene = shipped("dragon_box.ply.gz").expect("the benchmark needs this mesh");
    let s = Structures::build(&scene.triangles, &BuildConfig::default());
    for st in s.stats() {
        eprintln!(
            "{:5} internal {:>8} leaves {:>8} nodes {:>7.2} MiB indices {:>5.2} MiB total {:>7.2} MiB ({:5.1} %) SAH {:.2} time {:.1} ms",
            st.name,
            st.internal_nodes,
            st.leaves,
            st.bytes_nodes as f64 / dualsplit_accel::stats::MIB,
            st.bytes_indices as f64 / dualsplit_accel::stats::MIB,
            st.bytes_total as f64 / dualsplit_accel::stats::MIB,
            st.percent_of_bvh2,
            st.sah_cost,
            st.build_ms
        );
    }
    divan::main();
}
