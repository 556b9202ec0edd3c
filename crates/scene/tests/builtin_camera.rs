//! Cameras and lights: presets by file stem, fitting, command-line overrides.

use dualsplit_geometry::{Aabb, Vec3};
use dualsplit_scene::{Camera, CameraError, Light, file_stem, parse_vec3};
use std::path::Path;

fn dragon_box_bounds() -> Aabb {
    // The bounds of the shipped mesh dragon_box.ply.gz.
    Aabb::new(
        Vec3::new(-0.1595, 0.0527, -0.1583),
        Vec3::new(0.1478, 0.3601, 0.1491),
    )
}

fn sponza_bounds() -> Aabb {
    Aabb::new(
        Vec3::new(-17.4028, -0.9067, -7.7985),
        Vec3::new(17.4172, 15.6533, 7.8015),
    )
}

fn inside(b: &Aabb, p: Vec3) -> bool {
    p.cmpge(b.min).all() && p.cmple(b.max).all()
}

#[test]
fn file_stems_strip_scene_extensions() {
    assert_eq!(
        file_stem(Path::new("scenes/dragon_box.ply.gz")),
        "dragon_box"
    );
    assert_eq!(file_stem(Path::new("a/bunny.obj")), "bunny");
    assert_eq!(file_stem(Path::new("x.glb")), "x");
    assert_eq!(file_stem(Path::new("weird.name.ply")), "weird.name");
}

#[test]
fn every_shipped_stem_has_a_preset() {
    for stem in [
        "dragon",
        "dragon_res2",
        "dragon_res3",
        "dragon_res4",
        "dragon_box",
        "dragon_sponza",
        "sponza_dabrovic",
        "crytek_sponza",
        "bunny",
    ] {
        assert!(Camera::has_preset(stem), "{stem}");
    }
    assert!(!Camera::has_preset("teapot"));
    let b = dragon_box_bounds();
    assert_eq!(Camera::preset_for("teapot", &b), Camera::fit(&b));
    assert_eq!(Light::preset_for("teapot", &b), Light::fit(&b));
}

#[test]
fn dragon_box_is_seen_through_its_open_side() {
    let b = dragon_box_bounds();
    let c = Camera::preset_for("dragon_box", &b);
    // The box is open toward +z: the eye is in front of it, looking at its inside.
    assert!(c.eye.z > b.max.z, "eye {:?}", c.eye);
    assert!(inside(&b, c.target));
    assert!(inside(&b, Light::preset_for("dragon_box", &b).position));
}

#[test]
fn sponza_views_are_inside_the_atrium() {
    let b = sponza_bounds();
    for stem in ["sponza_dabrovic", "dragon_sponza"] {
        let c = Camera::preset_for(stem, &b);
        assert!(inside(&b, c.eye), "{stem}: eye {:?}", c.eye);
        assert!(inside(&b, c.target), "{stem}");
    }
}

#[test]
fn crytek_sponza_is_seen_down_its_nave() {
    // The Khronos sample's bounds (its accessors' min/max) after the root node's 0.008.
    let b = Aabb::new(
        Vec3::new(-1432.2, -2.46, -645.43) * 0.008,
        Vec3::new(1302.2, 1296.7, 574.9) * 0.008,
    );
    let c = Camera::preset_for("crytek_sponza", &b);
    assert!(inside(&b, c.eye) && inside(&b, c.target), "{c:?}");
    let d = (c.target - c.eye).normalize();
    // Along the long (x) axis, toward -x, slightly up, from the nave's middle.
    assert!(d.x < -0.95 && d.y > 0.0, "{d:?}");
    assert!((c.eye.z - b.center().z).abs() < 0.05 * b.extent().z);
    let l = Light::preset_for("crytek_sponza", &b);
    assert!(l.position.y > b.min.y + 0.9 * b.extent().y);
}

#[test]
fn fit_sees_the_whole_box() {
    for b in [
        Aabb::new(Vec3::new(-1.0, 0.0, -3.0), Vec3::new(5.0, 2.0, 1.0)),
        Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 10.0, 1.0)),
        dragon_box_bounds(),
    ] {
        let c = Camera::fit(&b);
        assert_eq!(c.target, b.center());
        assert!(!inside(&b, c.eye));
        let fwd = (c.target - c.eye).normalize();
        // Every corner lies inside the cone of half-angle fov/2 (inside a square image).
        for i in 0..8 {
            let p = Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            let angle = fwd.angle_between(p - c.eye);
            assert!(
                angle <= c.fov_y_deg.to_radians() * 0.5,
                "{b:?}: corner {p:?} at {angle}"
            );
        }
    }
}

