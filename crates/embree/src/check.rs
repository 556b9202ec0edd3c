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
