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
use crate::wide::simd::Kernel;
use dualsplit_geometry::{Hit, Ray, cull_limit, widen_exit};
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
        match avx2_token() {
            Some(t) => t.vectorize(Fast::<ANY> { dst: self, ray }).unpack(),
            None => self.fast::<ANY>(ray),
        }
    }

    #[inline(always)]
    fn fast<const ANY: bool>(&self, ray: &Ray) -> Option<Hit> {
        if self.is_empty() {
            return None;
        }
        let r = ray.precompute();
        let b = self.scene_box;
        let (mut t_min, mut t_max) = r.slab(b.min, b.max, ray.t_min, cull_limit(ray.t_max));
        if t_min > t_max {
            return None;
        }
        let words = &self.image.words[..];
        let packets = self.packets();
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
                && test_leaf::<ANY>(packets, first as usize, &rs, &r, &mut best, &mut best_t)
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

/// [`Dst::traverse_fast`]'s body as a [`Kernel`], to run compiled for AVX2.
struct Fast<'a, const ANY: bool> {
    dst: &'a Dst,
    ray: &'a Ray,
}

impl<const ANY: bool> Kernel for Fast<'_, ANY> {
    type Output = PackedHit;
    #[inline(always)]
    fn call(self) -> PackedHit {
        PackedHit::pack(self.dst.fast::<ANY>(self.ray))
    }
}
