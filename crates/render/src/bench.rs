//! CPU traversal throughput: deterministic ray sets, checked against BVH2 before timing.
//!
//! Method (tinybvh's habit: check, then time):
//!
//! 1. [`ray_sets`] runs every pixel's [`PixelJob`] of a frame on BVH2 (for one saved tree,
//!    on its own first traversal), through its observed traversal (the memory image, not the
//!    CPU-side path that plain queries use), and keeps each ray with that answer, split by
//!    [`RayKind`] (primary, shadow, diffuse), in pixel order. The rays are exactly those the
//!    renderer traces, so shadow and diffuse rays start on surfaces.
//! 2. [`measure`] first traces every ray of a set on the structure under test and compares
//!    the answer with the recorded one bit for bit ([`TraceResult::bit_eq`]); the first mismatch is a
//!    [`RenderError::Mismatch`], never a number.
//! 3. Then it traces the whole set, in parallel over chunks of [`CHUNK`] rays on every core
//!    (rayon), until [`MeasureConfig::min_seconds`] and [`MeasureConfig::min_repeats`] are
//!    both reached, and reports rays per second over all repeats.
//!
//! [`measure_interleaved`] times several tracers (our structures and a peer such as Embree)
//! on one set in turn, pass after pass, so that all of them see the same host noise; each
//! tracer is checked by its caller before.
//!
//! This is the one place the library reads the wall clock: a throughput is a measurement of
//! the machine, not a result of the algorithm. Nothing else depends on it.

use crate::trace::{run_job, trace_query};
use crate::{PixelJob, RayCounts, RayKind, RayQuery, RenderError, RenderSettings, TraceResult};
use dualsplit_accel::{AccelKind, NoObserver, Observer, TraversalSet};
use dualsplit_geometry::Ray;
use dualsplit_scene::Scene;
use rayon::prelude::*;
use std::time::Instant;

/// Rays per parallel work item while timing.
pub const CHUNK: usize = 1024;

/// The rays of one kind from a frame, with the reference's answers (BVH2's for
/// [`dualsplit_accel::Structures`]; see [`ray_sets`]).
#[derive(Clone, Debug)]
pub struct RaySet {
    /// Kind of every ray of the set.
    pub kind: RayKind,
    /// The rays, in pixel order (then issue order within a pixel).
    pub rays: Vec<Ray>,
    /// The reference's answer to each ray.
    pub expected: Vec<TraceResult>,
}

/// An observer that ignores every report but is not [`NoObserver`], so a BVH answers by
/// traversing its byte-exact image ([`Observer::OBSERVES_NOTHING`] is false): the reference
/// the timed structures, which answer from their CPU-side copies, are checked against.
struct ImageReference;

impl Observer for ImageReference {}

/// Builds the three ray sets (primary, shadow, diffuse; the *cast* workload's diffuse set is
/// empty) of a frame of `settings` by running every pixel's job on the reference traversal
/// of `structures` ([`TraversalSet::reference`]: BVH2 for every structure of a scene, the
/// tree's own traversal for one tree), reading its image.
pub fn ray_sets<S: TraversalSet>(
    scene: &Scene,
    structures: &S,
    settings: &RenderSettings,
) -> Result<[RaySet; 3], RenderError> {
    crate::validate(scene, settings)?;
    let rows: Vec<Vec<(RayQuery, TraceResult)>> = (0..settings.height)
        .into_par_iter()
        .map(|y| {
            let mut v = Vec::new();
            let mut counts = RayCounts::default();
            for x in 0..settings.width {
                let job = PixelJob::new(scene, settings, x, y);
                run_job(
                    job,
                    structures,
                    structures.reference(),
                    &mut ImageReference,
                    &mut counts,
                    |q, r| v.push((*q, *r)),
                );
            }
            v
        })
        .collect();
    let mut sets = RayKind::ALL.map(|kind| RaySet {
        kind,
        rays: Vec::new(),
        expected: Vec::new(),
    });
    for (q, r) in rows.into_iter().flatten() {
        let s = &mut sets[q.kind as usize];
        s.rays.push(q.ray);
        s.expected.push(r);
    }
    Ok(sets)
}

/// How long to time a set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasureConfig {
    /// Keep repeating the whole set until this much time has passed.
    pub min_seconds: f64,
    /// And at least this many repeats.
    pub min_repeats: u32,
}

