//! `builtin:forest`: a patch of forest standing in for the paper's Vegetation scene (1.1M
//! triangles; Lin et al. 2020, §4, Table 3).
//!
//! What makes vegetation hard for a tree structure is many small, thin, arbitrarily oriented
//! triangles that overlap heavily in space: their boxes overlap, so no split separates
//! them well, and a ray passes through many leaf boxes before it hits. The generator builds
//! exactly that: trees with a bent, tapered trunk, six primary and twenty-four secondary
//! branches (swept tubes) and hundreds of leaf cards (opaque diamond quads, two triangles
//! each) clustered around the twigs; an undergrowth of grass tufts (one thin triangle per
//! blade); and a gently rolling ground.
//!
//! Budget: the ground takes about 1 %, trees about 75 % of the rest, and grass blades fill
//! the remainder exactly, so the count equals `triangles`.

use super::Params;
use super::mesh::{Mesh, par_objects, split_evenly, unit_vector};
use crate::{Camera, Light, SceneError};
use dualsplit_geometry::{Pcg32, Triangle, Vec3};

/// Parameters of `builtin:forest`; each field is a spec key with its default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForestParams {
    /// `triangles`: target triangle count (default 1,100,000, like the paper's Vegetation).
    pub triangles: u32,
    /// `seed`: random seed (default 1).
    pub seed: u64,
    /// `leaves`: leaf cards per tree (default 1,000; two triangles each).
    pub leaves: u32,
    /// `size`: side of the square patch in metres (default 60).
    pub size: f32,
    /// `tree_share`: fraction of the budget (after the ground) spent on trees, the rest on grass
    /// (default 0.75).
    pub tree_share: f32,
}

impl Default for ForestParams {
    fn default() -> Self {
        Self {
            triangles: 1_100_000,
            seed: 1,
            leaves: 1_000,
            size: 60.0,
            tree_share: 0.75,
        }
    }
}

/// Trunk: sides, segments.
const TRUNK: (usize, usize) = (6, 8);
/// Primary branches per tree, sides, segments.
const PRIMARY: (usize, usize, usize) = (6, 5, 5);
/// Secondary branches per primary, sides, segments.
const SECONDARY: (usize, usize, usize) = (4, 3, 3);
/// Blades per grass tuft.
const TUFT: usize = 12;

impl ForestParams {
    /// Reads the keys from `p`, with range checks.
    pub fn from_params(p: &mut Params) -> Result<Self, SceneError> {
        let d = Self::default();
        let s = Self {
            triangles: p.get("triangles", d.triangles, 1, 50_000_000)?,
            seed: p.get("seed", d.seed, 0, u64::MAX)?,
            leaves: p.get("leaves", d.leaves, 0, 100_000)?,
            size: p.get("size", d.size, 1.0, 10_000.0)?,
            tree_share: p.get("tree_share", d.tree_share, 0.0, 1.0)?,
        };
        if s.triangles < 100 {
            return Err(p.error(format!(
                "`triangles={}` is too small: a forest needs at least 100",
                s.triangles
            )));
        }
        Ok(s)
    }

    /// Triangles of one tree.
    pub fn tree_triangles(&self) -> usize {
        let wood = 2 * TRUNK.0 * TRUNK.1
            + PRIMARY.0 * 2 * PRIMARY.1 * PRIMARY.2
            + PRIMARY.0 * SECONDARY.0 * 2 * SECONDARY.1 * SECONDARY.2;
        wood + 2 * self.leaves as usize
    }

    /// Ground grid resolution (quads per side): about 1 % of the budget, at most 96.
    fn ground_res(&self) -> usize {
        (((self.triangles as f64 * 0.01 / 2.0).sqrt()) as usize).clamp(1, 96)
    }

    /// (trees, grass blades).
    fn split(&self) -> (usize, usize) {
        let g = self.ground_res();
        let rest = self.triangles as usize - 2 * g * g;
        let trees = (rest as f64 * self.tree_share as f64) as usize / self.tree_triangles();
        (trees, rest - trees * self.tree_triangles())
    }

