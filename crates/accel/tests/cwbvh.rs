//! The compressed BVH8 ([`Cwbvh`]) against the BVH2, ray by ray: the closest hit (t bits,
//! triangle id, barycentrics) and the shadow answer, through the image traversal and the
//! plain query (the SIMD copy of the decoded boxes, with every instruction set this CPU
//! has), on the shipped meshes, the builtin test scenes, random small scenes (leaves of 1,
//! 2 and 4 triangles) and scenes spread over ±2^60; validation clean on all of them and
//! catching corrupted images; the leaf-span limit an error, never a panic.
//!
//! Release builds compare 40K rays of each kind per shipped mesh, debug builds 2K.
//!
//! `figures` (ignored) prints the sizes and quantization figures of `docs/cwbvh-encoding.md`:
//! `cargo test --release -p dualsplit-accel --test cwbvh -- --ignored --nocapture figures`.

use dualsplit_accel::cwbvh::{CwNode, Cwbvh, Meta, NODE_WORDS};
use dualsplit_accel::wide::cpu::SimdLevel;
use dualsplit_accel::{
    BuildConfig, Bvh2, BvhImage, CollapseConfig, CountingObserver, ImageError, NoObserver,
    NodeStep, Observer, Structures, WideBvh,
};
use dualsplit_geometry::{Aabb, Pcg32, Ray, Triangle, Vec3};
use dualsplit_testkit::oracle::{hit_bits, oracle_any, oracle_closest};
use dualsplit_testkit::rays::{random_rays, record_rays};
use dualsplit_testkit::scenes::{cuboid, random_scene, room, shipped, sphere};
use proptest::prelude::*;
use rayon::prelude::*;

const RAYS: usize = if cfg!(debug_assertions) {
    2_000
} else {
    40_000
};

/// A scene's BVH2 (as its reference image) and compressed BVH8 (checked against the BVH8
/// it is encoded from).
struct Built {
    tris: Vec<Triangle>,
    bvh2: BvhImage,
    cw: Cwbvh,
}

fn try_build(tris: &[Triangle], leaf: u32) -> Result<Built, ImageError> {
    let cfg = BuildConfig {
        max_leaf_size: leaf,
        ..BuildConfig::default()
    };
    try_build_with(tris, &cfg)
}

fn try_build_with(tris: &[Triangle], cfg: &BuildConfig) -> Result<Built, ImageError> {
    let boxes: Vec<Aabb> = tris.iter().map(|t| t.bounds()).collect();
    let bvh = Bvh2::build(&boxes, cfg);
    let zero = std::time::Duration::ZERO;
    let bvh2 = BvhImage::encode(&WideBvh::from_bvh2(&bvh), &bvh, tris, cfg, zero)?;
    let wide = WideBvh::collapse_bvh8(&bvh, &CollapseConfig::default());
    let bvh8 = BvhImage::encode(&wide, &bvh, tris, cfg, zero)?;
    let cw = Cwbvh::from_wide(&wide, &bvh, tris, zero)?;
    assert_eq!(cw.internal_nodes(), bvh8.internal_nodes);
    assert_eq!(cw.leaves(), bvh8.leaves);
    Ok(Built {
        tris: tris.to_vec(),
        bvh2,
        cw,
    })
}

fn build(tris: &[Triangle], leaf: u32) -> Built {
    let b = try_build(tris, leaf).expect("encodes");
    let rep = b.cw.validate();
    assert!(rep.is_ok(), "{rep:?}");
    assert_eq!(rep.structure, "cwbvh");
    assert_eq!(rep.triangles_referenced, tris.len());
    assert_eq!(rep.internal_nodes, b.cw.internal_nodes());
    assert_eq!(rep.leaves, b.cw.leaves());
    b
}

/// Closest hits: the image traversal (plain and counting), the plain query and every
/// instruction set's copy give the BVH2 image's answer, bit for bit.
fn check_closest(b: &Built, copies: &[dualsplit_accel::wide::cpu::CpuBvh], ray: &Ray, what: &str) {
    let want = hit_bits(b.bvh2.closest_hit_image(ray, &mut NoObserver));
    let got = [
        ("image", b.cw.closest_hit_image(ray, &mut NoObserver)),
        (
            "counted",
            b.cw.closest_hit(ray, &mut CountingObserver::default()),
        ),
        ("plain", b.cw.closest_hit(ray, &mut NoObserver)),
    ];
    for (path, h) in got {
        assert_eq!(hit_bits(h), want, "{what}: {path} {ray:?}");
    }
    for c in copies {
        let h = c
            .traverse::<false>(ray)
            .unwrap_or_else(|| b.cw.closest_hit_image(ray, &mut NoObserver));
        assert_eq!(hit_bits(h), want, "{what}: {:?} copy {ray:?}", c.level());
    }
}

