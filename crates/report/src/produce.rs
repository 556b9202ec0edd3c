//! Producers: compute each piece of [`ReportData`], each cached on disk by [`CacheKey`].
//!
//! ```text
//!  Scene ──▶ cpu piece     (structure sizes, build times, Mrays/s)   key: scene, cpu_res
//!        ──▶ render piece  (small PNG of the path workload)          key: scene, render_res
//!        ──▶ sim pieces    (one per configuration × workload × TMs)  key: scene, accel,
//!                                                                     workload, SimConfig, res
//! ```
//!
//! A scene's structures are built only when some piece of it is missing, and then once: the
//! CPU piece times that build and every piece after it shares the structures. Simulations
//! run side by side, one per host thread (a frame's TMs split over threads when there are
//! fewer frames than threads). A simulator error is recorded in the data as
//! "simulator unavailable: `<error>`" and never cached, so it is retried next time.

use crate::ReportError;
use crate::cache::{CODE_VERSION, Cache, CacheKey, SCHEMA};
use crate::data::{
    BuildTime, CpuData, ReportData, ReportSettings, RtxData, RtxRun, SceneReport, SimRun, Skipped,
    StructureSize, Throughput, TraversalCounts,
};
use crate::paper::{PaperMatch, PaperScene, PaperValues};
use base64::Engine;
use dualsplit_accel::{AccelKind, BuildConfig, CountingObserver, NoObserver, Structures};
use dualsplit_geometry::Hit;
use dualsplit_render::{PixelJob, RayKind, RayQuery, RenderSettings, TraceResult, Workload};
use dualsplit_scene::Scene;
use dualsplit_sim::{SimAccel, SimConfig, SimResult, ThreadModel};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::Instant;

/// Side of the square render shown for each scene.
pub const RENDER_RES: u32 = 192;
/// Samples per pixel of that render.
pub const RENDER_SPP: u32 = 8;
/// Minimum host time spent timing one (structure, ray kind) pair, in seconds.
pub const MIN_TIMING_S: f64 = 0.1;
/// Rays of each kind the CPU section times: fewer give timings dominated by warm caches
/// and start-up, so a kind with fewer rays is left out.
pub const CPU_RAYS: usize = 100_000;
/// Most frames of the path workload generated to gather [`CPU_RAYS`] rays of each kind.
pub const CPU_MAX_FRAMES: u32 = 8;
/// Simulations run side by side on two cores (the basis of `plan`'s time estimates).
pub const SIM_WORKERS: usize = 2;
/// The second TM count of "Beyond the paper" (beside the base count, the paper's 64): twice
/// the paper's chip, where the paper's memory-bound regime is stronger (its Table 7).
pub const BEYOND_TMS: u32 = 128;

/// Where producers report progress (the CLI draws indicatif bars; tests pass
/// [`NoProgress`]).
pub trait Progress: Sync {
    /// A phase of `total` units starts.
    fn begin(&self, phase: &str, total: u64);
    /// `n` more units are done.
    fn advance(&self, n: u64);
    /// The current phase is over.
    fn end(&self);
}

/// Progress that goes nowhere.
pub struct NoProgress;

impl Progress for NoProgress {
    fn begin(&self, _phase: &str, _total: u64) {}
    fn advance(&self, _n: u64) {}
    fn end(&self) {}
}

/// The simulator entry point, injectable so tests can count and fake simulations.
pub type SimulateFn<'a> = dyn Fn(
        &Scene,
        &Structures,
        SimAccel,
        &RenderSettings,
        &SimConfig,
        usize,
        &(dyn Fn(u64, u64) + Sync),
    ) -> Result<SimResult, String>
    + Sync
    + 'a;

/// The real simulator with thread model `model` ([`dualsplit_sim::simulate`]) on the
/// host threads it is given, errors as "simulator unavailable: …".
pub fn real_simulator(model: ThreadModel) -> Box<SimulateFn<'static>> {
    Box::new(
        move |scene, structures, accel, settings, cfg, threads, progress| {
            dualsplit_sim::simulate(
                &dualsplit_sim::FrameRequest::new(scene, structures, accel, settings, cfg)
                    .with_model(model)
                    .with_threads(threads),
                progress,
            )
            .map_err(|e| format!("simulator unavailable: {e}"))
        },
    )
}