    /// Ground height at `(x, z)`: a few long, low waves.
    fn height(&self, x: f32, z: f32) -> f32 {
        let k = std::f32::consts::TAU / self.size;
        0.6 * (x * k * 1.3 + 0.7).sin() * (z * k * 0.9).cos()
            + 0.3 * (x * k * 2.7 - z * k * 2.1).sin()
    }

    /// Generates the triangles (in parallel, deterministic): ground, trees, grass.
    pub fn triangles(&self) -> Vec<Triangle> {
        let g = self.ground_res();
        let (trees, blades) = self.split();
        let half = self.size * 0.5;
        let tufts = blades.div_ceil(TUFT);
        let blade_counts: Vec<usize> = split_evenly(blades, tufts).collect();
        let mut counts = vec![2 * g * g];
        counts.extend(std::iter::repeat_n(self.tree_triangles(), trees));
        counts.extend_from_slice(&blade_counts);
        // Object 0 is the ground, then the trees, then the grass tufts.
        par_objects(&counts, |i| match i {
            0 => {
                let mut ground = Mesh::with_capacity(2 * g * g);
                ground.grid(g, g, |u, v| {
                    let (x, z) = (-half + u * self.size, half - v * self.size);
                    Vec3::new(x, self.height(x, z), z)
                });
                ground
            }
            i if i <= trees => self.tree((i - 1) as u64),
            i => {
                let t = i - 1 - trees;
                self.tuft(t as u64, blade_counts[t])
            }
        })
    }

    /// A random point on the patch (away from the very edge), on the ground.
    fn place(&self, rng: &mut Pcg32, margin: f32) -> Vec3 {
        let h = self.size * 0.5 - margin;
        let (x, z) = (rng.range_f32(-h, h), rng.range_f32(-h, h));
        Vec3::new(x, self.height(x, z), z)
    }

    /// Tree `id`: trunk, 6 primaries, 24 secondaries, `leaves` cards.
    fn tree(&self, id: u64) -> Mesh {
        let mut rng = Pcg32::new(self.seed, 2 * id);
        let mut m = Mesh::with_capacity(self.tree_triangles());
        let base = self.place(&mut rng, 2.0) - Vec3::Y * 0.2;
        let h = rng.range_f32(6.0, 11.0);
        let r0 = 0.022 * h;
        // Trunk: a gently bent, tapered tube.
        let lean = Vec3::new(rng.range_f32(-1.0, 1.0), 0.0, rng.range_f32(-1.0, 1.0)) * 0.04 * h;
        let trunk: Vec<Vec3> = (0..=TRUNK.1)
            .map(|k| {
                let f = k as f32 / TRUNK.1 as f32;
                base + Vec3::Y * (h * f) + lean * (f * f)
            })
            .collect();
        m.tube(&trunk, TRUNK.0, |k| {
            r0 * (1.0 - 0.7 * k as f32 / TRUNK.1 as f32)
        });
        let trunk_at = |f: f32| base + Vec3::Y * (h * f) + lean * (f * f);
        let golden = 2.399_963;
        let az0 = rng.range_f32(0.0, std::f32::consts::TAU);
        let leaf_counts: Vec<usize> =
            split_evenly(self.leaves as usize, PRIMARY.0 * SECONDARY.0).collect();
        let mut twig = 0;
        for i in 0..PRIMARY.0 {
            let f = 0.4 + 0.55 * i as f32 / PRIMARY.0 as f32 + rng.range_f32(-0.03, 0.03);
            let az = az0 + golden * i as f32 + rng.range_f32(-0.3, 0.3);
            let up = rng.range_f32(0.35, 0.9);
            let dir = Vec3::new(az.cos(), up, az.sin()).normalize();
            let len = h * (0.55 - 0.3 * f) * rng.range_f32(0.8, 1.2);
            let start = trunk_at(f);
            let rb = r0 * (1.0 - 0.7 * f) * 0.7;
            let path = bent_path(start, dir, len, PRIMARY.2, 0.25);
            m.tube(&path, PRIMARY.1, |k| {
                rb * (1.0 - 0.6 * k as f32 / PRIMARY.2 as f32)
            });
            for j in 0..SECONDARY.0 {
                let g = 0.35 + 0.6 * (j as f32 + rng.next_f32()) / SECONDARY.0 as f32;
                let s0 = point_on(&path, g);
                let side = unit_vector(&mut rng);
                let d2 = (dir + side * 0.9 + Vec3::Y * 0.3).normalize();
                let l2 = len * rng.range_f32(0.3, 0.5);
                let p2 = bent_path(s0, d2, l2, SECONDARY.2, -0.2);
                m.tube(&p2, SECONDARY.1, |_| rb * 0.3);
                // Leaf cards clustered around the twig, drooping outward.
                let spread = 0.35 * l2 + 0.25;
                let size = 0.05 * h;
                for _ in 0..leaf_counts[twig] {
                    let c = point_on(&p2, rng.range_f32(0.15, 1.0))
                        + unit_vector(&mut rng) * (spread * rng.next_f32().sqrt());
                    let axis =
                        (d2 + unit_vector(&mut rng) * 0.9 - Vec3::Y * 0.4).normalize_or(Vec3::X);
                    let n = (Vec3::Y * 0.6 + unit_vector(&mut rng)).normalize_or(Vec3::Y);
                    let across = axis.cross(n).normalize_or(Vec3::Z);
                    let s = size * rng.range_f32(0.7, 1.3);
                    let (a, b) = (c, c + axis * s);
                    let mid = c + axis * (0.45 * s);
                    m.quad(a, mid + across * (0.22 * s), b, mid - across * (0.22 * s));
                }
                twig += 1;
            }
        }
        debug_assert_eq!(m.len(), self.tree_triangles());
        m
    }

