//! The instruction sets a traversal runs with ([`Isa`], [`SimdLevel`]); the dispatch of one
//! ray to the SSE2 code or to the code compiled for AVX2 is [`super::dispatch`].

use super::layout::{Chunk8, LANES};
use super::ray::RaySimd;
use crate::wide::simd::Avx2;
use wide::f32x4;

/// The instruction set a traversal runs with: [`Sse2`] (every x86-64 CPU; the portable
/// `wide` code elsewhere) or [`Avx2`] (one 8-wide box test per BVH8 node, and the whole
/// traversal compiled for AVX2). Answers are the same bits with either.
pub(crate) trait Isa: Copy {
    /// Entry distances (lanes 0–3, then 4–7) and the mask of the lanes of `n` that the ray
    /// meets on `[t_lo, t_hi]` (never an empty one, for a finite origin and direction).
    fn test8(self, rs: &RaySimd, n: &Chunk8, t_lo: f32, t_hi: f32) -> ([f32x4; 2], u32);

    /// The AVX2 token when these are AVX2's instructions (for [`Avx2::sort_hits8`]).
    fn avx2(self) -> Option<Avx2>;

    /// Lane `i` (below 8) of the entry distances `dv` of [`Isa::test8`] or of a 4-wide
    /// node's test.
    fn lane(self, dv: [f32x4; 2], i: usize) -> f32;
}

/// Baseline x86-64 (SSE2), or the portable `wide` code on other targets: 4-wide vectors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Sse2;

impl Isa for Sse2 {
    #[inline(always)]
    fn test8(self, rs: &RaySimd, n: &Chunk8, t_lo: f32, t_hi: f32) -> ([f32x4; 2], u32) {
        let half = |h: usize| rs.test_rows(|p| half_of(&n.planes[p], h), t_lo, t_hi);
        let ((e0, m0), (e1, m1)) = (half(0), half(1));
        ([e0, e1], m0 | m1 << LANES)
    }

    #[inline(always)]
    fn avx2(self) -> Option<Avx2> {
        None
    }

    #[inline(always)]
    fn lane(self, dv: [f32x4; 2], i: usize) -> f32 {
        let dist: [f32; 2 * LANES] = bytemuck::cast(dv);
        // Lanes are below 8 (the mask's bits), which the `& 7` tells the compiler, so the
        // lookup has no bounds check.
        dist[i & (2 * LANES - 1)]
    }
}

impl Isa for Avx2 {
    #[inline(always)]
    fn test8(self, rs: &RaySimd, n: &Chunk8, t_lo: f32, t_hi: f32) -> ([f32x4; 2], u32) {
        let (e, m) = self.slab8(
            &n.planes,
            rs.rows8,
            rs.os,
            rs.neg_invs,
            rs.neg_inv_ws,
            t_lo,
            t_hi,
        );
        (bytemuck::cast(e), m)
    }

    #[inline(always)]
    fn avx2(self) -> Option<Avx2> {
        Some(self)
    }

    #[inline(always)]
    fn lane(self, dv: [f32x4; 2], i: usize) -> f32 {
        self.lane8(bytemuck::cast(dv), i)
    }
}

/// Lanes `4h..4h + 4` of an 8-lane row.
#[inline(always)]
fn half_of<T: Copy + Default>(row: &[T; 8], h: usize) -> [T; LANES] {
    let mut out = [T::default(); LANES];
    out.copy_from_slice(&row[LANES * h..LANES * (h + 1)]);
    out
}

/// Which instructions the plain queries use: the best this CPU has, unless the environment
/// variable `DUALSPLIT_SIMD` is `sse2` (for measuring one against the other; answers are
/// the same bits either way).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimdLevel {
    /// 4-wide SSE2 code (the portable `wide` code off x86-64).
    Sse2,
    /// AVX2: 8-wide BVH8 box tests, the whole traversal compiled for AVX2.
    Avx2,
}

impl SimdLevel {
    /// The best level of this CPU, or SSE2 when `DUALSPLIT_SIMD=sse2`.
    pub fn detect() -> Self {
        static LEVEL: std::sync::OnceLock<SimdLevel> = std::sync::OnceLock::new();
        *LEVEL.get_or_init(|| {
            let forced =
                std::env::var("DUALSPLIT_SIMD").is_ok_and(|v| v.eq_ignore_ascii_case("sse2"));
            if Avx2::detect().is_some() && !forced {
                Self::Avx2
            } else {
                Self::Sse2
            }
        })
    }

    /// The AVX2 token when the level is AVX2 and this CPU has it.
    pub(super) fn token(self) -> Option<Avx2> {
        match self {
            Self::Avx2 => Avx2::detect(),
            Self::Sse2 => None,
        }
    }

    /// Every level this CPU can run, the baseline first.
    pub fn available() -> Vec<Self> {
        std::iter::once(Self::Sse2)
            .chain(Avx2::detect().map(|_| Self::Avx2))
            .collect()
    }
}

/// The AVX2 token when [`SimdLevel::detect`] chooses AVX2.
pub(crate) fn avx2_token() -> Option<Avx2> {
    static TOKEN: std::sync::OnceLock<Option<Avx2>> = std::sync::OnceLock::new();
    *TOKEN.get_or_init(|| SimdLevel::detect().token())
}
