//! `dualsplit bench`: CPU traversal throughput per structure and ray type, and full-frame
//! render times. Every structure's answers are checked against BVH2, ray by ray, before
//! anything is timed (see `dualsplit_render::bench`).
//!
//! With `--peer embree` the same ray sets are also traced on Intel Embree 3 (single-ray
//! `rtcIntersect1` / `rtcOccluded1`): its answers are compared with ours first (differences
//! must be explained as ties, grazing or interval-boundary hits, see `dualsplit_embree::agree`),
//! then ours and Embree's are timed interleaved, pass after pass, in one run. `--peer
//! embree,embree-robust` adds Embree built in its robust mode, the watertight guarantee
//! our traversals always give, timed in the same interleaved passes; `embree-avx2` adds
//! Embree with its kernels limited to AVX2, the instruction set our traversals use at most
//! (on a CPU with AVX-512 Embree otherwise runs its AVX-512 kernels).
//!
//! With `--tree FILE` the saved structure is measured instead of building: its traversals
//! only (`--accel` must name one of them), on rays recorded with its own first traversal
//! (`dualsplit check --tree` is what compares a saved tree with a fresh BVH2).
use super::render::{get_structures, load_scene};
use crate::args::{accel_names, parse_res, parse_workload};
use crate::loaded::Loaded;
use crate::output::JsonOut;
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::{AccelKind, NoObserver, TraversalSet};
use dualsplit_embree::{
    Agreement, EmbreeOptions, EmbreeScene, TErrors, agree_closest, agree_occluded, t_errors,
};
use dualsplit_geometry::Ray;
use dualsplit_render::bench::{
    Contender, MeasureConfig, RaySet, Throughput, Timing, measure, measure_interleaved, ray_sets,
    trace_fn, verify,
};
use dualsplit_render::{RayKind, RenderSettings, TraceResult, Workload, render, tile_count};
use dualsplit_scene::Scene;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::process::ExitCode;
use std::time::Instant;

/// A tracer to compare ours with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Peer {
    /// Intel Embree 3 (Debian's libembree-dev), single rays, built as a new user gets it
    /// (medium quality, no robust mode).
    Embree,
    /// The same in Embree's robust (watertight) mode: the guarantee our traversals always
    /// give, at Embree's cost for it.
    EmbreeRobust,
    /// Embree as a new user gets it, its kernels limited to AVX2 (`max_isa=avx2`): on a CPU
    /// with AVX-512, the instruction set our traversals use at most.
    EmbreeAvx2,
}

impl Peer {
    /// The peer's name in the results.
    fn name(self) -> &'static str {
        match self {
            Self::Embree => "embree",
            Self::EmbreeRobust => "embree-robust",
            Self::EmbreeAvx2 => "embree-avx2",
        }
    }

    /// How its Embree scene is built.
    fn options(self) -> EmbreeOptions {
        EmbreeOptions {
            robust: self == Self::EmbreeRobust,
            avx2_at_most: self == Self::EmbreeAvx2,
            ..EmbreeOptions::default()
        }
    }
}

/// Arguments of `dualsplit bench`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params
    /// (hairball, forest, atrium, cornell).
    #[arg(value_parser = crate::args::parse_scene)]
    scene: String,
    /// Traversals to measure, comma-separated; default all (with --tree, all of the saved
    /// structure's traversals).
    #[arg(long, value_delimiter = ',', value_parser = accel_names())]
    accel: Vec<AccelKind>,
    /// Measure the tree saved in FILE by `dualsplit build` instead of building; it must come
    /// from SCENE (its triangles are checked). Only its traversals exist (both decoders
    /// for a DST, its own kind for a BVH); the rays and their expected answers come from its
    /// first one (`check --tree` compares a saved tree with a fresh BVH2).
    #[arg(long, value_name = "FILE")]
    tree: Option<std::path::PathBuf>,
    /// Workload whose rays are measured: cast (primary, shadow) or path (primary, shadow, diffuse).
    #[arg(long, default_value = "path", value_parser = parse_workload)]
    workload: Workload,
    /// Frame resolution the rays come from, WIDTHxHEIGHT or N for N×N.
    #[arg(long, default_value = "512", value_parser = parse_res)]
    res: (u32, u32),
    /// Seed of the per-pixel random numbers.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Minimum seconds of timing per structure and ray type.
    #[arg(long, default_value_t = 1.0)]
    min_seconds: f64,
    /// Skip the full-frame render timing.
    #[arg(long)]
    no_frame: bool,
    /// Also trace the rays on peers, comma-separated (embree, embree-robust, embree-avx2),
    /// check that each agrees with ours, and time ours and the peers interleaved in one run.
    #[arg(long, value_enum, value_delimiter = ',')]
    peer: Vec<Peer>,
    /// Threads the timed traversals run on (default: every core). Loading, building and
    /// the checks use every core whatever this says.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=4096))]
    threads: Option<u32>,
    /// Print the results as JSON lines instead of a table; `--json=FILE` writes them to FILE.
    #[arg(long, value_name = "FILE", num_args = 0..=1, require_equals = true, default_missing_value = "-")]
    json: Option<std::path::PathBuf>,
}

