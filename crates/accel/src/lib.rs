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
pub mod saved;
pub mod set;
pub mod stats;
pub mod tree;
pub mod tree_set;
pub mod validate;
pub mod wide;

/// The geometry types of the public API, re-exported so that callers need not depend on
/// `dualsplit-geometry` or match its glam version.
pub mod math {
    pub use dualsplit_geometry::{Aabb, Hit, PrimId, Ray, Triangle, Vec3};
    /// The vector library `Vec3` comes from.
    pub use glam;
}

pub use build::{BuildConfig, Bvh2, Bvh2Node};
pub use image::{ByteAddr, ImageError, MemoryImage, SharedTriangles};
pub use observer::{CountingObserver, DstNodeKind, NoObserver, NodeStep, Observer};
pub use stats::StructureStats;
pub use validate::ValidationReport;
pub use wide::{BvhImage, BvhQuery, CollapseConfig, WideBvh};

pub use dst::{Dst, DstConfig};
pub use query::{DstPipeline, RayQuery};
/// The rayon crate builds and batch queries run on (for [`rayon::ThreadPool`]).
pub use rayon;
pub use set::{Plain, Tracer, TraversalSet};
pub use tree::{
    AnyTree, BuildStats, Bvh2Tree, BvhTree, CwbvhTree, DstDecoding, DstQTree, DstTree, TreeKind,
};
pub use tree_set::TreeSet;

use dualsplit_geometry::{Aabb, Hit, Ray, Triangle};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The traversal variants a workload can run on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AccelKind {
    /// Binary BVH, 52-byte nodes.
    Bvh2,
    /// 4-wide BVH (Dammertz collapse), 100-byte nodes.
    Bvh4,
    /// 8-wide BVH (Ylitie collapse), 200-byte nodes.
    Bvh8,
    /// Dual-split tree, software decoder (the paper's DST*): the fast CPU traversal
    /// ([`AccelKind::DST_SOFTWARE`], [`DstDecoding::Software`]; command line `dst-sw`).
    #[doc(alias = "DstSoftware")]
    DstSw,
    /// Dual-split tree traversed by the hardware pipeline's step function: the model of the
    /// paper's hardware, slower on a CPU ([`AccelKind::DST_PIPELINE`],
    /// [`DstDecoding::Pipeline`]; command line `dst`).
    #[doc(alias = "DstPipeline")]
    Dst,
    /// Compressed 8-wide BVH (Ylitie et al. 2017): the BVH8's nodes in 80 bytes, child
    /// boxes quantized to 8 bits per plane, conservatively ([`cwbvh`]; command line `cwbvh`).
    Cwbvh,
    /// Quantized dual-split tree: the DST's planes as k-bit offsets in a local frame, several
    /// levels collapsed into one fetch (the paper's §5 future work; [`dstq`]; command line
    /// `dst-q`).
    DstQ,
}

impl AccelKind {
    /// The DST's software decoder (the paper's DST\*), the fast CPU traversal: an
    /// unambiguous name for [`AccelKind::DstSw`].
    pub const DST_SOFTWARE: AccelKind = AccelKind::DstSw;
    /// The DST traversed by the hardware pipeline model: an unambiguous name for
    /// [`AccelKind::Dst`].
    pub const DST_PIPELINE: AccelKind = AccelKind::Dst;

    /// All kinds, in report order.
    pub const ALL: [AccelKind; 7] = [
        AccelKind::Bvh2,
        AccelKind::Bvh4,
        AccelKind::Bvh8,
        AccelKind::DstSw,
        AccelKind::Dst,
        AccelKind::Cwbvh,
        AccelKind::DstQ,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::Bvh2 => "bvh2",
            AccelKind::Bvh4 => "bvh4",
            AccelKind::Bvh8 => "bvh8",
            AccelKind::DstSw => "dst-sw",
            AccelKind::Dst => "dst",
            AccelKind::Cwbvh => "cwbvh",
            AccelKind::DstQ => "dst-q",
        }
    }

    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }
}

