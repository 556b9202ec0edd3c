//! The dispatch of one ray to the traversal loop ([`super::traverse`]) compiled for SSE2 or,
//! inside [`Avx2::vectorize`], for AVX2.

use super::isa::Sse2;
use super::lanes::Lanes;
use super::layout::TriPacket;
use super::traverse::{Entry, run};
use crate::wide::simd::{Avx2, Kernel};
use dualsplit_geometry::{Hit, Ray};

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
