//! The instruction sets a traversal runs with ([`SimdLevel`]) and the dispatch of one ray
//! to the SSE2 code or to the code compiled for AVX2.

use super::layout::{Chunk8, LANES, Lanes, TriPacket};
use super::ray::RaySimd;
use super::traverse::{Entry, run};
use crate::wide::simd::{Avx2, Kernel};
use dualsplit_geometry::{Hit, Ray};
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

/// [`run`] with SSE2, or with AVX2 inside [`Avx2::vectorize`] when `avx2` holds the token.
#[inline(always)]
pub(super) fn dispatch<N: Lanes, const ANY: bool>(
    avx2: Option<Avx2>,
    nodes: &[N],
    packets: &[TriPacket],
    ray: &Ray,
    stack: &mut [Entry],
) -> Option<Hit> {
    match avx2 {
        None => run_sse2::<N, ANY>(nodes, packets, ray, stack),
        Some(isa) => isa
            .vectorize(Run::<N, ANY> {
                isa,
                nodes,
                packets,
                ray,
                stack,
            })
            .unpack(),
    }
}

/// [`run`] with SSE2, out of line as the AVX2 path is (inside [`Avx2::vectorize`]): inlined,
/// it made the caller of both a large function whose entry and exit every ray paid.
#[inline(never)]
fn run_sse2<N: Lanes, const ANY: bool>(
    nodes: &[N],
    packets: &[TriPacket],
    ray: &Ray,
    stack: &mut [Entry],
) -> Option<Hit> {
    run::<N, Sse2, ANY>(Sse2, nodes, packets, ray, stack)
}

/// [`run`] with AVX2, as a [`Kernel`] for [`Avx2::vectorize`].
struct Run<'a, N, const ANY: bool> {
    isa: Avx2,
    nodes: &'a [N],
    packets: &'a [TriPacket],
    ray: &'a Ray,
    stack: &'a mut [Entry],
}

impl<N: Lanes, const ANY: bool> Kernel for Run<'_, N, ANY> {
    type Output = PackedHit;
    #[inline(always)]
    fn call(self) -> PackedHit {
        PackedHit::pack(run::<N, Avx2, ANY>(
            self.isa,
            self.nodes,
            self.packets,
            self.ray,
            self.stack,
        ))
    }
}

/// An `Option<Hit>` in 128 bits (the hit's bytes; a miss is all ones, so its prim is
/// `u32::MAX`, which no triangle id reaches), so that it comes back from the AVX2 function
/// in two registers rather than through memory, where the caller's 16-byte load of the
/// callee's four 4-byte stores cannot be forwarded and stalls.
#[derive(Clone, Copy)]
pub(crate) struct PackedHit(u128);

impl PackedHit {
    /// Packs `h`.
    #[inline(always)]
    pub(crate) fn pack(h: Option<Hit>) -> Self {
        Self(h.map_or(u128::MAX, bytemuck::cast))
    }

    /// The hit packed.
    #[inline(always)]
    pub(crate) fn unpack(self) -> Option<Hit> {
        let h: Hit = bytemuck::cast(self.0);
        (h.prim.0 != u32::MAX).then_some(h)
    }
}