/// One simulation to run.
#[derive(Clone, Debug)]
struct SimJob {
    scene: usize,
    accel: SimAccel,
    workload: Workload,
    tms: u32,
    key: CacheKey,
    /// The chip: the report's TRaX chip, or the RTX 2060 of "On an RTX-style GPU".
    cfg: SimConfig,
    /// Whether this is a frame of "On an RTX-style GPU" (simulated by the `simt` model).
    rtx: bool,
}

/// Computes a report, piece by piece, reusing cached pieces.
pub struct Producer<'a> {
    cache: Cache,
    settings: ReportSettings,
    progress: &'a dyn Progress,
    simulate: &'a SimulateFn<'a>,
    computed: AtomicU64,
    /// Host threads for the simulations ([`Producer::sim_threads`]).
    sim_threads: usize,
    /// The `simt` simulator of "On an RTX-style GPU" ([`Producer::with_rtx`]); without
    /// it the report has no such section.
    rtx: Option<&'a SimulateFn<'a>>,
}

impl<'a> Producer<'a> {
    /// A producer writing its cache to `cache`.
    pub fn new(
        cache: Cache,
        settings: ReportSettings,
        progress: &'a dyn Progress,
        simulate: &'a SimulateFn<'a>,
    ) -> Self {
        Self {
            cache,
            settings,
            progress,
            simulate,
            computed: AtomicU64::new(0),
            sim_threads: SIM_WORKERS,
            rtx: None,
        }
    }

    /// Adds "On an RTX-style GPU" ([`crate::rtx`]): its frames are simulated with
    /// `simulate` (the `simt` thread model: [`real_simulator`]`(ThreadModel::Simt)`) on the
    /// compiled-in RTX 2060 configuration, queued with the report's other frames.
    pub fn with_rtx(self, simulate: &'a SimulateFn<'a>) -> Self {
        Self {
            rtx: Some(simulate),
            ..self
        }
    }

    /// Runs the simulations on `threads` host threads in all ([`SIM_WORKERS`] unless
    /// set): as many frames side by side as there are threads (or frames), the threads
    /// shared among them ([`dualsplit_sim::share_threads`]). Results do not depend on it.
    pub fn sim_threads(self, threads: usize) -> Self {
        Self {
            sim_threads: threads.max(1),
            ..self
        }
    }

    /// How many pieces were computed (not found in the cache) so far.
    pub fn computed(&self) -> u64 {
        self.computed.load(Ordering::Relaxed)
    }

    /// The simulated jobs of a scene: every configuration × workload at the base TM count
    /// (Tables 4–6, and the quantized structures for "Beyond the paper"), path tracing with
    /// the paper's configurations at every TM count when `scaling` (Table 7), and the
    /// "Beyond the paper" configurations in both workloads at [`BEYOND_TMS`].
    fn sim_plan(&self, scaling: bool) -> Vec<(SimAccel, Workload, u32)> {
        sim_jobs(self.settings.base_tms, &self.settings.tms, scaling)
    }

    /// The scenes that get the TM-scaling study: those standing for the paper's Crytek
    /// Sponza and Hairball (Table 7), or the first scene when none does.
    pub fn scaling_scenes(scenes: &[Scene]) -> Vec<bool> {
        let names: Vec<String> = scenes
            .iter()
            .map(|s| format!("{} {}", s.name, s.spec))
            .collect();
        Self::scaling_specs(&names)
    }

    /// [`Producer::scaling_scenes`] from the scenes' specs alone (before loading them).
    pub fn scaling_specs(specs: &[String]) -> Vec<bool> {
        let wanted: Vec<bool> = specs
            .iter()
            .map(|spec| {
                PaperMatch::for_scene("", spec).is_some_and(|m| {
                    matches!(m.scene, PaperScene::CrytekSponza | PaperScene::Hairball)
                })
            })
            .collect();
        if wanted.iter().any(|&w| w) {
            wanted
        } else {
            (0..specs.len()).map(|i| i == 0).collect()
        }
    }

