//! Wide BVHs collapsed from the BVH2, their encoding into memory images and their
//! traversal (Lin et al. 2020, §4.2).
//!
//! * [`WideBvh`] is the logical tree: every internal node lists up to `arity` children, each
//!   an internal node or a leaf that is exactly a leaf of the source BVH2 (same triangle
//!   range of [`crate::Bvh2::prim_ids`]), so BVH2, BVH4 and BVH8 have identical leaves.
//!   - [`WideBvh::from_bvh2`]: the BVH2 itself seen as a 2-wide tree;
//!   - [`WideBvh::collapse_bvh4`]: BVH4 by removing every other level (Dammertz et al. 2008);
//!   - [`WideBvh::collapse_bvh8`]: BVH8 by the adaptive collapse of Ylitie et al. 2017.
//! * [`encode`](encode::encode) writes a `WideBvh` into a [`MemoryImage`] with a node layout
//!   ([`crate::bvh2::Node2`], [`Node4`], [`Node8`]).
//! * [`traverse`] is the single traversal (closest and any hit) over an image, generic over
//!   the node layout and the [`crate::Observer`].
//! * [`BvhImage`] bundles an encoded structure with its statistics.

mod collapse;
pub mod cpu;
pub mod encode;
mod node4;
mod node8;
pub(crate) mod simd;
mod structure;
pub mod traverse;
mod tree;

pub use collapse::CollapseConfig;
pub use node4::Node4;
pub use node8::Node8;
pub use structure::BvhFields;
pub use tree::{Bvh2Tree, BvhTree};

use crate::bvh2::Node2;
use crate::image::{ImageError, MemoryImage};
use crate::observer::{NoObserver, Observer};
use crate::validate::{ValidationReport, validate_image};
use crate::{BuildConfig, Bvh2};
use dualsplit_geometry::{Aabb, Hit, Ray};
use std::time::Duration;

/// A child of a [`WideNode`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WideChild {
    /// Internal child: index into [`WideBvh::nodes`].
    Node(u32),
    /// Leaf child: a triangle range of the source BVH2's `prim_ids`.
    Leaf {
        /// First index into `prim_ids`.
        first: u32,
        /// Triangle count.
        count: u32,
    },
}

/// An internal node of a [`WideBvh`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WideNode {
    /// The children (at most the tree's arity), each with its box.
    pub children: Vec<(Aabb, WideChild)>,
}

/// A logical wide BVH derived from a [`Bvh2`]; root at index 0 (always an internal node, with
/// zero children for an empty scene and one leaf child when the BVH2 root is a leaf).
#[derive(Clone, Debug, Default)]
pub struct WideBvh {
    /// Maximum children per node.
    pub arity: usize,
    /// Internal nodes; index 0 is the root.
    pub nodes: Vec<WideNode>,
}

impl WideBvh {
    /// The BVH2 as a 2-wide tree (its internal nodes, in the same order).
    pub fn from_bvh2(bvh: &Bvh2) -> Self {
        collapse::from_bvh2(bvh)
    }

    /// BVH4 by removing every other level of the BVH2 (Dammertz et al. 2008): a BVH4 node is a
    /// BVH2 node at even depth with each internal child replaced by that child's children.
    pub fn collapse_bvh4(bvh: &Bvh2) -> Self {
        collapse::dammertz4(bvh)
    }

    /// BVH8 by the adaptive collapse of Ylitie, Karras and Laine 2017 (HPG, "Efficient
    /// Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs"): a
    /// bottom-up cost over up to 8 roots per BVH2 node, then a top-down pass following it.
    /// Leaves stay the BVH2's leaves.
    pub fn collapse_bvh8(bvh: &Bvh2, cfg: &CollapseConfig) -> Self {
        collapse::ylitie8(bvh, cfg)
    }

    /// Number of leaves.
    pub fn leaf_count(&self) -> usize {
        self.nodes
            .iter()
            .flat_map(|n| &n.children)
            .filter(|c| matches!(c.1, WideChild::Leaf { .. }))
            .count()
    }

    /// The leaves' triangle sets, each sorted, the list sorted (for comparing structures).
    pub fn leaf_sets(&self, prim_ids: &[u32]) -> Vec<Vec<u32>> {
        let mut v: Vec<Vec<u32>> = self
            .nodes
            .iter()
            .flat_map(|n| &n.children)
            .filter_map(|c| match c.1 {
                WideChild::Leaf { first, count } => {
                    let mut s = prim_ids[first as usize..(first + count) as usize].to_vec();
                    s.sort_unstable();
                    Some(s)
                }
                WideChild::Node(_) => None,
            })
            .collect();
        v.sort_unstable();
        v
    }

