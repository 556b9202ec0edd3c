//! Per-ray equivalence of BVH2, BVH4 and BVH8 with a brute-force oracle on small random
//! scenes built to hit the edge cases: triangles on a coarse grid (shared edges, triangles
//! lying in box planes), flat and zero-area triangles, rays from grid points (starting on
//! planes) with zero direction components.

mod support;

use dualsplit_accel::{AccelKind, BuildConfig, NoObserver, Structures};
use dualsplit_geometry::{Ray, Triangle, Vec3};
use proptest::prelude::*;
use support::{key, oracle_any, oracle_closest};

const KINDS: [AccelKind; 3] = [AccelKind::Bvh2, AccelKind::Bvh4, AccelKind::Bvh8];

fn grid_point() -> impl Strategy<Value = Vec3> {
    // Coordinates on a 0.5 grid in [-2, 2]: many coincident planes and shared edges.
    prop::array::uniform3(-4i32..=4)
        .prop_map(|a| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32) * 0.5)
}

fn triangle() -> impl Strategy<Value = Triangle> {
    prop_oneof![
        // General triangles on the grid (some flat in a coordinate plane, some zero-area).
        4 => (grid_point(), grid_point(), grid_point()).prop_map(|(a, b, c)| Triangle::new(a, b, c)),
        // Axis-aligned: all three vertices share one coordinate.
        2 => (grid_point(), grid_point(), grid_point(), 0usize..3).prop_map(|(a, mut b, mut c, ax)| {
            b[ax] = a[ax];
            c[ax] = a[ax];
            Triangle::new(a, b, c)
        }),
        // Collinear (zero-area) triangles.
        1 => (grid_point(), grid_point()).prop_map(|(a, b)| Triangle::new(a, b, (a + b) * 0.5)),
        // Off-grid random triangles.
        2 => (prop::array::uniform9(-2f32..2.0)).prop_map(|v| Triangle::new(
            Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]), Vec3::new(v[6], v[7], v[8]))),
    ]
}

fn direction() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        // Components in {-1, 0, 1} (axis-parallel and diagonal rays, zero components).
        2 => prop::array::uniform3(-1i32..=1)
            .prop_filter("non-zero", |a| a != &[0, 0, 0])
            .prop_map(|a| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)),
        3 => prop::array::uniform3(-1f32..1.0)
            .prop_filter("non-zero", |a| a.iter().any(|&x| x != 0.0))
            .prop_map(Vec3::from),
    ]
}

fn ray() -> impl Strategy<Value = Ray> {
    (
        prop_oneof![
            grid_point(),
            prop::array::uniform3(-3f32..3.0).prop_map(Vec3::from)
        ],
        direction(),
        prop_oneof![Just((0.0f32, f32::INFINITY)), (0f32..2.0, 0f32..4.0)],
    )
        .prop_map(|(o, d, (t0, t1))| Ray::segment(o, d, t0, t1))
}

fn check(tris: &[Triangle], rays: &[Ray], cfg: &BuildConfig) {
    let s = Structures::build(tris, cfg);
    for rep in s.validate() {
        assert!(rep.is_ok(), "{rep:?}");
    }
    for (i, ray) in rays.iter().enumerate() {
        let want = key(oracle_closest(tris, ray));
        let want_any = oracle_any(tris, ray);
        for kind in KINDS {
            let got = key(s.closest_hit(kind, ray, &mut NoObserver));
            assert_eq!(got, want, "ray {i} {ray:?} closest on {kind:?}");
            let got_any = s.any_hit(kind, ray, &mut NoObserver);
            assert_eq!(got_any, want_any, "ray {i} {ray:?} any on {kind:?}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn matches_oracle(
        tris in prop::collection::vec(triangle(), 0..120),
        rays in prop::collection::vec(ray(), 1..40),
        leaf1 in any::<bool>(),
    ) {
        let cfg = if leaf1 { BuildConfig::single_triangle_leaves() } else { BuildConfig::high_quality() };
        check(&tris, &rays, &cfg);
    }
}

#[test]
fn empty_and_single_triangle_scenes() {
    let ray = Ray::new(Vec3::new(0.0, 0.0, -1.0), Vec3::Z);
    check(&[], &[ray], &BuildConfig::default());
    let tri = Triangle::new(
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    );
    check(
        &[tri],
        &[ray, Ray::new(Vec3::ZERO, Vec3::X)],
        &BuildConfig::default(),
    );
}

#[test]
fn equal_t_goes_to_smaller_id() {
    // Two coincident triangles (ids 0 and 1) copied many times: every structure must return
    // the smallest id among the equal-t hits.
    let a = Triangle::new(
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(1.0, -1.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
    );
    let tris: Vec<Triangle> = (0..50).map(|_| a).collect();
    let s = Structures::build(&tris, &BuildConfig::single_triangle_leaves());
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    for kind in KINDS {
        assert_eq!(
            s.closest_hit(kind, &ray, &mut NoObserver).unwrap().prim,
            0,
            "{kind:?}"
        );
    }
}

#[test]
fn ray_through_shared_edge_and_t_min_equals_t_max() {
    // Two triangles sharing the edge x = 0; the ray runs exactly through it.
    let tris = [
        Triangle::new(
            Vec3::new(0.0, -1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(-1.0, 0.0, 1.0),
        ),
        Triangle::new(
            Vec3::new(0.0, -1.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ),
    ];
    let rays = [
        Ray::new(Vec3::ZERO, Vec3::Z),
        Ray::segment(Vec3::ZERO, Vec3::Z, 1.0, 1.0),
        Ray::segment(Vec3::ZERO, Vec3::Z, 2.0, 1.0),
        Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::X),
    ];
    check(&tris, &rays, &BuildConfig::default());
}

#[test]
fn non_finite_and_huge_coordinates_do_not_panic() {
    let tris = [
        Triangle::new(Vec3::splat(f32::NAN), Vec3::ONE, Vec3::ZERO),
        Triangle::new(
            Vec3::splat(-3e38),
            Vec3::new(3e38, -3e38, 0.0),
            Vec3::new(0.0, 3e38, 1.0),
        ),
        Triangle::new(
            Vec3::new(-1.0, -1.0, 2.0),
            Vec3::new(1.0, -1.0, 2.0),
            Vec3::new(0.0, 1.0, 2.0),
        ),
    ];
    let s = Structures::build(&tris, &BuildConfig::default());
    let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
    let want = key(oracle_closest(&tris, &ray));
    for kind in KINDS {
        assert_eq!(
            key(s.closest_hit(kind, &ray, &mut NoObserver)),
            want,
            "{kind:?}"
        );
    }
}
