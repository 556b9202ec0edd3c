//! Determinism by pixel: a pixel regenerated alone yields exactly the rays and hits it had in
//! the full render; ray budgets; the shading formula; settings validation.

use dualsplit_accel::{AccelKind, BuildConfig, CountingObserver, NoObserver, Structures};
use dualsplit_geometry::{Pcg32, Triangle, Vec3};
use dualsplit_render::{
    ALBEDO, AMBIENT, PixelJob, RayKind, RenderError, RenderSettings, TraceResult, Workload, render,
    render_records, trace_pixel,
};
use dualsplit_scene::{Camera, Light, LoadStats, Scene};
use dualsplit_testkit::scenes::room;

#[test]
fn a_pixel_regenerated_alone_matches_the_full_render() {
    let scene = room(false, 10);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    for workload in Workload::ALL {
        let mut settings = RenderSettings::new(48, 36, workload);
        settings.spp = 2;
        settings.seed = 7;
        let records = render_records(&scene, &structures, AccelKind::Bvh2, &settings).unwrap();
        let frame = render(&scene, &structures, AccelKind::Bvh2, &settings, &|| {}).unwrap();
        assert_eq!(records.len(), 48 * 36);
        // The image and the recorded pixels come from the same job runs.
        for r in &records {
            assert_eq!(r.radiance.to_bits(), frame.image.get(r.x, r.y).to_bits());
        }
        // Regenerate random pixels alone, in random order, on every structure.
        let mut rng = Pcg32::new(3, 1);
        for _ in 0..60 {
            let (x, y) = (rng.below(48), rng.below(36));
            let full = &records[(y * 48 + x) as usize];
            for kind in AccelKind::ALL {
                let alone =
                    trace_pixel(&structures, kind, &scene, &settings, x, y, &mut NoObserver);
                assert!(
                    alone.bit_eq(full),
                    "{} {}: pixel ({x}, {y}) differs alone:\n{alone:?}\nin frame:\n{full:?}",
                    kind.name(),
                    workload.name()
                );
            }
        }
    }
}

#[test]
fn the_seed_changes_the_path_but_not_the_primary_rays() {
    let scene = room(true, 8);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    let a = RenderSettings::new(16, 16, Workload::Path);
    let b = RenderSettings { seed: 1, ..a };
    let ra = trace_pixel(
        &structures,
        AccelKind::Bvh2,
        &scene,
        &a,
        5,
        9,
        &mut NoObserver,
    );
    let rb = trace_pixel(
        &structures,
        AccelKind::Bvh2,
        &scene,
        &b,
        5,
        9,
        &mut NoObserver,
    );
    assert_eq!(
        ra.rays[0], rb.rays[0],
        "1 spp: the primary ray is the pixel centre"
    );
    assert!(!ra.bit_eq(&rb));
}

#[test]
fn path_budget_in_a_closed_room_is_exactly_five_bounces() {
    // No ray can escape a closed room, and there is no Russian roulette, so every sample
    // traces 1 primary + 5 diffuse rays, each followed by at most one shadow ray.
    let scene = room(true, 8);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    let mut settings = RenderSettings::new(24, 24, Workload::Path);
    settings.spp = 3;
    for r in render_records(&scene, &structures, AccelKind::Bvh2, &settings).unwrap() {
        assert_eq!(r.counts.primary.rays, 3, "pixel ({}, {})", r.x, r.y);
        assert_eq!(r.counts.primary.hits, 3);
        assert_eq!(r.counts.diffuse.rays, 15);
        assert_eq!(r.counts.diffuse.hits, 15);
        assert!(r.counts.shadow.rays <= 18);
        assert!(r.counts.rays() <= settings.max_rays_per_pixel());
        // Order: every shadow ray directly follows a closest hit that found a triangle.
        for w in r.rays.windows(2) {
            if w[1].query.kind == RayKind::Shadow {
                assert_ne!(w[0].query.kind, RayKind::Shadow);
                assert!(w[0].result.is_hit());
            }
        }
    }
}

#[test]
fn cast_budget_is_one_primary_and_at_most_one_shadow() {
    let scene = room(false, 8);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    let settings = RenderSettings::new(32, 32, Workload::Cast);
    let mut shadows = 0;
    for r in render_records(&scene, &structures, AccelKind::Bvh2, &settings).unwrap() {
        assert_eq!(r.counts.primary.rays, 1);
        assert_eq!(r.counts.diffuse.rays, 0);
        assert!(r.counts.shadow.rays <= r.counts.primary.hits);
        shadows += r.counts.shadow.rays;
    }
    assert!(shadows > 0);
}

#[test]
fn observer_sees_every_traversal() {
    let scene = room(false, 8);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    let settings = RenderSettings::new(16, 16, Workload::Path);
    let mut obs = CountingObserver::default();
    let r = trace_pixel(
        &structures,
        AccelKind::Bvh2,
        &scene,
        &settings,
        8,
        8,
        &mut obs,
    );
    assert!(r.counts.rays() >= 2);
    assert!(obs.triangle_tests > 0);
}

/// One triangle facing +z, a point light straight above the pixel's hit point.
fn plane_scene(light_z: f32) -> Scene {
    let tri = Triangle::new(
        Vec3::new(-10.0, -10.0, 0.0),
        Vec3::new(10.0, -10.0, 0.0),
        Vec3::new(0.0, 10.0, 0.0),
    );
    let mut s = Scene::from_triangles("plane", "plane", vec![tri], LoadStats::default()).unwrap();
    s.camera = Camera {
        eye: Vec3::new(0.0, 0.0, 5.0),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y_deg: 30.0,
    };
    s.light = Light {
        position: Vec3::new(0.0, 0.0, light_z),
        radius: 0.0,
        intensity: 1.5,
    };
    s
}

