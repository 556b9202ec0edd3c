//! `builtin:atrium`: an arcaded courtyard standing in for Crytek Sponza (262K triangles;
//! Lin et al. 2020, §4, Table 3).
//!
//! Sponza is the paper's example of regular, largely axis-aligned architecture: most of its
//! triangles lie in axis-aligned planes, so most of the BVH's child boxes share planes with
//! their parents and a dual-split tree needs few carving nodes (§4.2, Table 3). The
//! generator keeps that character:
//!
//! * axis-aligned: a tiled floor (every tile a thin box), masonry walls (every stone a box),
//!   square ground-floor piers, floor slabs, balustrades and an attic wall;
//! * curved, as Sponza's arches, columns and drapes are: two storeys of tessellated
//!   semicircular arches (whose front and back faces still lie in axis-aligned planes),
//!   round upper-storey columns (surfaces of revolution), cloth drapes with folds hanging in
//!   the upper arcades, and large vases in the courtyard.
//!
//! Budget: the curved elements' tessellation level is the largest whose count stays within
//! 35 % of `triangles`; floor tiles and wall stones fill the rest.

use super::Params;
use super::mesh::{CUBOID_TRIS, Mesh};
use crate::{Camera, Light, SceneError};
use dualsplit_geometry::{Pcg32, Triangle, Vec3};

/// Parameters of `builtin:atrium`; each field is a spec key with its default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AtriumParams {
    /// `triangles`: target triangle count (default 262,000, like Crytek Sponza).
    pub triangles: u32,
    /// `seed`: random seed of the drapes' folds and the stones' relief (default 1).
    pub seed: u64,
    /// `bays`: arches along each long side (default 10, range 2–64).
    pub bays: u32,
}

impl Default for AtriumParams {
    fn default() -> Self {
        Self {
            triangles: 262_000,
            seed: 1,
            bays: 10,
        }
    }
}

/// Half length of the courtyard (x).
const X: f32 = 14.0;
/// Distance of the arcade line from the centre (z).
const Z: f32 = 4.0;
/// Gallery depth behind the arcade.
const G: f32 = 3.2;
/// End walls at `x = ±XE`.
const XE: f32 = X + 1.6;
/// Gallery back walls at `z = ±ZE`.
const ZE: f32 = Z + G;
/// Top of the walls.
const TOP: f32 = 14.8;
/// Half thickness of the arcade (piers, arches).
const HT: f32 = 0.35;
/// Share of the budget the curved elements may take.
const CURVED_SHARE: f64 = 0.35;

impl AtriumParams {
    /// Reads the keys from `p`, with range checks.
    pub fn from_params(p: &mut Params) -> Result<Self, SceneError> {
        let d = Self::default();
        let s = Self {
            triangles: p.get("triangles", d.triangles, 1, 50_000_000)?,
            seed: p.get("seed", d.seed, 0, u64::MAX)?,
            bays: p.get("bays", d.bays, 2, 64)?,
        };
        if s.triangles < s.min_triangles() {
            return Err(p.error(format!(
                "`triangles={}` is too small: an atrium with {} bays needs at least {}",
                s.triangles,
                s.bays,
                s.min_triangles()
            )));
        }
        Ok(s)
    }

    /// The smallest budget: twice the structure at the coarsest tessellation.
    pub fn min_triangles(&self) -> u32 {
        (2 * self.structure(1).len()) as u32
    }

    /// Generates the triangles: structure, then floor tiles, then wall stones.
    pub fn triangles(&self) -> Vec<Triangle> {
        let budget = self.triangles as usize;
        let level = (1..=32)
            .take_while(|&l| self.structure(l).len() as f64 <= CURVED_SHARE * budget as f64)
            .last()
            .unwrap_or(1);
        let mut m = self.structure(level);
        let rest = budget.saturating_sub(m.len()) / CUBOID_TRIS;
        let tiles = rest * 2 / 5;
        self.floor_tiles(&mut m, tiles);
        self.masonry(&mut m, rest - tiles);
        m.tris
    }

