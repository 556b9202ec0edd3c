//! Scenes for tests and benchmarks: the shipped meshes, and a room built in code (no
//! loader needed).

use dualsplit_geometry::{Triangle, Vec3};
use dualsplit_scene::{Camera, Light, LoadStats, Scene};

/// Path of the shipped scene file `name` (in the `shared/scenes` folder beside the
/// repository).
pub fn scene_path(name: &str) -> String {
    format!(
        "{}/../../../shared/scenes/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// Loads the shipped scene `name` with `dualsplit_scene::load`.
///
/// # Panics
/// When the file is missing or does not parse, naming the path.
pub fn load_scene(name: &str) -> Scene {
    let path = scene_path(name);
    dualsplit_scene::load(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// The triangles of the shipped scene `name`.
pub fn load_shipped(name: &str) -> Vec<Triangle> {
    load_scene(name).triangles
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
