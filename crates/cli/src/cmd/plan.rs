//! `dualsplit plan`: writes a study's plan (`DIR/plan.json`), one entry per simulation,
//! for `run-job` to run anywhere (a Slurm job array, `xargs -P`, a loop) and `report
//! --from` to assemble. Takes the report's scene, resolution, TM and model options, plus
//! `--vary KEY=V1,V2,...` sweeps over any key of the hardware config TOML.

use super::report::{Resolved, SIM_RAYS_PER_SECOND, SIM_RAYS_PER_SECOND_RV32};
use crate::args::{SimAccelArg, parse_workload, sim_accel_names, sim_accels};
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_render::Workload;
use dualsplit_report::produce::SIM_WORKERS;
use dualsplit_report::study::plan::PlanScene;
use dualsplit_report::study::{Plan, PlanOptions, Vary};
use dualsplit_sim::{SimConfig, ThreadModel};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `dualsplit plan`.
#[derive(clap::Args)]
pub struct Args {
    /// What to simulate, as for `report`.
    #[command(flatten)]
    scope: crate::args::Scope,
    /// The study's directory: plan.json goes there, results into its cache/.
    #[arg(long)]
    out: PathBuf,
    /// Configurations to simulate (default: all).
    #[arg(long, value_delimiter = ',', value_parser = sim_accel_names())]
    accel: Vec<SimAccelArg>,
    /// Workloads to simulate (default: cast,path).
    #[arg(long, value_delimiter = ',', value_parser = parse_workload)]
    workload: Vec<Workload>,
    /// Hardware configuration TOML the sweeps start from (default: lin2020).
    #[arg(long)]
    config: Option<PathBuf>,
    /// A sweep: KEY=V1,V2,... over any key of the config TOML (dotted, e.g.
    /// l1.size_bytes=32768,65536 or units.dst_pipes=1,2). Repeat for a cross product.
    #[arg(long = "vary", value_name = "KEY=V1,V2,...")]
    vary: Vec<String>,
    /// Host threads to plan the study's runs for: the printed command runs jobs side by
    /// side on them, each `run-job` with its share (`--sim-threads`). Nothing in the plan
    /// depends on it.
    #[command(flatten)]
    threads: crate::args::SimThreads,
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    crate::output::prepare_dir(&args.out, "--out")?;
    let base_config = match &args.config {
        Some(p) => {
            let text = crate::input::read_text(p, crate::input::MAX_CONFIG_BYTES)?;
            SimConfig::from_toml(&text).with_context(|| format!("{}", p.display()))?
        }
        None => SimConfig::lin2020(),
    };
    let vary = args
        .vary
        .iter()
        .map(|v| Vary::parse(v, &base_config))
        .collect::<Result<Vec<_>, _>>()?;
    let mut keys: Vec<&str> = vary.iter().map(|v| v.key.as_str()).collect();
    keys.sort_unstable();
    if keys.windows(2).any(|w| w[0] == w[1]) {
        anyhow::bail!("a key is swept by two --vary options; list its values in one");
    }
    let scope = Resolved::new(&args.scope)?;
    let thread_model = scope.thread_model;
    let accels = if args.accel.is_empty() {
        dualsplit_sim::SimAccel::ALL.to_vec()
    } else {
        sim_accels(&args.accel)
    };
    let workloads = if args.workload.is_empty() {
        vec![Workload::Cast, Workload::Path]
    } else {
        args.workload.clone()
    };

    let mut plan_scenes = Vec::new();
    for spec in &scope.specs {
        let sp = ctx.spinner(format!("loading {spec}"));
        let scene = dualsplit_scene::load(spec).with_context(|| format!("loading scene {spec}"));
        sp.finish_and_clear();
        let scene = scene?;
        // Jobs may run in another folder: a file is named by its absolute path.
        let spec = if spec.starts_with("builtin:") {
            spec.clone()
        } else {
            std::fs::canonicalize(spec)
                .with_context(|| format!("resolving {spec}"))?
                .to_string_lossy()
                .into_owned()
        };
        plan_scenes.push(PlanScene {
            spec,
            name: scene.name.clone(),
            hash: scene.content_hash(),
        });
    }

    let plan = Plan::build(&PlanOptions {
        scenes: plan_scenes,
        width: scope.res,
        height: scope.res,
        tms: scope.tms,
        base_tms: scope.base_tms,
        thread_model,
        accels,
        workloads,
        base_config,
        vary,
    })?;
    if plan.entries.is_empty() {
        anyhow::bail!("the plan has no simulations (check --accel and --workload)");
    }
    let path = plan.save(&args.out)?;
    let per_core = per_core_rays_per_second(thread_model);
    let cpu_hours = plan.estimated_rays() / per_core / 3600.0;
    let longest_s = plan
        .entries
        .iter()
        .map(|e| e.estimated_rays() / per_core)
        .fold(0.0f64, f64::max);
    outln!(
        "wrote {}: {} jobs ({} scenes at {r}×{r}, {} thread model, {} swept combinations); \
         estimated {cpu_hours:.2} CPU-hours, the longest job about {} on one core",
        path.display(),
        plan.entries.len(),
        scope.specs.len(),
        thread_model.name(),
        dualsplit_report::study::vary::cross_product(&plan.vary).len(),
        duration(longest_s),
        r = scope.res,
    );
    let (side, each) = dualsplit_sim::share_threads(plan.entries.len(), args.threads.get());
    outln!(
        "run it on {} host threads: seq 0 {} | xargs -P {side} -I{{}} dualsplit -q run-job {} {{}} \
         --sim-threads {each}",
        side * each,
        plan.entries.len() - 1,
        args.out.display(),
    );
    Ok(ExitCode::SUCCESS)
}

/// Simulated rays per second on one core: the report's two-simulations-on-two-cores
/// speeds per simulation.
pub fn per_core_rays_per_second(model: ThreadModel) -> f64 {
    let two_cores = match model {
        ThreadModel::Rv32 => SIM_RAYS_PER_SECOND_RV32,
        // Not measured for the simt model: the fast model's speed is the estimate.
        ThreadModel::Fast | ThreadModel::Simt => SIM_RAYS_PER_SECOND,
    };
    two_cores / SIM_WORKERS as f64
}

fn duration(s: f64) -> String {
    if s >= 3600.0 {
        format!("{:.1} hours", s / 3600.0)
    } else if s >= 120.0 {
        format!("{:.0} minutes", (s / 60.0).ceil())
    } else {
        format!("{:.0} seconds", s.ceil().max(1.0))
    }
}
