//! Scene loading speed (the bar: `dragon_sponza.ply.gz`, 6.2M triangles, in at most 3 s),
//! with its components measured separately: reading, gzip inflation, PLY parsing and the
//! whole `load_file` (which also applies the degenerate/non-finite rule and bounds).
//!
//! `cargo bench -p dualsplit-scene --bench load`. The figures are in `docs/performance.md`.

use dualsplit_scene::load::{self, Format};
use std::path::PathBuf;

fn main() {
    divan::main();
}

/// A shipped scene, by file name.
fn scene(name: &str) -> PathBuf {
    dualsplit_testkit::scenes::shipped_path(name).expect("the benchmark needs this mesh")
}

const SCENES: &[&str] = &["dragon_box.ply.gz", "dragon_sponza.ply.gz"];

/// The whole load: read, inflate, parse, build triangles, drop/count, bounds.
#[divan::bench(args = SCENES, sample_count = 3, sample_size = 1)]
fn load_file(name: &str) -> usize {
    let s = load::load_file(&scene(name)).expect("shipped scene loads");
    s.triangles.len()
}

/// Reading the compressed file and inflating it.
#[divan::bench(args = SCENES, sample_count = 3, sample_size = 1)]
fn read_and_gunzip(name: &str) -> usize {
    let p = scene(name);
    let raw = std::fs::read(&p).expect("readable");
    load::maybe_gunzip(&p, raw).expect("gzip").len()
}

/// Parsing the inflated PLY bytes into triangles (no I/O, no inflation).
#[divan::bench(args = SCENES, sample_count = 3, sample_size = 1)]
fn parse_ply(bencher: divan::Bencher, name: &str) {
    let p = scene(name);
    let bytes = load::maybe_gunzip(&p, std::fs::read(&p).expect("readable")).expect("gzip");
    bencher.bench(|| {
        load::parse_bytes(&p, Format::Ply, &bytes)
            .expect("parses")
            .triangles
            .len()
    });
}
