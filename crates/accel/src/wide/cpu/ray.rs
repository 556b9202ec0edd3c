//! The ray's constants in SIMD registers and the 4-wide tests: the slab test of four boxes
//! and the first stage of the watertight test on a packet of four triangles.

use super::layout::{LANES, TriPacket};
use crate::wide::simd::{Avx2, PlaneRows8};
#[cfg(doc)]
use dualsplit_geometry::Triangle;
use dualsplit_geometry::{EXIT_WIDEN, Ray, RayPre, Vec3};
use wide::{CmpEq, CmpGt, CmpLe, CmpLt, f32x4};

/// What [`RaySimd::triangle_edges`] finds for the four triangles of a packet.
pub(super) struct Edges {
    pub(super) u: [f32; LANES],
    pub(super) v: [f32; LANES],
    pub(super) w: [f32; LANES],
    /// Lanes with an edge function equal to zero.
    pub(super) zero: u32,
    /// Lanes [`Triangle::intersect`] might accept.
    pub(super) candidates: u32,
}

/// What [`RaySimd::complete`] finds for the four triangles of a packet: the rest of
/// [`Triangle::intersect_from_edges`] but the comparison of `t` with the range's end.
pub(super) struct Completed {
    /// The distance to each triangle's plane, as [`Triangle::intersect`] computes it.
    pub(super) t: [f32; LANES],
    /// The barycentrics a hit reports.
    pub(super) u: [f32; LANES],
    pub(super) v: [f32; LANES],
    /// Lanes that pass the sign test and the determinant's checks, with a finite `t` not
    /// below the range's start: hits wherever `t` is not above the range's end.
    pub(super) ok: u32,
}

/// An axis, x, y or z: an index below 3 by its type, so that indexing a vertex's
/// coordinates with it needs no bounds check.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(super) enum Axis {
    /// x (0).
    X,
    /// y (1).
    Y,
    /// z (2).
    Z,
}

impl Axis {
    /// Axis `a` (below 3).
    #[inline(always)]
    fn new(a: usize) -> Self {
        match a {
            0 => Self::X,
            1 => Self::Y,
            _ => Self::Z,
        }
    }
}

/// The ray's constants broadcast to all lanes, the plane rows its signs pick, and the
/// watertight test's axes and shear.
///
/// The box tests take the negated reciprocal `-inv` and compute a plane distance as
/// `(o - p) * -inv`: IEEE subtraction and multiplication are symmetric in sign, so that is
/// `(p - o) * inv` bit for bit, except where `p` and `o` are the same number: both
/// differences are `+0` then, so the distance is the zero of the other sign (or NaN in both
/// forms when `inv` is infinite), which every comparison treats as equal. With the plane as the
/// subtrahend, its load from the node is an operand of the subtraction (x86 reads memory
/// only for the second operand), one instruction fewer per plane.
pub(crate) struct RaySimd {
    pub(super) o: [f32x4; 3],
    /// `-inv_dir` per axis.
    pub(super) neg_inv: [f32x4; 3],
    /// The origin and negated reciprocal direction as scalars.
    pub(super) os: [f32; 3],
    pub(super) neg_invs: [f32; 3],
    /// `-inv_dir * EXIT_WIDEN` per axis, broadcast and as scalars: far planes give
    /// `(o - p) * (-inv * EXIT_WIDEN)`, the exit widened in the pre-multiplied form (see
    /// the [`super`] module docs).
    pub(super) neg_inv_w: [f32x4; 3],
    pub(super) neg_inv_ws: [f32; 3],
    /// Plane rows of the near and far planes per axis.
    pub(super) near: [usize; 3],
    pub(super) far: [usize; 3],
    /// The same rows of a BVH8 node, for [`Avx2::slab8`].
    pub(super) rows8: PlaneRows8,
    /// The watertight test's axes `(kx, ky, kz)`.
    pub(super) k: [Axis; 3],
    /// The origin's coordinates on those axes, `o[kx]`, `o[ky]`, `o[kz]`, broadcast.
    pub(super) ok: [f32x4; 3],
    pub(super) sx: f32x4,
    pub(super) sy: f32x4,
}