#[test]
fn vectors_parse_with_spaces_and_signs() {
    assert_eq!(
        parse_vec3("eye", "1,-2.5, 3e1").unwrap(),
        Vec3::new(1.0, -2.5, 30.0)
    );
    for bad in ["", "1,2", "1,2,3,4", "a,b,c", "1,,3", "1,2,inf", "NaN,0,0"] {
        assert_eq!(
            parse_vec3("eye", bad),
            Err(CameraError::BadVector {
                what: "eye",
                value: bad.to_string()
            }),
            "{bad:?}"
        );
    }
}

#[test]
fn camera_overrides_apply_and_check() {
    let c = Camera::fit(&dragon_box_bounds());
    let o = c
        .with_overrides(Some("0,1,5"), Some("0,1,0"), Some(30.0))
        .unwrap();
    assert_eq!(o.eye, Vec3::new(0.0, 1.0, 5.0));
    assert_eq!(o.target, Vec3::new(0.0, 1.0, 0.0));
    assert_eq!(o.fov_y_deg, 30.0);
    assert_eq!(c.with_overrides(None, None, None).unwrap(), c);
    assert!(matches!(
        c.with_overrides(None, None, Some(180.0)),
        Err(CameraError::OutOfRange { what: "fov", .. })
    ));
    assert!(matches!(
        c.with_overrides(None, None, Some(f32::NAN)),
        Err(CameraError::OutOfRange { what: "fov", .. })
    ));
    assert!(matches!(
        c.with_overrides(Some("1,2,3"), Some("1,2,3"), None),
        Err(CameraError::NoViewDirection { .. })
    ));
    // Looking straight down along the up vector has no horizon.
    assert!(matches!(
        c.with_overrides(Some("0,5,0"), Some("0,0,0"), None),
        Err(CameraError::NoViewDirection { .. })
    ));
    assert!(matches!(
        c.with_overrides(None, Some("x"), None),
        Err(CameraError::BadVector { what: "target", .. })
    ));
    // An eye or target at 1e30 was refused as "eye and target coincide" (the view
    // direction's length overflowed).
    for (eye, target, what) in [
        (Some("0,0,1e30"), None, "eye"),
        (None, Some("1e30,0,0"), "target"),
        (Some("0,0,-4.7e18"), None, "eye"),
    ] {
        let e = c.with_overrides(eye, target, None).unwrap_err();
        assert!(
            matches!(e, CameraError::Far { what: w, .. } if w == what),
            "{e:?}"
        );
        assert!(e.to_string().contains("beyond ±4.611686e18"), "{e}");
    }
    assert!(c.with_overrides(Some("0,0,4.6e18"), None, None).is_ok());
}

#[test]
fn light_overrides_apply_and_check() {
    let l = Light::fit(&dragon_box_bounds());
    let o = l
        .with_overrides(Some("1,2,3"), Some(0.0), Some(2.0))
        .unwrap();
    assert_eq!(o.position, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(o.radius, 0.0);
    assert_eq!(o.intensity, 2.0);
    assert!(matches!(
        l.with_overrides(None, Some(-1.0), None),
        Err(CameraError::OutOfRange {
            what: "light-radius",
            ..
        })
    ));
    assert!(matches!(
        l.with_overrides(None, None, Some(0.0)),
        Err(CameraError::OutOfRange {
            what: "light-intensity",
            ..
        })
    ));
    assert!(matches!(
        l.with_overrides(Some("1;2;3"), None, None),
        Err(CameraError::BadVector { what: "light", .. })
    ));
    // A light at 1e20 dropped every shadow ray; at 1e19 its power overflowed.
    for far in ["1e20,1e20,1e20", "1e19,0,0"] {
        let e = l.with_overrides(Some(far), None, None).unwrap_err();
        assert!(matches!(e, CameraError::Far { what: "light", .. }), "{e:?}");
    }
    assert!(matches!(
        l.with_overrides(None, Some(1e19), None),
        Err(CameraError::OutOfRange {
            what: "light-radius",
            ..
        })
    ));
    // The range reads as words, not as "(-0.0000…117549, 3402823500000…)".
    let e = l.with_overrides(None, Some(-1.0), None).unwrap_err();
    assert_eq!(
        e.to_string(),
        "--light-radius -1: must be from 0 to 2^60 (1.1529215e18)"
    );
    assert_eq!(
        l.with_overrides(None, Some(-0.0), None)
            .unwrap()
            .radius
            .to_bits(),
        0
    );
}

#[test]
fn loading_a_shipped_file_applies_its_preset() {
    let Some(s) = dualsplit_testkit::scenes::shipped("dragon_res4.ply.gz") else {
        return;
    };
    assert_eq!(s.camera, Camera::preset_for("dragon_res4", &s.bounds));
    assert_eq!(s.light, Light::preset_for("dragon_res4", &s.bounds));
    assert_ne!(s.camera, Camera::fit(&s.bounds));
}