    fn sim_config(&self, tms: u32) -> SimConfig {
        let mut cfg = SimConfig::lin2020();
        cfg.tms = tms;
        cfg
    }

    fn sim_settings(&self, workload: Workload) -> RenderSettings {
        RenderSettings::new(self.settings.width, self.settings.height, workload)
    }

    /// Produces the whole report for `scenes` (already loaded); `skipped` lists the scenes
    /// that could not be loaded.
    pub fn run(&self, scenes: &[Scene], skipped: Vec<Skipped>) -> Result<ReportData, ReportError> {
        // Each scene's structures are built once, the first time a piece needs them (the
        // CPU piece reports that build's time), and shared by every piece after it.
        let structures: Vec<OnceLock<Result<Built, String>>> =
            scenes.iter().map(|_| OnceLock::new()).collect();
        // A scene whose structures cannot be built (an image offset overflow) fails the
        // pieces that need them with a typed error instead of panicking.
        let built = |i: usize| -> Result<&Built, ReportError> {
            structures[i]
                .get_or_init(|| build(&scenes[i]))
                .as_ref()
                .map_err(|message| ReportError::Build {
                    scene: scenes[i].name.clone(),
                    message: message.clone(),
                })
        };
        let get = |i: usize| built(i).map(|b| &b.structures);
        let hashes: Vec<String> = scenes.iter().map(|s| s.content_hash()).collect();

        // Host pieces: CPU measurements and renders.
        let mut cpu = Vec::new();
        let mut renders = Vec::new();
        self.progress
            .begin("CPU + renders", scenes.len() as u64 * 2);
        for (i, scene) in scenes.iter().enumerate() {
            let key = CacheKey::new(
                "cpu",
                &hashes[i],
                "all",
                "path",
                &format!("cpu_res={};rays={CPU_RAYS}", self.settings.cpu_res),
                (self.settings.cpu_res, self.settings.cpu_res),
            );
            // Incomplete CPU data (a structure the accel crate does not build yet) is not
            // cached, so it is measured again once the structure exists.
            cpu.push(self.cached(
                &key,
                || cpu_data(scene, built(i)?, self.settings.cpu_res),
                |c: &CpuData| c.sizes.iter().all(|s| s.bytes.is_ok()),
            )?);
            self.progress.advance(1);
            let key = CacheKey::new(
                "render",
                &hashes[i],
                "bvh2",
                "path",
                &format!("spp={RENDER_SPP}"),
                (RENDER_RES, RENDER_RES),
            );
            renders.push(self.cached(&key, || render_png_base64(scene, get(i)?), |_| true)?);
            self.progress.advance(1);
        }
        self.progress.end();

        // Simulated pieces.
        let scaling = Self::scaling_scenes(scenes);
        let mut runs: Vec<Vec<SimRun>> = scenes.iter().map(|_| Vec::new()).collect();
        let mut missing = VecDeque::new();
        for (i, _) in scenes.iter().enumerate() {
            for (accel, workload, tms) in self.sim_plan(scaling[i]) {
                let cfg = self.sim_config(tms);
                let key = CacheKey::new(
                    "sim",
                    &hashes[i],
                    &format!("{}@{}", accel.name(), self.settings.thread_model.name()),
                    workload.name(),
                    &serde_json::to_string(&cfg).unwrap_or_default(),
                    (self.settings.width, self.settings.height),
                );
                match self.cache.get::<SimResult>(&key) {
                    Some(r) => runs[i].push(SimRun {
                        accel,
                        workload,
                        tms,
                        result: Ok(r),
                    }),
                    None => missing.push_back(SimJob {
                        scene: i,
                        accel,
                        workload,
                        tms,
                        key,
                        cfg,
                        rtx: false,
                    }),
                }
            }
        }
        // "On an RTX-style GPU": its frames, on one scene, queued with the others.
        let rtx_cfg = match self.rtx {
            Some(_) if !scenes.is_empty() => {
                Some(crate::rtx::config().map_err(|message| ReportError::Build {
                    scene: "configs/rtx2060.toml".into(),
                    message,
                })?)
            }
            _ => None,
        };
        let rtx_scene =
            crate::rtx::scene_index(&scenes.iter().map(|s| s.spec.clone()).collect::<Vec<_>>());
        let mut rtx_runs = Vec::new();
        if let Some(base) = &rtx_cfg {
            for (accel, workload, warps, mshr) in crate::rtx::plan(base) {
                let cfg = crate::rtx::with_point(base, warps, mshr);
                let key = CacheKey::new(
                    "simt",
                    &hashes[rtx_scene],
                    &format!("{}@simt", accel.name()),
                    workload.name(),
                    &serde_json::to_string(&cfg).unwrap_or_default(),
                    (crate::rtx::RES, crate::rtx::RES),
                );
                match self.cache.get::<SimResult>(&key) {
                    Some(r) => rtx_runs.push(RtxRun {
                        accel,
                        workload,
                        rt_max_warps: warps,
                        rt_max_mshr: mshr,
                        result: Ok(r),
                    }),
                    None => missing.push_back(SimJob {
                        scene: rtx_scene,
                        accel,
                        workload,
                        tms: 0,
                        key,
                        cfg,
                        rtx: true,
                    }),
                }
            }
        }
        let pixels = u64::from(self.settings.width) * u64::from(self.settings.height);
        let rtx_pixels = u64::from(crate::rtx::RES) * u64::from(crate::rtx::RES);
        let job_pixels = |j: &SimJob| if j.rtx { rtx_pixels } else { pixels };
        self.progress
            .begin("simulating", missing.iter().map(job_pixels).sum());
        let (workers, per_frame) = dualsplit_sim::share_threads(missing.len(), self.sim_threads);
        let queue = Mutex::new(missing);
        let done: Mutex<Vec<(SimJob, Result<SimResult, String>)>> = Mutex::new(Vec::new());
        let write_error: Mutex<Option<ReportError>> = Mutex::new(None);
        std::thread::scope(|s| {
            for _ in 0..workers {
                s.spawn(|| {
                    loop {
                        let job = queue.lock().map(|mut q| q.pop_front()).ok().flatten();
                        let Some(job) = job else { break };
                        // Until the accel crate builds a DST it dispatches DST to BVH2, and a
                        // "DST" simulation would be BVH2's: report that instead of simulating.
                        let structures = match get(job.scene) {
                            Ok(s) => s,
                            Err(e) => {
                                self.progress.advance(job_pixels(&job));
                                if let Ok(mut d) = done.lock() {
                                    d.push((job, Err(format!("not simulated: {e}"))));
                                }
                                continue;
                            }
                        };
                        if matches!(job.accel, SimAccel::Dst | SimAccel::DstSw)
                            && let Err(e) = structure_bytes(structures, AccelKind::Dst)
                        {
                            self.progress.advance(job_pixels(&job));
                            if let Ok(mut d) = done.lock() {
                                d.push((job, Err(format!("not simulated: {e}"))));
                            }
                            continue;
                        }
                        let last = AtomicU64::new(0);
                        let report = |d: u64, _t: u64| {
                            let prev = last.swap(d, Ordering::Relaxed);
                            self.progress.advance(d.saturating_sub(prev));
                        };
                        let (simulate, settings) = match self.rtx {
                            Some(rtx) if job.rtx => (
                                rtx,
                                RenderSettings::new(crate::rtx::RES, crate::rtx::RES, job.workload),
                            ),
                            _ => (self.simulate, self.sim_settings(job.workload)),
                        };
                        let result = simulate(
                            &scenes[job.scene],
                            structures,
                            job.accel,
                            &settings,
                            &job.cfg,
                            per_frame,
                            &report,
                        );
                        self.progress
                            .advance(job_pixels(&job).saturating_sub(last.load(Ordering::Relaxed)));
                        if let Ok(r) = &result {
                            self.computed.fetch_add(1, Ordering::Relaxed);
                            if let Err(e) = self.cache.put(&job.key, r)
                                && let Ok(mut w) = write_error.lock()
                            {
                                w.get_or_insert(e);
                            }
                        }
                        if let Ok(mut d) = done.lock() {
                            d.push((job, result));
                        }
                    }
                });
            }
        });
        self.progress.end();
        if let Some(e) = write_error.into_inner().ok().flatten() {
            return Err(e);
        }
        for (job, result) in done.into_inner().unwrap_or_default() {
            if job.rtx {
                let (rt_max_warps, rt_max_mshr) = crate::rtx::point(&job.cfg);
                rtx_runs.push(RtxRun {
                    accel: job.accel,
                    workload: job.workload,
                    rt_max_warps,
                    rt_max_mshr,
                    result,
                });
                continue;
            }
            runs[job.scene].push(SimRun {
                accel: job.accel,
                workload: job.workload,
                tms: job.tms,
                result,
            });
        }

        let mut out = Vec::new();
        for (((scene, cpu), render), mut sim) in scenes.iter().zip(cpu).zip(renders).zip(runs) {
            let order = |r: &SimRun| {
                (
                    r.workload == Workload::Path,
                    r.tms,
                    SimAccel::ALL.iter().position(|&a| a == r.accel),
                )
            };
            sim.sort_by_key(order);
            out.push(SceneReport {
                name: scene.name.clone(),
                spec: scene.spec.clone(),
                triangles: scene.triangles.len() as u64,
                content_hash: scene.content_hash(),
                paper: PaperMatch::for_scene(&scene.name, &scene.spec)
                    .map(|m| m.with_bounds(&scene.bounds)),
                cpu,
                sim,
                render_png_base64: render,
                render_res: RENDER_RES,
            });
        }
        let rtx = rtx_cfg.map(|base| {
            let plan = crate::rtx::plan(&base);
            let at = |r: &RtxRun| {
                plan.iter()
                    .position(|p| *p == (r.accel, r.workload, r.rt_max_warps, r.rt_max_mshr))
            };
            rtx_runs.sort_by_key(at);
            let (base_warps, base_mshr) = crate::rtx::point(&base);
            RtxData {
                scene: scenes[rtx_scene].name.clone(),
                spec: scenes[rtx_scene].spec.clone(),
                res: crate::rtx::RES,
                base_warps,
                base_mshr,
                peak_dram_gbps: crate::rtx::peak_dram_gbps(&base),
                runs: rtx_runs,
            }
        });
        Ok(ReportData {
            code_version: format!("{CODE_VERSION}{SCHEMA}+sim{}", dualsplit_sim::MODEL_VERSION),
            settings: self.settings.clone(),
            scenes: out,
            skipped,
            scene_files: Default::default(),
            paper: PaperValues::published(),
            rtx,
        })
    }