impl RaySimd {
    /// The constants of the precomputed ray `r`.
    #[inline(always)]
    pub(crate) fn new(r: &RayPre) -> Self {
        let o = r.ray.origin;
        let inv = r.inv_dir;
        let s = |a: usize| 3 * r.neg[a] as usize;
        let o4 = [f32x4::splat(o.x), f32x4::splat(o.y), f32x4::splat(o.z)];
        let k = r.k.map(Axis::new);
        Self {
            o: o4,
            neg_inv: [
                f32x4::splat(-inv.x),
                f32x4::splat(-inv.y),
                f32x4::splat(-inv.z),
            ],
            os: [o.x, o.y, o.z],
            neg_invs: [-inv.x, -inv.y, -inv.z],
            neg_inv_w: [
                f32x4::splat(-inv.x * EXIT_WIDEN),
                f32x4::splat(-inv.y * EXIT_WIDEN),
                f32x4::splat(-inv.z * EXIT_WIDEN),
            ],
            neg_inv_ws: [
                -inv.x * EXIT_WIDEN,
                -inv.y * EXIT_WIDEN,
                -inv.z * EXIT_WIDEN,
            ],
            near: [s(0), 1 + s(1), 2 + s(2)],
            far: [3 - s(0), 4 - s(1), 5 - s(2)],
            rows8: PlaneRows8::new(r.neg),
            k,
            ok: k.map(|a| o4[a as usize]),
            sx: f32x4::splat(r.shear.x),
            sy: f32x4::splat(r.shear.y),
        }
    }

    /// The box test's constants of `ray` alone, for a shadow ray that has met no leaf yet
    /// (the traversal's first phase): the reciprocal and signs as [`RayPre::new`] computes
    /// them; the watertight test's fields hold axes x, y, z and no shear, not the ray's, and
    /// no box test reads them.
    #[inline(always)]
    pub(super) fn boxes(ray: &Ray) -> Self {
        Self::new(&RayPre {
            ray: *ray,
            inv_dir: RayPre::reciprocal(ray.dir),
            neg: RayPre::signs(ray.dir),
            k: [0, 1, 2],
            shear: Vec3::ZERO,
        })
    }

    /// The first stage of [`Triangle::intersect`] (shear, edge functions `u`, `v`, `w`, the
    /// same IEEE operations in the same order on the negated relative coordinates, which
    /// give the same bits wherever an edge function is not zero) on the four triangles of
    /// `pk` at once: the
    /// edge functions, the lanes where one of them is zero (the scalar test recomputes
    /// those in f64), and the lanes the scalar test might accept: all but those where no
    /// edge function is zero and their signs differ, which it rejects at that stage.
    #[inline(always)]
    pub(super) fn triangle_edges(&self, pk: &TriPacket) -> Edges {
        let [kx, ky, kz] = self.k.map(|a| a as usize);
        let [ox, oy, oz] = self.ok;
        // The vertices relative to the origin negated, `o - p` (so that the packet's row is
        // the subtraction's memory operand): `-(p - o)` bit for bit but for the sign of a
        // zero, so the sheared coordinates are too, and every edge function, a difference
        // of products of two of them, is the scalar test's bits wherever it is not zero
        // (zero lanes go to the scalar test, which recomputes them).
        let rel = |vertex: usize, axis: usize, o: f32x4| o - f32x4::new(pk.v[3 * vertex + axis]);
        let (ax, ay, az) = (rel(0, kx, ox), rel(0, ky, oy), rel(0, kz, oz));
        let (bx, by, bz) = (rel(1, kx, ox), rel(1, ky, oy), rel(1, kz, oz));
        let (cx, cy, cz) = (rel(2, kx, ox), rel(2, ky, oy), rel(2, kz, oz));
        let ax = ax - self.sx * az;
        let ay = ay - self.sy * az;
        let bx = bx - self.sx * bz;
        let by = by - self.sy * bz;
        let cx = cx - self.sx * cz;
        let cy = cy - self.sy * cz;
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = f32x4::splat(0.0);
        let any_zero = (u.cmp_eq(zero) | v.cmp_eq(zero) | w.cmp_eq(zero)).move_mask() as u32;
        // Some edge function negative and some positive: `keep_min` and `keep_max` return
        // one of their arguments, so a negative smallest or positive largest is one of the
        // three (a NaN one may be passed over, which can only keep a lane).
        let neg = keep_min(u, keep_min(v, w)).cmp_lt(zero);
        let pos = keep_max(u, keep_max(v, w)).cmp_gt(zero);
        let reject = (neg & pos).move_mask() as u32 & !any_zero;
        Edges {
            u: u.to_array(),
            v: v.to_array(),
            w: w.to_array(),
            zero: any_zero,
            candidates: 0b1111 & !reject,
        }
    }

