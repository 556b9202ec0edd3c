use glam::Vec3;

/// `γ_n = n·ε / (1 − n·ε)` with `ε = f32::EPSILON / 2` (the unit roundoff): a bound on the
/// relative error of `n` chained IEEE roundings (Higham; Ize 2013, "Robust BVH ray
/// traversal", JCGT 2(2), §3).
pub const fn gamma(n: u32) -> f32 {
    let e = f32::EPSILON * 0.5;
    let ne = n as f32 * e;
    ne / (1.0 - ne)
}

/// The factor `1 + 2γ₃` by which every exit-role plane distance is multiplied (Ize 2013).
///
/// A plane distance `(p - o) * inv` takes three roundings (the subtraction, the reciprocal
/// and the product), so the computed entry can lie up to `γ₃` (relative) after the exact
/// one and the computed exit up to `γ₃` before it: a ray aimed exactly at a box corner (or
/// a triangle vertex lying on a box face) could see `entry > exit` and lose a hit that the
/// watertight triangle test accepts. Widening exits by `1 + 2γ₃` restores `entry ≤ exit`.
pub const EXIT_WIDEN: f32 = 1.0 + 2.0 * gamma(3);

/// Widens an exit-role plane distance: `t * EXIT_WIDEN` (one multiplication, so NaN stays
/// NaN, ±∞ stays ±∞, ±0 stays ±0).
///
/// Every structure applies it to exactly the distances that play the exit role for the ray
/// (far planes by ray sign), and to nothing else. Because rounding is monotone and the
/// factor is positive, `min(widen_exit(a), widen_exit(b)) == widen_exit(min(a, b))`: a
/// structure that clips with the same planes in another grouping (the DST against its BVH2)
/// reaches exactly the same leaves.
///
/// Exits are widened away from zero: for the usual `t_min ≥ 0` a negative exit is a box
/// behind the ray and stays a miss, so the widening is conservative on `[0, ∞)`.
#[inline(always)]
pub fn widen_exit(t: f32) -> f32 {
    t * EXIT_WIDEN
}

/// A ray `origin + t * dir` valid for `t` in `[t_min, t_max]`.
///
/// Plain data (`repr(C)`, [`bytemuck::Pod`]): 32 bytes, eight little-endian `f32` on the
/// usual targets in the order origin.xyz, dir.xyz, t_min, t_max, so a file of rays can be
/// read in bulk with [`bytemuck::cast_slice`] (or [`bytemuck::pod_read_unaligned`] per ray
/// when the bytes are not 4-aligned).
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Direction (need not be normalised).
    pub dir: Vec3,
    /// Lower end of the valid interval.
    pub t_min: f32,
    /// Upper end of the valid interval.
    pub t_max: f32,
}

const _: () = assert!(std::mem::size_of::<Ray>() == 32);

impl Ray {
    /// A ray valid on `[0, ∞)`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self {
            origin,
            dir,
            t_min: 0.0,
            t_max: f32::INFINITY,
        }
    }

    /// A ray valid on `[t_min, t_max]`.
    pub fn segment(origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self {
        Self {
            origin,
            dir,
            t_min,
            t_max,
        }
    }

    /// True when every structure traces this ray: its origin and direction are finite and
    /// neither end of its interval is NaN (`t_max = +∞` is the usual unbounded ray).
    ///
    /// This is the one rule for rays outside it: every traversal of `dualsplit-accel`
    /// (closest hit and any hit, plain, observed and through a query context) answers a
    /// ray that is not traceable with a miss, without visiting a node. Entry points that
    /// take rays from outside (`dualsplit trace --rays`, the Python package's
    /// `Tree.intersect` and `Tree.occluded`) refuse such rays instead, naming the ray and
    /// the field ([`Ray::untraceable_field`]).
    #[inline(always)]
    pub fn is_traceable(&self) -> bool {
        self.origin.is_finite()
            && self.dir.is_finite()
            && !self.t_min.is_nan()
            && !self.t_max.is_nan()
    }

    /// The first field that makes the ray not [traceable](Ray::is_traceable), with its
    /// value: `("origin.y", inf)`, `("t_max", NaN)`; `None` for a traceable ray.
    pub fn untraceable_field(&self) -> Option<(&'static str, f32)> {
        const NAMES: [&str; 8] = [
            "origin.x", "origin.y", "origin.z", "dir.x", "dir.y", "dir.z", "t_min", "t_max",
        ];
        let v = [
            self.origin.x,
            self.origin.y,
            self.origin.z,
            self.dir.x,
            self.dir.y,
            self.dir.z,
            self.t_min,
            self.t_max,
        ];
        (0..8)
            .find(|&i| {
                if i < 6 {
                    !v[i].is_finite()
                } else {
                    v[i].is_nan()
                }
            })
            .map(|i| (NAMES[i], v[i]))
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }

    /// Per-ray constants used by the slab and triangle tests.
    #[inline]
    pub fn precompute(&self) -> RayPre {
        RayPre::new(self)
    }
}

/// `v[i]` for `i < 3` by selects rather than a load from a computed address (the values
/// are in registers, and `i` depends on the ray).
#[inline(always)]
fn pick(v: [f32; 3], i: usize) -> f32 {
    let b = v.map(f32::to_bits);
    f32::from_bits(if i == 0 {
        b[0]
    } else if i == 1 {
        b[1]
    } else {
        b[2]
    })
}

