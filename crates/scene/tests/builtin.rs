//! Builtin scenes: determinism, triangle budgets, sanity of the geometry, typed errors.

use dualsplit_geometry::Triangle;
use dualsplit_scene::{Scene, SceneError, builtin, load};

fn scene_of(spec: &str) -> Scene {
    builtin::generate(spec).unwrap_or_else(|e| panic!("{spec}: {e}"))
}

fn bits(t: &[Triangle]) -> Vec<u32> {
    t.iter()
        .flat_map(|t| {
            t.v.iter()
                .flat_map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        })
        .collect()
}

/// Small specs of every builtin, cheap enough for debug test runs.
const SMALL: [&str; 4] = [
    "hairball?triangles=20000&seed=3",
    "forest?triangles=30000&seed=3",
    "atrium?triangles=40000&seed=3",
    "cornell?subdiv=3",
];

#[test]
fn same_spec_gives_bit_identical_triangles() {
    for spec in SMALL {
        let a = scene_of(spec);
        let b = scene_of(spec);
        assert_eq!(a.triangles.len(), b.triangles.len(), "{spec}");
        assert!(
            bits(&a.triangles) == bits(&b.triangles),
            "{spec}: triangles differ"
        );
        assert_eq!(a.camera, b.camera, "{spec}");
        assert_eq!(a.light, b.light, "{spec}");
    }
}

#[test]
fn result_does_not_depend_on_thread_count() {
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    for spec in &SMALL[..3] {
        let a = one.install(|| scene_of(spec));
        let b = three.install(|| scene_of(spec));
        assert!(
            bits(&a.triangles) == bits(&b.triangles),
            "{spec}: differs by thread count"
        );
    }
}

#[test]
fn different_seed_gives_different_triangles() {
    for name in [
        "hairball?triangles=20000",
        "forest?triangles=30000",
        "atrium?triangles=40000",
    ] {
        let a = scene_of(&format!("{name}&seed=1"));
        let b = scene_of(&format!("{name}&seed=2"));
        assert!(
            bits(&a.triangles) != bits(&b.triangles),
            "{name}: seed has no effect"
        );
    }
}

fn assert_within_5_percent(spec: &str, want: usize) {
    let s = scene_of(spec);
    assert_eq!(s.stats.degenerate, 0, "{spec}: zero-area triangles");
    let got = s.triangles.len();
    let lo = want - want / 20;
    let hi = want + want / 20;
    assert!(
        (lo..=hi).contains(&got),
        "{spec}: {got} triangles, want {want} ± 5 %"
    );
}

#[test]
fn requested_sizes_are_met_within_5_percent() {
    for (name, sizes) in [
        ("hairball", &[160usize, 1_000, 7_777, 50_000][..]),
        ("forest", &[100, 1_000, 9_999, 60_000][..]),
        ("atrium", &[30_000, 77_777][..]),
    ] {
        for &n in sizes {
            assert_within_5_percent(&format!("{name}?triangles={n}"), n);
        }
    }
}

#[test]
fn default_sizes_match_the_paper_scenes() {
    // Lin et al. 2020, Table 3: Hairball 2.9M, Vegetation 1.1M, Crytek Sponza 262K.
    assert_within_5_percent("hairball", 2_900_000);
    assert_within_5_percent("forest", 1_100_000);
    assert_within_5_percent("atrium", 262_000);
    assert_eq!(scene_of("cornell").triangles.len(), 34);
}

#[test]
fn cornell_subdivision_count_is_exact() {
    for n in [1u32, 2, 5] {
        let s = scene_of(&format!("cornell?subdiv={n}"));
        assert_eq!(s.triangles.len(), 10 * (n * n) as usize + 24);
    }
}

#[test]
fn geometry_is_finite_and_bounds_are_sane() {
    for spec in SMALL {
        let s = scene_of(spec);
        assert_eq!(s.stats.non_finite, 0, "{spec}");
        assert!(s.triangles.iter().all(|t| t.is_finite()), "{spec}");
        assert!(s.bounds.is_finite(), "{spec}");
        let e = s.bounds.extent();
        assert!(e.min_element() > 0.0, "{spec}: flat bounds {e:?}");
        assert!(e.max_element() < 1000.0, "{spec}: huge bounds {e:?}");
        // Degenerate (zero-area) triangles are allowed by the loader rules but a generator
        // should not produce them.
        assert_eq!(s.stats.degenerate, 0, "{spec}");
        // The default camera looks at something inside the scene, from a finite eye, and
        // the light is finite.
        assert!(
            s.camera.eye.is_finite() && s.light.position.is_finite(),
            "{spec}"
        );
        let (lo, hi) = (s.bounds.min, s.bounds.max);
        let t = s.camera.target;
        assert!(
            t.cmpge(lo).all() && t.cmple(hi).all(),
            "{spec}: target {t:?} outside"
        );
        assert!(s.light.radius > 0.0 && s.light.intensity > 0.0, "{spec}");
    }
}

