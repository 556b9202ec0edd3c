//! The plain queries' DST* decoder: the software traversal of `traverse.rs` step for step
//! (same nodes of the same image, same plane arithmetic, same stack and pop rule), without
//! an observer, with the ray's constants in arrays indexed by axis, near and far chosen by
//! selects rather than branches, and the triangles of the leaves read from a copy of the
//! index region's triangles in its order, four to a packet (one load per leaf instead of an
//! index entry and then a triangle per triangle). Leaves are tested by
//! [`crate::wide::cpu`]'s packet test, whose answers are [`dualsplit_geometry::Triangle::intersect`]'s.
//!
//! Used only when nothing is observed ([`crate::Observer::OBSERVES_NOTHING`]); the
//! simulator and every counting observer run `traverse.rs`.

use super::Dst;
use super::header::HeaderOffset;
use super::pipeline::le_or_nan;
use super::traverse::{Stack, dual_carve, split_next};
use crate::image::Pages;
use crate::wide::cpu::{PackedHit, RaySimd, TriPacket, avx2_token, pack_entries, test_leaf};
use crate::wide::simd::{Avx2, Kernel};
use dualsplit_geometry::{Aabb, Hit, Ray, cull_limit, widen_exit};
use std::sync::Arc;

impl Dst {
    /// The index region's triangles in its order, four to a packet: slot `i` holds the
    /// triangle of index entry `i` (made on the first call).
    fn packets(&self) -> &[TriPacket] {
        self.packets.get_or_init(|| {
            let img = &self.image;
            let mut packets = Vec::new();
            let mut slots = 0;
            pack_entries(
                &mut packets,
                &mut slots,
                img.words[img.indices.clone()].iter().copied(),
                img.triangle_slice(),
            );
            Arc::new(Pages::from_slice(&packets))
        })
    }

    /// Closest hit (`ANY = false`) or some hit (`ANY = true`) of `ray`; compiled for AVX2
    /// where the plain BVH queries use it
    /// ([`crate::wide::cpu::SimdLevel::detect`]), the same answers.
    #[inline]
    pub(super) fn traverse_fast<const ANY: bool>(&self, ray: &Ray) -> Option<Hit> {
        self.query().traverse::<ANY>(ray)
    }

    /// A query context for tracing rays one by one with the plain decoder ([`DstQuery`]).
    pub fn query(&self) -> DstQuery<'_> {
        DstQuery {
            words: &self.image.words[..],
            packets: self.packets(),
            scene_box: self.scene_box,
            empty: self.is_empty(),
            avx2: avx2_token(),
        }
    }
}

/// A query context over a [`Dst`] for its plain decoder: the image's words, the
/// leaf-ordered triangle packets and the instruction set, found once rather than per ray
/// (the DST counterpart of [`crate::BvhQuery`]; [`Dst::closest_hit`] and [`Dst::any_hit`]
/// with a [`crate::NoObserver`] give the same answers). Made by [`Dst::query`].
#[derive(Clone, Copy)]
pub struct DstQuery<'a> {
    words: &'a [u32],
    packets: &'a [TriPacket],
    scene_box: Aabb,
    empty: bool,
    avx2: Option<Avx2>,
}

