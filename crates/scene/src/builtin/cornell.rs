//! `builtin:cornell`: a tiny Cornell box (unit cube open toward +z, a tall and a short
//! block) for tests: 34 triangles by default, every one of them visible from the default
//! camera. `subdiv=N` splits each wall into `N × N` quads (10·N² + 24 triangles), for tests
//! that want shared edges and more leaves.

use super::Params;
use super::mesh::Mesh;
use crate::{Camera, Light, SceneError};
use dualsplit_geometry::{Triangle, Vec3};

/// Parameters of `builtin:cornell`; each field is a spec key with its default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CornellParams {
    /// `subdiv`: each of the 5 walls is split into `subdiv × subdiv` quads (default 1,
    /// range 1–256).
    pub subdiv: u32,
}

impl Default for CornellParams {
    fn default() -> Self {
        Self { subdiv: 1 }
    }
}

impl CornellParams {
    /// Reads the keys from `p`, with range checks.
    pub fn from_params(p: &mut Params) -> Result<Self, SceneError> {
        Ok(Self {
            subdiv: p.get("subdiv", 1, 1, 256)?,
        })
    }

    /// Number of triangles generated: `10 · subdiv² + 24`.
    pub fn triangle_count(&self) -> usize {
        10 * (self.subdiv as usize).pow(2) + 24
    }

    /// Generates the triangles: floor, ceiling, back, left and right walls, then the short
    /// and the tall block (each a box turned about y, all 6 faces).
    pub fn triangles(&self) -> Vec<Triangle> {
        let n = self.subdiv as usize;
        let mut m = Mesh::with_capacity(self.triangle_count());
        let wall = |m: &mut Mesh, o: Vec3, u: Vec3, v: Vec3| {
            m.grid(n, n, |a, b| o + u * a + v * b);
        };
        wall(&mut m, Vec3::ZERO, Vec3::Z, Vec3::X); // floor y = 0
        wall(&mut m, Vec3::Y, Vec3::X, Vec3::Z); // ceiling y = 1
        wall(&mut m, Vec3::ZERO, Vec3::X, Vec3::Y); // back z = 0
        wall(&mut m, Vec3::ZERO, Vec3::Y, Vec3::Z); // left x = 0
        wall(&mut m, Vec3::X, Vec3::Z, Vec3::Y); // right x = 1
        block(&mut m, Vec3::new(0.68, 0.0, 0.62), 0.3, 0.3, -0.29);
        block(&mut m, Vec3::new(0.33, 0.0, 0.38), 0.3, 0.6, 0.29);
        m.tris
    }

    /// The classic view through the open side.
    pub fn camera(&self) -> Camera {
        Camera {
            eye: Vec3::new(0.5, 0.5, 1.95),
            target: Vec3::new(0.5, 0.5, 0.0),
            up: Vec3::Y,
            fov_y_deg: 39.0,
        }
    }

    /// A small light just under the middle of the ceiling.
    pub fn light(&self) -> Light {
        Light {
            position: Vec3::new(0.5, 0.9, 0.5),
            radius: 0.05,
            intensity: 1.0,
        }
    }
}

/// A box standing on the floor at `c` (centre of its footprint), `side` wide, `h` tall,
/// turned `angle` radians about y.
fn block(m: &mut Mesh, c: Vec3, side: f32, h: f32, angle: f32) {
    let (s, co) = angle.sin_cos();
    let p = |x: f32, y: f32, z: f32| {
        let (x, z) = ((x - 0.5) * side, (z - 0.5) * side);
        c + Vec3::new(x * co - z * s, y * h, x * s + z * co)
    };
    let start = m.len();
    m.cuboid(Vec3::ZERO, Vec3::ONE);
    for t in &mut m.tris[start..] {
        for v in &mut t.v {
            *v = p(v.x, v.y, v.z);
        }
    }
}
