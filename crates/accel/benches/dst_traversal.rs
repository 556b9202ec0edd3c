//! CPU traversal speed: closest-hit (primary, diffuse) and any-hit (shadow) rays on shipped
//! scenes, for the BVH2 traversal (the `Structures` reference), the DST software
//! decoder (DST*) and the DST pipeline-function loop. Rays come from the renderer's
//! path-tracing jobs (128² pixels, ≤ 16K rays per kind). Every ray is checked against the
//! BVH2 before anything is timed.
//!
//! `cargo bench -p dualsplit-accel --bench dst_traversal`

use divan::Bencher;
use divan::counter::ItemsCount;
use dualsplit_accel::dst::{Dst, DstConfig};
use dualsplit_accel::{AccelKind, CountingObserver, NoObserver, Structures};
use dualsplit_geometry::Ray;
use dualsplit_render::{PixelJob, RayKind, RenderSettings, TraceResult, Workload};
use dualsplit_scene::{LoadStats, Scene};
use dualsplit_testkit::dst::{build, check_dst_ray};
use dualsplit_testkit::scenes::shipped_triangles;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

const SCENES: [&str; 2] = ["bunny", "sponza_dabrovic"];
const CASES: [&str; 6] = [
    "bunny/primary",
    "bunny/shadow",
    "bunny/diffuse",
    "sponza_dabrovic/primary",
    "sponza_dabrovic/shadow",
    "sponza_dabrovic/diffuse",
];
/// Image side (16 under `cargo test --benches`, no `--bench` argument).
fn side() -> u32 {
    if !std::env::args().any(|a| a == "--bench") {
        16
    } else {
        128
    }
}
const MAX_RAYS: usize = 16_384;

struct Prepared {
    reference: Structures,
    dst: Dst,
    rays: [Vec<Ray>; 3],
}

fn prepare(name: &str) -> Prepared {
    let tris = shipped_triangles(&format!("{name}.ply.gz")).expect("the benchmark needs this mesh");
    let scene = Scene::from_triangles(name, name, tris, LoadStats::default()).expect("scene");
    let b = build(&scene.triangles, &DstConfig::hardware());
    let side = side();
    let settings = RenderSettings::new(side, side, Workload::Path);
    let mut rays: [Vec<Ray>; 3] = Default::default();
    for y in 0..side {
        for x in 0..side {
            let mut job = PixelJob::new(&scene, &settings, x, y);
            while let Some(q) = job.next_ray() {
                let hit = b
                    .reference
                    .closest_hit(AccelKind::Bvh2, &q.ray, &mut NoObserver);
                // Correctness before timing.
                check_dst_ray(&b.dst, &q.ray, hit, name);
                let list = &mut rays[q.kind as usize];
                if list.len() < MAX_RAYS {
                    list.push(q.ray);
                }
                job.submit(match q.kind {
                    RayKind::Shadow => TraceResult::Occluded(hit.is_some()),
                    _ => TraceResult::Closest(hit),
                });
            }
        }
    }
    // Deterministic per-ray work, printed beside the timings.
    for (k, kind) in ["primary", "shadow", "diffuse"].iter().enumerate() {
        let (mut bvh, mut dst) = (CountingObserver::default(), CountingObserver::default());
        for r in &rays[k] {
            if k == 1 {
                b.reference.any_hit(AccelKind::Bvh2, r, &mut bvh);
                b.dst.any_hit(r, &mut dst);
            } else {
                b.reference.closest_hit(AccelKind::Bvh2, r, &mut bvh);
                b.dst.closest_hit(r, &mut dst);
            }
        }
        let n = rays[k].len().max(1) as f64;
        eprintln!(
            "{name}/{kind}: {} rays | BVH2 per ray: {:.1} nodes, {:.1} box tests, {:.1} tris, {:.0} B \
             | DST per ray: {:.1} nodes, {:.1} plane tests, {:.1} leaves, {:.1} tris, {:.0} B",
            rays[k].len(),
            bvh.nodes as f64 / n,
            bvh.box_tests as f64 / n,
            bvh.triangle_tests as f64 / n,
            bvh.bytes as f64 / n,
            dst.nodes as f64 / n,
            dst.plane_tests as f64 / n,
            dst.leaves as f64 / n,
            dst.triangle_tests as f64 / n,
            dst.bytes as f64 / n,
        );
    }
    Prepared {
        reference: b.reference,
        dst: b.dst,
        rays,
    }
}

