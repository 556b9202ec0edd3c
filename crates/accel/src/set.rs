//! [`TraversalSet`]: the structures a workload runs on, each traversal chosen by its
//! [`AccelKind`]. Three sets exist: every structure of a scene ([`Structures`], every
//! kind), the trees of some kinds ([`crate::TreeSet`]) and one saved or built tree
//! ([`AnyTree`], the kinds of [`TreeKind::accel_kinds`](crate::TreeKind::accel_kinds):
//! `dst-sw` and `dst` for a DST, its own kind for a BVH). The renderer, the benchmarks and
//! the simulator take any of them.
//!
//! ```
//! use dualsplit_accel::math::{Ray, Triangle, Vec3};
//! use dualsplit_accel::{AccelKind, AnyTree, BuildConfig, Bvh2Tree, DstConfig, DstTree};
//! use dualsplit_accel::{NoObserver, Structures, TraversalSet};
//! let tris = vec![Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0))];
//! let all = Structures::build(&tris, &BuildConfig::default());
//! let bvh2 = Bvh2Tree::build(&tris[..], &BuildConfig::default())?;
//! let dst = AnyTree::from(DstTree::from_bvh2(&bvh2, &DstConfig::hardware())?);
//! assert_eq!(dst.kinds(), [AccelKind::DstSw, AccelKind::Dst]);
//! assert!(!dst.supports(AccelKind::Bvh2));
//! assert_eq!(dst.kind_names(), "dst-sw, dst");
//! let ray = Ray::new(Vec3::ZERO, Vec3::Z);
//! fn t(s: &impl TraversalSet, kind: AccelKind, ray: &Ray) -> Option<f32> {
//!     TraversalSet::closest_hit(s, kind, ray, &mut NoObserver).map(|h| h.t)
//! }
//! assert_eq!(t(&dst, AccelKind::Dst, &ray), t(&all, AccelKind::Bvh2, &ray));
//! assert_eq!(TraversalSet::scene_box(&dst), TraversalSet::scene_box(&all));
//! # Ok::<(), dualsplit_accel::AccelError>(())
//! ```

use crate::image::MemoryImage;
use crate::observer::{NoObserver, Observer};
use crate::structure::{PlainQuery, UnitMismatch};
use crate::{AccelKind, AnyTree, Plain, Structures, TreeKind};
use dualsplit_geometry::{Aabb, Hit, Ray};

/// Structures traversed by [`AccelKind`]: what a workload (render, benchmark, simulation)
/// runs on.
///
/// A kind outside [`TraversalSet::kinds`] has no traversal: entry points that take a set
/// and a kind (`dualsplit_render::render`, `dualsplit_sim::simulate`, ...) refuse it with
/// an error before tracing; the per-ray methods answer such a kind with a miss.
pub trait TraversalSet: Sync {
    /// The traversals this set answers, its reference first (the kind ray sets are
    /// recorded on: BVH2 for [`Structures`], the tree's first kind for an [`AnyTree`]).
    fn kinds(&self) -> &[AccelKind];

    /// True when `kind` is one of [`TraversalSet::kinds`].
    fn supports(&self, kind: AccelKind) -> bool {
        self.kinds().contains(&kind)
    }

    /// The command-line names of [`TraversalSet::kinds`], comma-separated (`dst-sw, dst`),
    /// for messages.
    fn kind_names(&self) -> String {
        let names: Vec<&str> = self.kinds().iter().map(|k| k.name()).collect();
        names.join(", ")
    }

    /// The reference traversal: the first of [`TraversalSet::kinds`].
    fn reference(&self) -> AccelKind {
        self.kinds()[0]
    }

    /// Closest hit of `ray` through traversal `kind` (a miss for a kind the set lacks).
    fn closest_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit>;

    /// True when `ray` hits any triangle within `[t_min, t_max]` through traversal `kind`
    /// (false for a kind the set lacks).
    fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> bool;

    /// The query context of traversal `kind` when its plain queries have one (the BVH
    /// kinds and the DST software decoder), which a [`Tracer`] then uses.
    fn plain(&self, kind: AccelKind) -> Option<Plain<'_>>;

    /// A query context for tracing rays of traversal `kind` one by one on one thread
    /// ([`Tracer`]).
    fn tracer(&self, kind: AccelKind) -> Tracer<'_, Self>
    where
        Self: Sized,
    {
        Tracer {
            set: self,
            kind,
            ctx: self.plain(kind),
        }
    }

    /// The memory image traversal `kind` reads (both DST kinds read the same image; a set
    /// of one tree has one image, whatever `kind` says).
    fn image(&self, kind: AccelKind) -> &MemoryImage;

