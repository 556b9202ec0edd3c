//! `builtin:hairball`: thin curly tubes tangled inside a sphere, standing in for Laine's
//! Hairball (2.9M triangles), the paper's scene with the highest depth complexity
//! (Lin et al. 2020, §4, Table 3, Fig. 9).
//!
//! Each strand is a smooth space curve grown inside the unit ball: its direction turns about
//! a slowly drifting curl axis (so it winds in loose helices that keep changing direction)
//! and steers back inward near the surface. The curve is swept with a small polygonal cross
//! section into an open tube. Thousands of such tubes give what makes the Hairball hard:
//! long, thin, heavily overlapping triangles whose boxes are mostly empty space, and many
//! surfaces along every ray.

use super::Params;
use super::mesh::{Mesh, in_unit_ball, par_objects, split_evenly, unit_vector};
use crate::{Camera, Light, SceneError};
use dualsplit_geometry::{Pcg32, Triangle, Vec3};

/// Parameters of `builtin:hairball`; each field is a spec key with its default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HairballParams {
    /// `triangles`: target triangle count (default 2,900,000, like the paper's Hairball).
    pub triangles: u32,
    /// `seed`: random seed (default 1).
    pub seed: u64,
    /// `sides`: sides of a tube's cross-section (default 4, range 3–16).
    pub sides: u32,
    /// `segments`: segments along a typical strand (default 48); the strand count follows
    /// from the budget.
    pub segments: u32,
    /// `radius`: tube radius relative to the ball radius (default 0.004).
    pub radius: f32,
    /// `length`: strand length relative to the ball radius (default 1.5).
    pub length: f32,
    /// `curl`: curvature of the strands in 1/ball-radius (default 9: curls of radius ≈ 0.11).
    pub curl: f32,
}

impl Default for HairballParams {
    fn default() -> Self {
        Self {
            triangles: 2_900_000,
            seed: 1,
            sides: 4,
            segments: 48,
            radius: 0.004,
            length: 1.5,
            curl: 9.0,
        }
    }
}

/// Ball radius in scene units.
const BALL: f32 = 1.0;

impl HairballParams {
    /// Reads the keys from `p`, with range checks.
    pub fn from_params(p: &mut Params) -> Result<Self, SceneError> {
        let d = Self::default();
        let sides = p.get("sides", d.sides, 3, 16)?;
        let s = Self {
            sides,
            triangles: p.get("triangles", d.triangles, 1, 50_000_000)?,
            seed: p.get("seed", d.seed, 0, u64::MAX)?,
            segments: p.get("segments", d.segments, 2, 10_000)?,
            radius: p.get("radius", d.radius, 1e-5, 0.2)?,
            length: p.get("length", d.length, 0.01, 100.0)?,
            curl: p.get("curl", d.curl, 0.0, 1000.0)?,
        };
        if s.triangles < s.min_triangles() {
            return Err(p.error(format!(
                "`triangles={}` is too small: a hairball with {} sides needs at least {}",
                s.triangles,
                s.sides,
                s.min_triangles()
            )));
        }
        Ok(s)
    }

    /// The smallest budget kept within 5 % (20 tube segments).
    pub fn min_triangles(&self) -> u32 {
        40 * self.sides
    }

    /// Segments of each strand: the budget's segments split evenly over the strands.
    fn strand_segments(&self) -> Vec<usize> {
        let per_seg = 2 * self.sides as usize;
        let total = (self.triangles as usize / per_seg).max(2);
        let strands = (total / self.segments as usize).max(1);
        split_evenly(total, strands).collect()
    }

    /// Generates the triangles (in parallel, deterministic).
    pub fn triangles(&self) -> Vec<Triangle> {
        let segs = self.strand_segments();
        let per_seg = 2 * self.sides as usize;
        let counts: Vec<usize> = segs.iter().map(|&n| n * per_seg).collect();
        par_objects(&counts, |i| self.strand(i as u64, segs[i]))
    }

    /// Strand `id` with `n` segments.
    fn strand(&self, id: u64, n: usize) -> Mesh {
        let mut rng = Pcg32::new(self.seed, id);
        let step = self.length * BALL / self.segments as f32;
        let mut p = in_unit_ball(&mut rng) * (0.92 * BALL);
        let mut d = unit_vector(&mut rng);
        let mut axis = unit_vector(&mut rng);
        // Per-strand curl varies ±50 % so the tangle is not uniform.
        let curl = self.curl / BALL * rng.range_f32(0.5, 1.5);
        let mut path = Vec::with_capacity(n + 1);
        path.push(p);
        for _ in 0..n {
            // The curl axis drifts slowly: loose helices that keep changing direction.
            axis = (axis + unit_vector(&mut rng) * 0.35).normalize_or(Vec3::Y);
            let q = glam::Quat::from_axis_angle(axis, curl * step);
            d = (q * d).normalize_or(Vec3::X);
            let r = p.length();
            if r > 0.85 * BALL {
                // Steer back inward, harder the further out.
                let k = ((r - 0.85 * BALL) / (0.15 * BALL)).min(1.0);
                d = (d - p / r * (k * 0.6 * d.dot(p / r).max(0.0) + 0.15 * k)).normalize_or(-p / r);
            }
            p += d * step;
            path.push(p);
        }
        let r = self.radius * BALL * rng.range_f32(0.7, 1.3);
        let mut m = Mesh::with_capacity(2 * self.sides as usize * n);
        m.tube(&path, self.sides as usize, |_| r);
        m
    }

    /// A view of the whole ball, slightly from above.
    pub fn camera(&self) -> Camera {
        Camera {
            eye: Vec3::new(0.9, 0.8, 2.9) * BALL,
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 42.0,
        }
    }

    /// A light above, left and in front of the ball.
    pub fn light(&self) -> Light {
        Light {
            position: Vec3::new(-2.0, 3.0, 2.5) * BALL,
            radius: 0.1 * BALL,
            intensity: 1.0,
        }
    }
}
