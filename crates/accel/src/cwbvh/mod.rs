//! The compressed 8-wide BVH (Ylitie, Karras and Laine 2017, HPG, "Efficient Incoherent Ray
//! Traversal on GPUs Through Compressed Wide BVHs"): the BVH8 of
//! [`WideBvh::collapse_bvh8`] (identical partitioning and leaves) with 80-byte nodes whose
//! child boxes are quantized to 8 bits per plane in a per-node frame.
//!
//! ```text
//!   Bvh2 ──collapse_bvh8──▶ WideBvh (arity 8) ──Cwbvh::from_wide──▶ MemoryImage (80-B nodes)
//!                                                     └─ decoded boxes ──▶ wide::cpu::CpuBvh
//! ```
//!
//! | file | what it holds |
//! |---|---|
//! | `node.rs` | the node ([`CwNode`], its byte table and worked example), [`Meta`], the conservative quantization ([`quantize_axis`]) |
//! | `encode.rs` | the image: nodes depth-first from word 0, each node's internal children adjacent, its leaf runs adjacent |
//! | `traverse.rs` | the image traversal (closest and any hit) over the decoded boxes |
//! | `validate.rs` | the structural check, exact subtree bounds, decoding back to a [`WideBvh`] |
//!
//! Image layout ([`crate::image`]'s three regions): nodes (20 words each, root at word 0),
//! index runs (triangle ids, [`RUN_END`](crate::image::RUN_END) on each run's last), triangles.
//! Unlike the BVH images there are no leaf words: a node addresses its leaves' runs through
//! its triangle base and 5-bit offsets ([`ImageError::LeafSpan`] when they do not reach).
//! The bit-level description, the rounding argument and a worked example are in
//! `docs/cwbvh-encoding.md`.
//!
//! Answers: every decoded box contains its exact box, so the traversal (and the plain
//! queries' SIMD copy, made from the decoded boxes) answer each ray exactly as the BVH2 does:
//! the same closest hit bit for bit and the same shadow answer.

mod encode;
mod node;
mod saved;
mod traverse;
mod tree;
mod validate;

pub use encode::NAME;
pub use node::{
    AxisFrame, CwNode, EMPTY_Q, LEAF_OFFSET_LIMIT, META_EMPTY, Meta, NODE_WORDS, QuantizedAxis,
    decode, quantize_axis, scale_of,
};
pub(crate) use saved::check_structure;
pub use tree::{CwbvhFields, CwbvhTree};

use crate::image::{ImageError, MemoryImage, SharedTriangles};
use crate::observer::Observer;
use crate::validate::ValidationReport;
use crate::wide::cpu::{CpuBvh, SimdLevel};
use crate::wide::{Node8, WideBvh};
use crate::{Bvh2, NoObserver};
use dualsplit_geometry::{Aabb, Hit, Ray};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

/// A compressed BVH8: its memory image, counts, and the CPU-side copy the plain queries
/// traverse (made on first use).
#[derive(Clone, Debug)]
pub struct Cwbvh {
    image: MemoryImage,
    internal_nodes: usize,
    leaves: usize,
    time: Duration,
    cpu: OnceLock<Arc<CpuBvh>>,
}

/// How much quantization grows the child boxes (over every non-empty child slot).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct QuantizationStats {
    /// Child slots measured.
    pub children: usize,
    /// Of them, those whose exact box has zero or non-finite half area (not in the means).
    pub degenerate: usize,
    /// Mean of `half_area(decoded) / half_area(exact) − 1` (relative growth of the child
    /// boxes' surface area).
    pub mean_area_growth: f64,
    /// Largest such growth.
    pub max_area_growth: f64,
    /// Mean over children and axes of `(decoded extent − exact extent) / node extent`
    /// (growth of a child's extent in units of its parent's extent: at most about
    /// `2 / 255` per axis).
    pub mean_extent_growth: f64,
}

impl Cwbvh {
    /// Encodes the BVH8 `wide` (arity 8, from [`WideBvh::collapse_bvh8`] of `bvh`): the
    /// same nodes, children in slot order, the same leaves. `time` is the collapse time
    /// (the encode time is added to it).
    pub fn from_wide(
        wide: &WideBvh,
        bvh: &Bvh2,
        triangles: impl Into<SharedTriangles>,
        time: Duration,
    ) -> Result<Self, ImageError> {
        let t0 = std::time::Instant::now();
        let image = encode::encode(wide, &bvh.prim_ids, triangles.into())?;
        let time = time + t0.elapsed();
        Ok(Self {
            image,
            internal_nodes: wide.nodes.len().max(1),
            leaves: wide.leaf_count(),
            time,
            cpu: OnceLock::new(),
        })
    }

    /// Rebuilds from a memory image (a saved tree): runs [`Cwbvh::validate`]'s check and
    /// returns its report when the image is not valid. The time is zero (nothing was built).
    pub fn from_image(image: MemoryImage) -> Result<Self, ValidationReport> {
        let rep = validate::walk(&image).report;
        if !rep.is_ok() {
            return Err(rep);
        }
        Ok(Self {
            image,
            internal_nodes: rep.internal_nodes,
            leaves: rep.leaves,
            time: Duration::ZERO,
            cpu: OnceLock::new(),
        })
    }

