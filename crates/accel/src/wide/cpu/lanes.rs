//! A node of the copy as lanes ([`Lanes`]): the one interface the copy, the lane order and
//! the traversal loop read [`Chunk`] and [`Chunk8`] through, with each layout's box test.

use super::isa::Isa;
use super::layout::{Chunk, Chunk8, EMPTY, LANES};
use super::ray::RaySimd;
use wide::f32x4;

/// A node of the copy with `W` lanes: [`Chunk`] (BVH2 and BVH4) or [`Chunk8`] (BVH8).
pub(crate) trait Lanes: bytemuck::Pod + Send + Sync + std::fmt::Debug {
    /// Children per node.
    const W: usize;
    /// A node with every lane empty (degenerate boxes, [`EMPTY`] words until the copy names
    /// the sentinel).
    const EMPTY: Self;
    /// Sets lane `l`'s box words (image order) and child word.
    fn set(&mut self, l: usize, boxw: [f32; 6], child: u32);
    /// Lane `l`'s child word.
    fn child(&self, l: usize) -> u32;
    /// Lane `l`'s box words (image order).
    fn lane_box(&self, l: usize) -> [f32; 6];
    /// Sets lane `l`'s child word.
    fn set_child(&mut self, l: usize, child: u32);
    /// The eight child words of a BVH8 node ([`Chunk8`]); `None` for narrower nodes.
    #[inline(always)]
    fn children8(&self) -> Option<&[u32; 8]> {
        None
    }
    /// Entry distances (lanes 0–3 in the first vector, 4–7 in the second) and the mask of
    /// the lanes the ray meets on `[t_lo, t_hi]`; for a finite origin and direction, never
    /// an empty one (its box has min `+∞` and max `−∞`).
    fn test<I: Isa>(&self, isa: I, rs: &RaySimd, t_lo: f32, t_hi: f32) -> ([f32x4; 2], u32);
}

macro_rules! lanes_impl {
    ($t:ty, $w:expr, |$n:ident, $isa:ident, $rs:ident, $lo:ident, $hi:ident| $test:expr $(, $more:item)*) => {
        impl Lanes for $t {
            const W: usize = $w;
            const EMPTY: Self = Self {
                planes: [
                    [f32::INFINITY; $w],
                    [f32::INFINITY; $w],
                    [f32::INFINITY; $w],
                    [f32::NEG_INFINITY; $w],
                    [f32::NEG_INFINITY; $w],
                    [f32::NEG_INFINITY; $w],
                ],
                child: [EMPTY; $w],
            };
            #[inline]
            fn set(&mut self, l: usize, boxw: [f32; 6], child: u32) {
                for (p, v) in boxw.into_iter().enumerate() {
                    self.planes[p][l] = v;
                }
                self.child[l] = child;
            }
            #[inline(always)]
            fn child(&self, l: usize) -> u32 {
                self.child[l]
            }
            #[inline]
            fn lane_box(&self, l: usize) -> [f32; 6] {
                std::array::from_fn(|p| self.planes[p][l])
            }
            #[inline]
            fn set_child(&mut self, l: usize, child: u32) {
                self.child[l] = child;
            }
            #[inline(always)]
            fn test<I: Isa>(
                &self,
                $isa: I,
                $rs: &RaySimd,
                $lo: f32,
                $hi: f32,
            ) -> ([f32x4; 2], u32) {
                let $n = self;
                $test
            }
            $($more)*
        }
    };
}
lanes_impl!(Chunk, LANES, |n, _isa, rs, t_lo, t_hi| {
    let (e, m) = rs.test(&n.planes, t_lo, t_hi);
    ([e, f32x4::splat(0.0)], m)
});
lanes_impl!(
    Chunk8,
    8,
    |n, isa, rs, t_lo, t_hi| isa.test8(rs, n, t_lo, t_hi),
    #[inline(always)]
    fn children8(&self) -> Option<&[u32; 8]> {
        Some(&self.child)
    }
);
