//! One correctness suite for every CPU structure: BVH2, BVH4, BVH8, the DST software
//! decoder (DST*), the DST pipeline loop, the compressed BVH8 and the quantized DST
//! ([`AccelKind::ALL`]) answer each ray exactly as the brute-force oracle does (closest
//! hit `t` bits and triangle id, and the any-hit answer), ray by ray.
//!
//! Two parts:
//! - a table of edge cases (zero and one triangle, flat and zero-area triangles, NaN and
//!   huge coordinates, rays with zero or non-finite direction components, rays starting on
//!   a plane, `t_min == t_max`, equal-`t` ties, a shared edge), each with its expected
//!   answer, looped over every BVH2 build preset and every DST preset;
//! - random small scenes on a coarse grid (shared edges, triangles lying in box planes) with
//!   rays from grid points.

use dualsplit_accel::dst::{DstConfig, DstError};
use dualsplit_accel::{AccelError, AccelKind, BuildConfig, Structures};
use dualsplit_geometry::{PrimId, Ray, Triangle, Vec3};
use dualsplit_testkit::dst::dst_presets;
use dualsplit_testkit::oracle::{check_ray, key, oracle_closest};
use dualsplit_testkit::scenes::cuboid;
use proptest::prelude::*;

/// What the oracle must answer for a ray of the table.
#[derive(Clone, Copy, Debug)]
enum Expect {
    /// No triangle on `[t_min, t_max]`.
    Miss,
    /// Closest hit at exactly `t` on triangle `prim`.
    Hit { t: f32, prim: u32 },
    /// Whatever the oracle answers (non-finite arithmetic, where the point is that every
    /// structure agrees with it and nothing panics).
    Oracle,
}

/// One row of the table: a scene and its rays.
struct Case {
    name: &'static str,
    tris: Vec<Triangle>,
    rays: Vec<(Ray, Expect)>,
}