    /// SAH cost with `cfg`'s costs: (Σ internal-node area·c_t + Σ leaf area·n·c_i) / root
    /// area, where an internal node's area is the union of its children's boxes.
    pub fn sah_cost(&self, cfg: &BuildConfig) -> f32 {
        let area = |n: &WideNode| {
            n.children
                .iter()
                .fold(Aabb::EMPTY, |b, c| b.union(c.0))
                .half_area() as f64
        };
        let Some(root) = self.nodes.first() else {
            return 0.0;
        };
        let root_area = area(root).max(f32::MIN_POSITIVE as f64);
        let mut c = 0.0f64;
        for n in &self.nodes {
            c += area(n) * cfg.cost_traversal as f64;
            for (b, ch) in &n.children {
                if let WideChild::Leaf { count, .. } = ch {
                    c += b.half_area() as f64 * *count as f64 * cfg.cost_triangle as f64;
                }
            }
        }
        (c / root_area) as f32
    }
}

/// An encoded BVH (2-, 4- or 8-wide): its memory image plus what it took to make it.
#[derive(Clone, Debug)]
pub struct BvhImage {
    /// Node width: 2, 4 or 8.
    pub arity: u8,
    /// The byte-exact memory image.
    pub image: MemoryImage,
    /// Internal nodes.
    pub internal_nodes: usize,
    /// Leaves (one leaf word each in the node region).
    pub leaves: usize,
    /// SAH cost (root-normalised, the build's costs).
    pub sah_cost: f32,
    /// Wall time of the BVH2 build (arity 2) or of the collapse (arity 4, 8); a measurement,
    /// not a result.
    pub time: Duration,
    /// The CPU-side copy the plain queries traverse ([`cpu`]), made on first use.
    pub(crate) cpu: std::sync::OnceLock<std::sync::Arc<cpu::CpuBvh>>,
}

impl BvhImage {
    /// Encodes `wide` (arity 2, 4 or 8) over `bvh`'s `prim_ids` and `triangles` (shared by
    /// the image, not copied, when given as [`crate::image::SharedTriangles`]).
    pub fn encode(
        wide: &WideBvh,
        bvh: &Bvh2,
        triangles: impl Into<crate::image::SharedTriangles>,
        cfg: &BuildConfig,
        time: Duration,
    ) -> Result<Self, ImageError> {
        let triangles = triangles.into();
        let image = match wide.arity {
            2 => encode::encode::<Node2>(wide, &bvh.prim_ids, triangles)?,
            4 => encode::encode::<Node4>(wide, &bvh.prim_ids, triangles)?,
            8 => encode::encode::<Node8>(wide, &bvh.prim_ids, triangles)?,
            a => panic!("unsupported BVH arity {a}"),
        };
        Ok(Self {
            arity: wide.arity as u8,
            image,
            internal_nodes: wide.nodes.len(),
            leaves: wide.leaf_count(),
            sah_cost: wide.sah_cost(cfg),
            time,
            cpu: Default::default(),
        })
    }

    /// The CPU-side copy of the image ([`cpu::CpuBvh`]) for this CPU's best instructions
    /// ([`cpu::SimdLevel::detect`]), made on the first call.
    #[inline]
    pub fn cpu(&self) -> &cpu::CpuBvh {
        // The made copy is one load and a check; making it is out of line (a per-ray call
        // otherwise).
        match self.cpu.get() {
            Some(c) => c,
            None => self.make_cpu(),
        }
    }

    /// [`BvhImage::cpu`] on its first call.
    #[cold]
    #[inline(never)]
    fn make_cpu(&self) -> &cpu::CpuBvh {
        self.cpu
            .get_or_init(|| std::sync::Arc::new(self.cpu_copy(cpu::SimdLevel::detect())))
    }

    /// A new CPU-side copy of the image whose traversal uses `level`'s instructions (SSE2
    /// when this CPU lacks them); for comparing levels.
    pub fn cpu_copy(&self, level: cpu::SimdLevel) -> cpu::CpuBvh {
        self.cpu_copy_with(level, cpu::merge_limit())
    }

    /// [`BvhImage::cpu_copy`] merging subtrees of at most `merge` triangles into one leaf
    /// (0: the image's leaves); for comparing merge limits.
    pub fn cpu_copy_with(&self, level: cpu::SimdLevel, merge: usize) -> cpu::CpuBvh {
        match self.arity {
            2 => cpu::CpuBvh::with_options::<Node2>(&self.image, level, merge),
            4 => cpu::CpuBvh::with_options::<Node4>(&self.image, level, merge),
            _ => cpu::CpuBvh::with_options::<Node8>(&self.image, level, merge),
        }
    }

