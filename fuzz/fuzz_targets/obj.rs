//! The Obj parser on arbitrary bytes: every input ends in a mesh or a typed error, within
//! small budgets, never a panic, an abort or a hang. A mesh that makes a scene (the
//! non-finite rule and the extent limit applied) has a finite camera and light, and a small
//! one builds every structure valid.
#![no_main]

use dualsplit_accel::{BuildConfig, Structures};
use dualsplit_scene::load::{self, Format};
use dualsplit_scene::{Limits, Scene};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// Budgets small enough that no input takes long or holds much memory.
const LIMITS: Limits = Limits {
    max_triangles: 1 << 16,
    max_bytes: 1 << 24,
};

/// Most triangles of a scene whose structures are built and validated.
const BUILD_MAX: usize = 256;

fuzz_target!(|data: &[u8]| {
    // A folder that does not exist: no external glTF buffer can be read.
    let path = Path::new("/nonexistent-dualsplit-fuzz/scene.obj");
    let Ok(mesh) = load::parse_bytes_with(path, Format::Obj, data, &LIMITS) else {
        return;
    };
    let Ok(scene) = Scene::from_triangles("fuzz", "fuzz.obj", mesh.triangles, mesh.stats) else {
        return;
    };
    let (c, l) = (&scene.camera, &scene.light);
    assert!(c.eye.is_finite() && c.target.is_finite(), "{c:?}");
    assert!(l.position.is_finite() && l.radius.is_finite(), "{l:?}");
    if scene.triangles.len() <= BUILD_MAX {
        let s = Structures::try_build(&scene.triangles, &BuildConfig::default()).expect("built");
        for rep in s.validate() {
            assert!(rep.is_ok(), "{rep:?}");
        }
    }
});
