//! Agreement between two answers to the same ray: ours and a peer's (Embree's).
//!
//! Two correct tracers may still name different triangles, for reasons that are not errors:
//!
//! * **Tie**: both triangles are hit at the same `t` (a ray through a shared edge or vertex,
//!   duplicated coplanar faces). dualsplit's rule gives such a ray to the smaller triangle
//!   id; Embree gives it to whichever triangle its traversal meets first.
//! * **Grazing**: the ray passes within a few f32 roundings of a triangle's edge (thin
//!   triangles, rays nearly in a triangle's plane). There the two ray–triangle tests round
//!   differently: dualsplit's is watertight (Woop et al. 2013), Embree's default is not.
//! * **Boundary**: the hit lies at an end of the ray's `[t_min, t_max]` interval, where the
//!   two tests' roundings of `t` decide whether it counts.
//!
//! [`classify`] decides, from the triangles' geometry in f64, which of these explains a
//! difference; a difference none of them explains (a hit on a triangle the ray does not
//! pass through, a triangle squarely hit but missed) is [`Verdict::Unexplained`].

use dualsplit_geometry::{Hit, Ray, Triangle};

/// Relative difference in `t` under which two hits count as a tie (both triangles meet
/// the ray at the same point, up to the peer's f32 rounding).
pub const TIE_REL: f64 = 1e-5;
/// A ray passing within this many f32 epsilons of the scene's coordinate magnitude
/// (`max |coordinate|` of the ray origin and the triangle) from a triangle's edge grazes
/// it: an f32 ray–triangle test rounds each vertex relative to the origin to about one
/// epsilon of that magnitude, and its edge functions compound a few such errors.
pub const GRAZE_EPS: f64 = 16.0;
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

/// Where a ray passes a triangle, in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    /// Ray parameter where the ray meets the triangle's plane (NaN when it is parallel).
    pub t: f64,
    /// Signed distance from the ray to the nearest edge line of the triangle, measured in
    /// the plane perpendicular to the ray (where the watertight test evaluates its edge
    /// functions): positive inside the triangle, negative outside. Thin triangles and rays
    /// nearly in a triangle's plane give small distances.
    pub edge_distance: f64,
    /// The distance under which the ray grazes the triangle: [`GRAZE_EPS`] f32 epsilons of
    /// the largest coordinate magnitude of the ray origin and the triangle.
    pub tolerance: f64,
}

/// Where `ray` passes `tri` ([`Crossing`]), or `None` for a zero direction or a triangle
/// with a non-finite coordinate.
pub fn crossing(tri: &Triangle, ray: &Ray) -> Option<Crossing> {
    let f = |v: dualsplit_geometry::Vec3| [v.x as f64, v.y as f64, v.z as f64];
    let (o, d) = (f(ray.origin), f(ray.dir));
    let vs = tri.v.map(f);
    let len = norm(d);
    if len == 0.0 || !len.is_finite() || !vs.iter().flatten().all(|c| c.is_finite()) {
        return None;
    }
    let d = d.map(|c| c / len);
    // An orthonormal basis (b1, b2) of the plane perpendicular to the ray.
    let a = d.map(f64::abs);
    let axis = if a[0] <= a[1] && a[0] <= a[2] {
        [1.0, 0.0, 0.0]
    } else if a[1] <= a[2] {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let b1 = cross(d, axis);
    let b1 = b1.map(|c| c / norm(b1));
    let b2 = cross(d, b1);
    let q = vs.map(|v| {
        let r = sub(v, o);
        [dot(r, b1), dot(r, b2)]
    });
    let edges = [(0, 1), (1, 2), (2, 0)];
    let e = edges.map(|(i, j)| q[i][0] * q[j][1] - q[i][1] * q[j][0]);
    let area2 = e[0] + e[1] + e[2];
    let edge_distance = if area2 == 0.0 {
        // The triangle projects onto a segment: the ray lies in its plane (or the triangle is
        // degenerate). It touches it at best, so the distance is never positive.
        -edges
            .iter()
            .map(|&(i, j)| segment_distance(q[i], q[j]))
            .fold(f64::INFINITY, f64::min)
    } else {
        let sign = area2.signum();
        edges
            .iter()
            .zip(e)
            .map(|(&(i, j), e)| {
                let l = (q[j][0] - q[i][0]).hypot(q[j][1] - q[i][1]);
                if l == 0.0 {
                    f64::INFINITY
                } else {
                    sign * e / l
                }
            })
            .fold(f64::INFINITY, f64::min)
    };
    let n = cross(sub(vs[1], vs[0]), sub(vs[2], vs[0]));
    let t = dot(n, sub(vs[0], o)) / dot(n, d) / len;
    let scale = vs
        .iter()
        .chain([&o])
        .flatten()
        .fold(0.0f64, |m, c| m.max(c.abs()));
    Some(Crossing {
        t,
        edge_distance,
        tolerance: GRAZE_EPS * f32::EPSILON as f64 * scale,
    })
}

/// Distance from the origin to the segment `a b` in 2D.
fn segment_distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let l2 = ab[0] * ab[0] + ab[1] * ab[1];
    let s = if l2 == 0.0 {
        0.0
    } else {
        (-(a[0] * ab[0] + a[1] * ab[1]) / l2).clamp(0.0, 1.0)
    };
    (a[0] + s * ab[0]).hypot(a[1] + s * ab[1])
}

