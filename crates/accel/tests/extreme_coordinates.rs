//! Scenes whose coordinates span the whole finite f32 range, up to ±`f32::MAX`: boxes wider
//! than `f32::MAX` (their extent overflows to +∞), surface areas and SAH costs that overflow,
//! subnormal and zero coordinates next to huge ones. Every structure (BVH2, BVH4, BVH8, the
//! DST under every preset) is built valid. (Traversals are not compared here: the CLI
//! refuses such scenes at load time, see `dualsplit_scene::Scene::MAX_EXTENT`.)

use dualsplit_accel::dst::Dst;
use dualsplit_accel::{BuildConfig, Bvh2, Structures};
use dualsplit_geometry::{Aabb, Triangle, Vec3};
use dualsplit_testkit::dst::{build_with, dst_presets};
use proptest::prelude::*;

/// A coordinate from anywhere in the finite f32 range: any sign, exponent and mantissa
/// (zero and subnormals included), the ends of the range, or an ordinary small value so that
/// small boxes nest inside huge ones.
fn coordinate() -> impl Strategy<Value = f32> {
    prop_oneof![
        (any::<bool>(), 0u32..255, 0u32..1 << 23)
            .prop_map(|(neg, e, m)| f32::from_bits(u32::from(neg) << 31 | e << 23 | m)),
        prop::sample::select(vec![f32::MAX, -f32::MAX, 3e38, -3e38, 1.9e19, -1.9e19,]),
        -4.0f32..4.0,
    ]
}

fn point() -> impl Strategy<Value = Vec3> {
    [coordinate(), coordinate(), coordinate()].prop_map(Vec3::from_array)
}

/// The extreme-range scene generator: 1 to 40 triangles with vertices from [`point`].
fn extreme_scene() -> impl Strategy<Value = Vec<Triangle>> {
    prop::collection::vec(
        [point(), point(), point()].prop_map(|[a, b, c]| Triangle::new(a, b, c)),
        1..40,
    )
}

/// Builds every structure of `tris` under every DST preset (`build_with` panics when the DST
/// does not validate against its BVH2) and asserts that every image validates.
fn check_scene(tris: &[Triangle], leaf: u32) {
    let bcfg = BuildConfig {
        max_leaf_size: leaf,
        ..BuildConfig::default()
    };
    for cfg in dst_presets() {
        let b = build_with(tris, &bcfg, &cfg);
        for rep in b.reference.validate() {
            assert!(rep.is_ok(), "{cfg:?}: {rep:?}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn extreme_scenes_build_valid_structures(
        tris in extreme_scene(),
        leaf in prop::sample::select(vec![1u32, 2, 4]),
    ) {
        check_scene(&tris, leaf);
    }
}

/// Triangles spread over ±3e38 (the scene's extent overflows) and nested ones of ordinary
/// size: before the chain DP took a fallback option, every cost overflowed and the DST's
/// first carving chain stopped short of its box (a tree `check` rejected).
#[test]
fn coordinates_at_3e38_build_a_valid_dst() {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let mut tris = vec![
        Triangle::new(
            v(-3e38, -3e38, -3e38),
            v(3e38, -3e38, -3e38),
            v(0.0, 3e38, 3e38),
        ),
        Triangle::new(
            v(-3e38, 3e38, -3e38),
            v(3e38, 3e38, 3e38),
            v(0.0, -3e38, 3e38),
        ),
    ];
    for i in 0..12 {
        let s = [1e19f32, 1e30, 1.0][i % 3] * (i as f32 + 1.0);
        tris.push(Triangle::new(
            v(s, 0.0, 0.0),
            v(0.0, s, 0.0),
            v(0.0, 0.0, -s),
        ));
    }
    let extent = tris
        .iter()
        .fold(Aabb::EMPTY, |b, t| b.union(t.bounds()))
        .extent();
    assert!(
        !extent.is_finite(),
        "the scene's extent overflows: {extent:?}"
    );
    check_scene(&tris, 4);
    // The conversion alone, from a BVH2 built with one triangle per leaf.
    let boxes: Vec<Aabb> = tris.iter().map(|t| t.bounds()).collect();
    let cfg = BuildConfig {
        max_leaf_size: 1,
        ..BuildConfig::default()
    };
    let bvh = Bvh2::build(&boxes, &cfg);
    for preset in dst_presets() {
        let dst = Dst::from_bvh2(&bvh, &tris[..], &preset).expect("conversion");
        dst.validate(&bvh).expect("valid DST");
        assert!(dst.stats().leaves + dst.stats().carving_leaves > 0);
    }
    let s = Structures::build(&tris, &cfg);
    assert!(s.validate().iter().all(|r| r.is_ok()));
}