/// Shadow answers, as [`check_closest`].
fn check_any(b: &Built, copies: &[dualsplit_accel::wide::cpu::CpuBvh], ray: &Ray, what: &str) {
    let want = b.bvh2.any_hit_image(ray, &mut NoObserver);
    assert_eq!(
        b.cw.any_hit_image(ray, &mut NoObserver),
        want,
        "{what}: image {ray:?}"
    );
    assert_eq!(
        b.cw.any_hit(ray, &mut NoObserver),
        want,
        "{what}: plain {ray:?}"
    );
    assert_eq!(
        b.cw.any_hit(ray, &mut CountingObserver::default()),
        want,
        "{what}: counted {ray:?}"
    );
    for c in copies {
        let h = c
            .traverse::<true>(ray)
            .map_or_else(|| b.cw.any_hit_image(ray, &mut NoObserver), |h| h.is_some());
        assert_eq!(h, want, "{what}: {:?} copy {ray:?}", c.level());
    }
}

fn copies(b: &Built) -> Vec<dualsplit_accel::wide::cpu::CpuBvh> {
    SimdLevel::available()
        .into_iter()
        .map(|l| b.cw.cpu_copy(l))
        .collect()
}

fn scene_box(tris: &[Triangle]) -> Aabb {
    tris.iter().fold(Aabb::EMPTY, |a, t| a.union(t.bounds()))
}

/// Rays recorded from path-traced pixel jobs plus random rays aimed at the scene.
fn equivalence_on(name: &str, scene: &dualsplit_scene::Scene, min_rays: usize) {
    let b = build(&scene.triangles, 4);
    let s = Structures::build(&scene.triangles, &BuildConfig::default());
    let side = (min_rays as f64).sqrt().ceil() as u32;
    let rays = record_rays(scene, &s, side, min_rays);
    let mut rng = Pcg32::new(0xc0b, 5);
    let random = random_rays(&mut rng, &b.tris, &scene_box(&b.tris), min_rays);
    let copies = copies(&b);
    for (what, set) in [
        ("primary", &rays.primary),
        ("diffuse", &rays.diffuse),
        ("random", &random),
    ] {
        set.par_iter().enumerate().for_each(|(i, ray)| {
            check_closest(&b, &copies, ray, &format!("{name} {what} {i}"));
        });
    }
    for (what, set) in [("shadow", &rays.shadow), ("random", &random)] {
        set.par_iter().enumerate().for_each(|(i, ray)| {
            check_any(&b, &copies, ray, &format!("{name} {what} {i}"));
        });
    }
}

#[test]
fn equivalence_dragon_res4() {
    if let Some(scene) = shipped("dragon_res4.ply.gz") {
        equivalence_on("dragon_res4", &scene, RAYS);
    }
}

#[test]
fn equivalence_bunny() {
    if let Some(scene) = shipped("bunny.ply.gz") {
        equivalence_on("bunny", &scene, RAYS);
    }
}

#[test]
fn equivalence_room() {
    equivalence_on("room", &room(false, 12), RAYS / 4);
}

/// Cuboids and spheres of very different sizes, some far from the origin: nodes whose
/// quantization steps are coarse next to their children.
#[test]
fn equivalence_cuboids_and_spheres() {
    let mut tris = Vec::new();
    for i in 0..6 {
        let s = 10f32.powi(i - 2);
        let c = Vec3::new(s * 3.0, -s, 1e5 * i as f32);
        cuboid(
            &mut tris,
            c - Vec3::splat(s),
            c + Vec3::new(s, 2.0 * s, 0.5 * s),
        );
        sphere(&mut tris, c + Vec3::splat(4.0 * s), s, 8);
    }
    let b = build(&tris, 4);
    let copies = copies(&b);
    let mut rng = Pcg32::new(4, 4);
    for (i, ray) in random_rays(&mut rng, &tris, &scene_box(&tris), 20_000)
        .iter()
        .enumerate()
    {
        check_closest(&b, &copies, ray, &format!("cuboids {i}"));
        check_any(&b, &copies, ray, &format!("cuboids {i}"));
    }
}

