//! Traversal benchmarks through [`Structures`] for every [`AccelKind`]: closest hit on
//! primary and diffuse-bounce rays, any hit on shadow rays, recorded from path-traced pixel
//! jobs on `dragon_box` and `sponza_dabrovic`. Every structure's answers are checked
//! against the BVH2 per ray before anything is timed.
//!
//! Run: `cargo bench -p dualsplit-accel --bench traversal`. Each sample traces a whole ray
//! set; divan reports the time per set (`RAYS` rays).

use dualsplit_accel::{AccelKind, BuildConfig, NoObserver, Structures};
use dualsplit_geometry::Ray;
use dualsplit_testkit::oracle::key;
use dualsplit_testkit::rays::record_rays;
use dualsplit_testkit::scenes::shipped;
use std::sync::OnceLock;

/// Rays of each kind per set.
const RAYS: usize = 20_000;

struct Data {
    s: Structures,
    primary: Vec<Ray>,
    shadow: Vec<Ray>,
    diffuse: Vec<Ray>,
}

fn data(scene: &str) -> &'static Data {
    static BOX: OnceLock<Data> = OnceLock::new();
    static SPONZA: OnceLock<Data> = OnceLock::new();
    let cell = if scene == "dragon_box" { &BOX } else { &SPONZA };
    cell.get_or_init(|| {
        let sc = shipped(&format!("{scene}.ply.gz")).expect("the benchmark needs this mesh");
        let s = Structures::build(&sc.triangles, &BuildConfig::default());
        let r = record_rays(&sc, &s, 150, RAYS);
        let cut = |v: Vec<Ray>| v.into_iter().take(RAYS).collect::<Vec<_>>();
        let d = Data {
            primary: cut(r.primary),
            shadow: cut(r.shadow),
            diffuse: cut(r.diffuse),
            s,
        };
        // Check before timing.
        for kind in AccelKind::ALL {
            for set in [&d.primary, &d.diffuse] {
                for ray in set {
                    let want = key(d.s.closest_hit(AccelKind::Bvh2, ray, &mut NoObserver));
                    assert_eq!(key(d.s.closest_hit(kind, ray, &mut NoObserver)), want);
                }
            }
            for ray in &d.shadow {
                let want = d.s.any_hit(AccelKind::Bvh2, ray, &mut NoObserver);
                assert_eq!(d.s.any_hit(kind, ray, &mut NoObserver), want);
            }
        }
        d
    })
}

/// `scene/kind` cases.
const CASES: [&str; 10] = [
    "dragon_box/bvh2",
    "dragon_box/bvh4",
    "dragon_box/bvh8",
    "dragon_box/dst-sw",
    "dragon_box/dst",
    "sponza_dabrovic/bvh2",
    "sponza_dabrovic/bvh4",
    "sponza_dabrovic/bvh8",
    "sponza_dabrovic/dst-sw",
    "sponza_dabrovic/dst",
];

fn case(c: &str) -> (&'static Data, AccelKind) {
    let (scene, kind) = c.split_once('/').unwrap();
    (data(scene), AccelKind::parse(kind).unwrap())
}

fn closest(bencher: divan::Bencher, c: &str, which: fn(&Data) -> &Vec<Ray>) {
    let (d, kind) = case(c);
    bencher.bench(|| {
        let mut n = 0u32;
        for ray in which(d) {
            n += d.s.closest_hit(kind, ray, &mut NoObserver).is_some() as u32;
        }
        n
    });
}

#[divan::bench(args = CASES, sample_count = 10)]
fn primary(bencher: divan::Bencher, c: &str) {
    closest(bencher, c, |d| &d.primary);
}

#[divan::bench(args = CASES, sample_count = 10)]
fn diffuse(bencher: divan::Bencher, c: &str) {
    closest(bencher, c, |d| &d.diffuse);
}

#[divan::bench(args = CASES, sample_count = 10)]
fn shadow(bencher: divan::Bencher, c: &str) {
    let (d, kind) = case(c);
    bencher.bench(|| {
        let mut n = 0u32;
        for ray in &d.shadow {
            n += d.s.any_hit(kind, ray, &mut NoObserver) as u32;
        }
        n
    });
}

fn main() {
    divan::main();
}
