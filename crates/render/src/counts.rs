//! Ray counters by kind: rays traced and how many hit (closest-hit rays that found a
//! triangle, shadow rays that were occluded).

use crate::{RayKind, TraceResult};
use serde::Serialize;

/// Rays of one kind and how many of them hit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct KindCounts {
    /// Rays traced.
    pub rays: u64,
    /// Rays that hit (closest hit found a triangle / shadow ray occluded).
    pub hits: u64,
}

impl KindCounts {
    /// Rays that missed (closest hit found nothing / shadow ray reached the light).
    pub fn misses(&self) -> u64 {
        self.rays - self.hits
    }
}

/// Ray counters of a pixel, a tile or a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RayCounts {
    /// Camera rays.
    pub primary: KindCounts,
    /// Shadow rays toward the light.
    pub shadow: KindCounts,
    /// Diffuse bounce rays.
    pub diffuse: KindCounts,
}

impl RayCounts {
    /// Counts one traced ray and its result.
    #[inline]
    pub fn record(&mut self, kind: RayKind, result: &TraceResult) {
        let c = self.get_mut(kind);
        c.rays += 1;
        c.hits += result.is_hit() as u64;
    }

    /// The counters of one kind.
    pub fn get(&self, kind: RayKind) -> KindCounts {
        match kind {
            RayKind::Primary => self.primary,
            RayKind::Shadow => self.shadow,
            RayKind::Diffuse => self.diffuse,
        }
    }

    fn get_mut(&mut self, kind: RayKind) -> &mut KindCounts {
        match kind {
            RayKind::Primary => &mut self.primary,
            RayKind::Shadow => &mut self.shadow,
            RayKind::Diffuse => &mut self.diffuse,
        }
    }

    /// All rays.
    pub fn rays(&self) -> u64 {
        self.primary.rays + self.shadow.rays + self.diffuse.rays
    }

    /// All hits.
    pub fn hits(&self) -> u64 {
        self.primary.hits + self.shadow.hits + self.diffuse.hits
    }

    /// All misses.
    pub fn misses(&self) -> u64 {
        self.rays() - self.hits()
    }

    /// Adds another counter set into this one.
    pub fn add(&mut self, o: &RayCounts) {
        for k in RayKind::ALL {
            let (a, b) = (self.get_mut(k), o.get(k));
            a.rays += b.rays;
            a.hits += b.hits;
        }
    }
}
