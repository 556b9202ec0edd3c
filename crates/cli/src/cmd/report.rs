//! `dualsplit report`: regenerates the paper's results section (Lin et al. 2020, §4) into a
//! directory: `index.html`, `report.md`, `results.json`, `csv/`, and the result cache
//! `cache/` that makes a repeated run take seconds.
//!
//! This file only resolves arguments into a plan (scenes, resolution, TM counts), loads the
//! scenes and draws progress; the work is `dualsplit_report::Producer`.

use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_render::Workload;
use dualsplit_report::data::{ReportSettings, Skipped};
use dualsplit_report::paper::PaperScene;
use dualsplit_report::produce::{BEYOND_TMS, SIM_WORKERS, real_simulator, sim_jobs};
use dualsplit_report::scenes::{self, SceneFiles};
use dualsplit_report::{Cache, Producer, Progress};
use dualsplit_sim::{SimAccel, ThreadModel};
use indicatif::ProgressBar;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::Instant;

/// Default stand-ins: the builtins at reduced sizes, keeping the paper's scene characters
/// (hairball ↔ Hairball, forest ↔ Vegetation, atrium ↔ Crytek Sponza). The default report
/// also takes the Dragon Box (`dragon_box.ply.gz`) from the scenes folder when it is there.
pub const DEFAULT_SCENES: [&str; 3] = [
    "builtin:atrium?triangles=30000",
    "builtin:forest?triangles=40000",
    "builtin:hairball?triangles=60000",
];
/// Default square resolution of the simulated frames. Threads run out of pixels before the
/// frame ends (scanline hand-out, the last pixels' paths the longest): measured on the
/// default scenes with 64 TMs, path tracing left up to 27 % of the thread-cycles idle at
/// 128², up to 18 % at 256² and 1 % at 512² (Dragon Box); 384² keeps the 64-TM tables
/// near or under the 10 % the report warns at, in a few minutes on 2 cores.
pub const DEFAULT_RES: u32 = 384;
/// The paper's scenes for `--full`: full-size builtins, plus the shipped meshes of
/// `dualsplit_report::scenes::PAPER_FILES` found in the scenes folder.
pub const FULL_SCENES: [&str; 3] = ["builtin:atrium", "builtin:forest", "builtin:hairball"];
/// 1024×1024: the resolution the paper states for Table 4 (ray casting); it states none
/// for path tracing (Table 5) or the other tables.
pub const FULL_RES: u32 = 1024;
/// Square resolution of the CPU ray sets (path workload rays).
pub const CPU_RES: u32 = 320;
/// Simulated rays per second of wall time on a 2-core machine, two simulations side by side,
/// with the `fast` thread model; used only for the up-front estimate. Measured with model
/// 7: dragon_box 256² path, BVH2, 477,571 rays in 3.3 s on one core (145K per second), two
/// at a time on 2 cores; other configurations and scenes run up to 2× slower.
pub const SIM_RAYS_PER_SECOND: f64 = 200_000.0;
/// The same with the compiled kernels (`rv32`). Measured with model 7: the same frame in
/// 16.1–16.6 s on one core (29K rays per second), two at a time.
pub const SIM_RAYS_PER_SECOND_RV32: f64 = 45_000.0;

