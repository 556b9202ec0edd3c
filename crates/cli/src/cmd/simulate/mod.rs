//! `dualsplit simulate`: one frame per configuration on the TRaX-style many-core model
//! (Lin et al. 2020, §4), each printed in full, then compared side by side.
//!
//! With `--tree FILE` the saved structure is simulated instead of building: only the
//! configurations of its traversals (DST\* and DST for a DST; BVH4 and BVH4+ for a BVH4),
//! by default all of them. The JSON is the same as when the structure is built.
//!
//! The checks, the runs and the JSON document are [`dualsplit_report::simulate`]'s, which
//! the Python package's `simulate` calls too.

use crate::args::{
    SimAccelArg, View, parse_positive, parse_res, parse_workload, sim_accel_names, sim_accels,
};
use crate::loaded::Loaded;
use crate::output::JsonOut;
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::TraversalSet;
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_report::simulate::{self as frames, SimulateJson};
use dualsplit_report::units;
use dualsplit_sim::{SimAccel, SimConfig, SimResult, ThreadModel};
use std::process::ExitCode;
use std::time::Duration;

mod simt;

/// Arguments of `dualsplit simulate`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params
    /// (hairball, forest, atrium, cornell).
    #[arg(value_parser = crate::args::parse_scene)]
    scene: String,
    /// Configurations, comma-separated, or all (every configuration; side by side on
    /// --sim-threads). Only the structures they read are built. With more than one, a comparison
    /// table follows, relative to the reference BVH2 when it is listed, else to the first.
    /// Default: the DST on its pipeline; with --tree, every configuration of the saved
    /// structure, and `all` means those.
    #[arg(long, value_delimiter = ',', value_parser = sim_accel_names())]
    accel: Vec<SimAccelArg>,
    /// Simulate the tree saved in FILE by `dualsplit build` instead of building; it must
    /// come from SCENE (its triangles are checked). Only its configurations exist:
    /// the ones that run its traversals.
    #[arg(long, value_name = "FILE")]
    tree: Option<std::path::PathBuf>,
    /// Workload: cast (primary + shadow ray) or path (5 diffuse bounces).
    #[arg(long, default_value = "path", value_parser = parse_workload)]
    workload: Workload,
    /// Resolution, WIDTHxHEIGHT or N for N×N.
    #[arg(long, default_value = "512", value_parser = parse_res)]
    res: (u32, u32),
    /// Override the number of TMs.
    #[arg(long, value_parser = parse_positive)]
    tms: Option<u32>,
    /// Hardware configuration TOML (default: the built-in lin2020 = configs/lin2020.toml).
    #[arg(long)]
    config: Option<std::path::PathBuf>,
    /// Thread model: rv32 (the compiled kernels, instruction by instruction; the reference)
    /// or fast (the macro-op replay calibrated against them: frame times within 13 %, about 5× faster),
    /// or simt (an RTX-style GPU with an RT unit per SM; needs --config configs/rtx2060.toml).
    #[arg(long, default_value = "rv32", value_parser = parse_model)]
    model: ThreadModel,
    /// Camera and light overrides.
    #[command(flatten)]
    view: View,
    /// Print JSON instead of a table; `--json=FILE` writes it to FILE.
    #[arg(long, value_name = "FILE", num_args = 0..=1, require_equals = true, default_missing_value = "-")]
    json: Option<std::path::PathBuf>,
    #[command(flatten)]
    threads: crate::args::SimThreads,
}

fn parse_model(s: &str) -> Result<ThreadModel, String> {
    ThreadModel::parse(s)
        .ok_or_else(|| format!("unknown thread model `{s}` (expected rv32, fast or simt)"))
}