    fn cached<T: serde::Serialize + serde::de::DeserializeOwned>(
        &self,
        key: &CacheKey,
        compute: impl FnOnce() -> Result<T, ReportError>,
        keep: impl FnOnce(&T) -> bool,
    ) -> Result<T, ReportError> {
        if let Some(v) = self.cache.get(key) {
            return Ok(v);
        }
        let v = compute()?;
        self.computed.fetch_add(1, Ordering::Relaxed);
        if keep(&v) {
            self.cache.put(key, &v)?;
        }
        Ok(v)
    }
}

/// Bytes of structure `kind`: nodes plus triangle-index lists (Table 3's sizes; triangle
/// data is shared by all structures and not counted), from `Structures::stats`. Both DST
/// variants share one image (`dst`). A structure the accel crate does not build yet reports
/// why instead of a number.
pub fn structure_bytes(structures: &Structures, kind: AccelKind) -> Result<u64, String> {
    let name = stats_name(kind);
    structures
        .stats()
        .into_iter()
        .find(|s| s.name == name)
        .map(|s| s.bytes_total)
        .ok_or_else(|| format!("the accel crate does not build `{name}` yet"))
}

/// The name `Structures::stats` uses for `kind`.
fn stats_name(kind: AccelKind) -> &'static str {
    match kind {
        AccelKind::DstSw | AccelKind::Dst => "dst",
        k => k.name(),
    }
}

