//! Scenes for tests and benchmarks: the shipped meshes, and a room built in code (no
//! loader needed).
//!
//! A shipped mesh is looked up by file name in the repository's `scenes/` folder (the small
//! meshes committed with the code), then in the folder of the large meshes: the one named by
//! the `DUALSPLIT_SHARED_SCENES` environment variable, else `shared/scenes` beside the
//! checkout. [`shipped`] and [`shipped_path`] return `None` when neither folder holds the
//! file, so a test needing a large mesh skips on a fresh clone, and report the skip on the
//! process's own standard error, past the test harness's capture (a passing test's output
//! is otherwise swallowed): `skipped scene: NAME not found in DIRS`. When the `CI`
//! environment variable is set they panic with that reason instead.

use dualsplit_geometry::{Pcg32, Triangle, Vec3};
use dualsplit_scene::{Camera, Light, LoadStats, Scene};
use std::path::{Path, PathBuf};

/// The environment variable naming the folder of the large meshes (default: `shared/scenes`
/// beside the checkout). Naming a missing folder hides the large meshes.
pub const SHARED_ENV: &str = "DUALSPLIT_SHARED_SCENES";

/// The repository's folder of committed meshes, `<repository>/scenes`.
pub fn repo_dir() -> PathBuf {
    checkout().join("scenes")
}

/// The repository's root: two folders above this crate's.
fn checkout() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .nth(2)
        .expect("crates/testkit lies two folders below the repository's root")
}

/// The folder of the large meshes: `DUALSPLIT_SHARED_SCENES` when set and not empty, else
/// `shared/scenes` beside the checkout.
pub fn shared_dir() -> PathBuf {
    match std::env::var_os(SHARED_ENV) {
        Some(v) if !v.is_empty() => PathBuf::from(v),
        _ => checkout()
            .parent()
            .unwrap_or(Path::new("/"))
            .join("shared/scenes"),
    }
}

/// Path of the shipped mesh `name`: in [`repo_dir`] if there, else in [`shared_dir`].
///
/// When neither holds it, reports `skipped scene: NAME not found in DIRS` ([`report_skip`])
/// and returns `None`.
///
/// # Panics
/// When neither folder holds it and the `CI` environment variable is set, naming both.
pub fn shipped_path(name: &str) -> Option<PathBuf> {
    let dirs = [repo_dir(), shared_dir()];
    if let Some(p) = dirs.iter().map(|d| d.join(name)).find(|p| p.is_file()) {
        return Some(p);
    }
    let reason = format!(
        "{name} not found in {} or {}",
        dirs[0].display(),
        dirs[1].display()
    );
    assert!(
        std::env::var_os("CI").is_none(),
        "{reason} (required when CI is set)"
    );
    report_skip(&reason);
    None
}

/// Writes `skipped scene: REASON` to the process's standard error itself, so that the line
/// shows in `cargo test`'s output even for a passing test (whose `eprintln!` the harness
/// captures and drops).
pub fn report_skip(reason: &str) {
    use std::io::Write;
    let line = format!("skipped scene: {reason}\n");
    let direct = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/stderr")
        .and_then(|mut f| f.write_all(line.as_bytes()));
    if direct.is_err() {
        eprint!("{line}");
    }
}

/// Loads the shipped mesh `name` found by [`shipped_path`] with `dualsplit_scene::load`;
/// `None` (with the printed reason) when it is missing.
///
/// # Panics
/// When it is missing under `CI`, or when the file does not load, naming the path.
pub fn shipped(name: &str) -> Option<Scene> {
    let path = shipped_path(name)?;
    let spec = path.to_str().expect("scene paths are UTF-8");
    Some(dualsplit_scene::load(spec).unwrap_or_else(|e| panic!("{spec}: {e}")))
}

/// The triangles of the shipped mesh `name`, as [`shipped`].
pub fn shipped_triangles(name: &str) -> Option<Vec<Triangle>> {
    shipped(name).map(|s| s.triangles)
}

/// Two triangles of the quad `a b c d` (counter-clockwise).
pub fn quad(out: &mut Vec<Triangle>, a: Vec3, b: Vec3, c: Vec3, d: Vec3) {
    out.push(Triangle::new(a, b, c));
    out.push(Triangle::new(a, c, d));
}