/// What a claimed hit on a triangle looks like from the triangle's geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Claim {
    /// The ray passes farther than the tolerance outside the triangle, or the triangle does
    /// not exist: the hit is false.
    Off,
    /// The ray passes through the triangle at plane distance `t` (the claimed `t` when the
    /// ray is parallel to the plane); `edge`: within the tolerance of an edge.
    On { t: f64, edge: bool },
}

fn claim(tris: &[Triangle], ray: &Ray, h: &Hit) -> Claim {
    let Some(c) = tris.get(h.prim.index()).and_then(|tri| crossing(tri, ray)) else {
        return Claim::Off;
    };
    if c.edge_distance < -c.tolerance {
        Claim::Off
    } else {
        Claim::On {
            t: if c.t.is_finite() { c.t } else { h.t as f64 },
            edge: c.edge_distance < c.tolerance,
        }
    }
}

fn boundary(t: f64, ray: &Ray) -> bool {
    let near = |b: f32| {
        let b = b as f64;
        b.is_finite() && (t - b).abs() <= BOUNDARY_REL * t.abs().max(b.abs())
    };
    near(ray.t_min) || near(ray.t_max)
}

/// Compares our closest hit with the peer's for `ray` over `tris` (the triangles both
/// were built from). For shadow rays, pass each side's closest hit on the segment when
/// their occlusion answers differ.
///
/// Hits with the same triangle are [`Verdict::Same`] whatever their `t`. A hit on a
/// triangle the ray passes outside of by more than the tolerance ([`Crossing`]) is false
/// and the difference [`Verdict::Unexplained`]. Otherwise, with "the nearer hit" the one
/// with the smaller f64 plane distance (the other tracer missed it, or found it wrongly):
/// [`Verdict::Tie`] when both hit at f64 plane distances equal to [`TIE_REL`];
/// [`Verdict::Grazing`] when the ray passes the nearer hit's triangle within the tolerance
/// of an edge; [`Verdict::Boundary`] when the nearer hit lies at an end of the ray's
/// interval; else [`Verdict::Unexplained`].
pub fn classify(tris: &[Triangle], ray: &Ray, ours: Option<Hit>, peer: Option<Hit>) -> Verdict {
    let nearer = match (ours, peer) {
        (None, None) => return Verdict::Same,
        (Some(a), Some(b)) if a.prim == b.prim => return Verdict::Same,
        (Some(a), Some(b)) => match (claim(tris, ray, &a), claim(tris, ray, &b)) {
            (Claim::On { t: ta, edge: ea }, Claim::On { t: tb, edge: eb }) => {
                if (ta - tb).abs() <= TIE_REL * ta.abs().max(tb.abs()) {
                    return Verdict::Tie;
                }
                if ta < tb { (ta, ea) } else { (tb, eb) }
            }
            _ => return Verdict::Unexplained,
        },
        (Some(h), None) | (None, Some(h)) => match claim(tris, ray, &h) {
            Claim::On { t, edge } => (t, edge),
            Claim::Off => return Verdict::Unexplained,
        },
    };
    match nearer {
        (_, true) => Verdict::Grazing,
        (t, false) if boundary(t, ray) => Verdict::Boundary,
        _ => Verdict::Unexplained,
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
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
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
    /// The first unexplained difference: the ray and both answers.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub first_unexplained: Option<String>,
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
        if v == Verdict::Unexplained && self.first_unexplained.is_none() {
            self.first_unexplained = Some(format!("{ray:?}: ours {ours:?}, peer {peer:?}"));
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
        if self.first_unexplained.is_none() {
            self.first_unexplained.clone_from(&o.first_unexplained);
        }
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