/// Per-ray precomputed values: the IEEE reciprocal direction (±∞ for zero components), the
/// direction signs, and the shear constants of the watertight triangle test.
#[derive(Clone, Copy, Debug)]
pub struct RayPre {
    /// The ray itself.
    pub ray: Ray,
    /// `1 / dir`, component-wise; ±∞ where a component is ±0.
    pub inv_dir: Vec3,
    /// `inv_dir[a] < 0` (or `-0.0` direction): the ray travels toward −a.
    pub neg: [bool; 3],
    /// Watertight test: the axis where `|dir|` is largest (kz) and the two others (kx, ky).
    pub k: [usize; 3],
    /// Watertight test shear constants `Sx, Sy, Sz`.
    pub shear: Vec3,
}

impl RayPre {
    /// Computes the constants for `ray`.
    ///
    /// Branch-free (the axis choice is selects, not jumps, as directions of diffuse rays
    /// are random) and with the five divisions done two vectors at a time; every value is
    /// the one the scalar definition gives (IEEE division is correctly rounded lane by lane,
    /// and `Sz = 1 / d[kz]` is `inv_dir[kz]`):
    /// `kz` is [`RayPre::major_axis`]; `(kx, ky)` follow it cyclically, swapped when
    /// `d[kz] < 0` to keep the winding; `Sx = d[kx] / d[kz]`, `Sy = d[ky] / d[kz]`.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let d = ray.dir;
        let inv = Self::reciprocal(d);
        let neg = Self::signs(d);
        let kz = Self::major_axis(d);
        let dkz = pick([d.x, d.y, d.z], kz);
        // (kx, ky) = (kz + 1, kz + 2) mod 3, two bits per kz in a constant.
        let (kx, ky) = ((0b00_10_01 >> (2 * kz)) & 3, (0b01_00_10 >> (2 * kz)) & 3);
        let (kx, ky) = if dkz < 0.0 { (ky, kx) } else { (kx, ky) };
        // d / d[kz] on every axis; Sx and Sy are two of its lanes.
        let s = glam::Vec4::new(d.x, d.y, d.z, 1.0) / glam::Vec4::splat(dkz);
        let s = [s.x, s.y, s.z];
        Self {
            ray: *ray,
            inv_dir: inv,
            neg,
            k: [kx, ky, kz],
            shear: Vec3::new(pick(s, kx), pick(s, ky), pick([inv.x, inv.y, inv.z], kz)),
        }
    }

    /// [`RayPre::inv_dir`] of a ray with direction `d`, as [`RayPre::new`] computes it.
    #[inline(always)]
    pub fn reciprocal(d: Vec3) -> Vec3 {
        (glam::Vec4::ONE / glam::Vec4::new(d.x, d.y, d.z, 1.0)).truncate()
    }

    /// [`RayPre::neg`] of a ray with direction `d`: the sign bit of each component.
    #[inline(always)]
    pub fn signs(d: Vec3) -> [bool; 3] {
        [
            d.x.is_sign_negative(),
            d.y.is_sign_negative(),
            d.z.is_sign_negative(),
        ]
    }

    /// The watertight test's `kz` for direction `d`: x when `|dx| >= |dy|` and `|dx| >=
    /// |dz|`, else y when `|dy| >= |dz|`, else z (so z when a component is NaN), by
    /// comparisons without jumps.
    #[inline(always)]
    pub fn major_axis(d: Vec3) -> usize {
        let a = d.abs();
        let x_max = (a.x >= a.y) & (a.x >= a.z);
        let y_max = a.y >= a.z;
        (!x_max) as usize * (1 + (!y_max) as usize)
    }

    /// Ray parameter where the ray meets the plane `x[axis] = p`: `(p - o[axis]) * inv[axis]`.
    /// NaN when the ray lies in the plane (see the crate's robustness rules).
    #[inline(always)]
    pub fn plane_t(&self, axis: usize, p: f32) -> f32 {
        (p - self.ray.origin[axis]) * self.inv_dir[axis]
    }

    /// The distance of an exit-role plane `x[axis] = p`: [`widen_exit`] of
    /// [`RayPre::plane_t`]. Callers decide the role (far plane by ray sign, or a carving
    /// plane whose corner bit says so); entry-role planes use plain [`RayPre::plane_t`].
    #[inline(always)]
    pub fn exit_t(&self, axis: usize, p: f32) -> f32 {
        widen_exit(self.plane_t(axis, p))
    }

    /// Slab test of a box against `[t_lo, t_hi]`: the clipped interval `(entry, exit)`, which
    /// is non-empty (`entry <= exit`) when the ray meets the box. Near and far planes are
    /// chosen by the ray's direction signs (not by swapping distances), so the degenerate
    /// box [`crate::Aabb::DEGENERATE`] (`min = +∞, max = -∞`) never hits, and NaN plane
    /// distances are ignored (closed slabs). The far-plane distances are widened by
    /// [`EXIT_WIDEN`] (Ize 2013) so grazing rays through a box corner are never rounded
    /// away; `t_hi` itself is not widened.
    #[inline(always)]
    pub fn slab(&self, min: Vec3, max: Vec3, t_lo: f32, t_hi: f32) -> (f32, f32) {
        let o = self.ray.origin;
        let inv = self.inv_dir;
        let (nx, fx) = if self.neg[0] {
            (max.x, min.x)
        } else {
            (min.x, max.x)
        };
        let (ny, fy) = if self.neg[1] {
            (max.y, min.y)
        } else {
            (min.y, max.y)
        };
        let (nz, fz) = if self.neg[2] {
            (max.z, min.z)
        } else {
            (min.z, max.z)
        };
        let entry = t_lo
            .max((nx - o.x) * inv.x)
            .max((ny - o.y) * inv.y)
            .max((nz - o.z) * inv.z);
        let exit = t_hi
            .min(widen_exit((fx - o.x) * inv.x))
            .min(widen_exit((fy - o.y) * inv.y))
            .min(widen_exit((fz - o.z) * inv.z));
        (entry, exit)
    }
}