/// Most pixels in a benchmark frame: 2^24 (4096 × 4096). The ray sets hold every ray of the
/// frame with BVH2's answer, about 450 bytes per pixel on the path workload (peak RSS of
/// `bench builtin:cornell --res 1024 --accel bvh2`: 459 MB), so about 7.5 GB at the limit.
pub const MAX_BENCH_PIXELS: u64 = 1 << 24;

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    if let Some(p) = args.peer.first()
        && !dualsplit_embree::available()
    {
        anyhow::bail!(
            "--peer {}: the Embree peer is missing: {}",
            p.name(),
            dualsplit_embree::STATUS
        );
    }
    let mut peers: Vec<Peer> = Vec::new();
    for &p in &args.peer {
        if !peers.contains(&p) {
            peers.push(p);
        }
    }
    // The measuring knob of the CPU copies' leaf merging: refused here when malformed (the
    // library would quietly keep its default).
    dualsplit_accel::wide::cpu::merge_limit_from_env().map_err(anyhow::Error::msg)?;
    let json = JsonOut::from_arg(args.json.as_deref())?;
    // JSON lines go out as they are measured on standard output, and all at the end to a
    // file.
    let mut lines: Vec<String> = Vec::new();
    let mut json_line = |v: String| {
        if json == Some(JsonOut::Stdout) {
            outln!("{v}");
        } else {
            lines.push(v);
        }
    };
    let pool = match args.threads {
        Some(n) => Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(n as usize)
                .build()
                .context("starting the timing threads")?,
        ),
        None => None,
    };
    let in_pool = |f: &mut (dyn FnMut() -> anyhow::Result<()> + Send)| match &pool {
        Some(p) => p.install(f),
        None => f(),
    };
    let scene = load_scene(&args.scene, ctx, json.is_some())?;
    let settings = RenderSettings {
        seed: args.seed,
        ..RenderSettings::new(args.res.0, args.res.1, args.workload)
    };
    dualsplit_render::validate(&scene, &settings)?;
    let pixels = u64::from(settings.width) * u64::from(settings.height);
    if pixels > MAX_BENCH_PIXELS {
        anyhow::bail!(
            "--res {}x{}: {pixels} pixels; bench holds every ray of its frame (about 450 bytes \
             per pixel), so at most {MAX_BENCH_PIXELS} (4096x4096)",
            settings.width,
            settings.height
        );
    }
    let structures = get_structures(&scene, args.tree.as_deref(), &[], ctx, json.is_some())?;
    json_line(structures.timing_json(&scene).to_string());
    let host = crate::host::Host::detect();
    json_line(serde_json::json!({ "host": host }).to_string());
    let accels = structures.kinds_or_all(&args.accel)?;
    let sp = ctx.spinner(format!(
        "generating rays on {}",
        structures.reference().name()
    ));
    let t = Instant::now();
    let sets = ray_sets(&scene, &structures, &settings)?;
    sp.finish_and_clear();
    let threads = pool
        .as_ref()
        .map_or_else(rayon::current_num_threads, |p| p.current_num_threads());
    let line = format!(
        "ray sets of a {}x{} {} frame: {} in {:.2} s; timing on {} threads of {host}; BVH \
         copies: {:?}, subtrees of at most {} triangles merged",
        settings.width,
        settings.height,
        settings.workload.name(),
        sets.iter()
            .map(|s| format!("{} {}", s.rays.len(), s.kind.name()))
            .collect::<Vec<_>>()
            .join(", "),
        t.elapsed().as_secs_f64(),
        threads,
        dualsplit_accel::wide::cpu::SimdLevel::detect(),
        dualsplit_accel::wide::cpu::merge_limit(),
    );
    super::render::say(&line, json.is_some());
    let cfg = MeasureConfig {
        min_seconds: args.min_seconds,
        ..MeasureConfig::default()
    };
    let peer_run = PeerRun {
        scene: &scene,
        structures: &structures,
        sets: &sets,
        accels: &accels,
        cfg: &cfg,
        json: json.is_some(),
        ctx,
        pool: pool.as_ref(),
    };
    if !peers.is_empty() {
        for l in peer_run.run(&peers)? {
            json_line(l);
        }
    }
    let show_rays = peers.is_empty();
    if json.is_none() && (show_rays || !args.no_frame) {
        outln!(
            "{:<8} {:>16} {:>16} {:>16} {:>14}",
            "accel",
            "primary Mrays/s",
            "shadow Mrays/s",
            "diffuse Mrays/s",
            "frame s"
        );
    }
    for &kind in &accels {
        let mut row: Vec<Throughput> = Vec::new();
        if show_rays {
            for set in sets.iter().filter(|s| !s.rays.is_empty()) {
                let sp = ctx.spinner(format!("{} {} rays", kind.name(), set.kind.name()));
                in_pool(&mut || {
                    row.push(measure(&structures, kind, set, &cfg)?);
                    Ok(())
                })?;
                sp.finish_and_clear();
            }
        }
        let frame_s = if args.no_frame {
            None
        } else {
            let bar = ctx.bar(tile_count(&settings), format!("{} frame", kind.name()));
            let t = Instant::now();
            in_pool(&mut || {
                render(&scene, &structures, kind, &settings, &|| bar.inc(1))?;
                Ok(())
            })?;
            bar.finish_and_clear();
            Some(t.elapsed().as_secs_f64())
        };
        if row.is_empty() && frame_s.is_none() {
            continue;
        }
        if json.is_some() {
            for r in &row {
                json_line(serde_json::to_string(r)?);
            }
            if let Some(s) = frame_s {
                json_line(
                    serde_json::json!({
                        "accel": kind, "frame_seconds": s, "width": settings.width,
                        "height": settings.height, "workload": settings.workload,
                    })
                    .to_string(),
                );
            }
        } else {
            let cell = |k: RayKind| {
                row.iter()
                    .find(|r| r.ray_kind == k)
                    .map(|r| format!("{:.2}", r.mrays_per_s))
                    .unwrap_or_else(|| "-".into())
            };
            outln!(
                "{:<8} {:>16} {:>16} {:>16} {:>14}",
                kind.name(),
                cell(RayKind::Primary),
                cell(RayKind::Shadow),
                cell(RayKind::Diffuse),
                frame_s
                    .map(|s| format!("{s:.3}"))
                    .unwrap_or_else(|| "-".into())
            );
        }
    }
    if let Some(out @ JsonOut::File(_)) = &json {
        out.emit(&lines.join("\n"))?;
    }
    Ok(ExitCode::SUCCESS)
}