/// A traced ray and its BVH2 answer.
struct Traced {
    query: RayQuery,
    answer: TraceResult,
}

fn trace(structures: &Structures, kind: AccelKind, q: &RayQuery) -> TraceResult {
    match q.kind {
        RayKind::Shadow => TraceResult::Occluded(structures.any_hit(kind, &q.ray, &mut NoObserver)),
        _ => TraceResult::Closest(structures.closest_hit(kind, &q.ray, &mut NoObserver)),
    }
}

fn same_answer(a: &TraceResult, b: &TraceResult) -> bool {
    let hit_eq = |x: &Option<Hit>, y: &Option<Hit>| match (x, y) {
        (None, None) => true,
        (Some(x), Some(y)) => x.t.to_bits() == y.t.to_bits() && x.prim == y.prim,
        _ => false,
    };
    match (a, b) {
        (TraceResult::Closest(x), TraceResult::Closest(y)) => hit_eq(x, y),
        (TraceResult::Occluded(x), TraceResult::Occluded(y)) => x == y,
        _ => false,
    }
}

/// The rays of one frame of the path workload at `res`×`res`, 1 spp, seed `seed`, traced on
/// BVH2, in scanline order (rows split over two threads; each pixel is deterministic).
fn frame_rays(scene: &Scene, structures: &Structures, res: u32, seed: u32) -> Vec<Traced> {
    let mut settings = RenderSettings::new(res, res, Workload::Path);
    settings.seed = seed;
    let row = |y: u32| -> Vec<Traced> {
        let mut out = Vec::new();
        for x in 0..res {
            let mut job = PixelJob::new(scene, &settings, x, y);
            while let Some(q) = job.next_ray() {
                let answer = trace(structures, AccelKind::Bvh2, &q);
                out.push(Traced { query: q, answer });
                job.submit(answer);
            }
        }
        out
    };
    let mut rows: Vec<Vec<Traced>> = (0..res).map(|_| Vec::new()).collect();
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..2u32)
            .map(|k| s.spawn(move || (k..res).step_by(2).map(|y| (y, row(y))).collect::<Vec<_>>()))
            .collect();
        for h in handles {
            for (y, r) in h.join().unwrap_or_default() {
                rows[y as usize] = r;
            }
        }
    });
    rows.into_iter().flatten().collect()
}

