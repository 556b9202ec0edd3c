//! The simulator's host speed on one frame: each thread model runs the frame on one host
//! core, `REPEATS` times, and the fastest run counts. Prints, per model, the simulated
//! instructions, the host seconds, the simulated instructions per host second, the `fast`
//! model's speed-up over `rv32` on the same frame, then the `rv32` frame's speed-up on 2 …
//! `THREADS` host threads (each thread count run `REPEATS` times, the counts alternated
//! round by round, fastest run counts; every run's result is checked equal to the one-thread
//! run's), and the process's peak resident memory.
//!
//! `cargo run --release -p dualsplit-sim --example sim_speed -- [SCENE] [RES] [ACCEL] [WORKLOAD] [REPEATS] [THREADS]`
//!
//! Defaults: `builtin:cornell`, 32 (×32), `bvh2`, `path`, 1, 1 (no curve). Only the
//! structure the configuration reads is built (`TreeSet`). Host timings move with the
//! machine's load; `docs/performance.md` gives the figures with their method (alternated
//! runs, quiet host).

use dualsplit_accel::{BuildConfig, TreeSet};
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_sim::{FrameRequest, SimAccel, SimConfig, ThreadModel, simulate};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, default: &str| args.get(i).cloned().unwrap_or_else(|| default.into());
    let spec = arg(0, "builtin:cornell");
    let res: u32 = arg(1, "32").parse()?;
    let accel = SimAccel::parse(&arg(2, "bvh2")).ok_or("unknown configuration")?;
    let workload = Workload::parse(&arg(3, "path")).ok_or("unknown workload (cast or path)")?;
    let repeats: u32 = arg(4, "1").parse::<u32>()?.max(1);
    let max_threads: usize = arg(5, "1").parse::<usize>()?.max(1);

    let scene = dualsplit_scene::load(&spec)?;
    let set = TreeSet::build(
        &scene.triangles[..],
        &BuildConfig::default(),
        &[accel.kind()],
    )?;
    let settings = RenderSettings::new(res, res, workload);
    let cfg = SimConfig::lin2020();
    println!(
        "{} ({} triangles), {res}×{res} {}, {}, {} TMs × {} threads, one host thread",
        scene.name,
        scene.triangles.len(),
        workload.name(),
        accel.name(),
        cfg.tms,
        cfg.tps_per_tm
    );
    let mut seconds = Vec::new();
    for model in [ThreadModel::Rv32, ThreadModel::Fast] {
        let frame = FrameRequest::new(&scene, &set, accel, &settings, &cfg).with_model(model);
        let mut best = f64::INFINITY;
        let mut result = None;
        for _ in 0..repeats {
            let t = Instant::now();
            let r = simulate(&frame, &|_, _| {})?;
            best = best.min(t.elapsed().as_secs_f64());
            result = Some(r);
        }
        let r = result.expect("at least one run");
        let instructions = r.instructions.total();
        println!(
            "{:>5}: {instructions} simulated instructions, {} cycles, {best:.3} s, {:.1} M simulated instructions/s per host core",
            model.name(),
            r.cycles,
            instructions as f64 / best / 1e6
        );
        seconds.push(best);
    }
    println!(
        "fast model: {:.2}× the rv32 model's speed on this frame",
        seconds[0] / seconds[1]
    );
    if max_threads > 1 {
        let frame = |threads| {
            FrameRequest::new(&scene, &set, accel, &settings, &cfg)
                .with_model(ThreadModel::Rv32)
                .with_threads(threads)
        };
        let reference = serde_json::to_string(&simulate(&frame(1), &|_, _| {})?)?;
        let mut best = vec![f64::INFINITY; max_threads];
        for _ in 0..repeats {
            for (k, b) in best.iter_mut().enumerate() {
                let t = Instant::now();
                let r = simulate(&frame(k + 1), &|_, _| {})?;
                *b = b.min(t.elapsed().as_secs_f64());
                if serde_json::to_string(&r)? != reference {
                    return Err(format!("{} host threads gave another result", k + 1).into());
                }
            }
        }
        for (k, b) in best.iter().enumerate() {
            println!(
                "rv32 on {} host thread{}: {b:.3} s, {:.2}× one thread (result identical)",
                k + 1,
                if k == 0 { "" } else { "s" },
                best[0] / b
            );
        }
    }
    match peak_rss_kib() {
        Some(kib) => println!("peak RSS: {:.1} MiB", kib as f64 / 1024.0),
        None => println!("peak RSS: not available on this system"),
    }
    Ok(())
}

/// The process's peak resident set (`VmHWM` of `/proc/self/status`), in KiB.
fn peak_rss_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}
