//! `dualsplit report`: regenerates the paper's results section (Lin et al. 2020, §4) into a
//! directory: `index.html`, `report.md`, `results.json`, `csv/`, and the result cache
//! `cache/` that makes a repeated run take seconds.
//!
//! This file only resolves arguments into a plan (scenes, resolution, TM counts), loads the
//! scenes and draws progress; the work is `dualsplit_report::Producer`.

use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_report::data::{ReportSettings, Skipped};
use dualsplit_report::produce::real_simulator;
use dualsplit_report::{Cache, Producer, Progress};
use dualsplit_sim::ThreadModel;
use indicatif::ProgressBar;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::Instant;

/// Default scenes: the builtins at reduced sizes, so the whole default report finishes in
/// about 5 minutes on a 2-core machine while keeping the paper's scene characters
/// (hairball ↔ Hairball, forest ↔ Vegetation, atrium ↔ Crytek Sponza).
pub const DEFAULT_SCENES: [&str; 3] = [
    "builtin:atrium?triangles=30000",
    "builtin:forest?triangles=40000",
    "builtin:hairball?triangles=60000",
];
/// Default square resolution of the simulated frames.
pub const DEFAULT_RES: u32 = 128;
/// The paper's scenes for `--full`: full-size builtins plus the shipped Dragon Box and Dragon
/// Sponza meshes when present.
pub const FULL_SCENES: [&str; 3] = ["builtin:atrium", "builtin:forest", "builtin:hairball"];
/// Shipped meshes added by `--full` when found (paths relative to the workspace root).
pub const FULL_FILES: [&str; 2] = ["dragon_box.ply.gz", "dragon_sponza.ply.gz"];
/// The paper's resolution (§4.3).
pub const FULL_RES: u32 = 1024;
/// Default TM counts (Table 7).
pub const DEFAULT_TMS: [u32; 3] = [32, 64, 128];
/// Square resolution of the CPU ray sets (path workload rays).
pub const CPU_RES: u32 = 64;
/// Simulated rays per second of wall time on a 2-core machine, two simulations side by side,
/// with the `fast` thread model; used only for the `--full` up-front estimate. Measured:
/// about 38K simulated rays per CPU second (release build, `lin2020` config, the default
/// builtins at 64×64).
pub const SIM_RAYS_PER_SECOND: f64 = 40_000.0;
/// The same with the compiled kernels (`rv32`). Measured: dragon_box 256² path, all eight
/// configurations two at a time, 3.82 M rays in about 260 s of wall time.
pub const SIM_RAYS_PER_SECOND_RV32: f64 = 14_000.0;

/// Arguments of `dualsplit report`.
#[derive(clap::Args)]
pub struct Args {
    /// Scenes: files (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params.
    /// Default: the builtins at reduced sizes (see `DEFAULT_SCENES`).
    scenes: Vec<String>,
    /// Square resolution of the simulated frames (default 128, 1024 with --full).
    #[arg(long)]
    res: Option<u32>,
    /// The paper's setup: 1024×1024, full-size scenes, 32/64/128 TMs.
    #[arg(long)]
    full: bool,
    /// Output directory.
    #[arg(long, default_value = "report")]
    out: PathBuf,
    /// TM counts of the scaling study (Table 7); Tables 4–6 use 64 when listed.
    #[arg(long, value_delimiter = ',', default_values_t = DEFAULT_TMS)]
    tms: Vec<u32>,
    /// Thread model: rv32 (the compiled kernels instruction by instruction, the reference)
    /// or fast (the macro-op replay: about 8× faster, an uncalibrated approximation).
    #[arg(long, default_value = "rv32")]
    model: String,
}

/// indicatif bars behind the report's `Progress` trait.
struct Bars<'a> {
    ctx: &'a Ctx,
    bar: Mutex<Option<ProgressBar>>,
}

impl Progress for Bars<'_> {
    fn begin(&self, phase: &str, total: u64) {
        if let Ok(mut b) = self.bar.lock() {
            *b = Some(self.ctx.bar(total, phase));
        }
    }
    fn advance(&self, n: u64) {
        if let Ok(b) = self.bar.lock()
            && let Some(b) = b.as_ref()
        {
            b.inc(n);
        }
    }
    fn end(&self) {
        if let Ok(mut b) = self.bar.lock()
            && let Some(b) = b.take()
        {
            b.finish_and_clear();
        }
    }
}

