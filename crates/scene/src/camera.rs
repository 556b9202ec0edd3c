use dualsplit_geometry::{Aabb, Vec3};
use serde::{Deserialize, Serialize};

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Up vector.
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
}

/// A spherical area light (radius 0 = point light).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Light {
    /// Centre.
    pub position: Vec3,
    /// Radius; shadow rays aim at a point sampled on the sphere.
    pub radius: f32,
    /// Radiant intensity (linear RGB, grey here).
    pub intensity: f32,
}

impl Camera {
    /// A camera looking at the centre of `b` from the +z/+y side, far enough to see it all.
    pub fn fit(b: &Aabb) -> Self {
        let c = b.center();
        let r = (b.extent().length() * 0.5).max(1e-3);
        let fov_y_deg: f32 = 45.0;
        let dist = r / (fov_y_deg.to_radians() * 0.5).sin();
        let dir = Vec3::new(0.35, 0.35, 1.0).normalize();
        Self {
            eye: c + dir * dist,
            target: c,
            up: Vec3::Y,
            fov_y_deg,
        }
    }
}

impl Light {
    /// A light above and in front of the scene, a little to the side of a fitted camera.
    pub fn fit(b: &Aabb) -> Self {
        let c = b.center();
        let e = b.extent();
        let r = (e.length() * 0.5).max(1e-3);
        Self {
            position: c + Vec3::new(-0.4 * e.x, 0.9 * e.y.max(r * 0.5), 0.6 * e.z.max(r * 0.3)),
            radius: r * 0.02,
            intensity: 1.0,
        }
    }
}
