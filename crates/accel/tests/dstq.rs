//! The quantized DST (`dst-q`): record round trips, conservative plane rounding (proptest),
//! per-ray equivalence with the BVH2 (closest t bits, triangle id, shadow answer) on the
//! shipped meshes and random small scenes for every supported k and cluster size,
//! `validate()` on every tree and on corrupted images, and the measurement table of
//! `docs/dstq-encoding.md` (`measure_table`, ignored: run it with
//! `cargo test --release -p dualsplit-accel --test dstq measure_table -- --ignored --nocapture`).

use dualsplit_accel::dst::{DstConfig, HeaderOffset, Partitioning};
use dualsplit_accel::dstq::frame::{choose_exponent, decode, q_max, quantize_down, quantize_up};
use dualsplit_accel::dstq::layout::ROOT_BIT;
use dualsplit_accel::dstq::record::{read_bits, write_bits};
use dualsplit_accel::dstq::{ChildRef, DstQ, DstQConfig, LeftRecord, QHeader, RecordFormat};
use dualsplit_accel::{
    AccelKind, BuildConfig, ByteAddr, CountingObserver, DstNodeKind, NoObserver, Observer,
    Structures,
};
use dualsplit_geometry::{Aabb, Pcg32, Ray, Triangle, Vec3};
use dualsplit_testkit::oracle::{key, oracle_closest};
use dualsplit_testkit::rays::{random_rays, record_rays};
use dualsplit_testkit::scenes::{random_scene, shipped};
use proptest::prelude::*;

/// Every supported config: k ∈ {4, 6, 8, 10, 12, 16} × 64 and 128-byte clusters.
fn configs() -> Vec<DstQConfig> {
    let mut v = Vec::new();
    for &cluster_bytes in &DstQConfig::MEASURED_CLUSTER_BYTES {
        for &bits in &DstQConfig::MEASURED_BITS {
            v.push(DstQConfig {
                bits,
                cluster_bytes,
            });
        }
    }
    v
}

/// Checks `q` against the BVH2 of `s` on one ray: closest t bits and triangle id (plain and
/// observed), and the shadow answer.
fn check_ray(s: &Structures, q: &DstQ, ray: &Ray, what: &str) {
    let want = s.closest_hit(AccelKind::Bvh2, ray, &mut NoObserver);
    let got = q.closest_hit(ray, &mut NoObserver);
    assert_eq!(key(got), key(want), "{what}: closest hit, ray {ray:?}");
    let obs = q.closest_hit(ray, &mut CountingObserver::default());
    assert_eq!(
        key(obs),
        key(want),
        "{what}: observed closest hit, ray {ray:?}"
    );
    let any = s.any_hit(AccelKind::Bvh2, ray, &mut NoObserver);
    assert_eq!(
        q.any_hit(ray, &mut NoObserver),
        any,
        "{what}: any hit, ray {ray:?}"
    );
}

fn build_all(s: &Structures, what: &str) -> Vec<DstQ> {
    configs()
        .into_iter()
        .map(|cfg| {
            let q = DstQ::from_dst(s.dst(), &cfg).expect("dst-q converts");
            let rep = q.validate(s.dst());
            assert!(rep.is_ok(), "{what} {cfg:?}: {rep:?}");
            assert!(q.validate_structure().is_ok(), "{what} {cfg:?}");
            q
        })
        .collect()
}

// ---------------------------------------------------------------- records and frames

