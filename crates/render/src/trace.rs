//! Running one pixel to completion: [`trace_pixel`] and the per-ray record.
//!
//! The renderer, the tests and the throughput benchmark all run jobs through [`run_job_by`]
//! (the renderer with a [`Tracer`] per tile, the others through [`run_job`]), so a pixel
//! regenerated alone goes through the job code that rendered it in the frame, and its rays
//! get the same answers bit for bit (the tracer's are the plain queries').

use crate::{PixelJob, RayCounts, RayKind, RayQuery, RenderSettings, TraceResult};
use dualsplit_accel::{AccelKind, Observer, Tracer, TraversalSet};
use dualsplit_scene::Scene;

/// One traced ray and its answer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TracedRay {
    /// The query the job issued.
    pub query: RayQuery,
    /// What the structure answered.
    pub result: TraceResult,
}

/// Everything one pixel did: its value, its ray counters and every ray in order.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelRecord {
    /// Pixel column.
    pub x: u32,
    /// Pixel row (0 = top).
    pub y: u32,
    /// Final linear radiance (average over samples).
    pub radiance: f32,
    /// Rays by kind, hits and misses.
    pub counts: RayCounts,
    /// Every ray the job traced, in issue order, with its result.
    pub rays: Vec<TracedRay>,
}

impl PixelRecord {
    /// Bitwise equality of two records: same pixel, same radiance bits, same rays (every
    /// origin, direction and interval bit) and same results ([`TraceResult::bit_eq`]).
    pub fn bit_eq(&self, o: &PixelRecord) -> bool {
        self.x == o.x
            && self.y == o.y
            && self.radiance.to_bits() == o.radiance.to_bits()
            && self.counts == o.counts
            && self.rays.len() == o.rays.len()
            && self.rays.iter().zip(&o.rays).all(|(a, b)| {
                a.query.kind == b.query.kind
                    && ray_bits(&a.query.ray) == ray_bits(&b.query.ray)
                    && a.result.bit_eq(&b.result)
            })
    }
}

fn ray_bits(r: &dualsplit_geometry::Ray) -> [u32; 8] {
    [
        r.origin.x.to_bits(),
        r.origin.y.to_bits(),
        r.origin.z.to_bits(),
        r.dir.x.to_bits(),
        r.dir.y.to_bits(),
        r.dir.z.to_bits(),
        r.t_min.to_bits(),
        r.t_max.to_bits(),
    ]
}

/// Traces one query on structure `kind`: closest hit for primary and diffuse rays, any hit
/// for shadow rays.
#[inline]
pub fn trace_query<S: TraversalSet, O: Observer>(
    structures: &S,
    kind: AccelKind,
    query: &RayQuery,
    obs: &mut O,
) -> TraceResult {
    match query.kind {
        RayKind::Shadow => TraceResult::Occluded(structures.any_hit(kind, &query.ray, obs)),
        RayKind::Primary | RayKind::Diffuse => {
            TraceResult::Closest(structures.closest_hit(kind, &query.ray, obs))
        }
    }
}

/// [`trace_query`] through a [`Tracer`] (no observer).
#[inline]
pub fn trace_with<S: TraversalSet>(tracer: &mut Tracer<'_, S>, query: &RayQuery) -> TraceResult {
    match query.kind {
        RayKind::Shadow => TraceResult::Occluded(tracer.any_hit(&query.ray)),
        RayKind::Primary | RayKind::Diffuse => TraceResult::Closest(tracer.closest_hit(&query.ray)),
    }
}

/// Runs `job` to completion on structure `kind`, counting every ray into `counts` and
/// handing each (query, result) to `sink`; returns the pixel's radiance.
#[inline]
pub fn run_job<S: TraversalSet, O: Observer>(
    job: PixelJob<'_>,
    structures: &S,
    kind: AccelKind,
    obs: &mut O,
    counts: &mut RayCounts,
    sink: impl FnMut(&RayQuery, &TraceResult),
) -> f32 {
    run_job_by(job, |q| trace_query(structures, kind, q, obs), counts, sink)
}

/// [`run_job`] with each query answered by `trace` (a [`Tracer`] through [`trace_with`],
/// where nothing is observed).
#[inline]
pub fn run_job_by(
    mut job: PixelJob<'_>,
    mut trace: impl FnMut(&RayQuery) -> TraceResult,
    counts: &mut RayCounts,
    mut sink: impl FnMut(&RayQuery, &TraceResult),
) -> f32 {
    while let Some(q) = job.next_ray() {
        let r = trace(&q);
        counts.record(q.kind, &r);
        sink(&q, &r);
        job.submit(r);
    }
    job.radiance()
}

/// Runs the [`PixelJob`] of pixel `(x, y)` to completion on structure `kind` and records every
/// ray, its result and the ray counters. The observer sees every traversal of the pixel in
/// order. Deterministic: the same arguments give a bitwise-identical record, whatever else
/// was traced before.
pub fn trace_pixel<S: TraversalSet, O: Observer>(
    structures: &S,
    kind: AccelKind,
    scene: &Scene,
    settings: &RenderSettings,
    x: u32,
    y: u32,
    obs: &mut O,
) -> PixelRecord {
    let mut counts = RayCounts::default();
    let mut rays = Vec::new();
    let job = PixelJob::new(scene, settings, x, y);
    let radiance = run_job(job, structures, kind, obs, &mut counts, |q, r| {
        rays.push(TracedRay {
            query: *q,
            result: *r,
        })
    });
    PixelRecord {
        x,
        y,
        radiance,
        counts,
        rays,
    }
}
