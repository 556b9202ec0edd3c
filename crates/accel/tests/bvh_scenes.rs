//! BVH2, BVH4 and BVH8 on the shipped scenes: identical leaves, clean validation, and
//! per-ray identical answers for primary, shadow and diffuse-bounce rays recorded from
//! path-traced pixel jobs on each scene's default camera: every BVH's plain query (its
//! CPU-side copy, [`dualsplit_accel::wide::cpu`]) and its image traversal (what the
//! simulator reads) against the BVH2's image traversal, hit for hit and bit for bit; the
//! CPU-side copies with every instruction set this CPU has (SSE2, and AVX2 where present),
//! and through [`Tracer`]s, each reused over the rays of one rayon job.
//!
//! Release builds (`cargo test --release`, what CI runs) compare at least 100K rays of each
//! kind per scene; debug builds compare 3K of each so that `cargo test` stays quick.

use dualsplit_accel::wide::cpu::{CpuBvh, SimdLevel};
use dualsplit_accel::{
    AccelKind, BuildConfig, CollapseConfig, NoObserver, Structures, Tracer, TraversalSet, WideBvh,
};
use dualsplit_testkit::oracle::{hit_bits, key};
use dualsplit_testkit::rays::record_rays;
use dualsplit_testkit::scenes::shipped;
use rayon::prelude::*;

const RAYS: usize = if cfg!(debug_assertions) {
    3_000
} else {
    100_000
};

fn equivalence(name: &str) {
    if let Some(scene) = shipped(name) {
        equivalence_on(name, &scene, RAYS);
    }
}

/// Every builtin scene (reduced sizes), with its preset camera; a quarter of the shipped
/// meshes' ray count (the dense hairball blocks most light paths).
#[test]
fn equivalence_builtins() {
    for spec in [
        "builtin:cornell",
        "builtin:atrium?triangles=20000",
        "builtin:forest?triangles=20000",
        "builtin:hairball?triangles=20000",
    ] {
        let scene = dualsplit_scene::load(spec).expect("builtin scene");
        equivalence_on(spec, &scene, RAYS / 4);
    }
}