impl Default for MeasureConfig {
    /// At least 1 s and 3 repeats.
    fn default() -> Self {
        Self {
            min_seconds: 1.0,
            min_repeats: 3,
        }
    }
}

/// A measured throughput.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Throughput {
    /// Structure.
    pub accel: AccelKind,
    /// Ray kind.
    pub ray_kind: RayKind,
    /// Rays in the set.
    pub rays: u64,
    /// Times the whole set was traced.
    pub repeats: u32,
    /// Wall-clock seconds of all repeats.
    pub seconds: f64,
    /// Millions of rays per second: `rays · repeats / seconds / 10⁶`.
    pub mrays_per_s: f64,
    /// Threads rayon used.
    pub threads: usize,
}

/// Traces every ray of `set` on `kind` and compares with the recorded answers, bit for bit.
pub fn verify<S: TraversalSet>(
    structures: &S,
    kind: AccelKind,
    set: &RaySet,
) -> Result<(), RenderError> {
    crate::frame::supported(structures, kind)?;
    let bad = set
        .rays
        .par_iter()
        .zip(&set.expected)
        .enumerate()
        .find_first(|(_, (ray, want))| {
            let q = RayQuery {
                ray: **ray,
                kind: set.kind,
            };
            !trace_query(structures, kind, &q, &mut NoObserver).bit_eq(want)
        });
    match bad {
        None => Ok(()),
        Some((index, (ray, want))) => {
            let q = RayQuery {
                ray: *ray,
                kind: set.kind,
            };
            let got = trace_query(structures, kind, &q, &mut NoObserver);
            Err(RenderError::Mismatch {
                accel: kind.name(),
                ray_kind: set.kind.name(),
                index,
                ray: format!("{ray:?}"),
                expected: format!("{want:?}"),
                got: format!("{got:?}"),
            })
        }
    }
}

/// Verifies `set` on `kind` against the recorded answers ([`verify`]), then times it ([`MeasureConfig`]).
/// An empty set gives zero rays and zero throughput.
pub fn measure<S: TraversalSet>(
    structures: &S,
    kind: AccelKind,
    set: &RaySet,
    cfg: &MeasureConfig,
) -> Result<Throughput, RenderError> {
    verify(structures, kind, set)?;
    let threads = rayon::current_num_threads();
    if set.rays.is_empty() {
        return Ok(Throughput {
            accel: kind,
            ray_kind: set.kind,
            rays: 0,
            repeats: 0,
            seconds: 0.0,
            mrays_per_s: 0.0,
            threads,
        });
    }
    let start = Instant::now();
    let mut repeats = 0u32;
    let mut sink = 0u64;
    loop {
        sink += set
            .rays
            .par_chunks(CHUNK)
            .map(|chunk| trace_slice(structures, kind, set.kind, chunk))
            .sum::<u64>();
        repeats += 1;
        let s = start.elapsed().as_secs_f64();
        if s >= cfg.min_seconds && repeats >= cfg.min_repeats {
            std::hint::black_box(sink);
            let rays = set.rays.len() as u64;
            return Ok(Throughput {
                accel: kind,
                ray_kind: set.kind,
                rays,
                repeats,
                seconds: s,
                mrays_per_s: rays as f64 * repeats as f64 / s / 1e6,
                threads,
            });
        }
    }
}

/// A tracer in an interleaved timing: a name and a function that traces every ray of a
/// slice (of one [`RayKind`]) and returns how many hit, so the result cannot be optimised
/// away. The per-ray loop lives inside the function, so each tracer's inner loop is
/// compiled for it alone.
pub struct Contender<'a> {
    /// Name in the results (`"bvh2"`, `"embree"`, …).
    pub name: &'a str,
    /// Traces a slice of rays; returns the number of hits.
    pub trace: &'a (dyn Fn(&[Ray]) -> u64 + Sync),
}