/// Everything the peer comparison needs.
struct PeerRun<'a> {
    scene: &'a Scene,
    structures: &'a Loaded,
    sets: &'a [RaySet; 3],
    accels: &'a [AccelKind],
    cfg: &'a MeasureConfig,
    json: bool,
    ctx: &'a Ctx,
    /// The timing threads (`--threads`), or none for rayon's global pool.
    pool: Option<&'a rayon::ThreadPool>,
}

/// A peer's Embree scene, built.
struct Built {
    peer: Peer,
    scene: EmbreeScene,
    build_s: f64,
}

/// What [`PeerRun::check`] finds for one peer, per ray kind.
struct Checked {
    /// Its agreement with BVH2's answers.
    agreement: BTreeMap<&'static str, Agreement>,
    /// Ours and its hit distances' errors against f64 (closest-hit kinds only).
    t_error: BTreeMap<&'static str, BTreeMap<&'static str, TErrors>>,
}

impl PeerRun<'_> {
    /// Builds each peer's Embree scene, checks its agreement on every set, then times ours
    /// and the peers' interleaved on the current rayon pool and prints them with our best
    /// structure's ratio to each peer (as a table), or returns them as JSON lines (the
    /// timings, then one summary line per peer).
    fn run(&self, peers: &[Peer]) -> anyhow::Result<Vec<String>> {
        let mut built = Vec::new();
        for &peer in peers {
            let sp = self
                .ctx
                .spinner(format!("building the {} scene", peer.name()));
            let t = Instant::now();
            let scene = EmbreeScene::with_options(&self.scene.triangles, &peer.options())
                .with_context(|| format!("--peer {}", peer.name()))?;
            sp.finish_and_clear();
            built.push(Built {
                peer,
                scene,
                build_s: t.elapsed().as_secs_f64(),
            });
        }
        let sets: Vec<&RaySet> = self.sets.iter().filter(|s| !s.rays.is_empty()).collect();

        // 1. Our structures against BVH2 (bit for bit), then BVH2 against each peer.
        for set in &sets {
            let sp = self
                .ctx
                .spinner(format!("checking {} rays", set.kind.name()));
            for &kind in self.accels {
                verify(self.structures, kind, set)?;
            }
            sp.finish_and_clear();
        }
        // Our hit distances' errors against f64, the same beside every peer.
        let ours_t: BTreeMap<&str, TErrors> = sets
            .iter()
            .filter(|set| set.kind != RayKind::Shadow)
            .map(|set| {
                let ours = t_errors(&self.scene.triangles, &set.rays, &closest_hits(set));
                (set.kind.name(), ours)
            })
            .collect();
        let mut checks = Vec::new();
        for b in &built {
            checks.push(self.check(b, &sets, &ours_t)?);
        }

        // 2. Timing, interleaved.
        let peer_names: Vec<&str> = built.iter().map(|b| b.peer.name()).collect();
        let mut timings: Vec<Timing> = Vec::new();
        for set in &sets {
            let sp = self.ctx.spinner(format!(
                "timing {} rays on {} and {}, interleaved",
                set.kind.name(),
                self.accels
                    .iter()
                    .map(|a| a.name())
                    .collect::<Vec<_>>()
                    .join(", "),
                peer_names.join(", ")
            ));
            let ours: Vec<_> = self
                .accels
                .iter()
                .map(|&a| trace_fn(self.structures, a, set.kind))
                .collect();
            let ray_kind = set.kind;
            let theirs: Vec<_> = built
                .iter()
                .map(|b| {
                    let peer = &b.scene;
                    move |rays: &[Ray]| -> u64 {
                        match ray_kind {
                            RayKind::Shadow => {
                                rays.iter().filter(|r| peer.occluded(r)).count() as u64
                            }
                            RayKind::Primary | RayKind::Diffuse => {
                                rays.iter().filter(|r| peer.intersect(r).is_some()).count() as u64
                            }
                        }
                    }
                })
                .collect();
            let mut contenders: Vec<Contender<'_>> = self
                .accels
                .iter()
                .zip(&ours)
                .map(|(a, f)| Contender {
                    name: a.name(),
                    trace: f,
                })
                .collect();
            for (name, f) in peer_names.iter().zip(&theirs) {
                contenders.push(Contender { name, trace: f });
            }
            let timed = || measure_interleaved(set, &contenders, self.cfg);
            timings.extend(match self.pool {
                Some(p) => p.install(timed),
                None => timed(),
            });
            sp.finish_and_clear();
        }

        // 3. Ratios: our fastest structure over each peer, per ray kind. Ours are found
        // once: the structure with the most Mrays/s over all passes, and the fastest pass
        // of any structure.
        let is_ours = |t: &&Timing| !peer_names.contains(&t.accel.as_str());
        let mut best = BTreeMap::new();
        let mut ours = Vec::new();
        for set in &sets {
            let of_kind = timings
                .iter()
                .filter(|t| t.ray_kind == set.kind)
                .filter(is_ours);
            let top = of_kind
                .clone()
                .max_by(|a, b| a.mrays_per_s.total_cmp(&b.mrays_per_s));
            let fastest = of_kind
                .map(|t| t.best_pass_mrays_per_s)
                .max_by(f64::total_cmp);
            if let (Some(top), Some(fastest)) = (top, fastest) {
                best.insert(set.kind.name(), top.accel.clone());
                ours.push((set.kind, top.mrays_per_s, fastest));
            }
        }
        let mut ratios = Vec::new();
        for b in &built {
            let mut ratio = BTreeMap::new();
            let mut ratio_fastest = BTreeMap::new();
            for &(kind, mrays, fastest) in &ours {
                let peer_t = timings
                    .iter()
                    .find(|t| t.ray_kind == kind && t.accel == b.peer.name());
                if let Some(p) = peer_t {
                    ratio.insert(kind.name(), mrays / p.mrays_per_s);
                    ratio_fastest.insert(kind.name(), fastest / p.best_pass_mrays_per_s);
                }
            }
            ratios.push((b.peer.name(), ratio, ratio_fastest));
        }
        let threads = timings.first().map_or(0, |t| t.threads);
        let mut lines = Vec::new();
        if self.json {
            for t in &timings {
                lines.push(serde_json::to_string(t)?);
            }
            for ((b, c), (_, ratio, ratio_fastest)) in built.iter().zip(&checks).zip(&ratios) {
                lines.push(
                    serde_json::json!({
                        "scene": self.scene.name, "peer": b.peer.name(),
                        "peer_version": b.scene.version(), "peer_build_seconds": b.build_s,
                        "threads": threads, "method": "interleaved",
                        "simd": format!("{:?}", dualsplit_accel::wide::cpu::SimdLevel::detect()),
                        "merge_max": dualsplit_accel::wide::cpu::merge_limit(),
                        "agreement": c.agreement, "t_error": c.t_error,
                        "best": best, "ratio_best_to_peer": ratio,
                        "ratio_best_to_peer_fastest_pass": ratio_fastest,
                    })
                    .to_string(),
                );
            }
        } else {
            print_timings(&timings, &best, &ratios, threads);
        }
        Ok(lines)
    }

    /// Checks peer `b` against BVH2 on `sets`: the agreement of its answers and, for the
    /// closest-hit sets (those `ours_t` holds our hit distances' errors for), the errors of
    /// its hit distances beside ours, printed unless JSON. Fails when a difference is
    /// unexplained.
    fn check(
        &self,
        b: &Built,
        sets: &[&RaySet],
        ours_t: &BTreeMap<&str, TErrors>,
    ) -> anyhow::Result<Checked> {
        let name = b.peer.name();
        let mut agreement = BTreeMap::new();
        let mut t_error = BTreeMap::new();
        for set in sets {
            let sp = self
                .ctx
                .spinner(format!("checking {} rays on {name}", set.kind.name()));
            agreement.insert(set.kind.name(), self.agree(&b.scene, set));
            if let Some(&ours) = ours_t.get(set.kind.name()) {
                let theirs: Vec<_> = set.rays.par_iter().map(|r| b.scene.intersect(r)).collect();
                let theirs = t_errors(&self.scene.triangles, &set.rays, &theirs);
                t_error.insert(
                    set.kind.name(),
                    BTreeMap::from([("ours", ours), (name, theirs)]),
                );
            }
            sp.finish_and_clear();
        }
        if !self.json {
            outln!(
                "{name} {}: scene built in {:.2} s; agreement with {} (every structure \
                 above equals it bit for bit):",
                b.scene.version(),
                b.build_s,
                self.structures.reference().name()
            );
            for set in sets {
                print_agreement(set.kind.name(), &agreement[set.kind.name()]);
            }
            outln!("hit distance t against f64 (relative error, p99.9 / max):");
            for (kind, e) in sets
                .iter()
                .filter_map(|s| t_error.get_key_value(s.kind.name()))
            {
                outln!(
                    "  {kind:<8} ours {:.1e} / {:.1e}; {name} {:.1e} / {:.1e}",
                    e["ours"].p999,
                    e["ours"].max,
                    e[name].p999,
                    e[name].max
                );
            }
        }
        if let Some((kind, a)) = agreement.iter().find(|(_, a)| !a.is_explained()) {
            if self.json {
                outln!(
                    "{}",
                    serde_json::json!({"peer": name, "agreement": agreement})
                );
            }
            anyhow::bail!(
                "{name} and {} disagree on {} {kind} rays that no tie, grazing or \
                 boundary hit explains ({} hit against miss, {} other triangle; the first: \
                 {}); refusing to time them",
                self.structures.reference().name(),
                a.hit_miss.unexplained + a.triangle.unexplained,
                a.hit_miss.unexplained,
                a.triangle.unexplained,
                a.first_unexplained.as_deref().unwrap_or("-")
            );
        }
        Ok(Checked { agreement, t_error })
    }

    /// Agreement of a peer's Embree scene with BVH2's answers on `set`.
    fn agree(&self, peer: &EmbreeScene, set: &RaySet) -> Agreement {
        let tris = &self.scene.triangles;
        match set.kind {
            RayKind::Shadow => {
                let ours: Vec<bool> = set.expected.iter().map(TraceResult::is_hit).collect();
                let reference = self.structures.reference();
                let closest = |r: &Ray| self.structures.closest_hit(reference, r, &mut NoObserver);
                agree_occluded(peer, tris, &set.rays, &ours, &closest)
            }
            RayKind::Primary | RayKind::Diffuse => {
                agree_closest(peer, tris, &set.rays, &closest_hits(set))
            }
        }
    }
}

