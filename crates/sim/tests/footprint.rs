//! The simulator's memory estimate ([`dualsplit_sim::footprint`]) bounds what a simulation
//! allocates: each run below happens under an allocator capped at the bytes already in use
//! plus the estimate, so one byte beyond it aborts this test. One test function, so no other
//! test allocates beside it.

use cap::Cap;
use dualsplit_accel::Structures;
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_sim::footprint::Footprint;
use dualsplit_sim::{FrameRequest, SimAccel, SimConfig, ThreadModel, simulate};
use std::alloc::System;

#[global_allocator]
static ALLOC: Cap<System> = Cap::new(System, usize::MAX);

#[test]
fn simulations_stay_within_their_estimate() {
    let scene = dualsplit_scene::load("builtin:hairball?triangles=20000").unwrap();
    let s = Structures::build(&scene.triangles, &Default::default());
    let big_caches = "tms = 4\n[l1]\nsize_bytes = 4194304\nassociativity = 4\n[l2]\nsize_bytes = 67108864\nassociativity = 8";
    let many = "tms = 128\ntps_per_tm = 64\n[dram]\nchannels = 64\nbanks_per_channel = 64\nread_queue = 1024";
    let cases: [(&str, ThreadModel, SimAccel, Workload, u32); 6] = [
        ("", ThreadModel::Rv32, SimAccel::Dst, Workload::Path, 64),
        (
            "",
            ThreadModel::Fast,
            SimAccel::Bvh8Plus,
            Workload::Path,
            64,
        ),
        (
            big_caches,
            ThreadModel::Rv32,
            SimAccel::Bvh2,
            Workload::Cast,
            32,
        ),
        (
            big_caches,
            ThreadModel::Fast,
            SimAccel::Bvh4,
            Workload::Cast,
            32,
        ),
        (many, ThreadModel::Rv32, SimAccel::DstSw, Workload::Cast, 48),
        (many, ThreadModel::Fast, SimAccel::Dst, Workload::Path, 48),
    ];
    for (toml, model, accel, wl, res) in cases {
        let cfg = SimConfig::from_toml(toml).unwrap();
        let settings = RenderSettings::new(res, res, wl);
        let est = Footprint::estimate(&cfg, accel, model, (res * res) as u64).total();
        let (before, max_before) = (ALLOC.allocated(), ALLOC.max_allocated());
        ALLOC.set_limit(before + est as usize).unwrap();
        let r = simulate(
            &FrameRequest::new(&scene, &s, accel, &settings, &cfg).with_model(model),
            &|_, _| {},
        )
        .unwrap();
        // The allocator keeps only its all-time peak: this run's is known when it set it.
        let peak = ALLOC.max_allocated();
        ALLOC.set_limit(usize::MAX).unwrap();
        drop(r);
        let mib = |b: usize| b as f64 / 1048576.0;
        let used = if peak > max_before {
            format!("{:.1} MiB", mib(peak - before))
        } else {
            format!("at most {:.1} MiB", mib(max_before - before))
        };
        eprintln!(
            "{model:?} {} {res}² {:?}: used {used} of its estimate {:.1} MiB",
            accel.name(),
            toml.lines().next().unwrap_or("lin2020"),
            mib(est as usize),
        );
    }
}