fn run_random(tris: &[Triangle], leaf: u32, seed: u64) {
    let b = build(tris, leaf);
    let copies = copies(&b);
    let mut rng = Pcg32::new(seed ^ 0x5eed, 11);
    for (i, ray) in random_rays(&mut rng, tris, &scene_box(tris), 60)
        .iter()
        .enumerate()
    {
        let what = format!("seed {seed} leaf {leaf} ray {i}");
        check_closest(&b, &copies, ray, &what);
        check_any(&b, &copies, ray, &what);
        assert_eq!(
            hit_bits(b.cw.closest_hit_image(ray, &mut NoObserver)),
            hit_bits(oracle_closest(tris, ray)),
            "{what}: oracle"
        );
        assert_eq!(
            b.cw.any_hit_image(ray, &mut NoObserver),
            oracle_any(tris, ray)
        );
    }
}

/// A coordinate within ±2^60 (the supported scene range): any exponent there, subnormals
/// and zero included, or an ordinary value.
fn coordinate60() -> impl Strategy<Value = f32> + Clone {
    prop_oneof![
        (any::<bool>(), 0u32..187, 0u32..1 << 23)
            .prop_map(|(neg, e, m)| f32::from_bits(u32::from(neg) << 31 | e << 23 | m)),
        prop::sample::select(vec![2f32.powi(60), -(2f32.powi(60)), 1e17, -1e17]),
        -4.0f32..4.0,
    ]
}

/// The extreme-range generator of `extreme_coordinates.rs`, any coordinate of f32.
fn coordinate_any() -> impl Strategy<Value = f32> + Clone {
    prop_oneof![
        (any::<bool>(), 0u32..255, 0u32..1 << 23)
            .prop_map(|(neg, e, m)| f32::from_bits(u32::from(neg) << 31 | e << 23 | m)),
        prop::sample::select(vec![f32::MAX, -f32::MAX, 3e38, -3e38, 1.9e19, -1.9e19]),
        -4.0f32..4.0,
    ]
}