    /// Bay width.
    fn bay(&self) -> f32 {
        2.0 * X / self.bays as f32
    }

    /// Everything but the tiles and stones, at tessellation `level`.
    fn structure(&self, level: usize) -> Mesh {
        let mut rng = Pcg32::new(self.seed, 0);
        let mut m = Mesh::default();
        let s = self.bay();
        let arch_segs = 4 * level;
        let sides = 4 * level + 4;
        // Foundation slab under the floor, plain backing walls and the attic.
        m.cuboid(Vec3::new(-XE, -0.3, -ZE), Vec3::new(XE, 0.0, ZE));
        for sz in [-1.0f32, 1.0] {
            let (z0, z1) = if sz > 0.0 {
                (ZE, ZE + 0.5)
            } else {
                (-ZE - 0.5, -ZE)
            };
            m.cuboid(Vec3::new(-XE - 0.5, 0.0, z0), Vec3::new(XE + 0.5, TOP, z1));
        }
        for sx in [-1.0f32, 1.0] {
            let (x0, x1) = if sx > 0.0 {
                (XE, XE + 0.5)
            } else {
                (-XE - 0.5, -XE)
            };
            m.cuboid(Vec3::new(x0, 0.0, -ZE), Vec3::new(x1, TOP, ZE));
        }
        for sz in [-1.0f32, 1.0] {
            let zc = sz * Z;
            let (za, zb) = (zc - HT, zc + HT);
            let gallery = |y0: f32, y1: f32| {
                let (a, b) = if sz > 0.0 { (za, ZE) } else { (-ZE, zb) };
                (Vec3::new(-XE, y0, a), Vec3::new(XE, y1, b))
            };
            // Storey 1: square piers with base and capital, arches, floor slab.
            for i in 0..=self.bays {
                let x = -X + s * i as f32;
                m.cuboid(Vec3::new(x - HT, 0.0, za), Vec3::new(x + HT, 4.2, zb));
                m.cuboid(
                    Vec3::new(x - 0.45, 0.0, zc - 0.45),
                    Vec3::new(x + 0.45, 0.35, zc + 0.45),
                );
                m.cuboid(
                    Vec3::new(x - 0.45, 3.9, zc - 0.45),
                    Vec3::new(x + 0.45, 4.2, zc + 0.45),
                );
            }
            for i in 0..self.bays {
                let xc = -X + s * (i as f32 + 0.5);
                arch(
                    &mut m,
                    xc,
                    4.2,
                    s * 0.5 - HT,
                    s * 0.5,
                    5.8,
                    za,
                    zb,
                    arch_segs,
                );
            }
            let (a, b) = gallery(5.8, 6.3);
            m.cuboid(a, b);
            // Storey 2: round columns, balustrades, arches, slab; drapes in every other bay.
            for i in 0..=self.bays {
                let x = -X + s * i as f32;
                let profile = [
                    (0.34, 0.0),
                    (0.34, 0.15),
                    (0.26, 0.3),
                    (0.24, 1.7),
                    (0.22, 3.0),
                    (0.32, 3.3),
                    (0.36, 3.5),
                ];
                m.lathe(Vec3::new(x, 6.3, zc), &profile, sides);
            }
            for i in 0..self.bays {
                let xc = -X + s * (i as f32 + 0.5);
                let w = s * 0.5 - 0.3;
                m.cuboid(
                    Vec3::new(xc - w, 6.3, zc - 0.12),
                    Vec3::new(xc + w, 7.2, zc + 0.12),
                );
                m.cuboid(
                    Vec3::new(xc - w, 7.2, zc - 0.2),
                    Vec3::new(xc + w, 7.35, zc + 0.2),
                );
                arch(
                    &mut m,
                    xc,
                    9.8,
                    s * 0.5 - HT,
                    s * 0.5,
                    11.4,
                    za,
                    zb,
                    arch_segs,
                );
                if i % 2 == 1 {
                    drape(
                        &mut m,
                        &mut rng,
                        xc,
                        s * 0.5 - 0.4,
                        11.0,
                        7.6,
                        zc - sz * 0.5,
                        sz,
                        level,
                    );
                }
            }
            let (a, b) = gallery(11.4, 11.9);
            m.cuboid(a, b);
            // Attic wall above the arcade and the gallery roof.
            m.cuboid(
                Vec3::new(-XE, 11.9, zc - 0.3),
                Vec3::new(XE, TOP - 0.3, zc + 0.3),
            );
            let (a, b) = gallery(TOP - 0.3, TOP);
            m.cuboid(a, b);
        }
        // Vases along the courtyard's axis.
        let vase = [
            (0.35, 0.0),
            (0.45, 0.15),
            (0.6, 0.5),
            (0.62, 0.8),
            (0.45, 1.15),
            (0.32, 1.3),
            (0.42, 1.45),
        ];
        for x in [-8.4, -2.8, 2.8, 8.4] {
            m.lathe(Vec3::new(x, 0.03, 0.0), &vase, sides + 4);
        }
        m
    }

