//! Edge cases of the shared ray tests: zero direction components, degenerate boxes, shared
//! edges.
use dualsplit_geometry::{Aabb, Ray, Triangle, Vec3};

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
    assert_eq!((e, x), (1.0, 2.0));
    // Same ray just outside the slab misses.
    let r = Ray::new(Vec3::new(1.0 + 1e-6, 0.5, -1.0), Vec3::Z).precompute();
    let (e, x) = r.slab(Vec3::ZERO, Vec3::ONE, 0.0, f32::INFINITY);
    assert!(e > x);
    // Negative zero direction components behave the same.
    let r = Ray::new(Vec3::new(0.0, 0.5, 2.0), Vec3::new(-0.0, -0.0, -1.0)).precompute();
    let (e, x) = r.slab(Vec3::ZERO, Vec3::ONE, 0.0, f32::INFINITY);
    assert_eq!((e, x), (1.0, 2.0));
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
    assert_eq!((e, x), (1.0, 1.0));
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

#[test]
fn interval_is_inclusive() {
    let t = Triangle::new(
        Vec3::new(-1.0, -1.0, 2.0),
        Vec3::new(1.0, -1.0, 2.0),
        Vec3::new(0.0, 1.0, 2.0),
    );
    let r = Ray::new(Vec3::ZERO, Vec3::Z).precompute();
    assert!(t.intersect(&r, 2.0, 2.0).is_some());
    assert!(t.intersect(&r, 0.0, 1.999).is_none());
}