impl DstQuery<'_> {
    /// Closest hit of `ray` (ordered by `(t, prim)`).
    #[inline]
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.traverse::<false>(ray)
    }

    /// True when `ray` hits any triangle within `[t_min, t_max]`.
    #[inline]
    pub fn any_hit(&self, ray: &Ray) -> bool {
        self.traverse::<true>(ray).is_some()
    }

    #[inline(always)]
    fn traverse<const ANY: bool>(&self, ray: &Ray) -> Option<Hit> {
        // Untraceable rays miss (`Ray::is_traceable`), in every structure alike.
        if !ray.is_traceable() {
            return None;
        }
        match self.avx2 {
            Some(t) => t.vectorize(Fast::<ANY> { q: self, ray }).unpack(),
            None => self.fast::<ANY>(ray),
        }
    }

    #[inline(always)]
    fn fast<const ANY: bool>(&self, ray: &Ray) -> Option<Hit> {
        if self.empty {
            return None;
        }
        let r = ray.precompute();
        let b = self.scene_box;
        let (mut t_min, mut t_max) = r.slab(b.min, b.max, ray.t_min, cull_limit(ray.t_max));
        if t_min > t_max {
            return None;
        }
        let (words, packets) = (self.words, self.packets);
        let rs = RaySimd::new(&r);
        let o = r.ray.origin.to_array();
        let inv = r.inv_dir.to_array();
        let neg = r.neg;
        // `(p - o[a]) * inv[a]`: `RayPre::plane_t`.
        let plane_t = |a: usize, p: f32| (p - o[a]) * inv[a];
        let mut best: Option<Hit> = None;
        let mut best_t = ray.t_max;
        let mut stack = Stack::new();
        let mut node = 0u32;
        loop {
            let at = node as usize;
            let w = HeaderOffset::from_bits(words[at]);
            // `Some(first)` when the node ends in a triangle run; `None` when it pops.
            let run = if !w.is_carving() {
                if w.is_leaf_flag() {
                    Some(w.offset())
                } else {
                    // Splitting node: t1 where the ray leaves the near child's half-space
                    // (exit role, widened), t2 where it enters the far one.
                    let a = w.axis();
                    let (p0, p1) = (f32::from_bits(words[at + 1]), f32::from_bits(words[at + 2]));
                    let left = w.offset();
                    let right = left + w.left_size();
                    let s = neg[a];
                    let (pn, pf) = if s { (p1, p0) } else { (p0, p1) };
                    let (near, far) = if s { (right, left) } else { (left, right) };
                    let t1 = widen_exit(plane_t(a, pn));
                    let t2 = plane_t(a, pf);
                    let near_hit = le_or_nan(t_min, t1);
                    let far_hit = le_or_nan(t2, t_max);
                    let (push, next) =
                        split_next(near_hit, far_hit, (near, far), (t1, t2), t_min, t_max);
                    if let Some(e) = push {
                        stack.push(e);
                    }
                    match next {
                        Some((n, lo, hi)) => {
                            (node, t_min, t_max) = (n, lo, hi);
                            continue;
                        }
                        None => None,
                    }
                }
            } else {
                let (p0, p1) = (f32::from_bits(words[at + 1]), f32::from_bits(words[at + 2]));
                let (lo, hi) = if !w.is_dual() {
                    // Single-axis carving: the exit plane after the sign swap (widened)
                    // clamps t_max, the entry plane raises t_min.
                    let a = w.axis();
                    let s = neg[a];
                    let (pe, pn) = if s { (p1, p0) } else { (p0, p1) };
                    (
                        t_min.max(plane_t(a, pn)),
                        t_max.min(widen_exit(plane_t(a, pe))),
                    )
                } else {
                    let (a0, a1) = w.axis_pair().axes();
                    dual_carve(&neg, w, (plane_t(a0, p0), plane_t(a1, p1)), t_min, t_max)
                };
                if le_or_nan(lo, hi) {
                    t_min = lo;
                    t_max = hi;
                    if !w.is_leaf_flag() {
                        node = w.offset();
                        continue;
                    }
                    Some(w.offset())
                } else {
                    None
                }
            };
            if let Some(first) = run
                && test_leaf::<ANY>(
                    // Some exactly when this runs inside `vectorize` (`traverse`).
                    self.avx2,
                    packets,
                    first as usize,
                    &rs,
                    &r,
                    &mut best,
                    &mut best_t,
                )
            {
                return best;
            }
            // Pop the next entry that can still hold a closer hit, clamping its t_max.
            let limit = cull_limit(best_t);
            loop {
                let Some(e) = stack.pop() else {
                    return best;
                };
                if le_or_nan(e.t_min, limit) {
                    (node, t_min, t_max) = (e.node, e.t_min, e.t_max.min(limit));
                    break;
                }
            }
        }
    }
}

/// [`DstQuery::fast`] as a [`Kernel`], to run compiled for AVX2.
struct Fast<'a, const ANY: bool> {
    q: &'a DstQuery<'a>,
    ray: &'a Ray,
}

impl<const ANY: bool> Kernel for Fast<'_, ANY> {
    type Output = PackedHit;
    #[inline(always)]
    fn call(self) -> PackedHit {
        PackedHit::pack(self.q.fast::<ANY>(self.ray))
    }
}