    /// About `n` floor tiles (thin boxes with grout gaps) over the whole floor.
    fn floor_tiles(&self, m: &mut Mesh, n: usize) {
        let (w, d) = (2.0 * XE, 2.0 * ZE);
        let (nx, nz) = grid_dims(n, w, d);
        let (tx, tz) = (w / nx as f32, d / nz as f32);
        let gap = 0.06 * tx.min(tz);
        for j in 0..nz {
            for i in 0..nx {
                let x = -XE + tx * i as f32;
                let z = -ZE + tz * j as f32;
                m.cuboid(
                    Vec3::new(x + gap, 0.0, z + gap),
                    Vec3::new(x + tx - gap, 0.03, z + tz - gap),
                );
            }
        }
    }

    /// About `n` wall stones on the inner faces of the four walls, in running bond.
    fn masonry(&self, m: &mut Mesh, n: usize) {
        // Gallery back walls (normal ∓z) and end walls (normal ∓x): (length, inner plane).
        let walls = [(2.0 * XE, 2usize), (2.0 * ZE, 2usize)];
        let area: f32 = walls.iter().map(|&(l, k)| l * TOP * k as f32).sum();
        let mut rng = Pcg32::new(self.seed, 1);
        for (w, &(len, _)) in walls.iter().enumerate() {
            let share = (n as f32 * len * TOP * 2.0 / area) as usize / 2;
            // Stones are about twice as wide as tall.
            let (cols, rows) = grid_dims(share, len, TOP * 2.0);
            let (sw, sh) = (len / cols as f32, TOP / rows as f32);
            let gap = 0.05 * sh;
            for side in [-1.0f32, 1.0] {
                for r in 0..rows {
                    let off = if r % 2 == 1 { 0.5 * sw } else { 0.0 };
                    for c in 0..cols {
                        let a = (c as f32 * sw + off).min(len) - len * 0.5;
                        let b = ((c + 1) as f32 * sw + off).min(len) - len * 0.5;
                        let (y0, y1) = (r as f32 * sh + gap, (r + 1) as f32 * sh - gap);
                        let depth = 0.04 + 0.03 * rng.next_f32();
                        if w == 0 {
                            let z = side * ZE;
                            m.cuboid(
                                Vec3::new(a + gap, y0, z.min(z - side * depth)),
                                Vec3::new(b - gap, y1, z.max(z - side * depth)),
                            );
                        } else {
                            let x = side * XE;
                            m.cuboid(
                                Vec3::new(x.min(x - side * depth), y0, a + gap),
                                Vec3::new(x.max(x - side * depth), y1, b - gap),
                            );
                        }
                    }
                }
            }
        }
    }

    /// Inside the courtyard near its west end, looking down the arcades.
    pub fn camera(&self) -> Camera {
        Camera {
            eye: Vec3::new(-X - 0.5, 2.4, -2.0),
            target: Vec3::new(6.0, 5.2, 0.9),
            up: Vec3::Y,
            fov_y_deg: 62.0,
        }
    }

