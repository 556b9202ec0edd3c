//! The cache as a user sees it: a second run with nothing changed computes nothing, a
//! changed setting computes only what depends on it, and a missing simulator leaves the
//! report usable.

mod common;

use common::{fake_simulate, random_scene};
use dualsplit_report::data::ReportSettings;
use dualsplit_report::{Cache, NoProgress, Producer};
use std::sync::atomic::{AtomicU64, Ordering};

/// Scenes whose CPU piece is incomplete (and therefore not cached).
fn incomplete_cpu(data: &dualsplit_report::ReportData) -> u64 {
    data.scenes
        .iter()
        .filter(|s| s.cpu.sizes.iter().any(|z| z.bytes.is_err()))
        .count() as u64
}

fn settings(width: u32) -> ReportSettings {
    ReportSettings {
        width,
        height: 4,
        tms: vec![32, 64, 128],
        base_tms: 64,
        cpu_res: 4,
        full: false,
        thread_model: dualsplit_sim::ThreadModel::Fast,
    }
}

#[test]
fn second_run_computes_nothing() {
    let dir = std::env::temp_dir().join(format!("dualsplit-report-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let scenes = [
        random_scene("hairball-test", 40, 1),
        random_scene("other", 30, 2),
    ];
    let calls = AtomicU64::new(0);
    let sim = |a: &_, b: &_, c, d: &_, e: &_, t, f: &(dyn Fn(u64, u64) + Sync)| {
        calls.fetch_add(1, Ordering::Relaxed);
        fake_simulate(a, b, c, d, e, t, f)
    };
    // Each scene: the 11 configurations cast and path at 64 TMs (22) and "Beyond the paper"
    // at 128 TMs (7 configurations, cast and path: 14). hairball-test stands in for
    // Hairball, so it also gets the TM study of the paper's 8 (path at 32 and 128: 16), of
    // which BVH2, BVH8, BVH8+ and DST at 128 are Beyond's already (−4): 48; the other 36.
    // Plus a CPU and a render piece per scene.
    let p = Producer::new(Cache::new(&dir), settings(4), &NoProgress, &sim);
    let first = p.run(&scenes, vec![]).unwrap();
    let runs: usize = first.scenes.iter().map(|s| s.sim.len()).sum();
    assert_eq!(runs, (22 + 16 + 14 - 4) + (22 + 14));
    // DST runs are simulated only once the accel crate builds a DST.
    let expect_sims = first
        .scenes
        .iter()
        .flat_map(|s| &s.sim)
        .filter(|r| r.result.is_ok())
        .count() as u64;
    assert!(expect_sims >= 36, "every BVH configuration is simulated");
    assert_eq!(calls.load(Ordering::Relaxed), expect_sims);
    assert_eq!(p.computed(), expect_sims + 4);

    // CPU pieces that lack a structure the accel crate does not build yet are not cached
    // (so they are measured once it exists); everything else must come from the cache.
    let incomplete = incomplete_cpu(&first);
    let p = Producer::new(Cache::new(&dir), settings(4), &NoProgress, &sim);
    let second = p.run(&scenes, vec![]).unwrap();
    assert_eq!(
        p.computed(),
        incomplete,
        "nothing changed, nothing computed"
    );
    assert_eq!(calls.load(Ordering::Relaxed), expect_sims);
    for (a, b) in first.scenes.iter().zip(&second.scenes) {
        assert_eq!(a.sim.len(), b.sim.len());
        for (x, y) in a.sim.iter().zip(&b.sim) {
            assert_eq!((x.accel, x.workload, x.tms), (y.accel, y.workload, y.tms));
            assert_eq!(
                x.result.as_ref().map(|r| r.cycles),
                y.result.as_ref().map(|r| r.cycles)
            );
        }
        assert_eq!(a.render_png_base64, b.render_png_base64);
    }

    // A new resolution recomputes the simulations only (CPU and render pieces do not
    // depend on it).
    let p = Producer::new(Cache::new(&dir), settings(8), &NoProgress, &sim);
    p.run(&scenes, vec![]).unwrap();
    assert_eq!(p.computed(), expect_sims + incomplete);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn simulator_errors_are_reported_not_cached() {
    let dir = std::env::temp_dir().join(format!("dualsplit-report-nosim-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let scenes = [random_scene("one", 20, 3)];
    let sim = |_: &_, _: &_, _, _: &_, _: &_, _, _: &(dyn Fn(u64, u64) + Sync)| {
        Err("simulator unavailable: not implemented".to_string())
    };
    let p = Producer::new(Cache::new(&dir), settings(4), &NoProgress, &sim);
    let data = p.run(&scenes, vec![]).unwrap();
    assert_eq!(p.computed(), 2, "CPU and render pieces only");
    assert_eq!(
        data.sim_error(),
        Some("simulator unavailable: not implemented")
    );
    let out = dir.join("out");
    dualsplit_report::write_report(&data, &out).unwrap();
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("simulator unavailable: not implemented"));
    assert!(html.contains("id=\"table3\""));
    // Nothing simulated was cached, so the next run tries again.
    let p = Producer::new(Cache::new(&dir), settings(4), &NoProgress, &sim);
    p.run(&scenes, vec![]).unwrap();
    assert_eq!(p.computed(), incomplete_cpu(&data));
    std::fs::remove_dir_all(&dir).unwrap();
}