proptest! {
    #[test]
    fn header_round_trip(
        code in prop::sample::select(HeaderOffset::ALL_VALID_HEADERS.to_vec()),
        local in any::<bool>(),
        child in any::<u32>(),
        run in 0u64..(1 << 26),
        bit in 0usize..200,
        cfg in prop::sample::select(configs()),
        left in prop::sample::select(vec![LeftRecord::Leaf, LeftRecord::Long, LeftRecord::Short]),
        q0 in any::<u32>(),
        q1 in any::<u32>(),
    ) {
        let fmt = cfg.record_format();
        let k = fmt.k;
        let exact = HeaderOffset::from_bits((code as u32) << 26);
        let c = if local {
            ChildRef::Local(child % (cfg.cluster_bytes * 8))
        } else {
            ChildRef::Cluster(child % (1 << 25))
        };
        let h = match exact.node_kind() {
            DstNodeKind::Leaf => QHeader::leaf(run).unwrap(),
            DstNodeKind::Split => QHeader::split(exact.axis(), left, c, &fmt).unwrap(),
            _ if exact.is_leaf_flag() => QHeader::carve_leaf(exact, run).unwrap(),
            _ => QHeader::carve(exact, c, &fmt).unwrap(),
        };
        prop_assert!(QHeader::code_is_valid(h.code()));
        prop_assert_eq!(h.node_kind(), exact.node_kind());
        if exact.is_split() {
            prop_assert_eq!(h.exact().axis(), exact.axis());
            prop_assert_eq!(h.left_record(), left);
        } else {
            prop_assert_eq!(h.code(), code as u32);
        }
        if h.is_leaf_flag() {
            prop_assert_eq!(h.run() as u64, run);
        } else {
            prop_assert_eq!(h.child(&fmt), c);
        }
        prop_assert_eq!(h.is_short(), !h.is_leaf_flag() && local);
        // The record through the bit stream, at any alignment, after junk bits.
        let mut w = [u32::MAX; 12];
        let hb = h.header_bits(&fmt);
        let (q0, q1) = (q0 & q_max(k), q1 & q_max(k));
        write_bits(&mut w, bit, hb, h.bits());
        write_bits(&mut w, bit + hb as usize, k, q0);
        write_bits(&mut w, bit + (hb + k) as usize, k, q1);
        let back = QHeader::decode(read_bits(&w, bit, 32), &fmt, 0).unwrap();
        prop_assert_eq!(back, h);
        prop_assert_eq!(back.record_bits(&fmt), hb + if exact.is_plain_leaf() { 0 } else { 2 * k });
        prop_assert_eq!(read_bits(&w, bit + hb as usize, k), q0);
        prop_assert_eq!(read_bits(&w, bit + (hb + k) as usize, k), q1);
    }
}

#[test]
fn short_headers_are_7_plus_w_bits() {
    let f64b = RecordFormat::new(8, 64);
    let f128b = RecordFormat::new(8, 128);
    assert_eq!(
        (f64b.short_header_bits(), f128b.short_header_bits()),
        (16, 17)
    );
}

/// A coordinate: ordinary, huge (up to ±2^60), tiny or subnormal, or zero.
fn coordinate() -> impl Strategy<Value = f32> {
    prop_oneof![
        -8.0f32..8.0,
        (any::<bool>(), 0u32..(127 + 61), 0u32..1 << 23)
            .prop_map(|(neg, e, m)| f32::from_bits(u32::from(neg) << 31 | e << 23 | m)),
        (any::<bool>(), 0u32..1 << 23)
            .prop_map(|(neg, m)| f32::from_bits(u32::from(neg) << 31 | m)),
        Just(0.0f32),
        Just(-0.0f32),
        prop::sample::select(vec![(1u64 << 60) as f32, -((1u64 << 60) as f32)]),
    ]
}

/// A plane to quantize in the frame `[lo, hi]`: inside it (interpolated or at its ends),
/// just outside, or anywhere.
fn plane_in(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    prop_oneof![
        (0.0f64..=1.0).prop_map(move |t| (lo as f64 + t * (hi as f64 - lo as f64)) as f32),
        prop::sample::select(vec![
            lo,
            hi,
            lo.next_up(),
            hi.next_down(),
            lo.next_down(),
            hi.next_up()
        ]),
        coordinate(),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4096, ..ProptestConfig::default() })]

    /// Fails when a quantized plane is not conservative: inside its frame a "≤" plane must
    /// decode at or above the exact plane and a "≥" plane at or below it, with the tightest
    /// such offset; outside it, at or beyond the frame's bound on the plane's side.
    #[test]
    fn quantized_planes_are_conservative(
        (lo, hi, x) in (coordinate(), coordinate(), any::<bool>())
            .prop_flat_map(|(a, b, flat)| {
                let (lo, hi) = if flat { (a, a) } else { (a.min(b), a.max(b)) };
                (Just(lo), Just(hi), plane_in(lo, hi))
            }),
        k in prop::sample::select(DstQConfig::MEASURED_BITS.to_vec()),
    ) {
        let e = choose_exponent(lo, hi, k);
        prop_assert!(decode(lo, e, q_max(k)) >= hi, "the frame's top reaches hi");
        prop_assert!(e == 0 || decode(lo, e - 1, q_max(k)) < hi, "smallest exponent");
        let up = quantize_up(x, lo, e, k);
        let down = quantize_down(x, lo, e, k);
        let (pu, pd) = (decode(lo, e, up), decode(lo, e, down));
        prop_assert!(up <= q_max(k) && down <= q_max(k));
        if (lo..=hi).contains(&x) {
            prop_assert!(pu >= x, "≤ plane {x} rounded down to {pu} (frame {lo}..{hi}, k {k})");
            prop_assert!(pd <= x, "≥ plane {x} rounded up to {pd} (frame {lo}..{hi}, k {k})");
            prop_assert!(up == 0 || decode(lo, e, up - 1) < x, "tightest ≤ plane");
            prop_assert!(down == q_max(k) || decode(lo, e, down + 1) > x, "tightest ≥ plane");
        }
        prop_assert!(pu >= x.min(hi), "≤ plane {x} below min(x, frame top {hi}): {pu}");
        prop_assert!(pd <= x.max(lo), "≥ plane {x} above max(x, frame bottom {lo}): {pd}");
    }
}