/// BVH2's closest hits of a closest-hit set (`None` for shadow answers).
fn closest_hits(set: &RaySet) -> Vec<Option<dualsplit_geometry::Hit>> {
    set.expected
        .iter()
        .map(|r| match r {
            TraceResult::Closest(h) => *h,
            TraceResult::Occluded(_) => None,
        })
        .collect()
}

fn print_agreement(kind: &str, a: &Agreement) {
    let d = |x: &dualsplit_embree::Differences| match x.total() {
        0 => "0".to_string(),
        n => format!(
            "{n} (tie {}, grazing {}, boundary {}, unexplained {})",
            x.tie, x.grazing, x.boundary, x.unexplained
        ),
    };
    outln!(
        "  {kind:<8} {:>8} rays, {:>8} same; hit/miss differs {}; triangle differs {}{}",
        a.rays,
        a.same,
        d(&a.hit_miss),
        d(&a.triangle),
        if kind == "shadow" {
            String::new()
        } else {
            format!("; same triangle, largest |Δt|/t {:.1e}", a.max_t_rel_diff)
        }
    );
}

/// Our best structure's ratio to one peer per ray kind: over all passes, and fastest pass
/// to fastest pass.
type Ratios<'a> = (&'a str, BTreeMap<&'a str, f64>, BTreeMap<&'a str, f64>);