/// Idle-at-end share of thread-cycles above which the chip is called not busy.
const IDLE_WARN: f64 = 0.10;

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let json = JsonOut::from_arg(args.json.as_deref())?;
    let (workload, model) = (args.workload, args.model);
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
    // The configuration and the frame are checked before the scene is loaded.
    let settings = RenderSettings::new(args.res.0, args.res.1, workload);
    frames::check_frame(&cfg, &settings, model)?;

    let mut scene = super::load(&args.scene, ctx)?;
    args.view.apply(&mut scene)?;
    // The frame and the camera obey the renderer's limits (the simulator renders the same
    // image), checked before the structures are built.
    dualsplit_render::validate(&scene, &settings)?;
    // Only the structures of the configurations asked for are built.
    let wanted: Vec<_> = if args.accel.is_empty() {
        vec![SimAccel::DEFAULT.kind()]
    } else {
        sim_accels(&args.accel).iter().map(|a| a.kind()).collect()
    };
    let structures = Loaded::get_for(&scene, args.tree.as_deref(), &wanted, ctx)?;
    let accels = configurations(&args.accel, &structures)?;

    let total = settings.width as u64 * settings.height as u64;
    let bars: Vec<_> = accels
        .iter()
        .map(|a| {
            (
                *a,
                ctx.bar(total, format!("{} {}", a.label(), workload.name())),
            )
        })
        .collect();
    let results = frames::simulate_frames(
        model,
        &scene,
        &structures,
        &accels,
        &settings,
        &cfg,
        args.threads.get(),
        &|accel, done, _| {
            if let Some((_, bar)) = bars.iter().find(|(a, _)| *a == accel) {
                bar.set_position(done);
            }
        },
    )?;
    for (_, bar) in &bars {
        bar.finish_and_clear();
    }
    let plain: Vec<&SimResult> = results.iter().map(|(r, _)| r).collect();
    let report = SimulateJson::new(&scene, &settings, model, &cfg, plain);
    let summary = &report.summary;

    if let Some(out) = json {
        out.emit(&report.to_json()?)?;
    } else if let (ThreadModel::Simt, Some(c)) = (model, &cfg.simt) {
        let size = (settings.width, settings.height, workload.name());
        simt::print(&scene.name, scene.triangles.len(), size, c, &results);
    } else {
        outln!(
            "scene {} ({} triangles), {}×{} {}, {} TMs × {} TPs, {} thread model",
            scene.name,
            scene.triangles.len(),
            settings.width,
            settings.height,
            workload.name(),
            cfg.tms,
            cfg.tps_per_tm,
            model.name()
        );
        let per_frame = dualsplit_sim::share_threads(results.len(), args.threads.get()).1;
        for (r, host) in &results {
            print_result(r, *host, per_frame);
        }
        if results.len() > 1 {
            outln!(
                "\ncomparison (frame time, energy and DRAM lines as % of {}; stalls and idle as shares of all thread-cycles)",
                summary.baseline.map_or("?", |a| a.label())
            );
            out!("{}", frames::table(summary));
        }
        let idle = summary
            .rows
            .iter()
            .map(|r| r.stalls.idle_at_end)
            .fold(0.0f64, f64::max);
        if idle > IDLE_WARN {
            outln!(
                "note: threads sat idle at the end of the frame for up to {:.0} % of their cycles: the frame has too few pixels for {} threads, so the chip is not busy; a larger --res compares the structures on a busy chip",
                100.0 * idle,
                cfg.tms * cfg.tps_per_tm
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// The configurations `--accel` names (each checked against a saved tree), or the default:
/// DST, or with `--tree` every configuration of the saved structure.
fn configurations(asked: &[SimAccelArg], structures: &Loaded) -> anyhow::Result<Vec<SimAccel>> {
    let tree = matches!(structures, Loaded::Saved { .. });
    if asked.is_empty() {
        return Ok(if tree {
            SimAccel::ALL
                .into_iter()
                .filter(|a| structures.supports(a.kind()))
                .collect()
        } else {
            vec![SimAccel::DEFAULT]
        });
    }
    for item in asked {
        if let SimAccelArg::One(a) = item {
            structures.require(a.name(), a.kind())?;
        }
    }
    Ok(sim_accels(asked)
        .into_iter()
        .filter(|a| structures.supports(a.kind()))
        .collect())
}

/// Prints one configuration's result; `host` is the wall time its simulation took on this
/// machine on `threads` host threads, shown with the simulator's speed in simulated
/// instructions per host second.
fn print_result(r: &SimResult, host: Duration, threads: usize) {
    let label = r.accel.map_or("?", |a| a.label());
    let e = &r.energy;
    let i = &r.instructions;
    let s = &r.stalls;
    let u = &r.utilisation;
    outln!("== {label}");
    outln!(
        "  frame time     {} ({} cycles), {} rays, {:.0} instructions and {:.0} thread-cycles per ray",
        units::time_ms(r.frame_ms),
        r.cycles,
        r.rays,
        r.instructions.total() as f64 / r.rays.max(1) as f64,
        r.cycles as f64 * r.threads as f64 / r.rays.max(1) as f64
    );
    outln!(
        "  energy         {} total: DRAM {}, caches {}, compute {}",
        units::energy_j(e.total()),
        units::energy_j(e.dram_j),
        units::energy_j(e.caches_j),
        units::energy_j(e.compute_j)
    );
    outln!(
        "  DRAM           {} lines read, {} activations, row-hit rate {:.1} %",
        r.dram_lines,
        r.dram_activations,
        100.0 * r.row_hit_rate
    );
    outln!(
        "  caches         L1 hit {:.1} % ({} accesses), L2 hit {:.1} % ({} accesses), L2 bank conflicts {} cycles",
        100.0 * r.l1_hit_rate,
        r.caches.l1_accesses,
        100.0 * r.l2_hit_rate,
        r.caches.l2_accesses,
        r.memory.l2_bank_conflict_cycles
    );
    let m = &r.memory;
    outln!(
        "  memory         DRAM {:.1} GB/s, read latency mean {:.1} / p95 {} cycles, {:.2} lines and {:.2} rays per pixel",
        m.dram_gbps,
        m.dram_latency_mean_cycles,
        m.dram_latency_p95_cycles,
        m.lines_per_pixel,
        m.rays_per_pixel
    );
    outln!(
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
        i.dst_ops + i.qdst_ops,
        i.atomics
    );
    if i.qbox_ops + i.qdst_ops > 0 {
        outln!(
            "  quantized      box ops {} (dequantized child boxes), dual-split ops {} (records)",
            i.qbox_ops,
            i.qdst_ops
        );
    }
    outln!(
        "  utilisation    issue {:.1} %, ray-box {:.1} %, ray-triangle {:.1} %, dual-split {:.1} %",
        100.0 * u.issue,
        100.0 * u.box_pipe,
        100.0 * u.tri_pipe,
        100.0 * u.dst_pipe
    );
    let tot = (r.cycles as f64 * r.threads as f64).max(1.0);
    let pct = |x: u64| 100.0 * x as f64 / tot;
    outln!(
        "  stalls (% of thread-cycles)  memory {:.1}, pipeline latency {:.1}, pipeline busy {:.1}, dependency {:.1}, busy unit {:.1}, fpinv {:.1}, L1/L2 bank {:.1}, icache {:.1}, atomic {:.1}, idle at end {:.1}",
        pct(s.memory),
        pct(s.pipeline_latency),
        pct(s.pipeline_busy),
        pct(s.dependency),
        pct(s.fu_busy),
        pct(s.fpinv),
        pct(s.l1_bank),
        pct(s.icache),
        pct(s.atomic),
        pct(s.idle)
    );
    let secs = host.as_secs_f64();
    outln!(
        "  host           {:.2} s on {threads} host thread{}, {:.1} M simulated instructions/s (MIPS)",
        secs,
        if threads == 1 { "" } else { "s" },
        r.instructions.total() as f64 / secs.max(1e-9) / 1e6
    );
}
