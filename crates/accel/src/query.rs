//! The one query trait every structure answers rays through: [`RayQuery`].
//!
//! A structure implements the two *observed* traversals (which report every fetch and step
//! to an [`Observer`], as the simulator needs); the plain, batch and normal forms follow
//! from them. Batch forms run on the current rayon pool, so
//! `pool.install(|| tree.intersect_batch(&rays))` picks the threads.

use crate::observer::{NoObserver, Observer};
use dualsplit_geometry::{Hit, Ray, Triangle, Vec3};
use rayon::prelude::*;

/// Closest-hit and occlusion queries against one acceleration structure.
///
/// Every implementation in this crate returns bit-identical answers for the same triangles:
/// closest hits are ordered by `(t, triangle id)` (see [`Hit::closer_than`]).
///
/// ```
/// use dualsplit_accel::math::{Ray, Triangle, Vec3};
/// use dualsplit_accel::{BuildConfig, Bvh2Tree, RayQuery};
/// let tris = vec![Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0))];
/// let bvh2 = Bvh2Tree::build(tris, &BuildConfig::default()).unwrap();
/// let ray = Ray::new(Vec3::ZERO, Vec3::Z);
/// assert_eq!(bvh2.intersect(&ray).unwrap().t, 2.0);
/// assert!(bvh2.occluded(&ray));
/// assert_eq!(bvh2.intersect_batch(&[ray, Ray::new(Vec3::ZERO, -Vec3::Z)])[1], None);
/// ```
pub trait RayQuery: Sync {
    /// Closest hit of `ray` within `[ray.t_min, ray.t_max]`, reporting the traversal to `obs`.
    fn intersect_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit>;

    /// True when `ray` hits any triangle within `[ray.t_min, ray.t_max]`, reporting the
    /// traversal to `obs`.
    fn occluded_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool;

    /// The triangles the structure references, in id order (`hit.prim` indexes them).
    fn triangles(&self) -> &[Triangle];

    /// Closest hit of `ray` within `[ray.t_min, ray.t_max]`.
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_observed(ray, &mut NoObserver)
    }

    /// True when `ray` hits any triangle within `[ray.t_min, ray.t_max]` (a shadow ray).
    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_observed(ray, &mut NoObserver)
    }

    /// [`RayQuery::intersect`] for every ray, in parallel on the current rayon pool; the
    /// answers are in the rays' order.
    fn intersect_batch(&self, rays: &[Ray]) -> Vec<Option<Hit>> {
        rays.par_iter().map(|r| self.intersect(r)).collect()
    }

    /// [`RayQuery::occluded`] for every ray, in parallel on the current rayon pool; the
    /// answers are in the rays' order.
    fn occluded_batch(&self, rays: &[Ray]) -> Vec<bool> {
        rays.par_iter().map(|r| self.occluded(r)).collect()
    }

    /// The unit geometric normal of the triangle `hit` landed on, `(v1 - v0) × (v2 - v0)`
    /// normalised; `None` when the id is not one of [`RayQuery::triangles`] or the triangle
    /// has zero area.
    fn hit_normal(&self, hit: &Hit) -> Option<Vec3> {
        self.triangles()
            .get(hit.prim.index())
            .and_then(|t| t.normal().try_normalize())
    }
}

/// `RayQuery` for a structure whose `closest_hit` and `any_hit` take an [`Observer`]: the
/// observed queries are those, the triangles `$tris`. With `query`, the batch forms trace
/// each rayon job's rays through one context of the structure's `query()`.
macro_rules! query_by_traversal {
    (@batch query) => {
        fn intersect_batch(
            &self,
            rays: &[dualsplit_geometry::Ray],
        ) -> Vec<Option<dualsplit_geometry::Hit>> {
            use rayon::prelude::*;
            rays.par_iter()
                .map_init(|| self.query(), |q, r| q.closest_hit(r))
                .collect()
        }
        fn occluded_batch(&self, rays: &[dualsplit_geometry::Ray]) -> Vec<bool> {
            use rayon::prelude::*;
            rays.par_iter()
                .map_init(|| self.query(), |q, r| q.any_hit(r))
                .collect()
        }
    };
    ($(#[$doc:meta])* $ty:ty, |$s:ident| $tris:expr $(, $batch:ident)?) => {
        $(#[$doc])*
        impl $crate::query::RayQuery for $ty {
            #[inline]
            fn intersect_observed<O: $crate::observer::Observer>(
                &self,
                ray: &dualsplit_geometry::Ray,
                obs: &mut O,
            ) -> Option<dualsplit_geometry::Hit> {
                self.closest_hit(ray, obs)
            }
            #[inline]
            fn occluded_observed<O: $crate::observer::Observer>(
                &self,
                ray: &dualsplit_geometry::Ray,
                obs: &mut O,
            ) -> bool {
                self.any_hit(ray, obs)
            }
            fn triangles(&self) -> &[dualsplit_geometry::Triangle] {
                let $s = self;
                $tris
            }
            $($crate::query::query_by_traversal!(@batch $batch);)?
        }
    };
}

pub(crate) use query_by_traversal;

/// `RayQuery` for a tree type through the structure inside it (`|s| &s.inner`).
macro_rules! query_via {
    ($ty:ty, |$s:ident| $inner:expr) => {
        impl $crate::query::RayQuery for $ty {
            #[inline]
            fn intersect_observed<O: $crate::observer::Observer>(
                &self,
                ray: &dualsplit_geometry::Ray,
                obs: &mut O,
            ) -> Option<dualsplit_geometry::Hit> {
                let $s = self;
                $crate::query::RayQuery::intersect_observed($inner, ray, obs)
            }
            #[inline]
            fn occluded_observed<O: $crate::observer::Observer>(
                &self,
                ray: &dualsplit_geometry::Ray,
                obs: &mut O,
            ) -> bool {
                let $s = self;
                $crate::query::RayQuery::occluded_observed($inner, ray, obs)
            }
            fn triangles(&self) -> &[dualsplit_geometry::Triangle] {
                let $s = self;
                $crate::query::RayQuery::triangles($inner)
            }
            fn intersect_batch(
                &self,
                rays: &[dualsplit_geometry::Ray],
            ) -> Vec<Option<dualsplit_geometry::Hit>> {
                let $s = self;
                $crate::query::RayQuery::intersect_batch($inner, rays)
            }
            fn occluded_batch(&self, rays: &[dualsplit_geometry::Ray]) -> Vec<bool> {
                let $s = self;
                $crate::query::RayQuery::occluded_batch($inner, rays)
            }
        }
    };
}

pub(crate) use query_via;
