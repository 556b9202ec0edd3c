//! Acceleration structures for dualsplit, all derived from one SAH binary BVH:
//!
//! ```text
//!   Bvh2 (build/) ──collapse──▶ BVH4 (Dammertz), BVH8 (Ylitie)     (wide/)
//!        │                          └──quantize──▶ CWBVH, 80-B nodes (cwbvh/)
//!        └──────────convert──▶ DST, identical bounds               (dst/)
//!                                   └──quantize──▶ DST-Q, clusters  (dstq/)
//!   each encoded into a byte-exact MemoryImage (image.rs) that its traversal reads
//! ```
//!
//! Every traversal is generic over an [`Observer`] (the one-traversal contract: README,
//! "What is where").
//! [`Structures`] builds all of them from one scene and dispatches by [`AccelKind`];
//! [`TraversalSet`] is what the renderer and the simulator run on: [`Structures`], or one
//! [`AnyTree`] (built alone or loaded from a saved file).
//!
//! ## Using the library
//!
//! Build exactly the structure you need, query it through [`RayQuery`], and save it to a
//! file to skip the build next time ([`saved`]):
//!
//! ```
//! use dualsplit_accel::math::{Ray, Triangle, Vec3};
//! use dualsplit_accel::{BuildConfig, Bvh2Tree, DstConfig, DstTree, RayQuery};
//! let tris = vec![Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0))];
//! let bvh2 = Bvh2Tree::build(tris, &BuildConfig::default())?;
//! let dst = DstTree::from_bvh2(&bvh2, &DstConfig::hardware())?;
//! let hits = dst.intersect_batch(&[Ray::new(Vec3::ZERO, Vec3::Z)]);
//! assert_eq!(hits[0].map(|h| h.t), Some(2.0));
//! # Ok::<(), dualsplit_accel::AccelError>(())
//! ```
//!
//! * Structures: [`Bvh2Tree::build`]; [`BvhTree::bvh4_from`], [`BvhTree::bvh8_from`],
//!   [`DstTree::from_bvh2`] and the quantized [`CwbvhTree::from_bvh2`] (compressed BVH8,
//!   [`cwbvh`]) and [`DstQTree::from_bvh2`] (quantized DST, [`dstq`]) derive the others from
//!   a BVH2, each with its [`BuildStats`] (times in milliseconds).
//! * Queries: [`RayQuery`] (`intersect`, `occluded`, batch forms, and the `_observed` forms
//!   the simulator uses). The plain and batch forms observe nothing, so they run the
//!   CPU-side path ([`Observer::OBSERVES_NOTHING`]: [`wide::cpu`] for a BVH, the DST's plain
//!   decoder), made from the image on first use, with the image traversal's answers bit for
//!   bit; the `_observed` forms read the image. Tracing many rays one by one on a thread,
//!   a query context made once for them skips finding the copy, its arrays and a stack per
//!   ray: [`BvhImage::query`] ([`BvhQuery`]), [`dst::Dst::query`] ([`dst::DstQuery`]), or
//!   [`TraversalSet::tracer`] ([`Tracer`]) for any traversal of a set. The batch forms use
//!   one per rayon job.
//! * DST traversals: [`DstDecoding::Software`] ([`AccelKind::DstSw`], `dst-sw`: the paper's
//!   DST\*, the fast one on a CPU) and [`DstDecoding::Pipeline`] ([`AccelKind::Dst`], `dst`:
//!   the hardware pipeline model). [`AccelKind::DST_SOFTWARE`] and
//!   [`AccelKind::DST_PIPELINE`] name them too.
//! * Math types: [`math`] re-exports the vector, ray, triangle and hit types (glam's `Vec3`
//!   included), so callers need not depend on glam.
//! * Threads: builds and batch queries run on the current rayon pool; use
//!   [`rayon::ThreadPool::install`] or [`Bvh2Tree::build_in`] to pick one.

pub mod build;
pub mod bvh2;
pub mod cwbvh;
pub mod dst;
pub mod dstq;
pub mod image;
pub mod observer;
pub mod query;
pub mod ray_file;
mod registry;
pub mod saved;
pub mod set;
pub mod stats;
pub mod structure;
pub mod tree;
pub mod tree_set;
pub mod validate;
pub mod wide;
// The toy structure of docs/extending.md, for its test (feature `toy`).
#[cfg(feature = "toy")]
pub mod toy;

/// The geometry types of the public API, re-exported so that callers need not depend on
/// `dualsplit-geometry` or match its glam version.
pub mod math {
    pub use dualsplit_geometry::{Aabb, Hit, PrimId, Ray, Triangle, Vec3};
    /// The vector library `Vec3` comes from.
    pub use glam;
}

pub use build::{BuildConfig, Bvh2, Bvh2Node};
pub use image::{ImageError, MemoryImage, SharedTriangles};
pub use observer::{
    ByteAddr, CountingObserver, DstNodeKind, NoObserver, NodeStep, Observer, StepOutcome,
};
pub use stats::StructureStats;
pub use validate::ValidationReport;
pub use wide::{BvhImage, BvhQuery, CollapseConfig, WideBvh};

pub use query::RayQuery;
/// The rayon crate builds and batch queries run on (for [`rayon::ThreadPool`]).
pub use rayon;
pub use registry::*;
pub use set::{Tracer, TraversalSet};
pub use stats::BuildStats;
pub use structure::{Structure, UnitMismatch};
pub use tree_set::TreeSet;

use dualsplit_geometry::{Hit, Ray, Triangle};
use std::time::Instant;

