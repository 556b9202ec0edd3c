//! Frame limits: every size a user can ask for is checked before anything is allocated,
//! and the message states the limit it breaks.

use dualsplit_render::{
    MAX_BOUNCES, MAX_PIXELS, MAX_SAMPLES, MAX_SIDE, MAX_SPP, RenderError, RenderSettings, Workload,
    validate,
};

fn check(width: u32, height: u32, spp: u32, bounces: u32) -> Result<(), RenderError> {
    let scene = dualsplit_scene::load("builtin:cornell").unwrap();
    let settings = RenderSettings {
        spp,
        bounces,
        ..RenderSettings::new(width, height, Workload::Path)
    };
    validate(&scene, &settings)
}

/// Expects a settings error whose message contains `needle`.
fn refused(r: Result<(), RenderError>, needle: &str) {
    match r {
        Err(e @ RenderError::Settings { .. }) => {
            assert!(e.to_string().contains(needle), "`{e}` lacks `{needle}`");
        }
        other => panic!("expected a settings error with `{needle}`, got {other:?}"),
    }
}

#[test]
fn frames_at_the_limits_pass() {
    let side = (MAX_PIXELS as f64).sqrt() as u32;
    assert!(check(side, side, 1, 5).is_ok());
    assert!(check(MAX_SIDE, (MAX_PIXELS / u64::from(MAX_SIDE)) as u32, 1, 5).is_ok());
    assert!(check(1, 1, MAX_SPP, MAX_BOUNCES).is_ok());
    // 1024 × 1024 at the most samples per pixel is exactly the sample limit.
    assert_eq!(1024 * 1024 * u64::from(MAX_SPP), MAX_SAMPLES);
    assert!(check(1024, 1024, MAX_SPP, 5).is_ok());
}

#[test]
fn frames_past_the_limits_are_refused_with_the_limit() {
    // 65535 × 65535 is within the per-side limit but would need about 34 GB.
    refused(check(65535, 65535, 1, 5), &MAX_PIXELS.to_string());
    // 65536 × 65536 is within the per-side limit: the pixel count refuses it.
    refused(check(65536, 65536, 1, 5), &MAX_PIXELS.to_string());
    refused(
        check(MAX_SIDE + 1, 1, 1, 5),
        &format!("{MAX_SIDE} pixels per side"),
    );
    refused(
        check(1, u32::MAX, 1, 5),
        &format!("{MAX_SIDE} pixels per side"),
    );
    refused(
        check(8, 8, MAX_SPP + 1, 5),
        &format!("{MAX_SPP} samples per pixel"),
    );
    refused(
        check(8, 8, u32::MAX, 5),
        &format!("{MAX_SPP} samples per pixel"),
    );
    refused(check(1024, 1025, MAX_SPP, 5), &MAX_SAMPLES.to_string());
    refused(check(8, 8, 1, MAX_BOUNCES + 1), &MAX_BOUNCES.to_string());
    refused(check(0, 8, 1, 5), "no pixel");
    refused(check(8, 8, 0, 5), "at least one sample");
}

#[test]
fn cameras_that_overflow_are_refused() {
    // Loading refuses a scene near f32::MAX (its fitted camera would be at infinity); a
    // caller may still set such a camera on a scene of its own.
    use dualsplit_geometry::{Triangle, Vec3};
    let t = Triangle::new(
        Vec3::splat(1e38),
        Vec3::splat(-1e38),
        Vec3::new(1e38, -1e38, 0.0),
    );
    let big = dualsplit_scene::Scene::from_triangles("big", "big", vec![t], Default::default());
    assert!(
        matches!(big, Err(dualsplit_scene::SceneError::Extent { .. })),
        "{big:?}"
    );
    let small = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
    let mut scene =
        dualsplit_scene::Scene::from_triangles("s", "s", vec![small], Default::default()).unwrap();
    scene.camera.eye = Vec3::new(1.0, 1.0, f32::INFINITY);
    let r = validate(&scene, &RenderSettings::new(8, 8, Workload::Cast));
    assert!(matches!(r, Err(RenderError::Camera { .. })), "{r:?}");
}

#[test]
fn lights_and_cameras_beyond_the_coordinate_limit_are_refused() {
    use dualsplit_geometry::{Triangle, Vec3};
    let small = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
    let base =
        dualsplit_scene::Scene::from_triangles("s", "s", vec![small], Default::default()).unwrap();
    let settings = RenderSettings::new(8, 8, Workload::Cast);
    // A light at 1e20 once dropped every shadow ray (its distance² overflowed) and exited 0;
    // at 1e19 the power 2·intensity·d² overflowed.
    for far in [1e20, 1e19, 4.7e18] {
        let mut s = base.clone();
        s.light.position = Vec3::splat(far);
        let r = validate(&s, &settings);
        assert!(matches!(r, Err(RenderError::Light { .. })), "{far}: {r:?}");
    }
    let mut s = base.clone();
    s.light.position = Vec3::splat(4.6e18);
    validate(&s, &settings).expect("a light within 2^62");
    s.light.intensity = 1e30;
    let r = validate(&s, &settings);
    assert!(
        matches!(&r, Err(e @ RenderError::Light { .. }) if e.to_string().contains("overflows")),
        "{r:?}"
    );
    let mut s = base.clone();
    s.light.radius = 1e19;
    assert!(matches!(
        validate(&s, &settings),
        Err(RenderError::Light { .. })
    ));
    let mut s = base.clone();
    s.camera.eye = Vec3::new(0.0, 0.0, 1e30);
    let r = validate(&s, &settings);
    assert!(
        matches!(&r, Err(e @ RenderError::Camera { .. }) if e.to_string().contains("beyond ±2^62")),
        "{r:?}"
    );
}