/// The 12 triangles of an axis-aligned box.
pub fn cuboid(out: &mut Vec<Triangle>, lo: Vec3, hi: Vec3) {
    let p = |x: bool, y: bool, z: bool| {
        Vec3::new(
            if x { hi.x } else { lo.x },
            if y { hi.y } else { lo.y },
            if z { hi.z } else { lo.z },
        )
    };
    let (f, t) = (false, true);
    quad(out, p(f, f, f), p(t, f, f), p(t, t, f), p(f, t, f));
    quad(out, p(f, f, t), p(f, t, t), p(t, t, t), p(t, f, t));
    quad(out, p(f, f, f), p(f, t, f), p(f, t, t), p(f, f, t));
    quad(out, p(t, f, f), p(t, f, t), p(t, t, t), p(t, t, f));
    quad(out, p(f, f, f), p(f, f, t), p(t, f, t), p(t, f, f));
    quad(out, p(f, t, f), p(t, t, f), p(t, t, t), p(f, t, t));
}

/// A UV sphere of `seg` × `seg` quads.
pub fn sphere(out: &mut Vec<Triangle>, c: Vec3, r: f32, seg: u32) {
    let at = |i: u32, j: u32| {
        let th = std::f32::consts::PI * i as f32 / seg as f32;
        let ph = std::f32::consts::TAU * j as f32 / seg as f32;
        c + r * Vec3::new(th.sin() * ph.cos(), th.cos(), th.sin() * ph.sin())
    };
    for i in 0..seg {
        for j in 0..seg {
            quad(out, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
        }
    }
}

/// A 2×2×2 room (open at +z unless `closed`), two boxes, a sphere of `seg`² quads, camera
/// inside looking at −z, a small light under the ceiling.
pub fn room(closed: bool, seg: u32) -> Scene {
    let mut t = Vec::new();
    // Walls: floor, ceiling, back, left, right (+ front when closed).
    quad(
        &mut t,
        Vec3::new(-1.0, -1.0, -1.0),
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(1.0, -1.0, 1.0),
        Vec3::new(1.0, -1.0, -1.0),
    );
    quad(
        &mut t,
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(1.0, 1.0, -1.0),
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(-1.0, 1.0, 1.0),
    );
    quad(
        &mut t,
        Vec3::new(-1.0, -1.0, -1.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(1.0, 1.0, -1.0),
        Vec3::new(-1.0, 1.0, -1.0),
    );
    quad(
        &mut t,
        Vec3::new(-1.0, -1.0, -1.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(-1.0, 1.0, 1.0),
        Vec3::new(-1.0, -1.0, 1.0),
    );
    quad(
        &mut t,
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(1.0, -1.0, 1.0),
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(1.0, 1.0, -1.0),
    );
    if closed {
        quad(
            &mut t,
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(-1.0, 1.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
        );
    }
    cuboid(
        &mut t,
        Vec3::new(-0.7, -1.0, -0.6),
        Vec3::new(-0.2, 0.2, -0.1),
    );
    cuboid(
        &mut t,
        Vec3::new(0.25, -1.0, -0.3),
        Vec3::new(0.65, -0.5, 0.1),
    );
    sphere(&mut t, Vec3::new(0.45, -0.2, -0.1), 0.3, seg);
    let mut s = Scene::from_triangles("room", "test:room", t, LoadStats::default()).unwrap();
    s.camera = Camera {
        eye: Vec3::new(0.0, 0.0, 0.95),
        target: Vec3::new(0.0, -0.1, -1.0),
        up: Vec3::Y,
        fov_y_deg: 70.0,
    };
    s.light = Light {
        position: Vec3::new(0.1, 0.85, 0.2),
        radius: 0.05,
        intensity: 1.0,
    };
    s
}

/// `n` random triangles from `seed`, scaled by `scale`, in one of four shapes: 0 free small
/// triangles (the second and third vertex pulled towards the first, so boxes differ), 1
/// grid-snapped (coordinates rounded: coincident planes, coordinates 0.0), 2 axis-aligned
/// (each triangle lying in a coordinate plane, on the grid), 3 flat (one z). Coordinates in
/// [−4, 4] before scaling. The structures' random-scene tests share it.
pub fn random_scene(seed: u64, n: usize, shape: u32, scale: f32) -> Vec<Triangle> {
    let mut rng = Pcg32::new(seed, 7);
    let pt = |rng: &mut Pcg32| {
        let p = Vec3::new(
            rng.range_f32(-4.0, 4.0),
            rng.range_f32(-4.0, 4.0),
            rng.range_f32(-4.0, 4.0),
        );
        let p = match shape {
            1 | 2 => p.round(),
            3 => Vec3::new(p.x, p.y, 1.0),
            _ => p,
        };
        p * scale
    };
    (0..n)
        .map(|_| {
            let a = pt(&mut rng);
            let mut b = pt(&mut rng);
            let mut c = pt(&mut rng);
            if shape == 2 {
                let axis = rng.below(3) as usize;
                b[axis] = a[axis];
                c[axis] = a[axis];
            } else if shape == 0 {
                b = a + (b - a) * 0.3;
                c = a + (c - a) * 0.3;
            }
            Triangle::new(a, b, c)
        })
        .collect()
}