fn tri(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> Triangle {
    Triangle::new(Vec3::from(a), Vec3::from(b), Vec3::from(c))
}

fn ray(o: [f32; 3], d: [f32; 3]) -> Ray {
    Ray::new(Vec3::from(o), Vec3::from(d))
}

fn segment(o: [f32; 3], d: [f32; 3], t_min: f32, t_max: f32) -> Ray {
    Ray::segment(Vec3::from(o), Vec3::from(d), t_min, t_max)
}

/// The unit triangle in the plane `z`.
fn unit_tri(z: f32) -> Triangle {
    tri([-1.0, -1.0, z], [1.0, -1.0, z], [0.0, 1.0, z])
}

fn cases() -> Vec<Case> {
    use Expect::{Hit, Miss, Oracle};
    let nan = f32::NAN;
    let inf = f32::INFINITY;
    vec![
        Case {
            name: "zero triangles",
            tris: vec![],
            rays: vec![
                (ray([0.0, 0.0, -1.0], [0.0, 0.0, 1.0]), Miss),
                (ray([0.0; 3], [1.0, 0.0, 0.0]), Miss),
            ],
        },
        Case {
            name: "one triangle",
            tris: vec![unit_tri(0.0)],
            rays: vec![
                (
                    ray([0.0, 0.0, -1.0], [0.0, 0.0, 1.0]),
                    Hit { t: 1.0, prim: 0 },
                ),
                (
                    ray([0.0, 0.0, 1.0], [0.0, 0.0, -0.5]),
                    Hit { t: 2.0, prim: 0 },
                ),
                (ray([0.0, 0.0, -1.0], [0.0, 0.0, -1.0]), Miss),
                (ray([2.0, 0.0, -1.0], [0.0, 0.0, 1.0]), Miss),
                // Lying in the triangle's plane.
                (ray([0.0; 3], [1.0, 0.0, 0.0]), Miss),
                (ray([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0]), Miss),
            ],
        },
        Case {
            name: "flat and zero-area triangles",
            tris: vec![
                // A point, a segment along x, then a segment along z.
                tri([0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]),
                tri([-1.0, 0.0, 2.0], [1.0, 0.0, 2.0], [0.0, 0.0, 2.0]),
                tri([0.0, 0.5, 0.0], [0.0, 0.5, 4.0], [0.0, 0.5, 2.0]),
                // A real triangle behind them, lying in a box plane of the scene.
                unit_tri(3.0),
            ],
            rays: vec![
                (
                    ray([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
                    Hit { t: 3.0, prim: 3 },
                ),
                (
                    ray([0.0, 0.5, -1.0], [0.0, 0.0, 1.0]),
                    Hit { t: 4.0, prim: 3 },
                ),
                (ray([0.0, 0.0, 2.0], [1.0, 0.0, 0.0]), Miss),
                (ray([0.0, -1.0, 1.0], [0.0, 1.0, 0.0]), Miss),
            ],
        },
        Case {
            name: "equal t goes to the smaller id",
            // Fifty coincident triangles (a leaf each under single-triangle leaves).
            tris: vec![unit_tri(1.0); 50],
            rays: vec![
                (ray([0.0; 3], [0.0, 0.0, 1.0]), Hit { t: 1.0, prim: 0 }),
                (
                    ray([0.0, 0.0, 2.0], [0.0, 0.0, -1.0]),
                    Hit { t: 1.0, prim: 0 },
                ),
                (
                    segment([0.0; 3], [0.0, 0.0, 1.0], 1.0, 1.0),
                    Hit { t: 1.0, prim: 0 },
                ),
            ],
        },
        Case {
            name: "shared edge and t_min == t_max",
            // Two triangles sharing the edge x = 0 in the plane z = 1.
            tris: vec![
                tri([0.0, -1.0, 1.0], [0.0, 1.0, 1.0], [-1.0, 0.0, 1.0]),
                tri([0.0, -1.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]),
            ],
            rays: vec![
                // Through the shared edge: both triangles hit at t = 1.
                (ray([0.0; 3], [0.0, 0.0, 1.0]), Hit { t: 1.0, prim: 0 }),
                (
                    segment([0.0; 3], [0.0, 0.0, 1.0], 1.0, 1.0),
                    Hit { t: 1.0, prim: 0 },
                ),
                (
                    segment([0.5, 0.0, 0.0], [0.0, 0.0, 1.0], 1.0, 1.0),
                    Hit { t: 1.0, prim: 1 },
                ),
                (segment([0.0; 3], [0.0, 0.0, 1.0], 0.5, 0.5), Miss),
                (segment([0.0; 3], [0.0, 0.0, 1.0], 2.0, 2.0), Miss),
                // t_min > t_max.
                (segment([0.0; 3], [0.0, 0.0, 1.0], 2.0, 1.0), Miss),
                // Segments ending exactly at, and starting just past, the hit.
                (
                    segment([0.0; 3], [0.0, 0.0, 1.0], 0.0, 1.0),
                    Hit { t: 1.0, prim: 0 },
                ),
                (segment([0.0; 3], [0.0, 0.0, 1.0], 1.0000001, inf), Miss),
                // Along the shared edge, in the triangles' plane.
                (ray([0.0, -2.0, 1.0], [0.0, 1.0, 0.0]), Miss),
                (ray([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]), Miss),
            ],
        },
        Case {
            name: "rays starting on a plane",
            // A closed unit cube of quads: every face lies in a bounding plane of the scene.
            tris: cube(),
            rays: vec![
                // From a face point inward and outward.
                (ray([0.25, 0.5, 0.0], [0.0, 0.0, 1.0]), Oracle),
                (ray([0.25, 0.5, 0.0], [0.0, 0.0, -1.0]), Oracle),
                // From a face point along the face (zero z component), and from an edge.
                (ray([0.25, 0.5, 0.0], [1.0, 0.0, 0.0]), Oracle),
                (ray([0.25, 0.5, 0.0], [1.0, 1.0, -0.0]), Oracle),
                (ray([0.0, 0.0, 0.5], [1.0, 1.0, 0.0]), Oracle),
                // From inside, axis-parallel with two zero components.
                (
                    ray([0.5, 0.5, 0.5], [0.0, -0.0, 1.0]),
                    Hit { t: 0.5, prim: 2 },
                ),
                (ray([0.5, 0.5, 0.5], [-1.0, 0.0, 0.0]), Oracle),
                // From outside, grazing a face.
                (ray([-1.0, 0.5, 1.0], [1.0, 0.0, 0.0]), Oracle),
                (ray([-1.0, 1.0, 1.0], [1.0, 0.0, 0.0]), Oracle),
            ],
        },
        Case {
            // NaN coordinates drop out of a triangle's box (`f32::min` and `max` ignore
            // NaN); infinite ones are refused (`infinite_triangles_are_refused`).
            name: "NaN and huge triangles",
            tris: vec![
                tri([nan; 3], [1.0; 3], [0.0; 3]),
                tri([-3e38, -3e38, 0.0], [3e38, -3e38, 0.0], [0.0, 3e38, 1.0]),
                unit_tri(2.0),
                tri([-1e30, -1e30, 1e30], [1e30, -1e30, 1e30], [0.0, 1e30, 1e30]),
            ],
            rays: vec![
                (ray([0.0, 0.0, -5.0], [0.0, 0.0, 1.0]), Oracle),
                (ray([0.0, 0.0, 1.5], [0.0, 0.0, 1.0]), Oracle),
                (ray([0.5; 3], [-1.0; 3]), Oracle),
                (ray([0.0, 0.0, 3.0], [0.0, 0.0, 1.0]), Oracle),
                (ray([0.0, 0.0, -1e30], [0.0, 0.0, 1.0]), Oracle),
            ],
        },
        Case {
            // Rays outside `Ray::is_traceable` (non-finite origin or direction, NaN interval
            // end) miss everywhere, the oracle included.
            name: "non-finite and zero rays",
            tris: vec![unit_tri(1.0), unit_tri(2.0)],
            rays: vec![
                (ray([nan, 0.0, 0.0], [0.0, 0.0, 1.0]), Miss),
                (ray([0.0; 3], [nan, 0.0, 1.0]), Miss),
                (ray([0.0; 3], [0.0, 0.0, inf]), Miss),
                (ray([0.0, 0.0, -inf], [0.0, 0.0, 1.0]), Miss),
                (ray([0.0; 3], [0.0; 3]), Oracle),
                (ray([0.0; 3], [0.0, 0.0, 1e-30]), Oracle),
                (ray([0.0; 3], [0.0, 0.0, 1e30]), Oracle),
                (segment([0.0; 3], [0.0, 0.0, 1.0], nan, inf), Miss),
                (segment([0.0; 3], [0.0, 0.0, 1.0], 0.0, nan), Miss),
                (segment([0.0; 3], [0.0, 0.0, 1.0], -inf, inf), Oracle),
            ],
        },
    ]
}

/// The twelve triangles of the unit cube `[0, 1]³` ([`cuboid`]: two per face in the order
/// z = 0, z = 1, x = 0, x = 1, y = 0, y = 1, each face's two triangles sharing a diagonal
/// through the face's centre, so the z = 1 face is triangles 2 and 3, meeting at
/// `(0.5, 0.5, 1)`).
fn cube() -> Vec<Triangle> {
    let mut t = Vec::new();
    cuboid(&mut t, Vec3::ZERO, Vec3::ONE);
    t
}

/// The BVH2 build presets each case runs under.
fn build_presets() -> [BuildConfig; 3] {
    [
        BuildConfig::default(),
        BuildConfig::high_quality(),
        BuildConfig::single_triangle_leaves(),
    ]
}

/// Builds every structure under `bcfg` and `dcfg` and validates them. Bounds containment
/// is undefined for NaN input, so scenes with non-finite triangles only have to build.
fn structures(tris: &[Triangle], bcfg: &BuildConfig, dcfg: &DstConfig) -> Structures {
    let s = Structures::try_build_with(tris, bcfg, dcfg).expect("structures");
    if tris.iter().all(Triangle::is_finite) {
        for rep in s.validate() {
            assert!(rep.is_ok(), "{rep:?}");
        }
    }
    s
}

#[test]
fn edge_cases_on_every_structure() {
    for case in cases() {
        for (i, &(ray, expect)) in case.rays.iter().enumerate() {
            let oracle = oracle_closest(&case.tris, &ray);
            match expect {
                Expect::Miss => assert_eq!(key(oracle), None, "{} ray {i}", case.name),
                Expect::Hit { t, prim } => assert_eq!(
                    key(oracle),
                    Some((t.to_bits(), PrimId(prim))),
                    "{} ray {i}: oracle {oracle:?}",
                    case.name
                ),
                Expect::Oracle => {}
            }
        }
        for bcfg in build_presets() {
            for dcfg in dst_presets() {
                let s = structures(&case.tris, &bcfg, &dcfg);
                for (i, (ray, _)) in case.rays.iter().enumerate() {
                    let what = format!("{} ray {i} ({bcfg:?}, {dcfg:?})", case.name);
                    check_ray(&s, &case.tris, ray, &what);
                }
            }
        }
    }
}

/// A triangle with an infinite coordinate gives its BVH2 nodes infinite boxes. The DST
/// conversion refuses them with [`DstError::NonFiniteBounds`]: it prices each carving step
/// by the surface area of a region, which an infinite box makes infinite or NaN, and it
/// uses ±∞ itself as the no-op partner plane of a lone face (`docs/dst-encoding.md`,
/// "Chains"). So `Structures` is not built and there is nothing to compare; this is the one
/// input the five structures do not share. Scene loading drops such triangles
/// (`dualsplit_scene`, "Degenerate and non-finite triangles"), so no loaded scene reaches it.
#[test]
fn infinite_triangles_are_refused() {
    let inf = f32::INFINITY;
    let tris = [
        unit_tri(2.0),
        tri([inf, 0.0, 4.0], [0.0, inf, 4.0], [-inf, -inf, 4.0]),
    ];
    for bcfg in build_presets() {
        for dcfg in dst_presets() {
            let got = Structures::try_build_with(&tris, &bcfg, &dcfg);
            assert!(
                matches!(got, Err(AccelError::Dst(DstError::NonFiniteBounds { .. }))),
                "{bcfg:?}, {dcfg:?}: {:?}",
                got.err()
            );
        }
    }
}

#[test]
fn suite_covers_every_structure() {
    // Feature `toy` appends the toy structure (`tests/toy.rs`).
    let toy = usize::from(cfg!(feature = "toy"));
    assert_eq!(
        AccelKind::ALL[..AccelKind::ALL.len() - toy],
        [
            AccelKind::Bvh2,
            AccelKind::Bvh4,
            AccelKind::Bvh8,
            AccelKind::DstSw,
            AccelKind::Dst,
            AccelKind::Cwbvh,
            AccelKind::DstQ
        ]
    );
}

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

fn random_ray() -> impl Strategy<Value = Ray> {
    (
        prop_oneof![
            grid_point(),
            prop::array::uniform3(-3f32..3.0).prop_map(Vec3::from)
        ],
        direction(),
        prop_oneof![
            Just((0.0f32, f32::INFINITY)),
            (0f32..2.0, 0f32..4.0),
            // t_min == t_max on the grid's plane distances.
            (0i32..=8).prop_map(|k| (k as f32 * 0.5, k as f32 * 0.5)),
        ],
    )
        .prop_map(|(o, d, (t0, t1))| Ray::segment(o, d, t0, t1))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn matches_oracle(
        tris in prop::collection::vec(triangle(), 0..120),
        rays in prop::collection::vec(random_ray(), 1..40),
        build in 0usize..3,
        dst in 0usize..3,
    ) {
        let (bcfg, dcfg) = (&build_presets()[build], &dst_presets()[dst]);
        let s = structures(&tris, bcfg, dcfg);
        for (i, ray) in rays.iter().enumerate() {
            check_ray(&s, &tris, ray, &format!("ray {i} ({bcfg:?}, {dcfg:?})"));
        }
    }
}
