//! Edge cases of the shared ray tests: zero direction components, degenerate boxes, shared
//! edges.
use dualsplit_geometry::{Aabb, EXIT_WIDEN, Pcg32, Ray, RayPre, Triangle, Vec3, widen_exit};

#[test]
fn degenerate_box_never_hits() {
    for d in [
        Vec3::X,
        -Vec3::Y,
        Vec3::new(0.3, -0.2, 0.9),
        Vec3::new(0.0, 0.0, 1.0),
    ] {
        let r = Ray::new(Vec3::ZERO, d).precompute();
        let (e, x) = r.slab(
            Aabb::DEGENERATE.min,
            Aabb::DEGENERATE.max,
            0.0,
            f32::INFINITY,
        );
        assert!(e > x, "dir {d:?} entered the degenerate box");
    }
}

#[test]
fn zero_direction_component_inside_closed_slab() {
    // Ray along +z lying exactly in the face plane x = 1 of the box: closed slab, so it hits.
    let r = Ray::new(Vec3::new(1.0, 0.5, -1.0), Vec3::Z).precompute();
    let (e, x) = r.slab(Vec3::ZERO, Vec3::ONE, 0.0, f32::INFINITY);
    assert!(e <= x);
    assert_eq!((e, x), (1.0, widen_exit(2.0)));
    // Same ray just outside the slab misses.
    let r = Ray::new(Vec3::new(1.0 + 1e-6, 0.5, -1.0), Vec3::Z).precompute();
    let (e, x) = r.slab(Vec3::ZERO, Vec3::ONE, 0.0, f32::INFINITY);
    assert!(e > x);
    // Negative zero direction components behave the same.
    let r = Ray::new(Vec3::new(0.0, 0.5, 2.0), Vec3::new(-0.0, -0.0, -1.0)).precompute();
    let (e, x) = r.slab(Vec3::ZERO, Vec3::ONE, 0.0, f32::INFINITY);
    assert_eq!((e, x), (1.0, widen_exit(2.0)));
}

#[test]
fn flat_box_is_hit() {
    let r = Ray::new(Vec3::new(0.5, 1.0, 0.5), -Vec3::Y).precompute();
    let (e, x) = r.slab(
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 1.0),
        0.0,
        f32::INFINITY,
    );
    // The exit is widened by 1 + 2γ₃ (Ize 2013); the entry is exact.
    assert_eq!((e, x), (1.0, widen_exit(1.0)));
}

#[test]
fn shared_edge_is_watertight() {
    // Two triangles of a quad; rays aimed exactly along the shared diagonal hit at least one.
    let a = Triangle::new(
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
    );
    let b = Triangle::new(
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    );
    for i in 0..=64 {
        let s = i as f32 / 64.0;
        let r = Ray::new(Vec3::new(s, s, 1.0), -Vec3::Z).precompute();
        let ha = a.intersect(&r, 0.0, f32::INFINITY);
        let hb = b.intersect(&r, 0.0, f32::INFINITY);
        assert!(
            ha.is_some() || hb.is_some(),
            "ray through the diagonal at {s} slipped through"
        );
    }
}

#[test]
fn degenerate_triangle_never_hit() {
    let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
    assert!(t.is_degenerate());
    let r = Ray::new(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z).precompute();
    assert!(t.intersect(&r, 0.0, f32::INFINITY).is_none());
}

/// A triangle in the plane z = 2 and the ray along +z from the origin through its inside.
fn facing_triangle() -> (Triangle, RayPre) {
    let t = Triangle::new(
        Vec3::new(-1.0, -1.0, 2.0),
        Vec3::new(1.0, -1.0, 2.0),
        Vec3::new(0.0, 1.0, 2.0),
    );
    (t, Ray::new(Vec3::ZERO, Vec3::Z).precompute())
}

#[test]
fn interval_is_inclusive() {
    let (t, r) = facing_triangle();
    assert!(t.intersect(&r, 2.0, 2.0).is_some());
    assert!(t.intersect(&r, 0.0, 1.999).is_none());
}

use dualsplit_testkit::grazing::{GRAZING_CASES, grazing_case};

/// The slab test without widening, for the test's premise: the plain rule rounds these
/// boxes away.
fn slab_unwidened(r: &RayPre, min: Vec3, max: Vec3) -> (f32, f32) {
    let (mut entry, mut exit) = (0.0f32, f32::INFINITY);
    for a in 0..3 {
        let (n, f) = if r.neg[a] {
            (max[a], min[a])
        } else {
            (min[a], max[a])
        };
        entry = entry.max(r.plane_t(a, n));
        exit = exit.min(r.plane_t(a, f));
    }
    (entry, exit)
}