/// Errors while building the structures of a scene.
#[derive(Debug, thiserror::Error)]
pub enum AccelError {
    /// A memory image could not be encoded (an offset field overflowed).
    #[error(transparent)]
    Image(#[from] ImageError),
    /// The dual-split tree could not be converted or encoded.
    #[error(transparent)]
    Dst(#[from] dst::DstError),
    /// The quantized dual-split tree could not be encoded.
    #[error(transparent)]
    DstQ(#[from] dstq::DstQError),
}

/// Wall time since `t0` in milliseconds (build times: host measurements, never results).
pub(crate) fn ms_since(t0: Instant) -> f64 {
    t0.elapsed().as_secs_f64() * 1e3
}

/// Every structure built from one scene's BVH2: the logical BVH2 and the encoded BVH2, BVH4
/// (Dammertz collapse) and BVH8 (Ylitie collapse), all with identical leaves, the
/// dual-split tree converted from the same BVH2 with identical bounds (hardware preset),
/// and their quantized forms: the compressed BVH8 ([`cwbvh::Cwbvh`]) and the quantized DST
/// ([`dstq::DstQ`], default [`dstq::DstQConfig`]).
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
    /// The encoded BVH2 (52-byte nodes); its `time` is the BVH2 build time.
    pub bvh2_image: BvhImage,
    /// The encoded BVH4 (100-byte nodes); its `time` is the collapse time.
    pub bvh4: BvhImage,
    /// The encoded BVH8 (200-byte nodes); its `time` is the collapse time.
    pub bvh8: BvhImage,
    /// The dual-split tree (identical bounds, [`dst::DstConfig::hardware`]).
    pub dst: dst::Dst,
    /// Wall time of the BVH2 → DST conversion, in milliseconds (a host measurement).
    pub dst_convert_ms: f64,
    /// The compressed BVH8, encoded from the same collapse as `bvh8`.
    pub cwbvh: cwbvh::Cwbvh,
    /// The quantized DST, encoded from `dst`.
    pub dstq: dstq::DstQ,
    /// Wall time of the DST → quantized DST encoding, in milliseconds (a host measurement).
    pub dstq_convert_ms: f64,
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
        Self::try_build_with(triangles, cfg, &dst::DstConfig::hardware())
    }

    /// Like [`Structures::try_build`] with an explicit DST configuration.
    pub fn try_build_with(
        triangles: &[Triangle],
        cfg: &BuildConfig,
        dst_cfg: &dst::DstConfig,
    ) -> Result<Self, AccelError> {
        let shared = SharedTriangles::from(triangles);
        let t0 = Instant::now();
        let boxes: Vec<Aabb> = triangles.iter().map(|t| t.bounds()).collect();
        let bvh2 = Bvh2::build(&boxes, cfg);
        let build_time = t0.elapsed();
        let wide2 = WideBvh::from_bvh2(&bvh2);
        let bvh2_image = BvhImage::encode(&wide2, &bvh2, shared.clone(), cfg, build_time)?;
        let t0 = Instant::now();
        let wide4 = WideBvh::collapse_bvh4(&bvh2);
        let t4 = t0.elapsed();
        let bvh4 = BvhImage::encode(&wide4, &bvh2, shared.clone(), cfg, t4)?;
        let t0 = Instant::now();
        let wide8 = WideBvh::collapse_bvh8(&bvh2, &CollapseConfig::default());
        let t8 = t0.elapsed();
        let bvh8 = BvhImage::encode(&wide8, &bvh2, shared.clone(), cfg, t8)?;
        let cwbvh = cwbvh::Cwbvh::from_wide(&wide8, &bvh2, shared.clone(), t8)?;
        let t0 = Instant::now();
        let dst = dst::Dst::from_bvh2(&bvh2, shared.clone(), dst_cfg)?;
        let dst_convert_ms = ms_since(t0);
        let t0 = Instant::now();
        let dstq = dstq::DstQ::from_dst(&dst, &dstq::DstQConfig::default())?;
        let dstq_convert_ms = ms_since(t0);
        let s = Self {
            triangles: shared,
            bvh2,
            bvh2_image,
            bvh4,
            bvh8,
            dst,
            dst_convert_ms,
            cwbvh,
            dstq,
            dstq_convert_ms,
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

    /// The encoded BVH that `kind` traverses (BVH2, BVH4, BVH8), or `None` for the others.
    pub fn encoded(&self, kind: AccelKind) -> Option<&BvhImage> {
        match kind {
            AccelKind::Bvh2 => Some(&self.bvh2_image),
            AccelKind::Bvh4 => Some(&self.bvh4),
            AccelKind::Bvh8 => Some(&self.bvh8),
            AccelKind::DstSw | AccelKind::Dst | AccelKind::Cwbvh | AccelKind::DstQ => None,
        }
    }

    /// The memory image `kind` reads (what the simulator replays fetches against). Both DST
    /// kinds read the same DST image.
    pub fn image(&self, kind: AccelKind) -> &MemoryImage {
        match kind {
            AccelKind::DstSw | AccelKind::Dst => self.dst.image(),
            AccelKind::Cwbvh => self.cwbvh.image(),
            AccelKind::DstQ => self.dstq.image(),
            AccelKind::Bvh2 | AccelKind::Bvh4 | AccelKind::Bvh8 => match self.encoded(kind) {
                Some(b) => &b.image,
                None => unreachable!("every BVH kind is encoded"),
            },
        }
    }

    /// Closest hit of `ray` on structure `kind`: the BVH traversals, the DST software
    /// decoder (DST*) or the traversal loop driven by the hardware pipeline's step function.
    #[inline]
    pub fn closest_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        match kind {
            AccelKind::Bvh2 => self.bvh2_image.closest_hit(ray, obs),
            AccelKind::Bvh4 => self.bvh4.closest_hit(ray, obs),
            AccelKind::Bvh8 => self.bvh8.closest_hit(ray, obs),
            AccelKind::DstSw => own_frame(|| self.dst.closest_hit(ray, obs)),
            AccelKind::Dst => own_frame(|| self.dst.closest_hit_pipeline(ray, obs)),
            AccelKind::Cwbvh => own_frame(|| self.cwbvh.closest_hit(ray, obs)),
            AccelKind::DstQ => own_frame(|| self.dstq.closest_hit(ray, obs)),
        }
    }

    /// True when `ray` hits any triangle within `[t_min, t_max]`.
    #[inline]
    pub fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        match kind {
            AccelKind::Bvh2 => self.bvh2_image.any_hit(ray, obs),
            AccelKind::Bvh4 => self.bvh4.any_hit(ray, obs),
            AccelKind::Bvh8 => self.bvh8.any_hit(ray, obs),
            AccelKind::DstSw => own_frame(|| self.dst.any_hit(ray, obs)),
            AccelKind::Dst => own_frame(|| self.dst.any_hit_pipeline(ray, obs)),
            AccelKind::Cwbvh => own_frame(|| self.cwbvh.any_hit(ray, obs)),
            AccelKind::DstQ => own_frame(|| self.dstq.any_hit(ray, obs)),
        }
    }

    /// Validates the three BVH images (BVH2, BVH4, BVH8), the DST (which must rebuild
    /// every BVH2 box exactly from its planes), the compressed BVH8 (every quantized box
    /// must contain its exact box) and the quantized DST.
    pub fn validate(&self) -> Vec<ValidationReport> {
        vec![
            self.bvh2_image.validate(),
            self.bvh4.validate(),
            self.bvh8.validate(),
            ValidationReport::of_dst(&self.dst, &self.bvh2),
            self.cwbvh.validate(),
            self.dstq.validate(&self.dst),
        ]
    }

    /// Size and build statistics of BVH2, BVH4, BVH8, the DST (the paper's Table 3) and the
    /// quantized structures, percentages relative to the BVH2 image.
    pub fn stats(&self) -> Vec<StructureStats> {
        let base = self.bvh2_image.bytes_total();
        vec![
            StructureStats::of("bvh2", &self.bvh2_image, base),
            StructureStats::of("bvh4", &self.bvh4, base),
            StructureStats::of("bvh8", &self.bvh8, base),
            StructureStats::of_dst(&self.dst.stats(), self.dst_convert_ms, base),
            StructureStats::of_cwbvh(&self.cwbvh, base),
            StructureStats::of_dstq(&self.dstq, self.dstq_convert_ms, base),
        ]
    }
}

/// Calls `f` in a function of its own. The query dispatchers ([`Structures::closest_hit`],
/// [`Structures::any_hit`]) take the DST and compressed traversals through it: inlined, their
/// loops gave the dispatcher a frame of some 1.5 KB whose entry and exit every ray paid,
/// the BVH queries' short path to the CPU-side copy included.
#[inline(never)]
fn own_frame<R>(f: impl FnOnce() -> R) -> R {
    f()
}
