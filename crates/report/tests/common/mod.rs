//! Test fixtures: a small random scene and a fake simulator.
#![allow(dead_code)]

use dualsplit_accel::Structures;
use dualsplit_geometry::{Pcg32, Triangle, Vec3};
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_scene::{LoadStats, Scene};
use dualsplit_sim::{EnergySplit, SimAccel, SimConfig, SimResult};

/// `n` random triangles in a unit cube above a floor, named `name`.
pub fn random_scene(name: &str, n: usize, seed: u64) -> Scene {
    let mut rng = Pcg32::new(seed, 7);
    let mut tris = vec![
        Triangle::new(
            Vec3::new(-2.0, 0.0, -2.0),
            Vec3::new(2.0, 0.0, 2.0),
            Vec3::new(2.0, 0.0, -2.0),
        ),
        Triangle::new(
            Vec3::new(-2.0, 0.0, -2.0),
            Vec3::new(-2.0, 0.0, 2.0),
            Vec3::new(2.0, 0.0, 2.0),
        ),
    ];
    for _ in 0..n {
        let c = Vec3::new(
            rng.range_f32(-1.0, 1.0),
            rng.range_f32(0.1, 1.5),
            rng.range_f32(-1.0, 1.0),
        );
        let mut p = || {
            c + Vec3::new(
                rng.range_f32(-0.2, 0.2),
                rng.range_f32(-0.2, 0.2),
                rng.range_f32(-0.2, 0.2),
            )
        };
        tris.push(Triangle::new(p(), p(), p()));
    }
    Scene::from_triangles(name, format!("test:{name}"), tris, LoadStats::default()).unwrap()
}

/// A deterministic fake simulated frame: DST fastest, wide BVHs slower, scaling sublinear.
pub fn fake_result(accel: SimAccel, workload: Workload, tms: u32, seed: u32) -> SimResult {
    let i = SimAccel::ALL.iter().position(|&a| a == accel).unwrap() as f64;
    let base = if workload == Workload::Path {
        20.0
    } else {
        5.0
    } + f64::from(seed);
    let factor = [1.0, 0.9, 1.1, 0.95, 1.3, 1.1, 1.2, 0.75, 0.8, 0.7, 0.85][i as usize];
    let scale = (64.0 / f64::from(tms)).powf(0.8);
    let frame_ms = base * factor * scale;
    let energy = EnergySplit {
        dram_j: 0.3 * factor,
        caches_j: 0.6 * factor,
        compute_j: 0.03,
    };
    SimResult {
        cycles: (frame_ms * 1e6) as u64,
        frame_ms,
        energy,
        dram_lines: (1e6 * factor * (1.0 + f64::from(seed))) as u64,
        rays: 1000,
        ..Default::default()
    }
}

/// A fake simulator with the signature of [`dualsplit_report::produce::SimulateFn`].
pub fn fake_simulate(
    _scene: &Scene,
    _s: &Structures,
    accel: SimAccel,
    settings: &RenderSettings,
    cfg: &SimConfig,
    _threads: usize,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<SimResult, String> {
    let total = u64::from(settings.width * settings.height);
    progress(total / 2, total);
    progress(total, total);
    Ok(fake_result(accel, settings.workload, cfg.tms, 0))
}