/// [`CPU_RAYS`] rays of each kind (primary, shadow, diffuse) from frames of the path
/// workload at `res`×`res` with seeds 0, 1, … (at most [`CPU_MAX_FRAMES`]), traced on BVH2;
/// a kind the frames yield fewer of (a camera that sees mostly sky) keeps what it has.
fn ray_sets(scene: &Scene, structures: &Structures, res: u32) -> [Vec<Traced>; 3] {
    let mut sets: [Vec<Traced>; 3] = Default::default();
    for seed in 0..CPU_MAX_FRAMES {
        if sets.iter().all(|s| s.len() >= CPU_RAYS) {
            break;
        }
        for t in frame_rays(scene, structures, res, seed) {
            let i = match t.query.kind {
                RayKind::Primary => 0,
                RayKind::Shadow => 1,
                RayKind::Diffuse => 2,
            };
            if sets[i].len() < CPU_RAYS {
                sets[i].push(t);
            }
        }
    }
    sets
}

/// A scene's structures, built once for every piece of the report, with the host time
/// their build took.
pub struct Built {
    /// Every structure, with the report's build settings.
    pub structures: Structures,
    /// Wall time of the build, in milliseconds (a measurement of this machine).
    pub ms: f64,
}

/// Every structure of `scene` with the report's build settings, timed; the error as text.
fn build(scene: &Scene) -> Result<Built, String> {
    let t0 = Instant::now();
    let structures = Structures::try_build(&scene.triangles, &BuildConfig::high_quality())
        .map_err(|e| e.to_string())?;
    Ok(Built {
        structures,
        ms: t0.elapsed().as_secs_f64() * 1e3,
    })
}