#[test]
fn infinite_planes_map_to_the_frame() {
    for k in DstQConfig::MEASURED_BITS {
        let e = choose_exponent(-3.0, 5.0, k);
        assert_eq!(quantize_up(f32::INFINITY, -3.0, e, k), q_max(k));
        assert_eq!(quantize_down(f32::NEG_INFINITY, -3.0, e, k), 0);
        assert!(decode(-3.0, e, q_max(k)) >= 5.0);
    }
}

#[test]
fn bad_configs_are_refused() {
    let dst = dualsplit_testkit::dst::build(&one_triangle(), &DstConfig::hardware()).dst;
    for (bits, cluster_bytes) in [(0, 64), (17, 64), (8, 30), (8, 62), (16, 28), (8, 8192)] {
        let cfg = DstQConfig {
            bits,
            cluster_bytes,
        };
        assert!(DstQ::from_dst(&dst, &cfg).is_err(), "{cfg:?}");
    }
}

// ---------------------------------------------------------------- equivalence with BVH2

fn one_triangle() -> Vec<Triangle> {
    vec![Triangle::new(
        Vec3::new(-1.0, -1.0, 2.0),
        Vec3::new(1.0, -1.0, 2.0),
        Vec3::new(0.0, 1.0, 2.0),
    )]
}

fn random_case(tris: &[Triangle], seed: u64, leaf: u32, similar: bool, scale: f32) {
    let tris: Vec<Triangle> = tris
        .iter()
        .map(|t| Triangle::new(t.v[0] * scale, t.v[1] * scale, t.v[2] * scale))
        .collect();
    let bcfg = BuildConfig {
        max_leaf_size: leaf,
        ..BuildConfig::default()
    };
    let dcfg = if similar {
        DstConfig::hardware().with_partitioning(Partitioning::Similar)
    } else {
        DstConfig::hardware()
    };
    let s = Structures::try_build_with(&tris, &bcfg, &dcfg).expect("structures");
    let qs = build_all(&s, "random scene");
    if tris.is_empty() {
        return;
    }
    let b = tris.iter().fold(Aabb::EMPTY, |a, t| a.union(t.bounds()));
    let mut rng = Pcg32::new(seed ^ 0x5eed, 11);
    let rays = random_rays(&mut rng, &tris, &b, 60);
    for ray in &rays {
        // The BVH2 equals the oracle on these scenes (tests/dst_random.rs); hold it here too.
        assert_eq!(
            key(s.closest_hit(AccelKind::Bvh2, ray, &mut NoObserver)),
            key(oracle_closest(&tris, ray))
        );
        for q in &qs {
            check_ray(&s, q, ray, &format!("{:?}", q.config()));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn random_scenes_match_bvh2(
        seed in any::<u64>(),
        n in 1usize..48,
        shape in 0u32..4,
        leaf in prop::sample::select(vec![1u32, 2, 4]),
        similar in any::<bool>(),
        scale in prop::sample::select(vec![1.0f32, 1e-30, 1e15, 3.0e17]),
    ) {
        random_case(&random_scene(seed, n, shape, 1.0), seed, leaf, similar, scale);
    }
}

#[test]
fn edge_scenes_match_bvh2() {
    // Empty scene: every ray misses.
    let s = Structures::build(&[], &BuildConfig::default());
    for q in build_all(&s, "empty") {
        assert!(q.is_empty());
        assert!(
            q.closest_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut NoObserver)
                .is_none()
        );
        assert!(!q.any_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut NoObserver));
    }
    random_case(&one_triangle(), 1, 4, false, 1.0);
    // Triangles in axis planes, a flat scene, a scene far from the origin.
    for shape in 0..4 {
        for seed in 0..6 {
            random_case(&random_scene(seed, 40, shape, 1.0), seed, 1, false, 1.0);
        }
    }
    let far: Vec<Triangle> = random_scene(9, 40, 0, 1.0)
        .iter()
        .map(|t| {
            let o = Vec3::splat((1u64 << 40) as f32);
            Triangle::new(t.v[0] * 1e8 + o, t.v[1] * 1e8 + o, t.v[2] * 1e8 + o)
        })
        .collect();
    random_case(&far, 9, 2, false, 1.0);
    // Rays with zero direction components along the planes of a grid scene.
    let tris = random_scene(3, 30, 1, 1.0);
    let s = Structures::build(&tris, &BuildConfig::default());
    let qs = build_all(&s, "grid");
    for t in &tris {
        for d in [Vec3::X, -Vec3::Y, Vec3::Z, Vec3::new(1.0, 0.0, -1.0)] {
            let ray = Ray::new(t.v[0] - d * 10.0, d);
            for q in &qs {
                check_ray(&s, q, &ray, "axis ray");
            }
        }
    }
}