#[test]
fn vertex_at_box_corner_enters_the_box() {
    for (i, &(_, _, k)) in GRAZING_CASES.iter().enumerate() {
        let (tri, ray) = grazing_case(i);
        let b = tri.bounds();
        assert!(
            (0..3).all(|a| tri.v[k][a] == b.min[a] || tri.v[k][a] == b.max[a]),
            "case {i}: vertex is not a box corner"
        );
        let r = ray.precompute();
        assert!(
            tri.intersect(&r, 0.0, f32::INFINITY).is_some(),
            "case {i}: watertight test misses"
        );
        let (e0, x0) = slab_unwidened(&r, b.min, b.max);
        assert!(
            e0 > x0,
            "case {i}: premise: the unwidened slab rounds the box away"
        );
        let (e, x) = r.slab(b.min, b.max, 0.0, f32::INFINITY);
        assert!(e <= x, "case {i}: widened slab still misses: ({e}, {x})");
    }
}

/// Seeded search: for every ray aimed at a box-corner vertex that the watertight test hits,
/// the slab test enters the triangle's box.
#[test]
fn rays_at_corner_vertices_always_enter_the_box() {
    let mut rng = Pcg32::new(0x1be, 3);
    let mut hits = 0;
    for _ in 0..50_000 {
        let mut p = || rng.cube_point(-4.0, 4.0);
        let (a, b, c, o) = (p().round(), p().round(), p().round(), p());
        let tri = Triangle::new(a, b, c);
        let bb = tri.bounds();
        for v in tri.v {
            let ray = Ray::new(o, v - o);
            let r = ray.precompute();
            if tri.intersect(&r, 0.0, f32::INFINITY).is_none() {
                continue;
            }
            hits += 1;
            let (e, x) = r.slab(bb.min, bb.max, 0.0, f32::INFINITY);
            assert!(e <= x, "ray {ray:?} at vertex {v:?} of {tri:?}: ({e}, {x})");
        }
    }
    assert!(hits > 10_000, "only {hits} vertex hits");
}

#[test]
fn widen_exit_rules() {
    // 1 + 2γ₃ with γ_n = nε/(1 − nε), ε = f32::EPSILON / 2.
    let e = f64::from(f32::EPSILON) / 2.0;
    let g3 = 3.0 * e / (1.0 - 3.0 * e);
    assert!((f64::from(EXIT_WIDEN) - (1.0 + 2.0 * g3)).abs() <= f64::from(f32::EPSILON) / 2.0);
    const { assert!(EXIT_WIDEN > 1.0) };
    assert!(widen_exit(f32::NAN).is_nan());
    assert_eq!(widen_exit(f32::INFINITY), f32::INFINITY);
    assert_eq!(widen_exit(f32::NEG_INFINITY), f32::NEG_INFINITY);
    assert_eq!(widen_exit(0.0).to_bits(), 0.0f32.to_bits());
    assert_eq!(widen_exit(-0.0).to_bits(), (-0.0f32).to_bits());
    // Monotone, so it commutes with min: the DST (planes clipped one node at a time) and
    // the BVH (one box at a time) reach the same leaves.
    let mut rng = Pcg32::new(9, 9);
    for _ in 0..10_000 {
        let (a, b) = (rng.range_f32(-8.0, 8.0), rng.range_f32(-8.0, 8.0));
        if a >= 0.0 {
            assert!(widen_exit(a) >= a, "{a}");
        }
        assert_eq!(
            widen_exit(a.min(b)).to_bits(),
            widen_exit(a).min(widen_exit(b)).to_bits(),
            "{a} {b}"
        );
    }
    // exit_t is widen_exit(plane_t).
    let r = Ray::new(Vec3::new(0.3, -1.0, 2.0), Vec3::new(0.7, 0.2, -0.5)).precompute();
    for a in 0..3 {
        assert_eq!(
            r.exit_t(a, 1.5).to_bits(),
            widen_exit(r.plane_t(a, 1.5)).to_bits()
        );
    }
}

/// Edge functions that underflowed (a determinant whose reciprocal overflows) give no hit,
/// whatever their signs, and an ordinary triangle still gives finite barycentrics.
#[test]
fn underflowed_edge_functions_never_hit() {
    let (tri, r) = facing_triangle();
    for edges in [
        [f32::from_bits(1), 0.0, 0.0],
        [1e-39, 1e-40, 0.0],
        [0.0, -1e-45, -1e-45],
    ] {
        assert!(
            tri.intersect_from_edges(&r, edges, 0.0, f32::INFINITY)
                .is_none(),
            "{edges:?}"
        );
    }
    let h = tri.intersect(&r, 0.0, f32::INFINITY).expect("hit");
    assert!(h.u.is_finite() && h.v.is_finite(), "{h:?}");
    // Just above the limit: 2^-127 has a finite reciprocal, so the edges decide.
    let h = tri.intersect_from_edges(&r, [2f32.powi(-127), 0.0, 0.0], 0.0, f32::INFINITY);
    assert!(h.is_some_and(|h| h.u == 0.0 && h.v == 0.0));
}
