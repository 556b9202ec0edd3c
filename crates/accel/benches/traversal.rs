//! Traversal benchmarks through [`Structures`] for every [`AccelKind`]: closest hit on
//! primary and diffuse-bounce rays, any hit on shadow rays, recorded from path-traced pixel
//! jobs on `dragon_box` and `sponza_dabrovic`. Every structure's answers are checked
//! against the BVH2 per ray before anything is timed.
//!
//! Run: `cargo bench -p dualsplit-accel --bench traversal`. Each sample traces a whole ray
//! set; divan reports the time per set (`RAYS` rays).

#[path = "../tests/support/mod.rs"]
mod support;

use dualsplit_accel::{AccelKind, BuildConfig, NoObserver, Structures};
use dualsplit_geometry::Ray;
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
        let sc = support::load_scene(&format!("{scene}.ply.gz"));
        let s = Structures::build(&sc.triangles, &BuildConfig::default());
        let r = support::record_rays(&sc, &s, 150, RAYS);
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
                    let want = support::key(d.s.closest_hit(AccelKind::Bvh2, ray, &mut NoObserver));
                    assert_eq!(
                        support::key(d.s.closest_hit(kind, ray, &mut NoObserver)),
                        want
                    );
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

const SCENES: [&str; 2] = ["dragon_box", "sponza_dabrovic"];
const KINDS: [&str; 5] = ["bvh2", "bvh4", "bvh8", "dst-sw", "dst"];

fn closest(bencher: divan::Bencher, scene: &str, kind: &str, which: fn(&Data) -> &Vec<Ray>) {
    let d = data(scene);
    let kind = AccelKind::parse(kind).unwrap();
    bencher.bench(|| {
        let mut n = 0u32;
        for ray in which(d) {
            n += d.s.closest_hit(kind, ray, &mut NoObserver).is_some() as u32;
        }
        n
    });
}

#[divan::bench(args = KINDS, consts = [0, 1], sample_count = 10)]
fn primary<const SCENE: usize>(bencher: divan::Bencher, kind: &str) {
    closest(bencher, SCENES[SCENE], kind, |d| &d.primary);
}

#[divan::bench(args = KINDS, consts = [0, 1], sample_count = 10)]
fn diffuse<const SCENE: usize>(bencher: divan::Bencher, kind: &str) {
    closest(bencher, SCENES[SCENE], kind, |d| &d.diffuse);
}

#[divan::bench(args = KINDS, consts = [0, 1], sample_count = 10)]
fn shadow<const SCENE: usize>(bencher: divan::Bencher, kind: &str) {
    let d = data(SCENES[SCENE]);
    let kind = AccelKind::parse(kind).unwrap();
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
