//! Agreement between two answers to the same ray: ours and a peer's (Embree's).
//!
//! Two correct tracers may still name different triangles, for reasons that are not errors:
//!
//! * **Tie**: both triangles are hit at the same `t` (a ray through a shared edge or vertex,
//!   duplicated coplanar faces). dualsplit's rule gives such a ray to the smaller triangle
//!   id; Embree gives it to whichever triangle its traversal meets first.
//! * **Grazing**: the ray passes within a hair of a triangle's edge, or nearly in its plane
//!   (thin triangles seen edge-on). There the two ray–triangle tests round differently:
//!   dualsplit's is watertight (Woop et al. 2013), Embree's default is not.
//! * **Boundary**: the hit lies at an end of the ray's `[t_min, t_max]` interval, where the
//!   two tests' roundings of `t` decide whether it counts.
//!
//! [`classify`] decides, from the triangles' geometry in f64, which of these explains a
//! difference; a difference none of them explains is [`Verdict::Unexplained`].

use dualsplit_geometry::{Hit, Ray, Triangle};

/// Relative difference in `t` under which two hits count as a tie (both triangles meet
/// the ray at the same point, up to the peer's f32 rounding).
pub const TIE_REL: f64 = 1e-5;
/// A hit whose smallest f64 barycentric is below this is on an edge.
pub const EDGE_BARY: f64 = 1e-4;
/// A ray whose direction makes a cosine below this with the triangle's normal is grazing
/// its plane.
pub const PLANE_COS: f64 = 1e-3;
/// Relative distance of a hit's `t` to `t_min` or `t_max` under which it is at the boundary.
pub const BOUNDARY_REL: f64 = 1e-4;

/// How two answers to one ray compare.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Both miss, or both hit the same triangle.
    Same,
    /// Different triangles (or hit against miss) at the same `t`.
    Tie,
    /// A hit on a triangle's edge or nearly in its plane.
    Grazing,
    /// A hit at an end of the ray's interval.
    Boundary,
    /// None of the above: one of the tracers is wrong.
    Unexplained,
}

/// The ray's intersection with a triangle's plane, in f64: `t`, the barycentrics
/// `(w, u, v)` (weights of `v0`, `v1`, `v2`) and the cosine between the ray and the normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneHit {
    /// Ray parameter.
    pub t: f64,
    /// Smallest of the three barycentrics (negative outside the triangle).
    pub min_bary: f64,
    /// `|cos|` of the angle between the ray direction and the triangle's normal.
    pub cos: f64,
}

/// The ray's intersection with `tri`'s plane in f64 (Möller–Trumbore without the inside
/// test), or `None` when the ray is parallel to the plane or the triangle is degenerate.
pub fn plane_hit(tri: &Triangle, ray: &Ray) -> Option<PlaneHit> {
    let f = |v: dualsplit_geometry::Vec3| [v.x as f64, v.y as f64, v.z as f64];
    let (o, d) = (f(ray.origin), f(ray.dir));
    let [v0, v1, v2] = tri.v.map(f);
    let e1 = sub(v1, v0);
    let e2 = sub(v2, v0);
    let p = cross(d, e2);
    let det = dot(e1, p);
    let n = cross(e1, e2);
    let scale = norm(d) * norm(n);
    if det == 0.0 || scale == 0.0 || !det.is_finite() {
        return None;
    }
    let s = sub(o, v0);
    let u = dot(s, p) / det;
    let q = cross(s, e1);
    let v = dot(d, q) / det;
    let t = dot(e2, q) / det;
    Some(PlaneHit {
        t,
        min_bary: u.min(v).min(1.0 - u - v),
        cos: (det / scale).abs(),
    })
}

/// Whether a hit on `tri` is grazing ([`EDGE_BARY`], [`PLANE_COS`]).
fn grazing(tri: &Triangle, ray: &Ray) -> bool {
    match plane_hit(tri, ray) {
        None => true,
        Some(h) => h.min_bary < EDGE_BARY || h.cos < PLANE_COS,
    }
}

fn boundary(t: f32, ray: &Ray) -> bool {
    let near = |a: f32, b: f32| {
        let (a, b) = (a as f64, b as f64);
        b.is_finite() && (a - b).abs() <= BOUNDARY_REL * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
    };
    near(t, ray.t_min) || near(t, ray.t_max)
}

