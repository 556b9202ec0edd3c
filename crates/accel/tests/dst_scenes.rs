//! DST on the shipped meshes: per-ray identical closest hits (t bits, triangle id) and
//! shadow answers to the source BVH2 (both partitioning modes, no allowance), through the
//! software traversal and the pipeline loop, on the rays the renderer's path-tracing jobs
//! generate (primary, shadow, diffuse).
//!
//! `cargo test --release` traces at least 100 000 rays of each kind per scene; debug builds
//! trace a smaller image so the suite stays quick.

use dualsplit_accel::dst::{DstConfig, Partitioning};
use dualsplit_accel::{AccelKind, NoObserver};
use dualsplit_render::{PixelJob, RayKind, RenderSettings, TraceResult, Workload};
use dualsplit_scene::{LoadStats, Scene};
use dualsplit_testkit::dst::{build, check_dst_ray};
use dualsplit_testkit::scenes::shipped_triangles;

/// Image side; pixels are visited in a scattered order until every ray kind has
/// [`MIN_RAYS`] rays (the open meshes send many rays to the sky, so shadow rays are rarest).
const SIDE: u32 = if cfg!(debug_assertions) { 256 } else { 1024 };
const MIN_RAYS: u64 = if cfg!(debug_assertions) {
    1_000
} else {
    100_000
};
/// A stride coprime with SIDE², spreading the visited pixels over the image.
const STRIDE: u32 = 7919;

fn scene_case(name: &str, cfg: DstConfig) {
    let Some(tris) = shipped_triangles(name) else {
        return;
    };
    let scene = Scene::from_triangles(name, name, tris, LoadStats::default()).expect("scene");
    rays_case(&scene, name, cfg, MIN_RAYS);
}

fn builtin_case(spec: &str) {
    let scene = dualsplit_scene::load(spec).expect("builtin scene");
    // The dense hairball blocks most light paths; a quarter of the shipped-mesh minimum.
    rays_case(&scene, spec, DstConfig::hardware(), MIN_RAYS / 4);
}

/// Every builtin scene (reduced sizes), with its preset camera.
#[test]
fn builtins() {
    for spec in [
        "builtin:cornell",
        "builtin:atrium?triangles=20000",
        "builtin:forest?triangles=20000",
        "builtin:hairball?triangles=20000",
    ] {
        builtin_case(spec);
    }
}

fn rays_case(scene: &Scene, name: &str, cfg: DstConfig, min_rays: u64) {
    let b = build(&scene.triangles, &cfg);
    let s = b.dst.stats();
    assert_eq!(
        s.node_bytes,
        12 * s.internal_nodes() + 4 * s.leaves,
        "{name}: node bytes"
    );
    assert_eq!(
        s.index_entries as usize,
        b.bvh.prim_ids.len(),
        "{name}: index entries"
    );
    let settings = RenderSettings::new(SIDE, SIDE, Workload::Path);
    let mut counts = [0u64; 3];
    let pixels = SIDE * SIDE;
    for i in 0..pixels {
        if counts.iter().all(|&n| n >= min_rays) {
            break;
        }
        let p = (i as u64 * STRIDE as u64 % pixels as u64) as u32;
        let (x, y) = (p % SIDE, p / SIDE);
        {
            let mut job = PixelJob::new(scene, &settings, x, y);
            while let Some(q) = job.next_ray() {
                let bvh = b
                    .reference
                    .closest_hit(AccelKind::Bvh2, &q.ray, &mut NoObserver);
                // Both partitioning modes equal the BVH2 bit for bit: with widened exits
                // (dualsplit-geometry, Ize 2013) the BVH2 does not round grazing hits
                // away, so a looser similar-mode leaf region has nothing extra to find.
                check_dst_ray(&b.dst, &q.ray, bvh, name);
                let result = match q.kind {
                    RayKind::Shadow => TraceResult::Occluded(bvh.is_some()),
                    _ => TraceResult::Closest(bvh),
                };
                counts[q.kind as usize] += 1;
                job.submit(result);
            }
        }
    }
    for (kind, n) in ["primary", "shadow", "diffuse"].iter().zip(counts) {
        assert!(n >= min_rays, "{name}: only {n} {kind} rays");
    }
}

#[test]
fn dragon_res4() {
    scene_case("dragon_res4.ply.gz", DstConfig::hardware());
}

#[test]
fn dragon_res4_software_preset_similar() {
    scene_case(
        "dragon_res4.ply.gz",
        DstConfig::software().with_partitioning(Partitioning::Similar),
    );
}

#[test]
fn bunny() {
    scene_case("bunny.ply.gz", DstConfig::hardware());
}

#[test]
fn sponza_dabrovic() {
    scene_case("sponza_dabrovic.ply.gz", DstConfig::hardware());
}

#[test]
fn sponza_dabrovic_software_preset() {
    scene_case("sponza_dabrovic.ply.gz", DstConfig::software());
}

/// Similar partitioning never adds nodes: above each leaf it may only drop carving nodes.
/// Prints both modes' sizes and per-ray work on the renderer's primary rays.
#[test]
fn similar_partitioning_effect() {
    let Some(tris) = shipped_triangles("bunny.ply.gz") else {
        return;
    };
    let scene = Scene::from_triangles("bunny", "bunny", tris, LoadStats::default()).expect("scene");
    let ident = build(&scene.triangles, &DstConfig::hardware());
    let similar = build(
        &scene.triangles,
        &DstConfig::hardware().with_partitioning(Partitioning::Similar),
    );
    let settings = RenderSettings::new(128, 128, Workload::Cast);
    let rays: Vec<_> = (0..128 * 128)
        .filter_map(|p| PixelJob::new(&scene, &settings, p % 128, p / 128).next_ray())
        .map(|q| q.ray)
        .collect();
    let (si, ss) = (ident.dst.stats(), similar.dst.stats());
    let (ti, ts) = (ident.dst.trace_stats(&rays), similar.dst.trace_stats(&rays));
    eprintln!(
        "identical: {si:?}\n  {:.1} % of BVH2, per ray {ti:?}",
        si.percent_of_bvh2()
    );
    eprintln!(
        "similar:   {ss:?}\n  {:.1} % of BVH2, per ray {ts:?}",
        ss.percent_of_bvh2()
    );
    assert!(ss.node_bytes <= si.node_bytes);
    assert_eq!(ss.splitting, si.splitting);
    assert!(ts.triangle_tests >= ti.triangle_tests);
}