fn print_timings(
    timings: &[Timing],
    best: &BTreeMap<&str, String>,
    ratios: &[Ratios<'_>],
    threads: usize,
) {
    let mut passes: Vec<String> = Vec::new();
    for t in timings {
        let p = format!("{} {}", t.repeats, t.ray_kind.name());
        if !passes.contains(&p) {
            passes.push(p);
        }
    }
    outln!(
        "interleaved on {threads} thread(s), passes: {}; Mrays/s over all passes (fastest pass)",
        passes.join(", ")
    );
    outln!(
        "{:<19} {:>18} {:>18} {:>18}",
        "accel",
        "primary",
        "shadow",
        "diffuse"
    );
    let mut names: Vec<&str> = Vec::new();
    for t in timings {
        if !names.contains(&t.accel.as_str()) {
            names.push(&t.accel);
        }
    }
    for name in names {
        let cell = |k: RayKind| {
            timings
                .iter()
                .find(|t| t.accel == name && t.ray_kind == k)
                .map(|t| format!("{:.2} ({:.2})", t.mrays_per_s, t.best_pass_mrays_per_s))
                .unwrap_or_else(|| "-".into())
        };
        outln!(
            "{name:<19} {:>18} {:>18} {:>18}",
            cell(RayKind::Primary),
            cell(RayKind::Shadow),
            cell(RayKind::Diffuse)
        );
    }
    for (peer, ratio, fastest) in ratios {
        let cell = |k: RayKind| match (ratio.get(k.name()), fastest.get(k.name())) {
            (Some(r), Some(f)) => format!("{r:.2} ({f:.2}) {}", best[k.name()]),
            _ => "-".into(),
        };
        outln!(
            "{:<19} {:>18} {:>18} {:>18}",
            format!("best/{peer}"),
            cell(RayKind::Primary),
            cell(RayKind::Shadow),
            cell(RayKind::Diffuse)
        );
    }
}