/// The prepared scene, ray set and shadow flag of `case`; `None` when `DST_BENCH_CASE` names
/// another case (to run one case under callgrind).
fn data(case: &str) -> Option<(&'static Prepared, &'static [Ray], bool)> {
    if std::env::var("DST_BENCH_CASE").is_ok_and(|c| c != case) {
        return None;
    }
    static DATA: OnceLock<Mutex<HashMap<&'static str, &'static Prepared>>> = OnceLock::new();
    let (scene, kind) = case.split_once('/').unwrap();
    let scene = SCENES.into_iter().find(|s| *s == scene).unwrap();
    let p = *DATA
        .get_or_init(Default::default)
        .lock()
        .unwrap()
        .entry(scene)
        .or_insert_with(|| Box::leak(Box::new(prepare(scene))));
    let k = match kind {
        "primary" => 0,
        "shadow" => 1,
        _ => 2,
    };
    Some((p, &p.rays[k], k == 1))
}

fn main() {
    divan::main();
}

// The timed loops are `#[inline(never)]` so callgrind can attribute instructions to each
// structure (`valgrind --tool=callgrind <bench binary> --bench --sample-count 1
// --sample-size 1`, then `callgrind_annotate --inclusive=yes`).

#[inline(never)]
fn run_bvh2(p: &Prepared, rays: &[Ray], shadow: bool) -> u32 {
    let mut n = 0u32;
    for r in rays {
        n += if shadow {
            p.reference.any_hit(AccelKind::Bvh2, r, &mut NoObserver) as u32
        } else {
            p.reference
                .closest_hit(AccelKind::Bvh2, r, &mut NoObserver)
                .is_some() as u32
        };
    }
    n
}

#[inline(never)]
fn run_dst_software(p: &Prepared, rays: &[Ray], shadow: bool) -> u32 {
    let mut n = 0u32;
    for r in rays {
        n += if shadow {
            p.dst.any_hit(r, &mut NoObserver) as u32
        } else {
            p.dst.closest_hit(r, &mut NoObserver).is_some() as u32
        };
    }
    n
}

#[inline(never)]
fn run_dst_pipeline(p: &Prepared, rays: &[Ray], shadow: bool) -> u32 {
    let mut n = 0u32;
    for r in rays {
        n += if shadow {
            p.dst.any_hit_pipeline(r, &mut NoObserver) as u32
        } else {
            p.dst.closest_hit_pipeline(r, &mut NoObserver).is_some() as u32
        };
    }
    n
}

#[divan::bench(args = CASES)]
fn bvh2(bencher: Bencher, case: &str) {
    let Some((p, rays, shadow)) = data(case) else {
        return bencher.bench(|| 0);
    };
    bencher
        .counter(ItemsCount::new(rays.len()))
        .bench(|| run_bvh2(p, rays, shadow));
}

#[divan::bench(args = CASES)]
fn dst_software(bencher: Bencher, case: &str) {
    let Some((p, rays, shadow)) = data(case) else {
        return bencher.bench(|| 0);
    };
    bencher
        .counter(ItemsCount::new(rays.len()))
        .bench(|| run_dst_software(p, rays, shadow));
}

#[divan::bench(args = CASES)]
fn dst_pipeline(bencher: Bencher, case: &str) {
    let Some((p, rays, shadow)) = data(case) else {
        return bencher.bench(|| 0);
    };
    bencher
        .counter(ItemsCount::new(rays.len()))
        .bench(|| run_dst_pipeline(p, rays, shadow));
}