    /// Closest hit of `ray` (ordered by `(t, prim)`). With an observer that observes
    /// nothing ([`Observer::OBSERVES_NOTHING`]) it traverses the CPU-side copy
    /// ([`BvhImage::cpu`]); otherwise it reads the image ([`BvhImage::closest_hit_image`]).
    /// Both give the same answer, bit for bit.
    #[inline]
    pub fn closest_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        if O::OBSERVES_NOTHING {
            return match self.cpu().traverse::<false>(ray) {
                Some(h) => h,
                None => self.declined_closest(ray, obs),
            };
        }
        self.closest_hit_image(ray, obs)
    }

    /// [`BvhImage::closest_hit_image`] of a ray the CPU-side copy declines (NaN bounds),
    /// kept out of line so that the plain query's frame stays small.
    #[cold]
    #[inline(never)]
    fn declined_closest<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        self.closest_hit_image(ray, obs)
    }

    /// [`BvhImage::any_hit_image`] of a ray the CPU-side copy declines, out of line.
    #[cold]
    #[inline(never)]
    fn declined_any<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        self.any_hit_image(ray, obs)
    }

    /// True when any triangle is hit within `[ray.t_min, ray.t_max]`; like
    /// [`BvhImage::closest_hit`], through the CPU-side copy when nothing is observed.
    #[inline]
    pub fn any_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        if O::OBSERVES_NOTHING {
            return match self.cpu().traverse::<true>(ray) {
                Some(h) => h.is_some(),
                None => self.declined_any(ray, obs),
            };
        }
        self.any_hit_image(ray, obs)
    }

    /// A query context for tracing rays one by one on one thread, through the CPU-side copy
    /// ([`BvhQuery`]); made once per thread or batch of rays.
    pub fn query(&self) -> BvhQuery<'_> {
        BvhQuery {
            bvh: self,
            cpu: self.cpu().query(),
        }
    }

    /// Closest hit of `ray` (ordered by `(t, prim)`), reading the image and reporting every
    /// fetch and step to `obs`.
    #[inline]
    pub fn closest_hit_image<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        match self.arity {
            2 => traverse::traverse::<Node2, O, false>(&self.image, ray, obs),
            4 => traverse::traverse::<Node4, O, false>(&self.image, ray, obs),
            _ => traverse::traverse::<Node8, O, false>(&self.image, ray, obs),
        }
    }

    /// True when any triangle is hit within `[ray.t_min, ray.t_max]`, reading the image.
    #[inline]
    pub fn any_hit_image<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        match self.arity {
            2 => traverse::traverse::<Node2, O, true>(&self.image, ray, obs),
            4 => traverse::traverse::<Node4, O, true>(&self.image, ray, obs),
            _ => traverse::traverse::<Node8, O, true>(&self.image, ray, obs),
        }
        .is_some()
    }

    /// Checks the image (see [`ValidationReport`]).
    pub fn validate(&self) -> ValidationReport {
        match self.arity {
            2 => validate_image::<Node2>(&self.image),
            4 => validate_image::<Node4>(&self.image),
            _ => validate_image::<Node8>(&self.image),
        }
    }

    /// Bytes of nodes plus triangle-index lists: the quantity of the paper's Table 3.
    pub fn bytes_total(&self) -> u64 {
        self.image.node_bytes() + self.image.index_bytes()
    }
}

/// A query context over a [`BvhImage`] (its CPU-side copy's [`cpu::CpuQuery`]): the plain
/// queries of [`BvhImage::closest_hit`] and [`BvhImage::any_hit`] with a [`NoObserver`], the
/// same answers bit for bit, without finding the copy, its arrays and a stack per ray.
/// Made by [`BvhImage::query`]; the counterpart of Embree's `RTCIntersectContext`.
pub struct BvhQuery<'a> {
    bvh: &'a BvhImage,
    cpu: cpu::CpuQuery<'a>,
}

impl BvhQuery<'_> {
    /// Closest hit of `ray` (ordered by `(t, prim)`).
    #[inline]
    pub fn closest_hit(&mut self, ray: &Ray) -> Option<Hit> {
        match self.cpu.traverse::<false>(ray) {
            Some(h) => h,
            None => self.bvh.declined_closest(ray, &mut NoObserver),
        }
    }

    /// True when any triangle is hit within `[ray.t_min, ray.t_max]`.
    #[inline]
    pub fn any_hit(&mut self, ray: &Ray) -> bool {
        match self.cpu.traverse::<true>(ray) {
            Some(h) => h.is_some(),
            None => self.bvh.declined_any(ray, &mut NoObserver),
        }
    }
}
