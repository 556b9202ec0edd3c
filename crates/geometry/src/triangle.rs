use crate::{Aabb, RayPre};
use glam::Vec3;

/// A triangle stored as its three vertices: 36 bytes, the layout of the triangle region of
/// every memory image (9 × f32: v0.xyz, v1.xyz, v2.xyz).
#[derive(Clone, Copy, Debug, PartialEq, Default, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Triangle {
    /// The vertices in order; the geometric normal is `(v1 - v0) × (v2 - v0)`.
    pub v: [Vec3; 3],
}

const _: () = assert!(std::mem::size_of::<Triangle>() == 36);

/// The result of a successful ray–triangle test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter.
    pub t: f32,
    /// Barycentric weight of `v[1]`.
    pub u: f32,
    /// Barycentric weight of `v[2]`.
    pub v: f32,
}

impl Triangle {
    /// A triangle from three vertices.
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Self {
        Self { v: [a, b, c] }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        Aabb::new(
            self.v[0].min(self.v[1]).min(self.v[2]),
            self.v[0].max(self.v[1]).max(self.v[2]),
        )
    }

    /// Centroid.
    pub fn centroid(&self) -> Vec3 {
        (self.v[0] + self.v[1] + self.v[2]) * (1.0 / 3.0)
    }

    /// Unnormalised geometric normal `(v1 - v0) × (v2 - v0)`.
    pub fn normal(&self) -> Vec3 {
        (self.v[1] - self.v[0]).cross(self.v[2] - self.v[0])
    }

    /// True when the triangle has zero area (collinear or coincident vertices).
    pub fn is_degenerate(&self) -> bool {
        self.normal() == Vec3::ZERO
    }

    /// True when every coordinate is finite.
    pub fn is_finite(&self) -> bool {
        self.v.iter().all(|p| p.is_finite())
    }

    /// Watertight ray–triangle intersection (Woop, Benthin, Wald 2013, JCGT 2(1)), two-sided.
    ///
    /// Returns a hit when the ray meets the triangle at `t` with `t_lo <= t <= t_hi`. Edge
    /// functions that evaluate to exactly zero are recomputed in double precision, so a ray
    /// through an edge shared by two triangles hits at least one of them, never neither.
    /// Degenerate (zero-area) triangles are never hit, nor are triangles whose edge functions
    /// underflow (a determinant below 2^-128 in magnitude: the ray's distance to the
    /// triangle dwarfs the triangle by a factor of about 1e26 or more).
    #[inline]
    pub fn intersect(&self, r: &RayPre, t_lo: f32, t_hi: f32) -> Option<TriangleHit> {
        let [kx, ky, kz] = r.k;
        let o = r.ray.origin;
        let a = self.v[0] - o;
        let b = self.v[1] - o;
        let c = self.v[2] - o;
        let (sx, sy) = (r.shear.x, r.shear.y);
        let ax = a[kx] - sx * a[kz];
        let ay = a[ky] - sy * a[kz];
        let bx = b[kx] - sx * b[kz];
        let by = b[ky] - sy * b[kz];
        let cx = c[kx] - sx * c[kz];
        let cy = c[ky] - sy * c[kz];
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let (ax, ay, bx, by, cx, cy) = (
                ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64,
            );
            u = (cx * by - cy * bx) as f32;
            v = (ax * cy - ay * cx) as f32;
            w = (bx * ay - by * ax) as f32;
        }
        self.intersect_from_edges(r, [u, v, w], t_lo, t_hi)
    }

    /// The rest of [`Triangle::intersect`] once its edge functions `[u, v, w]` are known (as
    /// it computes them, zeros recomputed in f64): the sign test, the determinant, `t` and
    /// its range, the barycentrics. A SIMD caller that computed the edge functions of several
    /// triangles with the same operations finishes each here with the same answer.
    #[inline]
    pub fn intersect_from_edges(
        &self,
        r: &RayPre,
        [u, v, w]: [f32; 3],
        t_lo: f32,
        t_hi: f32,
    ) -> Option<TriangleHit> {
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        // A determinant whose reciprocal overflows (|det| below 2^-128) means the edge
        // functions have underflowed: they no longer say where the ray passes (a triangle
        // ~1e26 times smaller than its distance from the origin can then "hit" a ray that
        // misses its box), and the barycentrics would be NaN or infinite. No hit.
        let inv_det = 1.0 / det;
        if det == 0.0 || !det.is_finite() || !inv_det.is_finite() {
            return None;
        }
        let t = self.plane_t(r);
        if !t.is_finite() || t < t_lo || t > t_hi {
            return None;
        }
        Some(TriangleHit {
            t,
            u: v * inv_det,
            v: w * inv_det,
        })
    }

    /// Where the ray meets the triangle's plane, in f64, rounded once to f32.
    ///
    /// The watertight test decides *whether* the ray hits; this gives *where*. Woop et al.'s
    /// f32 `t = Σ eᵢ·zᵢ / Σ eᵢ` loses digits to cancellation when the vertices lie far apart
    /// along the ray (a floor seen at a grazing angle, a ray leaving one large triangle for
    /// another): relative errors of 1e-5 and worse. Here `t = n·(v0 − o) / n·d` with
    /// `n = (v1 − v0) × (v2 − v0)` in f64, where the differences and products of f32
    /// coordinates are exact or nearly so.
    ///
    /// The direction is taken from the test's own constants, not from `ray.dir`:
    /// `d = d[kz]·(Sx, Sy, 1)` on the axes `(kx, ky, kz)` and `1/d[kz] = Sz`, so
    /// `t = Sz · n·(v0 − o) / (n[kx]·Sx + n[ky]·Sy + n[kz])`. The simulated hardware holds
    /// only the origin, the axes and the shear constants (its ray registers), and computes
    /// the same bits. ±∞ or NaN when the ray is parallel to the plane (in f64).
    #[inline]
    fn plane_t(&self, r: &RayPre) -> f32 {
        let f = |p: Vec3| [p.x as f64, p.y as f64, p.z as f64];
        let [p0, p1, p2] = self.v.map(f);
        let o = f(r.ray.origin);
        let e1 = [p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]];
        let e2 = [p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]];
        let n = [
            e1[1] * e2[2] - e1[2] * e2[1],
            e1[2] * e2[0] - e1[0] * e2[2],
            e1[0] * e2[1] - e1[1] * e2[0],
        ];
        let w = [p0[0] - o[0], p0[1] - o[1], p0[2] - o[2]];
        let num = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
        let [kx, ky, kz] = r.k;
        let den = n[kx] * r.shear.x as f64 + n[ky] * r.shear.y as f64 + n[kz];
        (num / den * r.shear.z as f64) as f32
    }
}
