//! Agreement of whole ray sets between our answers and Embree's, in parallel.

use crate::{Agreement, EmbreeScene};
use dualsplit_geometry::{Hit, Ray, Triangle};
use rayon::prelude::*;

/// Rays per parallel work item.
const CHUNK: usize = 4096;

/// Compares our closest hits `ours` (one per ray) with Embree's on `rays`.
pub fn agree_closest(
    peer: &EmbreeScene,
    tris: &[Triangle],
    rays: &[Ray],
    ours: &[Option<Hit>],
) -> Agreement {
    rays.par_chunks(CHUNK)
        .zip(ours.par_chunks(CHUNK))
        .map(|(rays, ours)| {
            let mut a = Agreement::default();
            for (ray, ours) in rays.iter().zip(ours) {
                a.record_closest(tris, ray, *ours, peer.intersect(ray));
            }
            a
        })
        .reduce(Agreement::default, |mut a, b| {
            a.merge(&b);
            a
        })
}

/// Compares our occlusion answers `ours` (one per ray) with Embree's on `rays`. Where they
/// differ, `our_closest` (our closest hit on the same segment) and Embree's closest hit name
/// the triangles that [`crate::classify`] explains the difference by.
pub fn agree_occluded(
    peer: &EmbreeScene,
    tris: &[Triangle],
    rays: &[Ray],
    ours: &[bool],
    our_closest: &(dyn Fn(&Ray) -> Option<Hit> + Sync),
) -> Agreement {
    rays.par_chunks(CHUNK)
        .zip(ours.par_chunks(CHUNK))
        .map(|(rays, ours)| {
            let mut a = Agreement::default();
            for (ray, &ours) in rays.iter().zip(ours) {
                a.record_occluded(tris, ray, ours, peer.occluded(ray), || {
                    (our_closest(ray), peer.intersect(ray))
                });
            }
            a
        })
        .reduce(Agreement::default, |mut a, b| {
            a.merge(&b);
            a
        })
}

/// Relative errors of hit distances against the f64 plane crossing of the ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct TErrors {
    /// Hits measured.
    pub hits: u64,
    /// Median relative error.
    pub p50: f64,
    /// 99th percentile.
    pub p99: f64,
    /// 99.9th percentile.
    pub p999: f64,
    /// Largest.
    pub max: f64,
}

/// The relative error `|t − t₆₄| / t₆₄` of every hit of `hits` (one per ray, `None` for a
/// miss), where `t₆₄` is where the ray meets the hit triangle's plane in f64
/// ([`crate::agree::crossing`]). Hits on a triangle the ray is parallel to are left out.
pub fn t_errors(tris: &[Triangle], rays: &[Ray], hits: &[Option<Hit>]) -> TErrors {
    let mut e: Vec<f64> = rays
        .par_iter()
        .zip(hits)
        .filter_map(|(ray, h)| {
            let h = (*h)?;
            let c = crate::agree::crossing(tris.get(h.prim.index())?, ray)?;
            let err = ((h.t as f64 - c.t) / c.t).abs();
            err.is_finite().then_some(err)
        })
        .collect();
    if e.is_empty() {
        return TErrors::default();
    }
    e.par_sort_unstable_by(f64::total_cmp);
    let q = |p: f64| e[((e.len() - 1) as f64 * p).round() as usize];
    TErrors {
        hits: e.len() as u64,
        p50: q(0.5),
        p99: q(0.99),
        p999: q(0.999),
        max: q(1.0),
    }
}