fn scene_of(c: impl Strategy<Value = f32> + Clone) -> impl Strategy<Value = Vec<Triangle>> {
    let point = [c.clone(), c.clone(), c].prop_map(Vec3::from_array);
    prop::collection::vec(
        [point.clone(), point.clone(), point].prop_map(|[a, b, c]| Triangle::new(a, b, c)),
        1..40,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn random_scenes_match_bvh2_and_oracle(
        seed in any::<u64>(),
        n in 1usize..48,
        shape in 0u32..4,
        leaf in prop::sample::select(vec![1u32, 2, 4]),
        scale in prop::sample::select(vec![1f32, 1e-30, 1e15, 2f32.powi(57)]),
    ) {
        run_random(&random_scene(seed, n, shape, scale), leaf, seed);
    }

    /// Scenes over ±2^60 (the supported range): valid, and every answer the BVH2's.
    #[test]
    fn scenes_within_2_pow_60_match_bvh2(
        tris in scene_of(coordinate60()),
        leaf in prop::sample::select(vec![1u32, 2, 4]),
        seed in any::<u64>(),
    ) {
        let b = build(&tris, leaf);
        let copies = copies(&b);
        let mut rng = Pcg32::new(seed, 3);
        for (i, ray) in random_rays(&mut rng, &tris, &scene_box(&tris), 40).iter().enumerate() {
            check_closest(&b, &copies, ray, &format!("ray {i}"));
            check_any(&b, &copies, ray, &format!("ray {i}"));
        }
    }

    /// Scenes over the whole finite f32 range (beyond what scene loading accepts): the
    /// image encodes and validates (decoded boxes may reach ±∞).
    #[test]
    fn extreme_scenes_build_valid_images(
        tris in scene_of(coordinate_any()),
        leaf in prop::sample::select(vec![1u32, 2, 4]),
    ) {
        build(&tris, leaf);
    }

    /// Leaves larger than 4 triangles: the image encodes and matches the BVH2, or the
    /// encoder returns `LeafSpan`; never a panic.
    #[test]
    fn large_leaves_encode_or_report_leaf_span(
        seed in any::<u64>(),
        n in 1usize..300,
        leaf in prop::sample::select(vec![5u32, 8, 16, 32]),
    ) {
        let tris = random_scene(seed, n, 0, 1.0);
        match try_build(&tris, leaf) {
            Ok(_) => run_random(&tris, leaf, seed),
            Err(e) => prop_assert!(matches!(e, ImageError::LeafSpan { limit: 31, .. }), "{e}"),
        }
    }
}

/// 256 coincident triangles with leaves of 16: a node's runs cannot start within 31 words
/// of its triangle base.
#[test]
fn leaf_span_is_an_error() {
    let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
    let tris = vec![t; 256];
    let e = try_build(&tris, 16).err().expect("leaf runs too far apart");
    assert!(
        matches!(e, ImageError::LeafSpan { words, limit: 31, .. } if words > 31),
        "{e}"
    );
    // The default leaf size always fits: 7 runs of at most 4 before the last.
    build(&tris, 4);
}

#[test]
fn empty_and_one_triangle_scenes() {
    let b = build(&[], 4);
    assert_eq!(b.cw.bytes_total(), 80);
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    assert!(b.cw.closest_hit(&ray, &mut NoObserver).is_none());
    assert!(!b.cw.any_hit_image(&ray, &mut NoObserver));
    let t = Triangle::new(
        Vec3::new(-1.0, -1.0, 2.0),
        Vec3::new(1.0, -1.0, 2.0),
        Vec3::new(0.0, 1.0, 2.0),
    );
    let b = build(&[t], 4);
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    assert_eq!(b.cw.closest_hit(&ray, &mut NoObserver).unwrap().t, 2.0);
    assert_eq!(
        b.cw.closest_hit_image(&ray, &mut NoObserver).unwrap().t,
        2.0
    );
    assert_eq!(b.cw.bytes_total(), 80 + 4);
}

/// The oracle suite's non-finite inputs (`oracle.rs`): NaN and ±3e38 triangles, infinite
/// ones (which only the DST refuses), rays with NaN or infinite parts and `t` ranges, under
/// every build preset: no panic, the BVH2's answers, a clean check where the scene is
/// finite.
#[test]
fn non_finite_scenes_and_rays() {
    let (nan, inf) = (f32::NAN, f32::INFINITY);
    let tri = |a: [f32; 3], b: [f32; 3], c: [f32; 3]| {
        Triangle::new(Vec3::from(a), Vec3::from(b), Vec3::from(c))
    };
    let unit = |z: f32| tri([-1.0, -1.0, z], [1.0, -1.0, z], [0.0, 1.0, z]);
    let scenes = [
        vec![
            tri([nan; 3], [1.0; 3], [0.0; 3]),
            tri([-3e38, -3e38, 0.0], [3e38, -3e38, 0.0], [0.0, 3e38, 1.0]),
            unit(2.0),
            tri([-1e30, -1e30, 1e30], [1e30, -1e30, 1e30], [0.0, 1e30, 1e30]),
        ],
        vec![unit(1.0), unit(2.0)],
        vec![
            unit(2.0),
            tri([inf, 0.0, 4.0], [0.0, inf, 4.0], [-inf, -inf, 4.0]),
        ],
    ];
    let o = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let mut rays = vec![
        Ray::new(o(0.0, 0.0, -5.0), Vec3::Z),
        Ray::new(o(0.0, 0.0, 1.5), Vec3::Z),
        Ray::new(Vec3::splat(0.5), Vec3::splat(-1.0)),
        Ray::new(o(0.0, 0.0, -1e30), Vec3::Z),
        Ray::new(o(nan, 0.0, 0.0), Vec3::Z),
        Ray::new(Vec3::ZERO, o(nan, 0.0, 1.0)),
        Ray::new(Vec3::ZERO, o(0.0, 0.0, inf)),
        Ray::new(o(0.0, 0.0, -inf), Vec3::Z),
        Ray::new(Vec3::ZERO, Vec3::ZERO),
        Ray::new(Vec3::ZERO, o(0.0, 0.0, 1e-30)),
        Ray::new(Vec3::ZERO, o(0.0, 0.0, 1e30)),
        Ray::new(o(0.0, 0.0, 3.0), o(0.0, 0.0, 1.0)),
    ];
    for (lo, hi) in [(nan, inf), (0.0, nan), (-inf, inf), (2.0, 2.0)] {
        rays.push(Ray::segment(Vec3::ZERO, Vec3::Z, lo, hi));
    }
    for tris in &scenes {
        for cfg in [
            BuildConfig::default(),
            BuildConfig::high_quality(),
            BuildConfig::single_triangle_leaves(),
        ] {
            let b = try_build_with(tris, &cfg).expect("encodes");
            if tris.iter().all(Triangle::is_finite) {
                assert!(b.cw.validate().is_ok(), "{:?}", b.cw.validate());
            }
            let copies = copies(&b);
            for (i, ray) in rays.iter().enumerate() {
                check_closest(&b, &copies, ray, &format!("ray {i}"));
                check_any(&b, &copies, ray, &format!("ray {i}"));
            }
        }
    }
}

/// The observer hears an 80-byte node fetch, one 8-ary step per node, the run and the
/// triangle fetches, and as many pushes as the BVH8 would make at most.
#[test]
fn observer_events() {
    #[derive(Default)]
    struct Log(Vec<String>);
    impl Observer for Log {
        fn fetch(&mut self, addr: dualsplit_accel::ByteAddr, bytes: u32) {
            self.0.push(format!("fetch {} {bytes}", addr.0));
        }
        fn step(&mut self, s: NodeStep) {
            self.0.push(format!("{s:?}"));
        }
    }
    let t = Triangle::new(
        Vec3::new(-1.0, -1.0, 2.0),
        Vec3::new(1.0, -1.0, 2.0),
        Vec3::new(0.0, 1.0, 2.0),
    );
    let b = build(&[t], 4);
    let mut log = Log::default();
    b.cw.closest_hit_image(&Ray::new(Vec3::ZERO, Vec3::Z), &mut log);
    // Node at 0 (20 words), run at word 20, triangle region from word 21.
    assert_eq!(
        log.0,
        [
            "fetch 0 80",
            "Bvh { arity: 8, valid: 1, hits: 1 }",
            "fetch 80 4",
            "Leaf { count: 1 }",
            "fetch 84 36",
        ]
    );
}

/// Writes node `at` back after `f` changed it.
fn patch(img: &mut dualsplit_accel::MemoryImage, at: usize, f: impl FnOnce(&mut CwNode)) {
    let mut n = *CwNode::read(&img.words, at);
    f(&mut n);
    img.words[at..at + NODE_WORDS].copy_from_slice(&n.to_words());
}

/// Validation catches a shrunk box (a `q_hi` lowered so that the decoded box no longer
/// holds its subtree), a flipped meta byte and a wrong leaf count; `from_image` refuses
/// them and accepts the original.
#[test]
fn validate_catches_corruption() {
    let scene = room(true, 8);
    let b = build(&scene.triangles, 4);
    let img = b.cw.image().clone();
    let again = Cwbvh::from_image(img.clone()).expect("valid image loads");
    assert_eq!(again.internal_nodes(), b.cw.internal_nodes());
    let ray = Ray::new(Vec3::new(0.1, 0.2, 0.5), Vec3::new(-0.3, -1.0, -0.2));
    assert_eq!(
        hit_bits(again.closest_hit(&ray, &mut NoObserver)),
        hit_bits(b.cw.closest_hit(&ray, &mut NoObserver))
    );
    let root = *CwNode::read(&img.words, 0);
    // Some slot and axis where the decoded box is wider than one step.
    let (k, a) = (0..8)
        .flat_map(|k| (0..3).map(move |a| (k, a)))
        .find(|&(k, a)| root.slot(k) != Meta::Empty && root.q_hi[a][k] > root.q_lo[a][k] + 1)
        .expect("a wide slot");
    let mut shrunk = img.clone();
    patch(&mut shrunk, 0, |n| n.q_hi[a][k] = n.q_lo[a][k]);
    let rep = Cwbvh::from_image(shrunk).expect_err("shrunk box");
    assert!(
        rep.errors.iter().any(|e| e.contains("does not contain")),
        "{rep:?}"
    );

    // An internal slot's meta byte turned into a leaf's.
    let k = (0..8)
        .find(|&k| root.slot(k) == Meta::Internal)
        .expect("an internal child");
    let mut flipped = img.clone();
    patch(&mut flipped, 0, |n| n.meta[k] ^= 0x80);
    assert!(Cwbvh::from_image(flipped).is_err());
    // The internal bit cleared: the slot reads as a leaf, its node unreached.
    let mut flipped = img.clone();
    patch(&mut flipped, 0, |n| n.imask &= !(1 << k));
    let rep = Cwbvh::from_image(flipped).expect_err("imask bit");
    assert!(rep.error_count > 0);

    // A leaf's count bits or offset changed.
    let (at, leaf) = (0..img.nodes.len() / NODE_WORDS)
        .map(|i| i * NODE_WORDS)
        .find_map(|at| {
            let n = CwNode::read(&img.words, at);
            (0..8)
                .find(|&k| matches!(n.slot(k), Meta::Leaf { .. }))
                .map(|k| (at, k))
        })
        .expect("a leaf");
    for flip in [0x01, 0x40, 0xc0] {
        let mut bad = img.clone();
        patch(&mut bad, at, |n| n.meta[leaf] ^= flip);
        let rep = Cwbvh::from_image(bad).expect_err("leaf meta");
        assert!(rep.error_count > 0, "flip {flip:#x}");
    }
    // An exponent out of range.
    let mut bad = img.clone();
    patch(&mut bad, 0, |n| n.e[1] = 0);
    assert!(Cwbvh::from_image(bad).is_err());
    // Truncated node region.
    let mut bad = img.clone();
    bad.nodes = 0..NODE_WORDS - 1;
    assert!(Cwbvh::from_image(bad).is_err());
}