#[test]
fn hairball_stays_in_its_ball() {
    let s = scene_of("hairball?triangles=50000&seed=9");
    for t in &s.triangles {
        for p in t.v {
            assert!(p.length() < 1.1, "hairball vertex {p:?} outside the ball");
        }
    }
}

#[test]
fn atrium_is_mostly_axis_aligned() {
    // What makes Sponza-like scenes cheap for dual-split trees (Lin et al. 2020, §4.2).
    let s = scene_of("atrium?triangles=40000");
    let aligned = s
        .triangles
        .iter()
        .filter(|t| {
            let n = t.normal().abs();
            let m = n.max_element();
            (n.x == m && n.y == 0.0 && n.z == 0.0)
                || (n.y == m && n.x == 0.0 && n.z == 0.0)
                || (n.z == m && n.x == 0.0 && n.y == 0.0)
        })
        .count();
    assert!(
        aligned * 10 >= s.triangles.len() * 6,
        "only {aligned} of {} triangles axis-aligned",
        s.triangles.len()
    );
}

#[test]
fn load_resolves_builtin_specs() {
    let s = load("builtin:cornell?subdiv=2").unwrap();
    assert_eq!(s.name, "cornell");
    assert_eq!(s.spec, "builtin:cornell?subdiv=2");
    assert_eq!(s.triangles.len(), 64);
}

fn message(spec: &str) -> String {
    match builtin::generate(spec) {
        Err(SceneError::Builtin { spec: s, message }) => {
            assert_eq!(s, spec);
            message
        }
        Err(e) => panic!("{spec}: wrong error kind {e:?}"),
        Ok(_) => panic!("{spec}: accepted"),
    }
}

#[test]
fn bad_specs_are_typed_errors() {
    assert!(message("teapot").contains("unknown builtin scene `teapot`"));
    assert!(message("").contains("missing scene name"));
    assert!(message("hairball?colour=red").contains("unknown key `colour`"));
    assert!(message("cornell?seed=1").contains("unknown key `seed`"));
    assert!(message("forest?triangles=many").contains("`triangles=many`"));
    assert!(message("forest?triangles=-5").contains("`triangles=-5`"));
    assert!(message("hairball?triangles=0").contains("out of range"));
    assert!(message("atrium?triangles=0").contains("out of range"));
    assert!(message("cornell?subdiv=0").contains("out of range"));
    assert!(message("hairball?triangles=50").contains("too small"));
    assert!(message("atrium?triangles=500").contains("too small"));
    assert!(message("hairball?radius=NaN").contains("out of range"));
    assert!(message("hairball?seed=1&seed=2").contains("given twice"));
    assert!(message("hairball?seed").contains("key=value"));
    assert!(message("hairball?seed=").contains("empty"));
    assert!(message("hairball?sides=2").contains("out of range"));
}

#[test]
fn bad_spec_errors_display_the_spec() {
    let e = builtin::generate("forest?leaves=x").unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("forest?leaves=x") && text.contains("leaves"),
        "{text}"
    );
}

#[test]
fn extreme_knobs_give_finite_scenes_of_the_right_size() {
    for (spec, want) in [
        ("hairball?triangles=5000&sides=3&segments=2&curl=0", 5000),
        (
            "hairball?triangles=5000&sides=16&segments=10000&radius=0.2&length=100",
            5000,
        ),
        ("hairball?triangles=5000&radius=0.00001&curl=1000", 5000),
        ("forest?triangles=5000&leaves=0&tree_share=1", 5000),
        ("forest?triangles=5000&tree_share=0&size=1", 5000),
        ("forest?triangles=20000&leaves=100000", 20000),
        ("atrium?triangles=100000&bays=64", 100000),
        ("atrium?triangles=20000&bays=2", 20000),
    ] {
        let s = scene_of(spec);
        assert_eq!(s.stats.non_finite, 0, "{spec}");
        assert!(s.bounds.is_finite(), "{spec}");
        let n = s.triangles.len();
        assert!(
            n.abs_diff(want) * 20 <= want,
            "{spec}: {n} triangles, want {want}"
        );
    }
}