    /// Sun-like light high above the open courtyard.
    pub fn light(&self) -> Light {
        Light {
            position: Vec3::new(-6.0, 34.0, 3.0),
            radius: 1.0,
            intensity: 1.0,
        }
    }
}

/// `(columns, rows)` of a grid of about `n` cells over a `w × h` rectangle with square-ish
/// cells (each at least 1).
fn grid_dims(n: usize, w: f32, h: f32) -> (usize, usize) {
    let cols = ((n as f32 * w / h).sqrt().round() as usize).max(1);
    let rows = (n as f32 / cols as f32).round().max(1.0) as usize;
    (cols, rows)
}

/// A semicircular arch of radius `r` springing at height `y0` around `xc`, filling the
/// rectangle `[xc - hw, xc + hw] × [y0, top]` between the planes `z = za` and `z = zb`:
/// front and back faces (axis-aligned planes) plus the curved intrados.
#[allow(clippy::too_many_arguments)]
fn arch(m: &mut Mesh, xc: f32, y0: f32, r: f32, hw: f32, top: f32, za: f32, zb: f32, segs: usize) {
    let h = top - y0;
    let corner = h.atan2(hw);
    let mut angles: Vec<f32> = (0..=segs)
        .map(|k| std::f32::consts::PI * (1.0 - k as f32 / segs as f32))
        .collect();
    angles.extend([corner, std::f32::consts::PI - corner]);
    angles.sort_by(|a, b| b.total_cmp(a));
    let pts: Vec<(f32, f32, f32, f32)> = angles
        .iter()
        .map(|&a| {
            let (s, c) = a.sin_cos();
            // Where the ray from the centre at angle `a` leaves the rectangle.
            let t = if c.abs() < 1e-6 {
                h / s
            } else {
                (hw / c.abs()).min(if s > 1e-6 { h / s } else { f32::MAX })
            };
            (xc + r * c, y0 + r * s, xc + t * c, y0 + t * s)
        })
        .collect();
    for w in pts.windows(2) {
        let ((ix0, iy0, ox0, oy0), (ix1, iy1, ox1, oy1)) = (w[0], w[1]);
        for z in [za, zb] {
            m.quad(
                Vec3::new(ix0, iy0, z),
                Vec3::new(ox0, oy0, z),
                Vec3::new(ox1, oy1, z),
                Vec3::new(ix1, iy1, z),
            );
        }
        m.quad(
            Vec3::new(ix0, iy0, za),
            Vec3::new(ix1, iy1, za),
            Vec3::new(ix1, iy1, zb),
            Vec3::new(ix0, iy0, zb),
        );
    }
}

/// A cloth drape `2·hw` wide hanging from `y_top` to `y_bot` in the plane `z = z0`, with
/// vertical folds that deepen toward the hem and a billow toward the courtyard (`toward`).
#[allow(clippy::too_many_arguments)]
fn drape(
    m: &mut Mesh,
    rng: &mut Pcg32,
    xc: f32,
    hw: f32,
    y_top: f32,
    y_bot: f32,
    z0: f32,
    toward: f32,
    level: usize,
) {
    let folds = rng.range_f32(4.0, 7.0);
    let phase = rng.range_f32(0.0, std::f32::consts::TAU);
    let billow = rng.range_f32(0.2, 0.45);
    m.grid(6 * level, 8 * level, |u, v| {
        let x = xc - hw + 2.0 * hw * u;
        let y = y_top - (y_top - y_bot) * v;
        let fold = 0.12 * (folds * std::f32::consts::TAU * u + phase).sin() * (0.3 + 0.7 * v);
        let bulge = -toward * billow * (std::f32::consts::PI * u).sin() * v * v;
        // The hem hangs a little lower in the middle.
        let sag = -0.25 * (std::f32::consts::PI * u).sin() * v * v;
        Vec3::new(x, y + sag, z0 + fold + bulge)
    });
}