fn equivalence_on(name: &str, scene: &dualsplit_scene::Scene, min_rays: usize) {
    let s = Structures::build(&scene.triangles, &BuildConfig::default());
    for rep in s.validate() {
        assert!(rep.is_ok(), "{name}: {rep:?}");
        assert_eq!(rep.triangles_referenced, scene.triangles.len());
    }
    let side = (min_rays as f64).sqrt().ceil() as u32;
    let rays = record_rays(scene, &s, side, min_rays);
    assert!(
        rays.primary.len() >= min_rays,
        "{name}: {} primary",
        rays.primary.len()
    );
    assert!(
        rays.shadow.len() >= min_rays,
        "{name}: {} shadow",
        rays.shadow.len()
    );
    assert!(
        rays.diffuse.len() >= min_rays,
        "{name}: {} diffuse",
        rays.diffuse.len()
    );
    // Copies with every instruction set (and, with the best one, without leaf merging),
    // answers taken from the image where a copy declines the ray (`None`: NaN bounds).
    let levels = SimdLevel::available();
    let copies: Vec<(AccelKind, SimdLevel, CpuBvh)> =
        [AccelKind::Bvh2, AccelKind::Bvh4, AccelKind::Bvh8]
            .into_iter()
            .flat_map(|kind| {
                let b = s.encoded(kind).unwrap();
                let unmerged = (
                    kind,
                    SimdLevel::detect(),
                    b.cpu_copy_with(SimdLevel::detect(), 0),
                );
                levels
                    .iter()
                    .map(move |&l| (kind, l, b.cpu_copy(l)))
                    .chain(std::iter::once(unmerged))
            })
            .collect();
    for (kind, level, c) in &copies {
        assert_eq!(c.level(), *level, "{name}: {kind:?}");
    }
    const KINDS: [AccelKind; 3] = [AccelKind::Bvh2, AccelKind::Bvh4, AccelKind::Bvh8];
    let tracers = || -> [Tracer<'_, Structures>; 3] { KINDS.map(|k| s.tracer(k)) };
    for (what, set) in [("primary", &rays.primary), ("diffuse", &rays.diffuse)] {
        set.par_iter()
            .enumerate()
            .for_each_init(tracers, |tracers, (i, ray)| {
                let want = hit_bits(s.bvh2_image().closest_hit_image(ray, &mut NoObserver));
                for (kind, t) in KINDS.iter().zip(tracers.iter_mut()) {
                    assert_eq!(
                        hit_bits(t.closest_hit(ray)),
                        want,
                        "{name}: {what} ray {i} {ray:?} through {kind:?}'s tracer"
                    );
                }
                for kind in KINDS {
                    let b = s.encoded(kind).unwrap();
                    let image = hit_bits(b.closest_hit_image(ray, &mut NoObserver));
                    assert_eq!(
                        image, want,
                        "{name}: {what} ray {i} {ray:?} on {kind:?}'s image"
                    );
                    let got = s.closest_hit(kind, ray, &mut NoObserver);
                    assert_eq!(
                        hit_bits(got),
                        want,
                        "{name}: {what} ray {i} {ray:?} on {kind:?}"
                    );
                    assert_eq!(key(got).is_some(), want.is_some());
                }
                for (kind, level, c) in &copies {
                    let got = c.traverse::<false>(ray).unwrap_or_else(|| {
                        s.encoded(*kind)
                            .unwrap()
                            .closest_hit_image(ray, &mut NoObserver)
                    });
                    assert_eq!(
                        hit_bits(got),
                        want,
                        "{name}: {what} ray {i} {ray:?} on {kind:?} with {level:?}"
                    );
                }
            });
    }
    rays.shadow
        .par_iter()
        .enumerate()
        .for_each_init(tracers, |tracers, (i, ray)| {
            let want = s
                .bvh2_image()
                .closest_hit_image(ray, &mut NoObserver)
                .is_some();
            for (kind, t) in KINDS.iter().zip(tracers.iter_mut()) {
                assert_eq!(
                    t.any_hit(ray),
                    want,
                    "{name}: shadow ray {i} {ray:?} through {kind:?}'s tracer"
                );
            }
            for kind in KINDS {
                let b = s.encoded(kind).unwrap();
                let image = b.any_hit_image(ray, &mut NoObserver);
                assert_eq!(
                    image, want,
                    "{name}: shadow ray {i} {ray:?} on {kind:?}'s image"
                );
                let got = s.any_hit(kind, ray, &mut NoObserver);
                assert_eq!(got, want, "{name}: shadow ray {i} {ray:?} on {kind:?}");
            }
            for (kind, level, c) in &copies {
                let got = c.traverse::<true>(ray).map_or_else(
                    || {
                        s.encoded(*kind)
                            .unwrap()
                            .any_hit_image(ray, &mut NoObserver)
                    },
                    |h| h.is_some(),
                );
                assert_eq!(
                    got, want,
                    "{name}: shadow ray {i} {ray:?} on {kind:?} with {level:?}"
                );
            }
        });
}

#[test]
fn equivalence_dragon_res4() {
    equivalence("dragon_res4.ply.gz");
}

#[test]
fn equivalence_bunny() {
    equivalence("bunny.ply.gz");
}

#[test]
fn equivalence_sponza_dabrovic() {
    equivalence("sponza_dabrovic.ply.gz");
}

#[test]
fn equivalence_dragon_box() {
    equivalence("dragon_box.ply.gz");
}

#[test]
fn identical_leaves_in_all_three() {
    for name in ["dragon_res4.ply.gz", "sponza_dabrovic.ply.gz"] {
        let Some(scene) = shipped(name) else {
            continue;
        };
        let boxes: Vec<_> = scene.triangles.iter().map(|t| t.bounds()).collect();
        let bvh = dualsplit_accel::Bvh2::build(&boxes, &BuildConfig::default());
        let l2 = WideBvh::from_bvh2(&bvh).leaf_sets(&bvh.prim_ids);
        let l4 = WideBvh::collapse_bvh4(&bvh).leaf_sets(&bvh.prim_ids);
        let l8 = WideBvh::collapse_bvh8(&bvh, &CollapseConfig::default()).leaf_sets(&bvh.prim_ids);
        assert_eq!(l2.len(), bvh.leaf_count());
        assert_eq!(l2, l4, "{name}: BVH4 leaves differ");
        assert_eq!(l2, l8, "{name}: BVH8 leaves differ");
        let w4 = WideBvh::collapse_bvh4(&bvh);
        let w8 = WideBvh::collapse_bvh8(&bvh, &CollapseConfig::default());
        assert!(
            w4.nodes
                .iter()
                .all(|n| n.children.len() <= 4 && !n.children.is_empty())
        );
        assert!(
            w8.nodes
                .iter()
                .all(|n| n.children.len() <= 8 && !n.children.is_empty())
        );
        // Wider trees have fewer internal nodes.
        assert!(w4.nodes.len() < bvh.nodes.len() / 2 + 1);
        assert!(w8.nodes.len() < w4.nodes.len());
    }
}

/// Every leaf of every copy, merged or not, lies in as few triangle packets as its size
/// allows: a leaf that would straddle one packet more starts at a packet's first lane
/// (the copy pads the lanes it skips).
#[test]
fn copy_leaves_span_fewest_packets() {
    use dualsplit_accel::image::RUN_END;
    use dualsplit_accel::wide::cpu::{CpuNodes, LANES, LEAF};
    let mut scenes = vec![(
        "builtin:cornell".to_string(),
        dualsplit_scene::load("builtin:cornell").expect("builtin scene"),
    )];
    scenes.extend(shipped("dragon_res4.ply.gz").map(|s| ("dragon_res4".to_string(), s)));
    for (name, scene) in &scenes {
        let s = Structures::build(&scene.triangles, &BuildConfig::default());
        for kind in [AccelKind::Bvh2, AccelKind::Bvh4, AccelKind::Bvh8] {
            for merge in [0, 4, 16] {
                let c = s
                    .encoded(kind)
                    .unwrap()
                    .cpu_copy_with(SimdLevel::detect(), merge);
                let words: Vec<u32> = match &c.nodes {
                    CpuNodes::Four(n) => n.iter().flat_map(|n| n.child).collect(),
                    CpuNodes::Eight(n) => n.iter().flat_map(|n| n.child).collect(),
                };
                let ids: Vec<u32> = c.packets.iter().flat_map(|p| p.prim).collect();
                let mut leaves = 0;
                for w in words.into_iter().filter(|w| w & LEAF != 0) {
                    let slot = (w & !LEAF) as usize;
                    // The leaf's triangles: up to the first id with bit 31 set (RUN_END on
                    // its last, or a padding lane).
                    let n = 1 + ids[slot..]
                        .iter()
                        .position(|id| id & RUN_END != 0)
                        .expect("every leaf ends");
                    let spanned = (slot % LANES + n).div_ceil(LANES);
                    assert_eq!(
                        spanned,
                        n.div_ceil(LANES),
                        "{name} {kind:?} merge {merge}: leaf at slot {slot} of {n} triangles"
                    );
                    leaves += 1;
                }
                assert!(leaves > 0, "{name} {kind:?}");
            }
        }
    }
}

/// Rays whose direction or origin holds NaN or an infinity: a plane distance that is NaN
/// keeps the running interval, so such a ray can meet every lane of a node, empty ones
/// included (whose words name the copy's sentinel leaf). Every copy answers as its own
/// image traversal does, closest hit and shadow, without a panic.
#[test]
fn non_finite_rays_answer_as_the_image() {
    let scene = dualsplit_scene::load("builtin:cornell").expect("builtin scene");
    let s = Structures::build(&scene.triangles, &BuildConfig::default());
    let values = [
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        0.0,
        -0.0,
        1.0,
        -0.3,
    ];
    let mut rays = Vec::new();
    for &x in &values {
        for &y in &values {
            for &z in &values {
                let dir = dualsplit_geometry::Vec3::new(x, y, z);
                let inside = dualsplit_geometry::Vec3::new(0.1, 0.2, 0.3);
                rays.push(dualsplit_geometry::Ray::new(inside, dir));
                rays.push(dualsplit_geometry::Ray::new(dir, inside));
            }
        }
    }
    for kind in [AccelKind::Bvh2, AccelKind::Bvh4, AccelKind::Bvh8] {
        let b = s.encoded(kind).unwrap();
        for level in SimdLevel::available() {
            for c in [b.cpu_copy(level), b.cpu_copy_with(level, 0)] {
                for ray in &rays {
                    let want = hit_bits(b.closest_hit_image(ray, &mut NoObserver));
                    let got = c
                        .traverse::<false>(ray)
                        .unwrap_or_else(|| b.closest_hit_image(ray, &mut NoObserver));
                    assert_eq!(hit_bits(got), want, "{ray:?} on {kind:?} with {level:?}");
                    let want = b.any_hit_image(ray, &mut NoObserver);
                    let got = c
                        .traverse::<true>(ray)
                        .map_or_else(|| b.any_hit_image(ray, &mut NoObserver), |h| h.is_some());
                    assert_eq!(got, want, "{ray:?} on {kind:?} with {level:?}");
                }
            }
        }
    }
}