fn shipped_case(name: &str, n: usize) {
    let Some(scene) = shipped(name) else {
        return;
    };
    let s = Structures::build(&scene.triangles, &BuildConfig::default());
    let qs = build_all(&s, name);
    let sets = record_rays(&scene, &s, 48, n);
    let b = s.dst().scene_box();
    let random = random_rays(&mut Pcg32::new(5, 5), &scene.triangles, &b, n);
    for q in &qs {
        let what = format!("{name} {:?}", q.config());
        for rays in [&sets.primary, &sets.shadow, &sets.diffuse, &random] {
            for ray in rays.iter().take(n) {
                check_ray(&s, q, ray, &what);
            }
        }
    }
}

#[test]
fn dragon_res4_matches_bvh2() {
    shipped_case("dragon_res4.ply.gz", 3000);
}

#[test]
fn bunny_matches_bvh2() {
    shipped_case("bunny.ply.gz", 3000);
}

/// The observed traversal reports the exact DST's steps for every node it shares with it,
/// and the frame and record words it reads lie inside the node region.
#[test]
fn observer_reports_word_accurate_fetches() {
    #[derive(Default)]
    struct Fetches(Vec<(ByteAddr, u32)>);
    impl Observer for Fetches {
        fn fetch(&mut self, addr: ByteAddr, bytes: u32) {
            self.0.push((addr, bytes));
        }
    }
    let tris = random_scene(4, 40, 0, 1.0);
    let s = Structures::build(&tris, &BuildConfig::default());
    let b = s.dst().scene_box();
    let rays = random_rays(&mut Pcg32::new(1, 2), &tris, &b, 200);
    for q in build_all(&s, "observer") {
        let node_end = q.image().node_bytes();
        let cb = q.config().cluster_bytes as u64;
        for ray in &rays {
            let mut f = Fetches::default();
            q.closest_hit(ray, &mut f);
            for &(a, n) in &f.0 {
                assert!(a.0 % 4 == 0 && n % 4 == 0 && n > 0);
                if a.0 < node_end {
                    // A record never crosses its block.
                    assert_eq!(a.0 / cb, (a.0 + n as u64 - 1) / cb, "{a:?} {n}");
                }
            }
            // Exact DST work is a lower bound of the quantized work.
            let (mut e, mut o) = (CountingObserver::default(), CountingObserver::default());
            s.dst().closest_hit(ray, &mut e);
            q.closest_hit(ray, &mut o);
            assert!(o.nodes >= e.nodes && o.triangle_tests >= e.triangle_tests);
        }
    }
}

// ---------------------------------------------------------------- validate

fn dragon_or_random() -> Structures {
    match shipped("dragon_res4.ply.gz") {
        Some(sc) => Structures::build(&sc.triangles, &BuildConfig::default()),
        None => Structures::build(&random_scene(2, 400, 0, 1.0), &BuildConfig::default()),
    }
}