    /// Grass tuft `id` with `n` blades (one thin triangle each).
    fn tuft(&self, id: u64, n: usize) -> Mesh {
        let mut rng = Pcg32::new(self.seed, 2 * id + 1);
        let c = self.place(&mut rng, 0.5);
        let mut m = Mesh::with_capacity(n);
        for _ in 0..n {
            let a = rng.range_f32(0.0, std::f32::consts::TAU);
            let (s, co) = a.sin_cos();
            let foot = c + Vec3::new(co, 0.0, s) * rng.range_f32(0.0, 0.15) - Vec3::Y * 0.05;
            let w = rng.range_f32(0.015, 0.03);
            let side = Vec3::new(-s, 0.0, co) * w;
            let tip = foot
                + Vec3::new(co, 0.0, s) * rng.range_f32(0.05, 0.3)
                + Vec3::Y * rng.range_f32(0.25, 0.7);
            m.tri(foot - side, foot + side, tip);
        }
        m
    }

    /// Standing at the edge of the patch, a little above the grass, looking in.
    pub fn camera(&self) -> Camera {
        let h = self.size * 0.5;
        Camera {
            eye: Vec3::new(0.28 * h, 7.5, 1.55 * h),
            target: Vec3::new(0.0, 4.5, 0.15 * h),
            up: Vec3::Y,
            fov_y_deg: 55.0,
        }
    }

    /// A sun-like light high above, behind the camera's left shoulder.
    pub fn light(&self) -> Light {
        Light {
            position: Vec3::new(-0.8, 1.6, 1.0) * self.size,
            radius: 0.02 * self.size,
            intensity: 1.0,
        }
    }
}

/// `segments + 1` points from `start` along `dir` for `len`, bending up (`lift > 0`) or down.
fn bent_path(start: Vec3, dir: Vec3, len: f32, segments: usize, lift: f32) -> Vec<Vec3> {
    (0..=segments)
        .map(|k| {
            let f = k as f32 / segments as f32;
            start + dir * (len * f) + Vec3::Y * (lift * len * f * f)
        })
        .collect()
}

/// The point at fraction `f` of a polyline's vertices (linear between them).
fn point_on(path: &[Vec3], f: f32) -> Vec3 {
    let x = f.clamp(0.0, 1.0) * (path.len() - 1) as f32;
    let i = (x as usize).min(path.len() - 2);
    path[i].lerp(path[i + 1], x - i as f32)
}