fn shared_scene(file: &str) -> Option<String> {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes")
        .join(file);
    p.is_file().then(|| p.display().to_string())
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let start = Instant::now();
    if args.tms.is_empty() || args.tms.contains(&0) {
        anyhow::bail!("--tms needs positive TM counts, e.g. --tms 32,64,128");
    }
    let res = args
        .res
        .unwrap_or(if args.full { FULL_RES } else { DEFAULT_RES });
    if res == 0 {
        anyhow::bail!("--res must be positive");
    }
    // The simulated frames obey the renderer's frame limit.
    if u64::from(res) * u64::from(res) > dualsplit_render::MAX_PIXELS {
        anyhow::bail!(
            "--res {res}: at most {} pixels in a frame (--res 16384)",
            dualsplit_render::MAX_PIXELS
        );
    }
    let user_scenes = !args.scenes.is_empty();
    let specs: Vec<String> = if user_scenes {
        args.scenes.clone()
    } else if args.full {
        let mut v: Vec<String> = FULL_SCENES.iter().map(|s| s.to_string()).collect();
        v.extend(FULL_FILES.iter().filter_map(|f| shared_scene(f)));
        v
    } else {
        DEFAULT_SCENES.iter().map(|s| s.to_string()).collect()
    };
    let mut tms = args.tms.clone();
    tms.sort_unstable();
    tms.dedup();
    let base_tms = if tms.contains(&64) {
        64
    } else {
        tms[tms.len() / 2]
    };

    let mut scenes = Vec::new();
    let mut skipped = Vec::new();
    for spec in &specs {
        let sp = ctx.spinner(format!("loading {spec}"));
        let loaded = dualsplit_scene::load_with(spec, &ctx.limits);
        sp.finish_and_clear();
        match loaded {
            Ok(s) => scenes.push(s),
            Err(e) if !user_scenes => {
                eprintln!("warning: default scene {spec} skipped: {e}");
                skipped.push(Skipped {
                    spec: spec.clone(),
                    error: e.to_string(),
                });
            }
            Err(e) => return Err(e).with_context(|| format!("loading scene {spec}")),
        }
    }

    let thread_model = ThreadModel::parse(&args.model).ok_or_else(|| {
        anyhow::anyhow!("unknown --model `{}` (expected rv32 or fast)", args.model)
    })?;
    if scenes.is_empty() {
        anyhow::bail!(
            "no scene could be loaded: {}",
            skipped
                .iter()
                .map(|s| format!("{} ({})", s.spec, s.error))
                .collect::<Vec<_>>()
                .join("; ")
        );
    }
    if args.full {
        let pixels = f64::from(res) * f64::from(res);
        let scaling = Producer::scaling_scenes(&scenes)
            .iter()
            .filter(|&&b| b)
            .count();
        let extra_tms = tms.iter().filter(|&&t| t != base_tms).count();
        // 8 configurations; up to 2 rays per pixel for casting and 12 for path tracing (see
        // dualsplit-render), about 1.5 and 6 on average.
        let frames = scenes.len() * 16 + scaling * extra_tms * 8;
        let rays = 8.0 * pixels * (1.5 + 6.0) * scenes.len() as f64
            + (scaling * extra_tms * 8) as f64 * pixels * 6.0;
        let secs = rays
            / match thread_model {
                ThreadModel::Rv32 => SIM_RAYS_PER_SECOND_RV32,
                ThreadModel::Fast => SIM_RAYS_PER_SECOND,
            };
        let when = if secs >= 3600.0 {
            format!("{:.1} hours", secs / 3600.0)
        } else {
            format!("{:.0} minutes", (secs / 60.0).ceil())
        };
        eprintln!(
            "--full: {} scenes at {res}×{res}, {frames} simulated frames; roughly {when} on a 2-core machine (cached pieces are skipped)",
            scenes.len()
        );
    }

    let settings = ReportSettings {
        width: res,
        height: res,
        tms,
        base_tms,
        cpu_res: CPU_RES,
        full: args.full,
        thread_model,
    };
    let simulate = real_simulator(thread_model);
    let bars = Bars {
        ctx,
        bar: Mutex::new(None),
    };
    let producer = Producer::new(
        Cache::new(args.out.join("cache")),
        settings,
        &bars,
        &*simulate,
    );
    let data = producer.run(&scenes, skipped)?;
    let written = dualsplit_report::write_report(&data, &args.out)?;
    if let Some(e) = data.sim_error() {
        eprintln!("note: {e}; simulated sections say so");
    }
    println!(
        "wrote {} ({} files; {} pieces computed, the rest from {}) in {:.1} s",
        args.out.join("index.html").display(),
        written.len(),
        producer.computed(),
        args.out.join("cache").display(),
        start.elapsed().as_secs_f64()
    );
    Ok(ExitCode::SUCCESS)
}