    /// [`Triangle::intersect_from_edges`] on the four lanes of `pk` from the edge functions
    /// `e` (lanes with an edge function equal to zero excepted: the scalar test recomputes
    /// those in f64), but for the comparison of `t` with the range's end, which the caller
    /// makes as its closest hit moves: the same sign test, determinant, reciprocal and
    /// checks in f32 lane by lane, and `t` from [`Avx2::plane_t4`], the scalar test's f64
    /// arithmetic on four lanes. IEEE operations lane by lane are the scalar ones, so every
    /// lane's answer is the scalar test's bits.
    #[inline(always)]
    pub(super) fn complete(
        &self,
        avx2: Avx2,
        pk: &TriPacket,
        e: &Edges,
        r: &RayPre,
        t_lo: f32,
    ) -> Completed {
        let o = r.ray.origin;
        let t = f32x4::new(avx2.plane_t4(
            &pk.v,
            [o.x, o.y, o.z],
            r.k,
            [r.shear.x, r.shear.y, r.shear.z],
        ));
        let (u, v, w) = (f32x4::new(e.u), f32x4::new(e.v), f32x4::new(e.w));
        let zero = f32x4::splat(0.0);
        // `(u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)` rejects; a NaN compares
        // false, as in the scalar test.
        let neg = u.cmp_lt(zero) | v.cmp_lt(zero) | w.cmp_lt(zero);
        let pos = u.cmp_gt(zero) | v.cmp_gt(zero) | w.cmp_gt(zero);
        let det = u + v + w;
        let inv_det = f32x4::splat(1.0) / det;
        // `|x| < ∞` exactly when `x` is finite (a NaN compares false).
        let finite = |x: f32x4| x.abs().cmp_lt(f32x4::splat(f32::INFINITY));
        let det_ok = !det.cmp_eq(zero) & finite(det) & finite(inv_det);
        // `t < t_lo` rejects: a NaN start rejects nothing, as in the scalar test.
        let t_ok = finite(t) & !t.cmp_lt(f32x4::splat(t_lo));
        let ok = (!(neg & pos) & det_ok & t_ok).move_mask() as u32;
        Completed {
            t: t.to_array(),
            u: (v * inv_det).to_array(),
            v: (w * inv_det).to_array(),
            ok,
        }
    }

    /// Entry distances of four boxes (`planes[p][lane]`) clipped to `[t_lo, t_hi]`, and the mask of
    /// the lanes the ray meets (`entry <= exit`; an empty lane's box, min `+∞` and max `−∞`,
    /// has none for a finite origin and direction). Plane distances are `(o - p) * -inv`
    /// (see [`RaySimd`]), far ones `(o - p) * (-inv * EXIT_WIDEN)`.
    #[inline(always)]
    pub(super) fn test(&self, planes: &[[f32; LANES]; 6], t_lo: f32, t_hi: f32) -> (f32x4, u32) {
        self.test_rows(|p| planes[p], t_lo, t_hi)
    }

    /// [`RaySimd::test`] with plane `p`'s row given by `row(p)`.
    #[inline(always)]
    pub(super) fn test_rows(
        &self,
        row: impl Fn(usize) -> [f32; LANES],
        t_lo: f32,
        t_hi: f32,
    ) -> (f32x4, u32) {
        let mut entry = f32x4::splat(t_lo);
        let mut exit = f32x4::splat(t_hi);
        for a in 0..3 {
            let tn = (self.o[a] - f32x4::new(row(self.near[a]))) * self.neg_inv[a];
            let tf = (self.o[a] - f32x4::new(row(self.far[a]))) * self.neg_inv_w[a];
            entry = keep_max(tn, entry);
            exit = keep_min(tf, exit);
        }
        (entry, entry.cmp_le(exit).move_mask() as u32)
    }
}

/// Whether SSE's `maxps`/`minps` are available: `maxps x, b` is exactly
/// `x > b ? x : b` and `minps x, b` is `x < b ? x : b` (`wide`'s `fast_max`/`fast_min` use
/// them where SSE is on), one instruction where the portable form takes a compare and a blend.
const SSE: bool = cfg!(all(
    any(target_arch = "x86", target_arch = "x86_64"),
    target_feature = "sse"
));

/// `if x > bound { x } else { bound }` per lane: a NaN `x` keeps the bound.
#[inline(always)]
pub(super) fn keep_max(x: f32x4, bound: f32x4) -> f32x4 {
    if SSE {
        x.fast_max(bound)
    } else {
        keep_max_portable(x, bound)
    }
}

/// [`keep_max`] by compare and blend, on any target.
#[inline(always)]
pub(super) fn keep_max_portable(x: f32x4, bound: f32x4) -> f32x4 {
    x.cmp_gt(bound).blend(x, bound)
}

/// `if x < bound { x } else { bound }` per lane: a NaN `x` keeps the bound.
#[inline(always)]
pub(super) fn keep_min(x: f32x4, bound: f32x4) -> f32x4 {
    if SSE {
        x.fast_min(bound)
    } else {
        keep_min_portable(x, bound)
    }
}

/// [`keep_min`] by compare and blend, on any target.
#[inline(always)]
pub(super) fn keep_min_portable(x: f32x4, bound: f32x4) -> f32x4 {
    x.cmp_lt(bound).blend(x, bound)
}
