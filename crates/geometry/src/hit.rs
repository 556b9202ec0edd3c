use crate::TriangleHit;

/// A triangle id: the triangle's index in the scene's triangle array, which every
/// structure's leaves and the hit it returns name it by.
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, bytemuck::Pod, bytemuck::Zeroable,
)]
#[repr(transparent)]
pub struct PrimId(pub u32);

impl PrimId {
    /// The id as an index into the triangle array.
    #[inline(always)]
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

impl std::fmt::Display for PrimId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

/// A closest-hit result: the ray parameter and the triangle id (index into the scene's
/// triangle array), plus the barycentric coordinates of the hit.
///
/// Plain data (`repr(C)`, [`bytemuck::Pod`]): 16 bytes in the order `t`, `prim`, `u`, `v`,
/// so hits can be written and read in bulk.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Hit {
    /// Ray parameter of the hit point.
    pub t: f32,
    /// Triangle id.
    pub prim: PrimId,
    /// Barycentric u (weight of vertex 1).
    pub u: f32,
    /// Barycentric v (weight of vertex 2).
    pub v: f32,
}

const _: () = assert!(std::mem::size_of::<Hit>() == 16);

impl Hit {
    /// The total order used by every closest-hit traversal: smaller `t` wins, equal `t` goes
    /// to the smaller triangle id. Using it everywhere makes results independent of the
    /// order in which a structure visits its leaves.
    #[inline]
    pub fn closer_than(&self, t: f32, prim: PrimId) -> bool {
        self.t < t || (self.t == t && self.prim < prim)
    }

    /// The hit `h` of triangle `prim`.
    #[inline]
    pub fn on(prim: PrimId, h: TriangleHit) -> Self {
        Self {
            t: h.t,
            prim,
            u: h.u,
            v: h.v,
        }
    }

    /// Puts the hit `h` of triangle `prim` into `best` unless `best` is closer by
    /// [`Hit::closer_than`]'s order; true when it did.
    #[inline]
    pub fn keep_closest(best: &mut Option<Hit>, prim: PrimId, h: TriangleHit) -> bool {
        let keep = best.is_none_or(|b| !b.closer_than(h.t, prim));
        if keep {
            *best = Some(Self::on(prim, h));
        }
        keep
    }
}

/// The far bound used for culling nodes against the current best hit `best_t` (or the ray's
/// `t_max` for shadow rays): `best_t` widened by a relative 2^-12.
///
/// Slab distances and triangle distances are computed with different arithmetic, so a
/// triangle hit at `t` can sit one or two ulps before the computed entry of the box that
/// holds it. Culling at exactly `best_t` could then skip a leaf holding an equal-`t` hit with a
/// smaller id (a ray through a shared edge), and two structures would disagree. The margin
/// costs a negligible amount of extra work and keeps all structures bit-identical.
#[inline]
pub fn cull_limit(best_t: f32) -> f32 {
    best_t + best_t.abs() * (1.0 / 4096.0) + f32::MIN_POSITIVE
}