    /// The box around every triangle (the BVH2's root box; the DST stores it beside its
    /// image).
    fn scene_box(&self) -> Aabb;

    /// Whether the tree traversal `kind` reads fits the hardware unit it is simulated on
    /// ([`crate::Structure::fits_unit`]); `Ok` for a kind the set lacks.
    fn fits_unit(&self, kind: AccelKind) -> Result<(), UnitMismatch>;
}

impl TraversalSet for Structures {
    fn kinds(&self) -> &[AccelKind] {
        &AccelKind::ALL
    }

    #[inline]
    fn closest_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        Structures::closest_hit(self, kind, ray, obs)
    }

    #[inline]
    fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        Structures::any_hit(self, kind, ray, obs)
    }

    fn plain(&self, kind: AccelKind) -> Option<Plain<'_>> {
        self.tree(kind.tree_kind()).plain_query(kind)
    }

    fn image(&self, kind: AccelKind) -> &MemoryImage {
        Structures::image(self, kind)
    }

    fn scene_box(&self) -> Aabb {
        self.tree(TreeKind::REFERENCE).scene_box()
    }

    fn fits_unit(&self, kind: AccelKind) -> Result<(), UnitMismatch> {
        self.tree(kind.tree_kind()).fits_unit()
    }
}

impl TraversalSet for AnyTree {
    fn kinds(&self) -> &[AccelKind] {
        self.kind().accel_kinds()
    }

    #[inline]
    fn closest_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        AnyTree::closest_hit(self, kind, ray, obs).flatten()
    }

    #[inline]
    fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        AnyTree::any_hit(self, kind, ray, obs).unwrap_or(false)
    }

    fn plain(&self, kind: AccelKind) -> Option<Plain<'_>> {
        if kind.tree_kind() != self.kind() {
            return None;
        }
        self.plain_query(kind)
    }

    fn image(&self, _kind: AccelKind) -> &MemoryImage {
        AnyTree::image(self)
    }

    fn scene_box(&self) -> Aabb {
        AnyTree::scene_box(self)
    }

    fn fits_unit(&self, kind: AccelKind) -> Result<(), UnitMismatch> {
        if kind.tree_kind() != self.kind() {
            return Ok(());
        }
        AnyTree::fits_unit(self)
    }
}

/// A query context over traversal `kind` of a [`TraversalSet`], for tracing rays one by one
/// on one thread without observing them (a renderer's or benchmark's inner loop; the
/// counterpart of Embree's `RTCIntersectContext`): a traversal whose structure has a query
/// context ([`crate::Structure::Query`]: the BVHs' holds their CPU-side copy's arrays and a
/// traversal stack) runs through it, the others through the set's plain queries.
/// The answers are [`TraversalSet::closest_hit`]'s and [`TraversalSet::any_hit`]'s with a
/// [`NoObserver`], bit for bit. Made by [`TraversalSet::tracer`].
///
/// ```
/// use dualsplit_accel::math::{Ray, Triangle, Vec3};
/// use dualsplit_accel::{AccelKind, BuildConfig, Structures, TraversalSet};
/// let tris = vec![Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0))];
/// let s = Structures::build(&tris, &BuildConfig::default());
/// let mut t = s.tracer(AccelKind::Bvh8); // once per thread or batch of rays
/// let rays = [Ray::new(Vec3::ZERO, Vec3::Z), Ray::new(Vec3::ZERO, -Vec3::Z)];
/// let hits: Vec<Option<f32>> = rays.iter().map(|r| t.closest_hit(r).map(|h| h.t)).collect();
/// assert_eq!(hits, [Some(2.0), None]);
/// assert!(t.any_hit(&rays[0]));
/// ```
pub struct Tracer<'a, S> {
    set: &'a S,
    kind: AccelKind,
    ctx: Option<Plain<'a>>,
}

impl<S: TraversalSet> Tracer<'_, S> {
    /// Closest hit of `ray` (a miss for a kind the set lacks).
    #[inline]
    pub fn closest_hit(&mut self, ray: &Ray) -> Option<Hit> {
        match &mut self.ctx {
            Some(q) => q.closest_hit(ray),
            None => self.set.closest_hit(self.kind, ray, &mut NoObserver),
        }
    }

    /// True when `ray` hits any triangle within `[t_min, t_max]` (false for a kind the set
    /// lacks).
    #[inline]
    pub fn any_hit(&mut self, ray: &Ray) -> bool {
        match &mut self.ctx {
            Some(q) => q.any_hit(ray),
            None => self.set.any_hit(self.kind, ray, &mut NoObserver),
        }
    }
}