/// Compares our closest hit with the peer's for `ray` over `tris` (the triangles both
/// were built from). For shadow rays, pass each side's closest hit on the segment when
/// their occlusion answers differ.
///
/// Hits with the same triangle are [`Verdict::Same`] whatever their `t`. Otherwise, in
/// order: [`Verdict::Tie`] when both hit and their f64 plane distances agree to
/// [`TIE_REL`]; [`Verdict::Grazing`] when either hit is grazing; [`Verdict::Boundary`] when
/// either hit is at an end of the ray's interval; else [`Verdict::Unexplained`]. A hit
/// naming a triangle outside `tris` is unexplained.
pub fn classify(tris: &[Triangle], ray: &Ray, ours: Option<Hit>, peer: Option<Hit>) -> Verdict {
    let tri = |h: &Hit| tris.get(h.prim.index());
    match (ours, peer) {
        (None, None) => Verdict::Same,
        (Some(a), Some(b)) if a.prim == b.prim => Verdict::Same,
        (Some(a), Some(b)) => {
            let (Some(ta), Some(tb)) = (tri(&a), tri(&b)) else {
                return Verdict::Unexplained;
            };
            let tie = match (plane_hit(ta, ray), plane_hit(tb, ray)) {
                (Some(pa), Some(pb)) => (pa.t - pb.t).abs() <= TIE_REL * pa.t.abs().max(pb.t.abs()),
                _ => false,
            };
            if tie {
                Verdict::Tie
            } else if grazing(ta, ray) || grazing(tb, ray) {
                Verdict::Grazing
            } else if boundary(a.t, ray) || boundary(b.t, ray) {
                Verdict::Boundary
            } else {
                Verdict::Unexplained
            }
        }
        (Some(h), None) | (None, Some(h)) => {
            let Some(t) = tri(&h) else {
                return Verdict::Unexplained;
            };
            if grazing(t, ray) {
                Verdict::Grazing
            } else if boundary(h.t, ray) {
                Verdict::Boundary
            } else {
                Verdict::Unexplained
            }
        }
    }
}

/// Differences of one kind, by [`Verdict`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Differences {
    /// Explained as ties.
    pub tie: u64,
    /// Explained as grazing hits.
    pub grazing: u64,
    /// Explained as hits at an end of the interval.
    pub boundary: u64,
    /// Not explained.
    pub unexplained: u64,
}

impl Differences {
    /// All differences.
    pub fn total(&self) -> u64 {
        self.tie + self.grazing + self.boundary + self.unexplained
    }

    fn add(&mut self, v: Verdict) {
        match v {
            Verdict::Same => {}
            Verdict::Tie => self.tie += 1,
            Verdict::Grazing => self.grazing += 1,
            Verdict::Boundary => self.boundary += 1,
            Verdict::Unexplained => self.unexplained += 1,
        }
    }

    fn merge(&mut self, o: &Differences) {
        self.tie += o.tie;
        self.grazing += o.grazing;
        self.boundary += o.boundary;
        self.unexplained += o.unexplained;
    }
}

/// The agreement of a set of rays.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Agreement {
    /// Rays compared.
    pub rays: u64,
    /// Rays with the same answer (both miss, or the same triangle; for shadow rays, the same
    /// occlusion).
    pub same: u64,
    /// One side hit, the other missed.
    pub hit_miss: Differences,
    /// Both hit, different triangles.
    pub triangle: Differences,
    /// Largest relative difference of `t` among hits on the same triangle (closest-hit
    /// rays only).
    pub max_t_rel_diff: f64,
}

impl Agreement {
    /// Records one closest-hit ray.
    pub fn record_closest(
        &mut self,
        tris: &[Triangle],
        ray: &Ray,
        ours: Option<Hit>,
        peer: Option<Hit>,
    ) {
        self.rays += 1;
        let v = classify(tris, ray, ours, peer);
        match (ours, peer) {
            (Some(a), Some(b)) if a.prim == b.prim => {
                let d = ((a.t as f64 - b.t as f64) / (a.t as f64)).abs();
                if d.is_finite() {
                    self.max_t_rel_diff = self.max_t_rel_diff.max(d);
                }
            }
            _ => {}
        }
        match (ours.is_some(), peer.is_some(), v) {
            (_, _, Verdict::Same) => self.same += 1,
            (true, true, v) => self.triangle.add(v),
            (_, _, v) => self.hit_miss.add(v),
        }
    }

    /// Records one shadow ray whose occlusion answers were `ours` and `peer`; `closest` gives
    /// (our closest hit, the peer's) on the segment and is called only when they differ.
    pub fn record_occluded(
        &mut self,
        tris: &[Triangle],
        ray: &Ray,
        ours: bool,
        peer: bool,
        closest: impl FnOnce() -> (Option<Hit>, Option<Hit>),
    ) {
        self.rays += 1;
        if ours == peer {
            self.same += 1;
            return;
        }
        let (a, b) = closest();
        // A side that said "occluded" but finds no closest hit (or the reverse) is
        // inconsistent with itself: unexplained.
        let v = if a.is_some() == ours && b.is_some() == peer {
            classify(tris, ray, a, b)
        } else {
            Verdict::Unexplained
        };
        self.hit_miss.add(if v == Verdict::Same {
            Verdict::Unexplained
        } else {
            v
        });
    }

    /// Adds another set's counts.
    pub fn merge(&mut self, o: &Agreement) {
        self.rays += o.rays;
        self.same += o.same;
        self.hit_miss.merge(&o.hit_miss);
        self.triangle.merge(&o.triangle);
        self.max_t_rel_diff = self.max_t_rel_diff.max(o.max_t_rel_diff);
    }

    /// True when every difference is explained.
    pub fn is_explained(&self) -> bool {
        self.hit_miss.unexplained == 0 && self.triangle.unexplained == 0
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
