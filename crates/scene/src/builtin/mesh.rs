//! Mesh helpers shared by the builtin generators: quads, boxes, parametric grids, swept
//! tubes and surfaces of revolution, each with a known triangle count so generators can
//! size their objects to a triangle budget before generating them.

use dualsplit_geometry::{Pcg32, Triangle, Vec3};

/// A growing triangle soup.
#[derive(Clone, Debug, Default)]
pub(crate) struct Mesh {
    /// The triangles so far.
    pub tris: Vec<Triangle>,
}

/// Triangles of [`Mesh::cuboid`].
pub(crate) const CUBOID_TRIS: usize = 12;

impl Mesh {
    /// An empty mesh with room for `n` triangles.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            tris: Vec::with_capacity(n),
        }
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// One triangle.
    #[inline]
    pub fn tri(&mut self, a: Vec3, b: Vec3, c: Vec3) {
        self.tris.push(Triangle::new(a, b, c));
    }

    /// The quad `a b c d` (in ring order) as two triangles.
    #[inline]
    pub fn quad(&mut self, a: Vec3, b: Vec3, c: Vec3, d: Vec3) {
        self.tri(a, b, c);
        self.tri(a, c, d);
    }

    /// An axis-aligned box: 6 faces, [`CUBOID_TRIS`] triangles.
    pub fn cuboid(&mut self, min: Vec3, max: Vec3) {
        let p = |x: bool, y: bool, z: bool| {
            Vec3::new(
                if x { max.x } else { min.x },
                if y { max.y } else { min.y },
                if z { max.z } else { min.z },
            )
        };
        let (f, t) = (false, true);
        self.quad(p(f, f, f), p(f, t, f), p(t, t, f), p(t, f, f)); // -z
        self.quad(p(f, f, t), p(t, f, t), p(t, t, t), p(f, t, t)); // +z
        self.quad(p(f, f, f), p(f, f, t), p(f, t, t), p(f, t, f)); // -x
        self.quad(p(t, f, f), p(t, t, f), p(t, t, t), p(t, f, t)); // +x
        self.quad(p(f, f, f), p(t, f, f), p(t, f, t), p(f, f, t)); // -y
        self.quad(p(f, t, f), p(f, t, t), p(t, t, t), p(t, t, f)); // +y
    }

    /// A parametric surface `f(u, v)`, `u, v ∈ [0, 1]`, on an `nu × nv` grid of quads:
    /// `2 · nu · nv` triangles.
    pub fn grid(&mut self, nu: usize, nv: usize, f: impl Fn(f32, f32) -> Vec3) {
        let row = |j: usize| -> Vec<Vec3> {
            (0..=nu)
                .map(|i| f(i as f32 / nu as f32, j as f32 / nv as f32))
                .collect()
        };
        let mut prev = row(0);
        for j in 1..=nv {
            let cur = row(j);
            for i in 0..nu {
                self.quad(prev[i], prev[i + 1], cur[i + 1], cur[i]);
            }
            prev = cur;
        }
    }

    /// A tube of `sides` sides swept along `path` with radius `radius(i)` at point `i`,
    /// open at both ends: `2 · sides · (path.len() - 1)` triangles. Frames are parallel
    /// transported along the path so the tube never twists.
    pub fn tube(&mut self, path: &[Vec3], sides: usize, radius: impl Fn(usize) -> f32) {
        if path.len() < 2 {
            return;
        }
        let tangent = |i: usize| -> Vec3 {
            let a = path[i.saturating_sub(1)];
            let b = path[(i + 1).min(path.len() - 1)];
            (b - a).normalize_or(Vec3::Y)
        };
        self.tris.reserve(2 * sides * (path.len() - 1));
        let t = tangent(0);
        let (mut n, _) = t.any_orthonormal_pair();
        let ring = |out: &mut Vec<Vec3>, c: Vec3, t: Vec3, n: Vec3, r: f32| {
            let b = t.cross(n);
            out.clear();
            out.extend((0..sides).map(|k| {
                let a = std::f32::consts::TAU * k as f32 / sides as f32;
                c + (n * a.cos() + b * a.sin()) * r
            }));
        };
        let (mut prev, mut cur) = (Vec::with_capacity(sides), Vec::with_capacity(sides));
        ring(&mut prev, path[0], t, n, radius(0));
        for (i, &c) in path.iter().enumerate().skip(1) {
            let t = tangent(i);
            // Parallel transport: remove the new tangent's component from the old normal.
            n = (n - t * n.dot(t)).normalize_or(t.any_orthonormal_pair().0);
            ring(&mut cur, c, t, n, radius(i));
            for k in 0..sides {
                let k1 = (k + 1) % sides;
                self.quad(prev[k], prev[k1], cur[k1], cur[k]);
            }
            std::mem::swap(&mut prev, &mut cur);
        }
    }

    /// A surface of revolution around the vertical axis through `base`, from a profile of
    /// `(radius, height)` points: `2 · sides · (profile.len() - 1)` triangles.
    pub fn lathe(&mut self, base: Vec3, profile: &[(f32, f32)], sides: usize) {
        self.grid(sides, profile.len() - 1, |u, v| {
            let a = std::f32::consts::TAU * u;
            let x = v * (profile.len() - 1) as f32;
            let i = (x as usize).min(profile.len() - 2);
            let f = x - i as f32;
            let r = profile[i].0 + (profile[i + 1].0 - profile[i].0) * f;
            let h = profile[i].1 + (profile[i + 1].1 - profile[i].1) * f;
            base + Vec3::new(r * a.cos(), h, r * a.sin())
        });
    }
}

/// A point uniformly distributed in the unit ball.
pub(crate) fn in_unit_ball(rng: &mut Pcg32) -> Vec3 {
    loop {
        let p = Vec3::new(
            rng.range_f32(-1.0, 1.0),
            rng.range_f32(-1.0, 1.0),
            rng.range_f32(-1.0, 1.0),
        );
        if p.length_squared() <= 1.0 {
            return p;
        }
    }
}

/// A unit vector uniformly distributed on the sphere.
pub(crate) fn unit_vector(rng: &mut Pcg32) -> Vec3 {
    let z = rng.range_f32(-1.0, 1.0);
    let phi = rng.range_f32(0.0, std::f32::consts::TAU);
    let r = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Splits `total` items into `parts` counts that differ by at most one (the first
/// `total % parts` get one more).
pub(crate) fn split_evenly(total: usize, parts: usize) -> impl Iterator<Item = usize> {
    let base = total / parts.max(1);
    let extra = total % parts.max(1);
    (0..parts).map(move |i| base + usize::from(i < extra))
}

/// Generates objects in parallel straight into their slots of one output array: object `i`
/// has exactly `counts[i]` triangles and lands after objects `0..i`, whatever the thread
/// count, so the result is deterministic.
pub(crate) fn par_objects(counts: &[usize], make: impl Fn(usize) -> Mesh + Sync) -> Vec<Triangle> {
    use rayon::prelude::*;
    let mut out = vec![Triangle::default(); counts.iter().sum()];
    let mut slots = Vec::with_capacity(counts.len());
    let mut rest = out.as_mut_slice();
    for &n in counts {
        let (slot, tail) = std::mem::take(&mut rest).split_at_mut(n);
        slots.push(slot);
        rest = tail;
    }
    slots.into_par_iter().enumerate().for_each(|(i, slot)| {
        let m = make(i);
        assert_eq!(
            m.len(),
            slot.len(),
            "object {i} has the wrong triangle count"
        );
        slot.copy_from_slice(&m.tris);
    });
    out
}
