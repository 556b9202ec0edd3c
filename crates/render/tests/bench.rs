//! Throughput measurement: ray sets are the renderer's rays, and a structure that disagrees
//! with BVH2 is an error, not a number.

use dualsplit_accel::{AccelKind, BuildConfig, Structures};
use dualsplit_render::bench::{
    Contender, MeasureConfig, measure, measure_interleaved, ray_sets, trace_fn, verify,
};
use dualsplit_render::{RayKind, RenderError, RenderSettings, TraceResult, Workload, render};
use dualsplit_testkit::scenes::room;

#[test]
fn ray_sets_hold_exactly_the_frames_rays() {
    let scene = room(false, 8);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    for workload in Workload::ALL {
        let settings = RenderSettings::new(20, 16, workload);
        let sets = ray_sets(&scene, &structures, &settings).unwrap();
        let frame = render(&scene, &structures, AccelKind::Bvh2, &settings, &|| {}).unwrap();
        for set in &sets {
            let c = frame.counts.get(set.kind);
            assert_eq!(set.rays.len() as u64, c.rays, "{workload:?} {:?}", set.kind);
            let hits = set.expected.iter().filter(|r| r.is_hit()).count() as u64;
            assert_eq!(hits, c.hits);
        }
        assert_eq!(sets[0].rays.len(), 20 * 16);
        assert_eq!(sets[2].rays.is_empty(), workload == Workload::Cast);
    }
}

#[test]
fn measure_checks_every_structure_then_times() {
    let scene = room(false, 8);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    let sets = ray_sets(
        &scene,
        &structures,
        &RenderSettings::new(16, 16, Workload::Path),
    )
    .unwrap();
    let cfg = MeasureConfig {
        min_seconds: 0.0,
        min_repeats: 2,
    };
    for kind in AccelKind::ALL {
        for set in &sets {
            let t = measure(&structures, kind, set, &cfg).unwrap();
            assert_eq!(t.rays, set.rays.len() as u64);
            assert_eq!(t.repeats, 2);
            assert!(t.mrays_per_s > 0.0 && t.mrays_per_s.is_finite());
        }
    }
}

#[test]
fn a_wrong_answer_is_reported_with_the_ray() {
    let scene = room(false, 8);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    let mut sets = ray_sets(
        &scene,
        &structures,
        &RenderSettings::new(8, 8, Workload::Cast),
    )
    .unwrap();
    let shadow = &mut sets[RayKind::Shadow as usize];
    assert!(!shadow.rays.is_empty());
    let i = shadow.rays.len() / 2;
    let TraceResult::Occluded(o) = shadow.expected[i] else {
        panic!("shadow set holds a closest-hit result")
    };
    shadow.expected[i] = TraceResult::Occluded(!o);
    match verify(&structures, AccelKind::Dst, shadow) {
        Err(RenderError::Mismatch {
            index,
            accel,
            ray_kind,
            ..
        }) => {
            assert_eq!((index, accel, ray_kind), (i, "dst", "shadow"));
        }
        other => panic!("expected a mismatch, got {other:?}"),
    }
    let cfg = MeasureConfig::default();
    assert!(measure(&structures, AccelKind::Bvh2, shadow, &cfg).is_err());
}

#[test]
fn interleaved_timing_gives_every_contender_the_same_passes() {
    let scene = room(false, 8);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    let sets = ray_sets(
        &scene,
        &structures,
        &RenderSettings::new(16, 16, Workload::Path),
    )
    .unwrap();
    let cfg = MeasureConfig {
        min_seconds: 0.0,
        min_repeats: 3,
    };
    for set in &sets {
        let f2 = trace_fn(&structures, AccelKind::Bvh2, set.kind);
        let f8 = trace_fn(&structures, AccelKind::Bvh8, set.kind);
        let none = |_: &[dualsplit_geometry::Ray]| 0u64;
        let contenders = [
            Contender {
                name: "bvh2",
                trace: &f2,
            },
            Contender {
                name: "bvh8",
                trace: &f8,
            },
            Contender {
                name: "nothing",
                trace: &none,
            },
        ];
        let t = measure_interleaved(set, &contenders, &cfg);
        let hits = set.expected.iter().filter(|r| r.is_hit()).count() as u64;
        assert_eq!(t.len(), 3);
        for (c, t) in contenders.iter().zip(&t) {
            assert_eq!(t.accel, c.name);
            assert_eq!(
                (t.ray_kind, t.rays, t.repeats),
                (set.kind, set.rays.len() as u64, 3)
            );
            assert!(t.best_pass_mrays_per_s >= t.mrays_per_s, "{t:?}");
        }
        assert_eq!((t[0].hits, t[1].hits, t[2].hits), (hits, hits, 0));
        assert!(hits > 0, "{:?}: the room's rays hit something", set.kind);
    }
}