/// Bit position of the first record in block 0 whose kind is `kind` (walking the
/// in-cluster records from the root in order of their bits).
fn first_record(q: &DstQ, kind: DstNodeKind) -> Option<u32> {
    let cw = q.config().cluster_words() as usize;
    let words = &q.image().words[..cw];
    let fmt = q.config().record_format();
    let mut bit = ROOT_BIT;
    while bit + 32 <= q.config().cluster_bytes * 8 {
        let h = QHeader::read(read_bits(words, bit as usize, 32), &fmt);
        if h.node_kind() == kind && QHeader::code_is_valid(h.code()) {
            return Some(bit);
        }
        bit += h.record_bits(&fmt);
    }
    None
}

#[test]
fn validate_catches_a_shrunk_plane() {
    let s = dragon_or_random();
    for cfg in configs() {
        let q = DstQ::from_dst(s.dst(), &cfg).unwrap();
        let bit = first_record(&q, DstNodeKind::Split).expect("a split in the root block");
        let k = cfg.bits as usize;
        let mut img = q.image().clone();
        // P0 of a split is a "≤" plane: offset 0 moves it to the frame's bottom.
        let fmt = cfg.record_format();
        let h = QHeader::read(read_bits(&img.words, bit as usize, 32), &fmt);
        let p0 = (bit + h.header_bits(&fmt)) as usize;
        assert_ne!(read_bits(&img.words, p0, k as u32), 0);
        write_bits(&mut img.words, p0, k as u32, 0);
        let bad = DstQ::from_image(img, q.scene_box(), cfg).expect("still well formed");
        let rep = bad.validate(s.dst());
        assert!(!rep.is_ok(), "{cfg:?}");
        assert!(
            rep.errors.iter().any(|e| e.contains("not conservative")),
            "{cfg:?}: {rep:?}"
        );
        // P1 is a "≥" plane: the top offset moves it to the frame's top.
        let mut img = q.image().clone();
        write_bits(&mut img.words, p0 + k, k as u32, q_max(k as u32));
        let bad = DstQ::from_image(img, q.scene_box(), cfg).unwrap();
        assert!(!bad.validate(s.dst()).is_ok(), "{cfg:?}");
    }
}

