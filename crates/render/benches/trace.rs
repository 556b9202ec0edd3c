//! Divan benchmarks of the renderer on a synthetic room (two boxes and a 16K-triangle
//! sphere): a small frame per structure and workload, and single-ray-kind throughput over
//! rays checked against BVH2 first (`dualsplit_render::bench::verify`).
//!
//! Run with `cargo bench -p dualsplit-render`. Figures for real scenes come from
//! `dualsplit bench` (see docs/performance.md).

use dualsplit_accel::{AccelKind, BuildConfig, NoObserver, Structures};
use dualsplit_render::bench::{RaySet, ray_sets, verify};
use dualsplit_render::{RayQuery, RenderSettings, Workload, render, trace_query};
use dualsplit_scene::Scene;
use dualsplit_testkit::scenes::room;
use std::sync::OnceLock;

fn main() {
    divan::main();
}

struct Fixture {
    scene: Scene,
    structures: Structures,
    sets: [RaySet; 3],
}

fn fixture() -> &'static Fixture {
    static F: OnceLock<Fixture> = OnceLock::new();
    F.get_or_init(|| {
        let scene = room(false, 90);
        let structures = Structures::build(&scene.triangles, &BuildConfig::default());
        let sets = ray_sets(
            &scene,
            &structures,
            &RenderSettings::new(128, 128, Workload::Path),
        )
        .expect("valid settings");
        for kind in AccelKind::ALL {
            for set in &sets {
                verify(&structures, kind, set).expect("structures agree with BVH2");
            }
        }
        Fixture {
            scene,
            structures,
            sets,
        }
    })
}

const KINDS: [&str; 5] = ["bvh2", "bvh4", "bvh8", "dst-sw", "dst"];

/// A 64×64 path-traced frame, parallel over tiles.
#[divan::bench(args = KINDS)]
fn frame_64(bencher: divan::Bencher, accel: &str) {
    let f = fixture();
    let kind = AccelKind::parse(accel).expect("known kind");
    let s = RenderSettings::new(64, 64, Workload::Path);
    bencher.bench(|| render(&f.scene, &f.structures, kind, &s, &|| {}).expect("renders"));
}

fn trace_set(bencher: divan::Bencher, accel: &str, set: usize) {
    let f = fixture();
    let kind = AccelKind::parse(accel).expect("known kind");
    let set = &f.sets[set];
    bencher
        .counter(divan::counter::ItemsCount::new(set.rays.len()))
        .bench(|| {
            set.rays
                .iter()
                .map(|r| {
                    let q = RayQuery {
                        ray: *r,
                        kind: set.kind,
                    };
                    trace_query(&f.structures, kind, &q, &mut NoObserver).is_hit() as u32
                })
                .sum::<u32>()
        });
}

/// Primary rays of a 128×128 frame, one thread.
#[divan::bench(args = KINDS)]
fn primary(bencher: divan::Bencher, accel: &str) {
    trace_set(bencher, accel, 0);
}

/// Shadow rays of a 128×128 path-traced frame, one thread.
#[divan::bench(args = KINDS)]
fn shadow(bencher: divan::Bencher, accel: &str) {
    trace_set(bencher, accel, 1);
}

/// Diffuse bounce rays of a 128×128 path-traced frame, one thread.
#[divan::bench(args = KINDS)]
fn diffuse(bencher: divan::Bencher, accel: &str) {
    trace_set(bencher, accel, 2);
}