#[test]
fn cast_shading_follows_the_lambert_point_light_formula() {
    let scene = plane_scene(2.0);
    // 1×1 image: the pixel centre looks straight down the −z axis and hits (0, 0, 0).
    let settings = RenderSettings::new(1, 1, Workload::Cast);
    let mut job = PixelJob::new(&scene, &settings, 0, 0);
    let q = job.next_ray().unwrap();
    assert_eq!(q.kind, RayKind::Primary);
    let hit = scene.triangles[0]
        .intersect(&q.ray.precompute(), 0.0, f32::INFINITY)
        .unwrap();
    job.submit(TraceResult::Closest(Some(dualsplit_geometry::Hit {
        t: hit.t,
        prim: dualsplit_geometry::PrimId(0),
        u: hit.u,
        v: hit.v,
    })));
    let s = job.next_ray().unwrap();
    assert_eq!(s.kind, RayKind::Shadow);
    // The shadow ray leaves the surface on the lit side and ends before the light.
    assert!(s.ray.origin.z > 0.0 && s.ray.origin.z < 1e-3);
    assert!(s.ray.at(s.ray.t_max).z < 2.0);
    job.submit(TraceResult::Occluded(false));
    assert!(job.next_ray().is_none());
    // Expected: ambient + albedo/π · power · cos / d², power normalised to the scene centre.
    let dc = (scene.light.position - scene.bounds.center()).length_squared();
    let power = scene.light.intensity * dc * 2.0;
    let d2 = (scene.light.position - s.ray.origin).length_squared();
    let want = AMBIENT * ALBEDO + ALBEDO / std::f32::consts::PI * power / d2;
    assert!(
        (job.radiance() - want).abs() <= want * 1e-5,
        "{} vs {want}",
        job.radiance()
    );
}

#[test]
fn a_light_behind_the_surface_casts_no_shadow_ray() {
    let scene = plane_scene(-2.0);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    let settings = RenderSettings::new(1, 1, Workload::Cast);
    let r = trace_pixel(
        &structures,
        AccelKind::Bvh2,
        &scene,
        &settings,
        0,
        0,
        &mut NoObserver,
    );
    assert_eq!(r.counts.primary.hits, 1);
    assert_eq!(r.counts.shadow.rays, 0);
    assert_eq!(r.radiance, AMBIENT * ALBEDO);
}

#[test]
#[should_panic(expected = "does not match")]
fn a_mismatched_result_kind_is_a_caller_bug() {
    let scene = plane_scene(2.0);
    let settings = RenderSettings::new(1, 1, Workload::Cast);
    let mut job = PixelJob::new(&scene, &settings, 0, 0);
    job.submit(TraceResult::Occluded(true));
}

#[test]
fn bad_settings_and_cameras_are_typed_errors() {
    let scene = plane_scene(2.0);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    let ok = RenderSettings::new(4, 4, Workload::Cast);
    let run =
        |scene: &Scene, s: &RenderSettings| render(scene, &structures, AccelKind::Bvh2, s, &|| {});
    assert!(matches!(
        run(&scene, &RenderSettings { width: 0, ..ok }),
        Err(RenderError::Settings { width: 0, .. })
    ));
    assert!(matches!(
        run(&scene, &RenderSettings { spp: 0, ..ok }),
        Err(RenderError::Settings { spp: 0, .. })
    ));
    let mut s = scene.clone();
    s.camera.target = s.camera.eye;
    assert!(matches!(run(&s, &ok), Err(RenderError::Camera { .. })));
    let mut s = scene.clone();
    s.camera.up = s.camera.target - s.camera.eye;
    assert!(matches!(run(&s, &ok), Err(RenderError::Camera { .. })));
    let mut s = scene.clone();
    s.camera.fov_y_deg = 180.0;
    assert!(matches!(run(&s, &ok), Err(RenderError::Camera { .. })));
    let mut s = scene.clone();
    s.light.position.x = f32::NAN;
    assert!(matches!(run(&s, &ok), Err(RenderError::Light { .. })));
    assert!(run(&scene, &ok).is_ok());
}

#[test]
fn without_shadow_rays_no_shadow_ray_is_traced_and_light_is_never_occluded() {
    let scene = room(true, 8);
    let structures = Structures::build(&scene.triangles, &BuildConfig::default());
    for workload in Workload::ALL {
        let on = RenderSettings::new(24, 24, workload);
        assert!(on.shadows, "shadow rays by default");
        let off = RenderSettings {
            shadows: false,
            ..on
        };
        let a = render_records(&scene, &structures, AccelKind::Bvh2, &on).unwrap();
        let b = render_records(&scene, &structures, AccelKind::Bvh2, &off).unwrap();
        let shadows = |r: &[dualsplit_render::PixelRecord]| {
            r.iter()
                .flat_map(|p| &p.rays)
                .filter(|t| t.query.kind == RayKind::Shadow)
                .count()
        };
        assert!(shadows(&a) > 0, "{}", workload.name());
        assert_eq!(shadows(&b), 0, "{}", workload.name());
        // The same paths (the random numbers do not depend on the shadow rays), every light
        // sample counted: no pixel is darker, and an occluded sample makes some brighter.
        for (p, q) in a.iter().zip(&b) {
            assert!(q.radiance >= p.radiance, "({}, {})", p.x, p.y);
        }
        assert!(a.iter().zip(&b).any(|(p, q)| q.radiance > p.radiance));
    }
}
