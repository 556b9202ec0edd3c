//! `dualsplit simulate`: one frame on the TRaX-style many-core model (Lin et al. 2020, §4).
use crate::progress::Ctx;
use anyhow::{Context, bail};
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_sim::{SimAccel, SimConfig, SimResult, ThreadModel, simulate_model};
use std::process::ExitCode;
use std::time::{Duration, Instant};

/// Arguments of `dualsplit simulate`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params.
    scene: String,
    /// Configuration: bvh2, bvh2+, bvh4, bvh4+, bvh8, bvh8+, dst-sw, dst, or all (two at a time).
    #[arg(long, default_value = "dst")]
    accel: String,
    /// Workload: cast (primary + shadow ray) or path (5 diffuse bounces).
    #[arg(long, default_value = "path")]
    workload: String,
    /// Image resolution (N×N pixels).
    #[arg(long, default_value_t = 512)]
    res: u32,
    /// Override the number of TMs.
    #[arg(long)]
    tms: Option<u32>,
    /// Hardware configuration TOML (default: the built-in lin2020 = configs/lin2020.toml).
    #[arg(long)]
    config: Option<std::path::PathBuf>,
    /// Thread model: rv32 (the compiled kernels, instruction by instruction; the reference)
    /// or fast (the macro-op replay).
    #[arg(long, default_value = "rv32")]
    model: String,
    /// Print JSON (an array of results) instead of a table.
    #[arg(long)]
    json: bool,
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let accels: Vec<SimAccel> = if args.accel == "all" {
        SimAccel::ALL.to_vec()
    } else {
        match SimAccel::parse(&args.accel) {
            Some(a) => vec![a],
            None => bail!(
                "unknown --accel `{}` (expected bvh2, bvh2+, bvh4, bvh4+, bvh8, bvh8+, dst-sw, dst or all)",
                args.accel
            ),
        }
    };
    let workload = match args.workload.as_str() {
        "cast" => Workload::Cast,
        "path" => Workload::Path,
        w => bail!("unknown --workload `{w}` (expected cast or path)"),
    };
    let Some(model) = ThreadModel::parse(&args.model) else {
        bail!("unknown --model `{}` (expected rv32 or fast)", args.model);
    };
    if args.res == 0 {
        bail!("--res must be at least 1");
    }
    let mut cfg = match &args.config {
        Some(p) => {
            let text = crate::input::read_text(p, crate::input::MAX_CONFIG_BYTES)?;
            SimConfig::from_toml(&text).with_context(|| format!("in {}", p.display()))?
        }
        None => SimConfig::lin2020(),
    };
    if let Some(t) = args.tms {
        cfg.tms = t;
    }
    cfg.validate()?;

    let scene = super::load(&args.scene, ctx)?;
    let settings = RenderSettings::new(args.res, args.res, workload);
    // The frame and the camera obey the renderer's limits (the simulator renders the same
    // image), checked before the structures are built.
    dualsplit_render::validate(&scene, &settings)?;
    let structures = super::build(&scene, ctx)?;

    // Each run's host time, for the table's `host` line only: a host measurement is never
    // part of a result (the JSON is the same on every machine).
    let sim_one = |accel: SimAccel| -> anyhow::Result<(SimResult, Duration)> {
        let total = settings.width as u64 * settings.height as u64;
        let bar = ctx.bar(total, format!("{} {}", accel.label(), workload.name()));
        let t0 = Instant::now();
        let r = simulate_model(
            model,
            &scene,
            &structures,
            accel,
            &settings,
            &cfg,
            &|done, _| bar.set_position(done),
        )
        .with_context(|| format!("simulating {}", accel.label()))?;
        let host = t0.elapsed();
        bar.finish_and_clear();
        Ok((r, host))
    };
    // Two configurations at a time: each run is single-threaded and deterministic.
    let mut results = Vec::with_capacity(accels.len());
    for pair in accels.chunks(2) {
        let out: Vec<anyhow::Result<(SimResult, Duration)>> = std::thread::scope(|s| {
            let handles: Vec<_> = pair
                .iter()
                .map(|&a| {
                    let f = &sim_one;
                    s.spawn(move || f(a))
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("simulation thread panicked"))
                .collect()
        });
        for r in out {
            results.push(r?);
        }
    }

    if args.json {
        let results: Vec<&SimResult> = results.iter().map(|(r, _)| r).collect();
        println!("{}", serde_json::to_string_pretty(&results)?);
    } else {
        println!(
            "scene {} ({} triangles), {}×{} {}, {} TMs × {} TPs, {} thread model",
            scene.name,
            scene.triangles.len(),
            args.res,
            args.res,
            workload.name(),
            cfg.tms,
            cfg.tps_per_tm,
            model.name()
        );
        for (r, host) in &results {
            print_result(r, *host);
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Prints one configuration's result; `host` is the wall time its simulation took on this
/// machine (one core), shown with the simulator's speed in simulated instructions per host
/// second.
fn print_result(r: &SimResult, host: Duration) {
    let label = r.accel.map_or("?", |a| a.label());
    let e = &r.energy;
    let i = &r.instructions;
    let s = &r.stalls;
    let u = &r.utilisation;
    println!("== {label}");
    println!(
        "  frame time     {:.3} ms ({} cycles), {} rays, {:.0} instructions and {:.0} thread-cycles per ray",
        r.frame_ms,
        r.cycles,
        r.rays,
        r.instructions.total() as f64 / r.rays.max(1) as f64,
        r.cycles as f64 * r.threads as f64 / r.rays.max(1) as f64
    );
    println!(
        "  energy         {:.4} J total: DRAM {:.4} J, caches {:.4} J, compute {:.4} J",
        e.total(),
        e.dram_j,
        e.caches_j,
        e.compute_j
    );
    println!(
        "  DRAM           {} lines read, {} activations, row-hit rate {:.1} %",
        r.dram_lines,
        r.dram_activations,
        100.0 * r.row_hit_rate
    );
    println!(
        "  caches         L1 hit {:.1} % ({} accesses), L2 hit {:.1} % ({} accesses)",
        100.0 * r.l1_hit_rate,
        r.caches.l1_accesses,
        100.0 * r.l2_hit_rate,
        r.caches.l2_accesses
    );
    println!(
        "  instructions   {} total: int {}, fpadd {}, fpmul {}, fpcmp {}, fpinv {}, local {}, loads {}, box issues {}, tri {}, dual-split {}, atomics {}",
        i.total(),
        i.mix.int,
        i.mix.fpadd,
        i.mix.fpmul,
        i.mix.fpcmp,
        i.mix.fpinv,
        i.mix.local,
        i.loads,
        i.box_issues,
        i.tri_ops,
        i.dst_ops,
        i.atomics
    );
    println!(
        "  utilisation    issue {:.1} %, ray-box {:.1} %, ray-triangle {:.1} %, dual-split {:.1} %",
        100.0 * u.issue,
        100.0 * u.box_pipe,
        100.0 * u.tri_pipe,
        100.0 * u.dst_pipe
    );
    let tot = (r.cycles as f64 * r.threads as f64).max(1.0);
    let pct = |x: u64| 100.0 * x as f64 / tot;
    println!(
        "  stalls (% of thread-cycles)  memory {:.1}, pipeline latency {:.1}, pipeline busy {:.1}, dependency {:.1}, busy unit {:.1}, fpinv {:.1}, L1 bank {:.1}, atomic {:.1}, idle at end {:.1}",
        pct(s.memory),
        pct(s.pipeline_latency),
        pct(s.pipeline_busy),
        pct(s.dependency),
        pct(s.fu_busy),
        pct(s.fpinv),
        pct(s.l1_bank),
        pct(s.atomic),
        pct(s.idle)
    );
    let secs = host.as_secs_f64();
    println!(
        "  host           {:.2} s on one core, {:.1} M simulated instructions/s (MIPS)",
        secs,
        r.instructions.total() as f64 / secs.max(1e-9) / 1e6
    );
}