/// Arguments of `dualsplit report`.
#[derive(clap::Args)]
pub struct Args {
    /// What to simulate: scenes, frame size, TM counts, thread model.
    #[command(flatten)]
    scope: crate::args::Scope,
    /// Output directory.
    #[arg(long)]
    out: Option<PathBuf>,
    #[command(flatten)]
    threads: crate::args::SimThreads,
    /// Print the plan (scenes, frames, configurations) and the time estimate, then stop
    /// without loading anything.
    #[arg(long)]
    dry_run: bool,
    /// Leave out "On an RTX-style GPU" (the simt model's frames on one scene, about 20
    /// CPU-seconds cold).
    #[arg(long)]
    no_rtx: bool,
    /// Assemble the study in DIR (made by `dualsplit plan`, filled by `run-job`) from the
    /// results in DIR/cache/ into DIR/report/ (or --out when given); missing entries are
    /// listed, not run.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["specs", "full", "dry_run", "tms", "model", "res", "scenes_dir"])]
    from: Option<PathBuf>,
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

/// Runs the subcommand.
pub fn run(mut args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    if let Some(dir) = &args.from {
        return super::study_report::run(dir, args.out.as_deref());
    }
    let start = Instant::now();
    let out = args.out.take().unwrap_or_else(|| PathBuf::from("report"));
    crate::output::prepare_dir(&out, "--out")?;
    let scope = Resolved::new(&args.scope)?;
    eprintln!("{}", scope.scene_files.describe());
    let user_scenes = !args.scope.specs.is_empty();
    let plan = Plan {
        specs: &scope.specs,
        res: scope.res,
        tms: &scope.tms,
        base_tms: scope.base_tms,
        thread_model: scope.thread_model,
        rtx: !args.no_rtx,
    };
    eprintln!("{}", plan.describe());
    if args.dry_run {
        return Ok(ExitCode::SUCCESS);
    }

    let mut scenes = Vec::new();
    let mut skipped = Vec::new();
    for spec in &scope.specs {
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
    let settings = ReportSettings {
        width: scope.res,
        height: scope.res,
        tms: scope.tms,
        base_tms: scope.base_tms,
        cpu_res: CPU_RES,
        full: args.scope.full,
        thread_model: scope.thread_model,
    };
    let simulate = real_simulator(scope.thread_model);
    let simt = real_simulator(ThreadModel::Simt);
    let bars = Bars {
        ctx,
        bar: Mutex::new(None),
    };
    let mut producer = Producer::new(Cache::new(out.join("cache")), settings, &bars, &*simulate)
        .sim_threads(args.threads.get());
    if !args.no_rtx {
        producer = producer.with_rtx(&*simt);
    }
    let mut data = producer.run(&scenes, skipped)?;
    data.scene_files = scope.scene_files;
    let written = dualsplit_report::write_report(&data, &out)?;
    if let Some(e) = data.sim_error() {
        eprintln!("note: {e}; simulated sections say so");
    }
    for w in dualsplit_report::summary::idle_warnings(&data, None) {
        eprintln!("warning: {w}");
    }
    outln!(
        "wrote {} ({} files; {} pieces computed, the rest from {}) in {:.1} s",
        out.join("index.html").display(),
        written.len(),
        producer.computed(),
        out.join("cache").display(),
        start.elapsed().as_secs_f64()
    );
    Ok(ExitCode::SUCCESS)
}

/// A study's scope ([`crate::args::Scope`], shared by `report` and `plan`) resolved into
/// what to simulate.
pub struct Resolved {
    /// The scenes folder found and the paper's meshes in it.
    pub scene_files: SceneFiles,
    /// The scenes, as [`resolve_specs`] picks them.
    pub specs: Vec<String>,
    /// Square resolution of the simulated frames.
    pub res: u32,
    /// TM counts of the scaling study, ascending, without repeats.
    pub tms: Vec<u32>,
    /// The TM count of Tables 4–6: 64 when listed, else the middle one.
    pub base_tms: u32,
    /// The thread model.
    pub thread_model: ThreadModel,
}

impl Resolved {
    /// Applies the defaults (plain or `--full`), checks the values, finds the scenes
    /// folder and picks the scenes. Loads no scene.
    pub fn new(scope: &crate::args::Scope) -> anyhow::Result<Self> {
        let dir = scenes::find_here(scope.scenes_dir.as_deref())?;
        let scene_files = SceneFiles::scan(dir.as_ref());
        let mut tms = scope.tms.clone();
        tms.sort_unstable();
        tms.dedup();
        if tms.is_empty() || tms.contains(&0) {
            anyhow::bail!("--tms needs positive TM counts, e.g. --tms 32,64,128");
        }
        let res = scope
            .res
            .unwrap_or(if scope.full { FULL_RES } else { DEFAULT_RES });
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
        let specs = resolve_specs(&scope.specs, scope.full, &scene_files);
        let base_tms = if tms.contains(&64) {
            64
        } else {
            tms[tms.len() / 2]
        };
        let model = scope
            .model
            .as_deref()
            .unwrap_or(if scope.full { "rv32" } else { "fast" });
        let thread_model = ThreadModel::parse(model).ok_or_else(|| {
            anyhow::anyhow!("unknown --model `{model}` (expected rv32, fast or simt)")
        })?;
        Ok(Self {
            scene_files,
            specs,
            res,
            tms,
            base_tms,
            thread_model,
        })
    }
}

/// The scenes of a report or study: those given, else the paper's meshes found in the
/// scenes folder (all with `full`; by default the paper's scenes: the reconstructed Dragon
/// Box and Crytek Sponza), then the builtins, less the stand-in of a paper scene whose own
/// mesh was found (the atrium when `crytek_sponza.gltf` is there).
pub fn resolve_specs(given: &[String], full: bool, scene_files: &SceneFiles) -> Vec<String> {
    if !given.is_empty() {
        return given.to_vec();
    }
    let found: Vec<_> = scene_files
        .files
        .iter()
        .filter(|f| f.path.is_some() && (full || f.same_mesh))
        .collect();
    let has_own = |scene: PaperScene| found.iter().any(|f| f.same_mesh && f.scene == scene);
    let builtins: &[&str] = if full { &FULL_SCENES } else { &DEFAULT_SCENES };
    found
        .iter()
        .filter_map(|f| f.path.clone())
        .chain(
            builtins
                .iter()
                .filter(|b| {
                    dualsplit_report::paper::PaperMatch::for_scene("", b)
                        .is_none_or(|m| !has_own(m.scene))
                })
                .map(|s| s.to_string()),
        )
        .collect()
}

/// What a report will simulate, known before any scene is loaded.
struct Plan<'a> {
    specs: &'a [String],
    res: u32,
    tms: &'a [u32],
    base_tms: u32,
    thread_model: ThreadModel,
    /// Whether "On an RTX-style GPU" runs.
    rtx: bool,
}

impl Plan<'_> {
    /// Frames of "On an RTX-style GPU" and their scene, when it runs.
    fn rtx_frames(&self) -> Option<(usize, &str)> {
        if !self.rtx || self.specs.is_empty() {
            return None;
        }
        let cfg = dualsplit_report::rtx::config().ok()?;
        let scene = &self.specs[dualsplit_report::rtx::scene_index(self.specs)];
        Some((dualsplit_report::rtx::plan(&cfg).len(), scene))
    }