    /// The byte-exact memory image.
    pub fn image(&self) -> &MemoryImage {
        &self.image
    }

    /// Internal nodes (80 bytes each).
    pub fn internal_nodes(&self) -> usize {
        self.internal_nodes
    }

    /// Leaves (index runs).
    pub fn leaves(&self) -> usize {
        self.leaves
    }

    /// Collapse plus encode time (a host measurement, not a result).
    pub fn time(&self) -> Duration {
        self.time
    }

    /// Bytes of nodes plus triangle-index runs: the quantity of the paper's Table 3.
    pub fn bytes_total(&self) -> u64 {
        self.image.node_bytes() + self.image.index_bytes()
    }

    /// The CPU-side copy ([`CpuBvh`], 8-lane nodes of the decoded boxes) for this CPU's best
    /// instructions, made on the first call.
    pub fn cpu(&self) -> &CpuBvh {
        self.cpu
            .get_or_init(|| Arc::new(self.cpu_copy(SimdLevel::detect())))
    }

    /// A new CPU-side copy using `level`'s instructions: the image decoded into a BVH8
    /// image of the decoded boxes, copied as [`crate::BvhImage::cpu_copy`] copies a BVH8.
    pub fn cpu_copy(&self, level: SimdLevel) -> CpuBvh {
        let (wide, prim_ids) = validate::decode_wide(&self.image);
        let img = crate::wide::encode::encode::<Node8>(
            &wide,
            &prim_ids,
            self.image.triangle_data.clone(),
        )
        .expect("a decoded compressed BVH8 fits the BVH8 layout");
        CpuBvh::with_level::<Node8>(&img, level)
    }

    /// Closest hit of `ray` (ordered by `(t, prim)`): through the CPU-side copy when `obs`
    /// observes nothing, else reading the image ([`Cwbvh::closest_hit_image`]). Both give
    /// the BVH2's answer bit for bit.
    #[inline]
    pub fn closest_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        if O::OBSERVES_NOTHING {
            return match self.cpu().traverse::<false>(ray) {
                Some(h) => h,
                None => self.declined_closest(ray),
            };
        }
        self.closest_hit_image(ray, obs)
    }

    /// True when any triangle is hit within `[ray.t_min, ray.t_max]`; like
    /// [`Cwbvh::closest_hit`], through the CPU-side copy when nothing is observed.
    #[inline]
    pub fn any_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        if O::OBSERVES_NOTHING {
            return match self.cpu().traverse::<true>(ray) {
                Some(h) => h.is_some(),
                None => self.declined_any(ray),
            };
        }
        self.any_hit_image(ray, obs)
    }

    /// The image traversal of a ray the CPU-side copy declines (NaN interval ends).
    #[cold]
    #[inline(never)]
    fn declined_closest(&self, ray: &Ray) -> Option<Hit> {
        self.closest_hit_image(ray, &mut NoObserver)
    }

    /// [`Cwbvh::declined_closest`] for shadow rays.
    #[cold]
    #[inline(never)]
    fn declined_any(&self, ray: &Ray) -> bool {
        self.any_hit_image(ray, &mut NoObserver)
    }

    /// Closest hit of `ray`, reading the image and reporting every fetch and step to `obs`.
    #[inline]
    pub fn closest_hit_image<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        traverse::traverse::<O, false>(&self.image, ray, obs)
    }

    /// True when any triangle is hit within `[ray.t_min, ray.t_max]`, reading the image.
    #[inline]
    pub fn any_hit_image<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        traverse::traverse::<O, true>(&self.image, ray, obs).is_some()
    }

    /// Checks the image (structure `cwbvh`): reachability, regions, meta bytes, triangle
    /// references, and that every decoded child box contains the exact bounds of its
    /// subtree's triangles (recomputed from the triangles).
    pub fn validate(&self) -> ValidationReport {
        validate::walk(&self.image).report
    }

    /// How much quantization grows the child boxes, decoded against the exact bounds of
    /// each child's triangles.
    pub fn quantization_stats(&self) -> QuantizationStats {
        let slots = validate::walk(&self.image).slots;
        let mut s = QuantizationStats {
            children: slots.len(),
            ..Default::default()
        };
        let (mut area_n, mut ext_n) = (0usize, 0usize);
        for sb in &slots {
            let (ad, ax) = (sb.decoded.half_area64(), sb.exact.half_area64());
            if ax > 0.0 && ax.is_finite() && ad.is_finite() {
                let g = ad / ax - 1.0;
                s.mean_area_growth += g;
                s.max_area_growth = s.max_area_growth.max(g);
                area_n += 1;
            } else {
                s.degenerate += 1;
            }
            for a in 0..3 {
                let extent = |b: &Aabb| b.max[a] as f64 - b.min[a] as f64;
                let n = extent(&sb.node);
                let g = (extent(&sb.decoded) - extent(&sb.exact)) / n;
                if n > 0.0 && g.is_finite() {
                    s.mean_extent_growth += g;
                    ext_n += 1;
                }
            }
        }
        if area_n > 0 {
            s.mean_area_growth /= area_n as f64;
        }
        if ext_n > 0 {
            s.mean_extent_growth /= ext_n as f64;
        }
        s
    }
}