/// Host measurements of one scene from its `built` structures: build times, sizes, and
/// single-thread Mrays/s per structure and ray kind, each structure checked ray by ray
/// against BVH2 before it is timed.
pub fn cpu_data(scene: &Scene, built: &Built, cpu_res: u32) -> Result<CpuData, ReportError> {
    let structures = &built.structures;
    let all_structures_ms = built.ms;
    let build_ms = structures
        .stats()
        .into_iter()
        .map(|s| BuildTime {
            structure: s.name,
            ms: s.build_ms,
        })
        .collect();
    let sizes = AccelKind::ALL
        .iter()
        .map(|&kind| StructureSize {
            kind,
            bytes: structure_bytes(structures, kind),
        })
        .collect();
    let sets = ray_sets(scene, structures, cpu_res);
    let mut throughput = Vec::new();
    for (ray_kind, set) in [RayKind::Primary, RayKind::Shadow, RayKind::Diffuse]
        .into_iter()
        .zip(&sets)
    {
        let set: Vec<&Traced> = set.iter().collect();
        for kind in AccelKind::ALL {
            let mrays_per_s = if set.len() < CPU_RAYS {
                Err(format!(
                    "{} {} rays from {CPU_MAX_FRAMES} frames, fewer than the {CPU_RAYS} a timing needs",
                    set.len(),
                    ray_kind.name()
                ))
            } else {
                time_set(structures, kind, ray_kind, &set)
            };
            throughput.push(Throughput {
                kind,
                ray_kind,
                rays: set.len() as u64,
                mrays_per_s,
            });
        }
    }
    let counts = traversal_counts(structures, &sets);
    Ok(CpuData {
        sizes,
        build_ms,
        all_structures_ms,
        throughput,
        counts,
    })
}

/// The simulated jobs of one scene (configuration, workload, TM count) for a report at
/// `base_tms` with the scaling study at `tms`: every configuration × workload at the base
/// count (Tables 4–6, and the quantized structures for "Beyond the paper"), path tracing
/// with the paper's configurations at every other count of `tms` when `scaling` (Table 7),
/// and the "Beyond the paper" configurations in both workloads at [`BEYOND_TMS`]; each job
/// once.
pub fn sim_jobs(base_tms: u32, tms: &[u32], scaling: bool) -> Vec<(SimAccel, Workload, u32)> {
    let mut plan = Vec::new();
    for workload in [Workload::Cast, Workload::Path] {
        for accel in SimAccel::ALL {
            plan.push((accel, workload, base_tms));
        }
    }
    if scaling {
        for &t in tms {
            if t != base_tms {
                for accel in SimAccel::PAPER {
                    plan.push((accel, Workload::Path, t));
                }
            }
        }
    }
    for workload in [Workload::Cast, Workload::Path] {
        for accel in SimAccel::BEYOND {
            let job = (accel, workload, BEYOND_TMS);
            if !plan.contains(&job) {
                plan.push(job);
            }
        }
    }
    plan
}

/// The structures whose per-ray work "Beyond the paper" compares: the BVH8 and its
/// compressed form, the DST and its quantized form.
pub const COUNTED: [AccelKind; 4] = [
    AccelKind::Bvh8,
    AccelKind::Cwbvh,
    AccelKind::Dst,
    AccelKind::DstQ,
];

/// [`TraversalCounts`] of the [`COUNTED`] structures on each ray set (primary, shadow,
/// diffuse), with a counting observer.
fn traversal_counts(structures: &Structures, sets: &[Vec<Traced>; 3]) -> Vec<TraversalCounts> {
    let mut out = Vec::new();
    for (ray_kind, set) in [RayKind::Primary, RayKind::Shadow, RayKind::Diffuse]
        .into_iter()
        .zip(sets)
    {
        if set.is_empty() {
            continue;
        }
        for kind in COUNTED {
            let mut obs = CountingObserver::default();
            for r in set {
                dualsplit_render::trace_query(structures, kind, &r.query, &mut obs);
            }
            let n = set.len() as f64;
            out.push(TraversalCounts {
                kind,
                ray_kind,
                rays: set.len() as u64,
                nodes: obs.nodes as f64 / n,
                box_tests: obs.box_tests as f64 / n,
                plane_tests: obs.plane_tests as f64 / n,
                triangle_tests: obs.triangle_tests as f64 / n,
                bytes: obs.bytes as f64 / n,
            });
        }
    }
    out
}