    /// Every scene's simulated jobs ([`dualsplit_report::produce::sim_jobs`]).
    fn jobs(&self) -> Vec<(SimAccel, Workload, u32)> {
        Producer::scaling_specs(self.specs)
            .into_iter()
            .flat_map(|scaling| sim_jobs(self.base_tms, self.tms, scaling))
            .collect()
    }

    /// Simulated frames at the base TM count and at the other counts (the TM-scaling study
    /// of Table 7 and "Beyond the paper" at 128 TMs).
    fn frames(&self) -> (usize, usize) {
        let jobs = self.jobs();
        let base = jobs.iter().filter(|j| j.2 == self.base_tms).count();
        (base, jobs.len() - base)
    }

    /// Wall seconds the simulations take on a 2-core machine, from the rays of the frames
    /// (about 1.5 per pixel cast, 6 path, as `dualsplit-render` traces them on the paper's
    /// scenes) and the measured simulation speed.
    fn seconds(&self) -> f64 {
        let pixels = f64::from(self.res) * f64::from(self.res);
        let per_pixel = |w: Workload| match w {
            Workload::Cast => 1.5,
            Workload::Path => 6.0,
        };
        let rays: f64 = self.jobs().iter().map(|j| pixels * per_pixel(j.1)).sum();
        let rtx = if self.rtx_frames().is_some() {
            dualsplit_report::rtx::CPU_SECONDS / SIM_WORKERS as f64
        } else {
            0.0
        };
        rays / match self.thread_model {
            ThreadModel::Rv32 => SIM_RAYS_PER_SECOND_RV32,
            // Not measured for the simt model: the fast model's speed is the estimate.
            ThreadModel::Fast | ThreadModel::Simt => SIM_RAYS_PER_SECOND,
        } + rtx
    }

