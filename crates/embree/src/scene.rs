//! [`EmbreeScene`]: the scene's triangles in an Embree BVH, traced one ray at a time.

use crate::{EmbreeError, EmbreeOptions};
use dualsplit_geometry::{Hit, Ray, Triangle};

#[cfg(dualsplit_embree)]
use crate::linked as imp;
#[cfg(not(dualsplit_embree))]
use crate::missing as imp;

/// The triangles of a scene in one Embree triangle mesh (geometry 0), committed and ready for
/// queries from any number of threads.
///
/// Triangle `i` of the slice is Embree's primitive `i`, so [`Hit::prim`] names the same
/// triangle as every dualsplit structure. Embree skips degenerate triangles when it builds,
/// as the watertight test never hits them.
pub struct EmbreeScene {
    inner: imp::Scene,
}

impl EmbreeScene {
    /// Builds the scene with Embree's defaults ([`EmbreeOptions::default`]).
    ///
    /// # Errors
    /// [`EmbreeError::Missing`] when the crate was built without the library; otherwise
    /// whatever Embree reports while building.
    pub fn new(triangles: &[Triangle]) -> Result<Self, EmbreeError> {
        Self::with_options(triangles, &EmbreeOptions::default())
    }

    /// Builds the scene with `options`.
    ///
    /// # Errors
    /// As [`EmbreeScene::new`].
    pub fn with_options(
        triangles: &[Triangle],
        options: &EmbreeOptions,
    ) -> Result<Self, EmbreeError> {
        Ok(Self {
            inner: imp::Scene::new(triangles, options)?,
        })
    }

    /// Closest hit of `ray` on `[t_min, t_max]` (`rtcIntersect1`): Embree's `t` (`tfar`),
    /// primitive id and barycentrics.
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.inner.intersect(ray)
    }

    /// Whether anything blocks `ray` on `[t_min, t_max]` (`rtcOccluded1`).
    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.inner.occluded(ray)
    }

    /// The library's version, e.g. `"3.13.5"`.
    pub fn version(&self) -> String {
        self.inner.version()
    }

    /// Triangles handed to Embree.
    pub fn triangles(&self) -> usize {
        self.inner.triangles()
    }
}

impl std::fmt::Debug for EmbreeScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EmbreeScene")
            .field("version", &self.version())
            .field("triangles", &self.triangles())
            .finish()
    }
}