#[test]
fn validate_catches_bad_offsets() {
    let s = dragon_or_random();
    let cfg = DstQConfig::default();
    let q = DstQ::from_dst(s.dst(), &cfg).unwrap();
    let bit = first_record(&q, DstNodeKind::Split).unwrap() as usize;
    let fmt = cfg.record_format();
    let h = QHeader::read(read_bits(&q.image().words, bit, 32), &fmt);
    assert!(h.is_short(), "the root's children share its cluster");
    let axis = h.exact().axis();
    let short = |c| QHeader::split(axis, h.left_record(), c, &fmt).unwrap();
    let long = QHeader::split(
        axis,
        h.left_record(),
        ChildRef::Cluster((1 << 25) - 1),
        &fmt,
    );
    for (bad, n) in [
        (short(ChildRef::Local(3)).bits(), 16), // a local child inside the frame
        (short(ChildRef::Local(511)).bits(), 16), // a local child at the line's end
        (long.unwrap().bits(), 32),             // a cluster past the region
        (0, 16),                                // an invalid code (split with B = 00)
    ] {
        let mut img = q.image().clone();
        write_bits(&mut img.words, bit, n, bad);
        let rep = DstQ::from_image(img, q.scene_box(), cfg).expect_err("refused");
        assert!(!rep.is_ok() && rep.structure == "dst-q", "{bad:#x}");
    }
    // A truncated node region.
    let mut img = q.image().clone();
    img.nodes.end -= 1;
    assert!(DstQ::from_image(img, q.scene_box(), cfg).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Arbitrary words in a tree's node region give a report (or a tree that traverses
    /// without panicking), never a panic or an endless walk.
    #[test]
    fn arbitrary_words_never_panic(
        seed in any::<u64>(),
        edits in prop::collection::vec((any::<u32>(), any::<u32>()), 1..24),
    ) {
        let tris = random_scene(seed, 30, 0, 1.0);
        let s = Structures::build(&tris, &BuildConfig::default());
        let cfg = DstQConfig::default();
        let q = DstQ::from_dst(s.dst(), &cfg).unwrap();
        let mut img = q.image().clone();
        let n = img.nodes.len().max(1) as u32;
        for (at, v) in edits {
            let i = (at % n) as usize;
            if i < img.nodes.len() {
                img.words[i] = v;
            }
        }
        if let Ok(t) = DstQ::from_image(img, q.scene_box(), cfg) {
            let _ = t.validate(s.dst());
            let b = s.dst().scene_box();
            for ray in random_rays(&mut Pcg32::new(seed, 3), &tris, &b, 8) {
                t.closest_hit(&ray, &mut CountingObserver::default());
            }
        }
    }
}

/// The worked example of `docs/dstq-encoding.md`, §5, word for word.
#[test]
fn worked_example_words() {
    let tris = vec![
        Triangle::new(
            Vec3::new(-1.0, -1.0, 2.0),
            Vec3::new(1.0, -1.0, 2.0),
            Vec3::new(0.0, 1.0, 2.0),
        ),
        Triangle::new(
            Vec3::new(-0.5, -2.0, 3.0),
            Vec3::new(1.0, -1.0, 3.5),
            Vec3::new(0.0, 0.3, 3.0),
        ),
    ];
    let bcfg = BuildConfig {
        max_leaf_size: 1,
        ..BuildConfig::default()
    };
    let s = Structures::try_build_with(&tris, &bcfg, &DstConfig::hardware()).unwrap();
    let q = DstQ::from_dst(s.dst(), &DstQConfig::default()).unwrap();
    assert!(q.validate(s.dst()).is_ok());
    let img = q.image();
    assert_eq!(img.nodes.len(), 16, "one 64-byte line");
    assert_eq!(
        &img.words[..8],
        &[
            0xbf80_0000, // origin x = -1.0
            0xc000_0000, // origin y = -2.0
            0x4000_0000, // origin z = 2.0
            0x0378_7979, // e = (121, 121, 120), 3 records
            0x8000_5016, // root, short header: split on z, left long, local child at bit 160;
            //              q0 = 0x00 (z ≤ 2.0), q1 = 0x80 (z ≥ 3.0)
            0x0000_0033, // left: single-axis y carving leaf, run 0
            0x0065_40ff, // left q0 = 255 (y ≤ +∞ → 1.984375), q1 = 64 (y ≥ -1); right header, low half
            0x9420_0000, // right header, high half (dual xy carving leaf, run 1); q0 = 32, q1 = 148
        ]
    );
    assert!(img.words[8..16].iter().all(|&w| w == 0));
    let st = q.stats();
    assert_eq!((st.clusters, st.used_bits, st.node_bytes), (1, 256, 64));
}

/// A coordinate from anywhere in the finite f32 range (as `tests/extreme_coordinates.rs`).
fn any_coordinate() -> impl Strategy<Value = f32> {
    prop_oneof![
        (any::<bool>(), 0u32..255, 0u32..1 << 23)
            .prop_map(|(neg, e, m)| f32::from_bits(u32::from(neg) << 31 | e << 23 | m)),
        prop::sample::select(vec![f32::MAX, -f32::MAX, 3e38, -3e38, 1.9e19, -1.9e19]),
        -4.0f32..4.0,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Scenes spanning the whole finite f32 range (frames wider than `f32::MAX`, subnormal
    /// extents next to huge ones) convert under every config and validate against the DST.
    #[test]
    fn extreme_scenes_convert_and_validate(
        tris in prop::collection::vec(
            [any_coordinate(), any_coordinate(), any_coordinate()]
                .prop_map(Vec3::from_array)
                .prop_flat_map(|a| (Just(a), [any_coordinate(), any_coordinate(), any_coordinate()].prop_map(Vec3::from_array), [any_coordinate(), any_coordinate(), any_coordinate()].prop_map(Vec3::from_array)))
                .prop_map(|(a, b, c)| Triangle::new(a, b, c)),
            1..40,
        ),
        leaf in prop::sample::select(vec![1u32, 4]),
    ) {
        let bcfg = BuildConfig { max_leaf_size: leaf, ..BuildConfig::default() };
        let s = Structures::try_build_with(&tris, &bcfg, &DstConfig::hardware()).expect("structures");
        build_all(&s, "extreme scene");
    }
}