    fn describe(&self) -> String {
        let (base, scaling) = self.frames();
        let secs = self.seconds();
        let when = if secs >= 3600.0 {
            format!("{:.1} hours", secs / 3600.0)
        } else if secs >= 120.0 {
            format!("{:.0} minutes", (secs / 60.0).ceil())
        } else {
            format!("{:.0} seconds", secs.ceil())
        };
        format!(
            "plan: {} scenes ({}) at {r}×{r}, {} thread model; {base} frames at {} TMs \
             ({} configurations, cast and path) and {scaling} frames at other TM counts (the \
             paper's configurations at {:?} TMs on the scaling scenes, and BVH2, BVH8, BVH8+, \
             DST and the quantized structures at {BEYOND_TMS}){}; simulations roughly {when} \
             on a 2-core machine (cached frames are skipped)",
            self.specs.len(),
            self.specs.join(", "),
            self.thread_model.name(),
            self.base_tms,
            SimAccel::ALL.len(),
            self.tms,
            self.rtx_frames().map_or_else(String::new, |(n, scene)| format!(
                "; and {n} frames of \"On an RTX-style GPU\" (simt model, {scene} at {r2}×{r2}; \
                 --no-rtx leaves them out)",
                r2 = dualsplit_report::rtx::RES
            )),
            r = self.res,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dualsplit_report::scenes::{ScenesDir, Source};

    fn files(names: &[&str]) -> (tempfile::TempDir, SceneFiles) {
        let dir = tempfile::tempdir().unwrap();
        for n in names {
            std::fs::write(dir.path().join(n), "").unwrap();
        }
        let sd = ScenesDir {
            path: dir.path().to_path_buf(),
            source: Source::Flag,
        };
        let f = SceneFiles::scan(Some(&sd));
        (dir, f)
    }

    #[test]
    fn the_real_crytek_sponza_replaces_the_atrium() {
        let (_d, none) = files(&[]);
        assert_eq!(resolve_specs(&[], false, &none), DEFAULT_SCENES.to_vec());

        let (_d, f) = files(&[
            "dragon_box.ply.gz",
            "crytek_sponza.gltf",
            "dragon_sponza.ply.gz",
        ]);
        let specs = resolve_specs(&[], false, &f);
        assert!(specs[0].ends_with("dragon_box.ply.gz"), "{specs:?}");
        assert!(specs[1].ends_with("crytek_sponza.gltf"), "{specs:?}");
        assert!(specs.iter().all(|s| !s.contains("atrium")), "{specs:?}");
        assert_eq!(&specs[2..], &DEFAULT_SCENES[1..]);
        // --full adds the stand-in Dragon Sponza, still without the atrium.
        let full = resolve_specs(&[], true, &f);
        assert_eq!(full.len(), 5, "{full:?}");
        assert!(full.iter().any(|s| s.ends_with("dragon_sponza.ply.gz")));
        assert!(full.iter().all(|s| !s.contains("atrium")), "{full:?}");
        // Scenes given on the command line are taken as they are.
        let given = vec!["builtin:atrium".to_string()];
        assert_eq!(resolve_specs(&given, false, &f), given);
    }
}