/// Wall time since `t0` in milliseconds (build times: host measurements, never results).
pub(crate) fn ms_since(t0: Instant) -> f64 {
    t0.elapsed().as_secs_f64() * 1e3
}

/// Every structure of the registry built from one scene's BVH2, in [`TreeKind::ALL`] order:
/// the BVH2 itself, each structure derived from it with the same leaves and bounds, with
/// [`Presets`] (the DST's hardware preset, the default BVH8 collapse and quantized DST
/// unless built with others). Each folder adds its typed accessor ([`Structures::dst`],
/// [`Structures::bvh8`], ...); [`Structures::tree`] gives any of them.
///
/// ```
/// use dualsplit_accel::{AccelKind, BuildConfig, NoObserver, Structures};
/// use dualsplit_geometry::{Ray, Triangle, Vec3};
/// let tris = [Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0))];
/// let s = Structures::build(&tris, &BuildConfig::default());
/// let ray = Ray::new(Vec3::ZERO, Vec3::Z);
/// for kind in AccelKind::ALL {
///     assert_eq!(s.closest_hit(kind, &ray, &mut NoObserver).unwrap().t, 2.0);
/// }
/// ```
pub struct Structures {
    /// The scene's triangles (ids are indices), shared by every structure's image.
    pub triangles: SharedTriangles,
    /// The source BVH2 (logical).
    pub bvh2: Bvh2,
    /// One tree per [`TreeKind`], in [`TreeKind::ALL`] order.
    trees: Vec<AnyTree>,
}

impl Structures {
    /// Builds every structure for `triangles`.
    ///
    /// # Panics
    /// When an image offset overflows its field (more than about 2^28 words of BVH4 nodes,
    /// i.e. tens of millions of triangles); use [`Structures::try_build`] to get the error.
    pub fn build(triangles: &[Triangle], cfg: &BuildConfig) -> Self {
        match Self::try_build(triangles, cfg) {
            Ok(s) => s,
            Err(e) => panic!("{e}"),
        }
    }

    /// Builds every structure for `triangles`, or reports which image could not be encoded.
    pub fn try_build(triangles: &[Triangle], cfg: &BuildConfig) -> Result<Self, AccelError> {
        Self::try_build_presets(triangles, cfg, &Presets::default())
    }

    /// Like [`Structures::try_build`] with explicit presets.
    pub fn try_build_presets(
        triangles: &[Triangle],
        cfg: &BuildConfig,
        presets: &Presets,
    ) -> Result<Self, AccelError> {
        let shared = SharedTriangles::from(triangles);
        let bvh2 = Bvh2Tree::build(shared.clone(), cfg)?;
        let mut trees: Vec<AnyTree> = Vec::with_capacity(TreeKind::ALL.len());
        for kind in TreeKind::ALL {
            let tree = AnyTree::derive_with(&bvh2, kind, presets, &trees)?;
            trees.push(tree);
        }
        let s = Self {
            triangles: shared,
            bvh2: bvh2.into_logical(),
            trees,
        };
        // Debug builds check every image (bounds containment is undefined for NaN input,
        // which scene loading drops anyway).
        if cfg!(debug_assertions) && triangles.iter().all(Triangle::is_finite) {
            for rep in s.validate() {
                debug_assert!(rep.is_ok(), "encoder produced an invalid image: {rep:?}");
            }
        }
        Ok(s)
    }

    /// The tree of `kind`.
    #[inline]
    pub fn tree(&self, kind: TreeKind) -> &AnyTree {
        &self.trees[kind as usize]
    }

    /// Every tree, in [`TreeKind::ALL`] order.
    pub fn trees(&self) -> &[AnyTree] {
        &self.trees
    }

    /// The tree of `kind` as its own type `T` (the folders' typed accessors).
    ///
    /// # Panics
    /// When `T` is not the type the registry gives `kind` (a bug in the caller).
    pub(crate) fn structure<T: Structure + 'static>(&self, kind: TreeKind) -> &T {
        match self.tree(kind).get::<T>() {
            Some(t) => t,
            None => panic!("the {kind} tree is not a {}", std::any::type_name::<T>()),
        }
    }

    /// The memory image `kind` reads (what the simulator replays fetches against). The
    /// traversals of one structure read the same image.
    pub fn image(&self, kind: AccelKind) -> &MemoryImage {
        self.tree(kind.tree_kind()).image()
    }

    /// Closest hit of `ray` on traversal `kind`.
    #[inline]
    pub fn closest_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        self.tree(kind.tree_kind())
            .closest_hit(kind, ray, obs)
            .flatten()
    }

    /// True when `ray` hits any triangle within `[t_min, t_max]`.
    #[inline]
    pub fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        self.tree(kind.tree_kind())
            .any_hit(kind, ray, obs)
            .unwrap_or(false)
    }

    /// Validates every structure ([`Structure::validate`]), each against the BVH2 and the
    /// structures derived with it.
    pub fn validate(&self) -> Vec<ValidationReport> {
        self.trees
            .iter()
            .map(|t| t.validate_among(&self.bvh2, &self.trees))
            .collect()
    }

    /// Size and build statistics of every structure (the paper's Table 3 and the
    /// quantized structures), percentages relative to the reference BVH2's image.
    pub fn stats(&self) -> Vec<StructureStats> {
        let base = self.tree(TreeKind::REFERENCE).image();
        let base = base.node_bytes() + base.index_bytes();
        self.trees.iter().map(|t| t.structure_stats(base)).collect()
    }
}