/// The timing of one tracer on one set, from [`measure_interleaved`].
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Timing {
    /// The contender's name.
    pub accel: String,
    /// Ray kind.
    pub ray_kind: RayKind,
    /// Rays in the set.
    pub rays: u64,
    /// Times the whole set was traced (the same for every contender of a run).
    pub repeats: u32,
    /// Wall-clock seconds of all its passes.
    pub seconds: f64,
    /// Millions of rays per second over all passes: `rays / (seconds / repeats) / 10⁶`, from
    /// whole nanoseconds, so it never exceeds [`Timing::best_pass_mrays_per_s`].
    pub mrays_per_s: f64,
    /// Millions of rays per second of its fastest pass (the least disturbed).
    pub best_pass_mrays_per_s: f64,
    /// Threads the passes ran on.
    pub threads: usize,
    /// Hits in one pass.
    pub hits: u64,
}

/// Times `contenders` on `set`, interleaved: each round traces the whole set once with every
/// contender, starting with a different one each round, until every contender has run
/// [`MeasureConfig::min_seconds`] and [`MeasureConfig::min_repeats`] passes. A pass runs on
/// the current rayon pool: in one sequential loop when it has one thread, otherwise in
/// parallel over chunks of [`CHUNK`] rays.
///
/// The contenders are not checked here; the caller verifies them first ([`verify`], or a
/// peer's agreement check). An empty set or no contenders give no timings.
pub fn measure_interleaved(
    set: &RaySet,
    contenders: &[Contender<'_>],
    cfg: &MeasureConfig,
) -> Vec<Timing> {
    let threads = rayon::current_num_threads();
    if set.rays.is_empty() || contenders.is_empty() {
        return Vec::new();
    }
    let pass = |c: &Contender<'_>| -> (u128, u64) {
        let start = Instant::now();
        let hits = if threads == 1 {
            (c.trace)(&set.rays)
        } else {
            set.rays.par_chunks(CHUNK).map(|ch| (c.trace)(ch)).sum()
        };
        (start.elapsed().as_nanos(), hits)
    };
    let n = contenders.len();
    // Whole nanoseconds: their sums are exact, so the mean pass is never shorter than the
    // best one, as it would be by rounding with summed seconds.
    let mut nanos = vec![0u128; n];
    let mut best = vec![u128::MAX; n];
    let mut hits = vec![0u64; n];
    let mut repeats = 0u32;
    let min_nanos = cfg.min_seconds * 1e9;
    while repeats < cfg.min_repeats || nanos.iter().any(|&s| (s as f64) < min_nanos) {
        for k in 0..n {
            let i = (repeats as usize + k) % n;
            let (s, h) = pass(&contenders[i]);
            nanos[i] += s;
            best[i] = best[i].min(s);
            hits[i] = std::hint::black_box(h);
        }
        repeats += 1;
    }
    let rays = set.rays.len() as u64;
    contenders
        .iter()
        .enumerate()
        .map(|(i, c)| {
            // A pass shorter than the clock's tick counts as one nanosecond.
            let per_pass = (nanos[i] as f64 / f64::from(repeats)).max(1.0);
            Timing {
                accel: c.name.to_string(),
                ray_kind: set.kind,
                rays,
                repeats,
                seconds: nanos[i] as f64 / 1e9,
                mrays_per_s: rays as f64 / (per_pass / 1e9) / 1e6,
                best_pass_mrays_per_s: rays as f64 / (best[i].max(1) as f64 / 1e9) / 1e6,
                threads,
                hits: hits[i],
            }
        })
        .collect()
}

/// The [`Contender`] trace function of structure `kind` for rays of kind `ray_kind`.
pub fn trace_fn<S: TraversalSet>(
    structures: &S,
    kind: AccelKind,
    ray_kind: RayKind,
) -> impl Fn(&[Ray]) -> u64 + Sync + '_ {
    move |rays: &[Ray]| trace_slice(structures, kind, ray_kind, rays)
}

/// Traces every ray of `rays` (all of kind `ray_kind`) on structure `kind` through one
/// [`Tracer`](dualsplit_accel::Tracer) and returns how many hit: the per-ray loop of a
/// timing.
#[inline]
fn trace_slice<S: TraversalSet>(
    structures: &S,
    kind: AccelKind,
    ray_kind: RayKind,
    rays: &[Ray],
) -> u64 {
    let mut t = structures.tracer(kind);
    match ray_kind {
        RayKind::Shadow => rays.iter().map(|r| t.any_hit(r) as u64).sum(),
        RayKind::Primary | RayKind::Diffuse => {
            rays.iter().map(|r| t.closest_hit(r).is_some() as u64).sum()
        }
    }
}