fn time_set(
    structures: &Structures,
    kind: AccelKind,
    ray_kind: RayKind,
    set: &[&Traced],
) -> Result<f64, String> {
    if matches!(kind, AccelKind::DstSw | AccelKind::Dst) {
        // A DST variant: timed only once the accel crate builds a DST (until then it
        // dispatches to BVH2, and timing it would report BVH2 under DST's name).
        structure_bytes(structures, kind)?;
    }
    if set.is_empty() {
        return Err("no rays of this kind".into());
    }
    let mismatches = set
        .iter()
        .filter(|r| !same_answer(&trace(structures, kind, &r.query), &r.answer))
        .count() as u64;
    if mismatches > 0 {
        return Err(ReportError::Mismatch {
            structure: kind.name().into(),
            ray_kind: format!("{ray_kind:?}"),
            mismatches,
            rays: set.len() as u64,
        }
        .to_string());
    }
    let t0 = Instant::now();
    let mut traced = 0u64;
    let mut sink = 0u64;
    while t0.elapsed().as_secs_f64() < MIN_TIMING_S {
        for r in set {
            if let TraceResult::Closest(Some(_)) | TraceResult::Occluded(true) =
                trace(structures, kind, &r.query)
            {
                sink += 1;
            }
        }
        traced += set.len() as u64;
    }
    std::hint::black_box(sink);
    Ok(traced as f64 / t0.elapsed().as_secs_f64() / 1e6)
}

/// Renders the scene's path workload ([`RENDER_RES`]², [`RENDER_SPP`] spp) on BVH2 and
/// returns it as a base64 PNG (grey, gamma 2.2).
pub fn render_png_base64(scene: &Scene, structures: &Structures) -> Result<String, ReportError> {
    let mut settings = RenderSettings::new(RENDER_RES, RENDER_RES, Workload::Path);
    settings.spp = RENDER_SPP;
    let row = |y: u32| -> Vec<u8> {
        (0..RENDER_RES)
            .map(|x| {
                let mut job = PixelJob::new(scene, &settings, x, y);
                while let Some(q) = job.next_ray() {
                    job.submit(trace(structures, AccelKind::Bvh2, &q));
                }
                let v = job.radiance().clamp(0.0, 1.0).powf(1.0 / 2.2);
                (v * 255.0).round() as u8
            })
            .collect()
    };
    // Two threads (even and odd rows); each pixel is deterministic, so the image is too.
    let mut rows: Vec<Vec<u8>> = vec![Vec::new(); RENDER_RES as usize];
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..2u32)
            .map(|k| {
                s.spawn(move || {
                    (k..RENDER_RES)
                        .step_by(2)
                        .map(|y| (y, row(y)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for h in handles {
            for (y, r) in h.join().unwrap_or_default() {
                rows[y as usize] = r;
            }
        }
    });
    let pixels: Vec<u8> = rows.concat();
    let png = encode_png(RENDER_RES, RENDER_RES, png::ColorType::Grayscale, &pixels).map_err(
        |message| ReportError::Png {
            what: format!("render of {}", scene.name),
            message,
        },
    )?;
    Ok(base64::engine::general_purpose::STANDARD.encode(png))
}

/// Encodes 8-bit pixels as a PNG.
pub fn encode_png(
    width: u32,
    height: u32,
    color: png::ColorType,
    data: &[u8],
) -> Result<Vec<u8>, String> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(color);
    enc.set_depth(png::BitDepth::Eight);
    let mut w = enc.write_header().map_err(|e| e.to_string())?;
    w.write_image_data(data).map_err(|e| e.to_string())?;
    w.finish().map_err(|e| e.to_string())?;
    Ok(out)
}
