//! The CPU-side copy of a BVH image that the plain queries traverse: child boxes of each
//! node stored lane by lane (structure of arrays: a [`Chunk`] of 4 lanes for BVH2 and BVH4,
//! a [`Chunk8`] of 8 for BVH8) so that one SIMD slab test covers a node, and triangles
//! copied in leaf order, four to a packet lane by lane, so that the first stage of the
//! watertight test runs on four triangles at once.
//!
//! It is made from the byte-exact image (so from the same BVH2 and collapse: the same
//! children, the same box words) when a plain query first needs it, and is used only when
//! the caller observes nothing ([`crate::Observer::OBSERVES_NOTHING`]); the simulator and
//! every counting observer still read the image through [`super::traverse`]. One change of
//! shape: an internal child whose subtree holds at most [`MERGE_MAX`] triangles becomes one
//! leaf holding them all, under the same box. The answers are the image traversal's, ray
//! for ray and bit for bit:
//!
//! * the box test is [`super::traverse`]'s arithmetic lane by lane: `(p - o) * inv`, far
//!   planes multiplied by [`EXIT_WIDEN`], the interval clipped by compare-and-select (x86's
//!   `maxps`/`minps` keep the running bound when a plane distance is NaN, exactly as the
//!   scalar `if tn > entry`); rays whose interval ends are NaN take the image traversal;
//! * the triangle test is [`Triangle::intersect`] on the same triangle words (a SIMD first
//!   stage computes its edge functions with the same operations, drops only triangles it
//!   would reject at that stage, and the scalar [`Triangle::intersect_from_edges`] finishes
//!   the others), and hits are kept by [`Hit::closer_than`]'s `(t, prim)` order, which makes
//!   the closest hit independent of the order in which triangles are tested;
//! * nodes are culled against the same [`cull_limit`] of the best `t`, which keeps every
//!   box that can hold an equally near hit with a smaller id; a merged leaf is entered
//!   whenever its subtree's root would be, and then tests every triangle the subtree could
//!   have led to (and more), so it can add no closer hit and lose none.
//!
//! Only the visiting order of a node's hit children differs (nearest first, the rest pushed
//! by a rank computed from their entry distances, ties in either order; for shadow rays the
//! first hit child first and the rest as they come), which changes no answer.
//!
//! Instructions ([`SimdLevel`]): with AVX2 (detected at run time) a BVH8 node is one 8-wide
//! test and the whole traversal is compiled for AVX2 (`simd.rs`); otherwise SSE2, which
//! every x86-64 CPU has (two 4-wide tests per BVH8 node), or `wide`'s portable code
//! elsewhere. Hit children about to be pushed are prefetched (every line of the node or
//! packet), and nodes and packets live in transparent huge pages ([`Pages`]). Figures:
//! `docs/performance.md`, "CPU traversal".

use super::simd::{Avx2, Kernel};
use crate::image::{ChildKind, MemoryImage, NodeLayout, Pages, RUN_END};
use dualsplit_geometry::{EXIT_WIDEN, Hit, PrimId, Ray, RayPre, Triangle, Vec3, cull_limit};
use std::cell::Cell;
use wide::{CmpEq, CmpGt, CmpLe, CmpLt, f32x4, i32x4};

/// Lanes of one SSE register of `f32`: children per [`Chunk`], triangles per [`TriPacket`].
pub const LANES: usize = 4;

/// Child word of a leaf: bit 31 set, bits 0–30 the slot of its first triangle in
/// [`CpuBvh::packets`] (`4 · packet + lane`).
pub const LEAF: u32 = 1 << 31;

/// Child word of an empty lane.
pub const EMPTY: u32 = u32::MAX;

/// A BVH2 or BVH4 node of the copy: its children's boxes plane by plane, then their child
/// words.
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(16))]
pub struct Chunk {
    /// `planes[p][lane]`: plane `p` of the lane's box, in the image's box-word order
    /// (min.x, min.y, min.z, max.x, max.y, max.z). Empty lanes hold the degenerate box.
    pub planes: [[f32; LANES]; 6],
    /// Per lane: a node (its index), a leaf ([`LEAF`] | first triangle) or [`EMPTY`].
    pub child: [u32; LANES],
}

/// A BVH8 node of the copy, laid out as [`Chunk`] with eight lanes, so that one AVX
/// register holds a plane of all eight children (and two SSE registers one half each).
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(32))]
pub struct Chunk8 {
    /// `planes[p][lane]`, as [`Chunk::planes`].
    pub planes: [[f32; 8]; 6],
    /// Per lane, as in [`Chunk`]: a node, a leaf or [`EMPTY`].
    pub child: [u32; 8],
}

/// Four consecutive triangles of the leaf-ordered triangle list, vertex coordinates lane by
/// lane, with their ids. Leaves follow one another without padding: a leaf starts at any
/// lane (its child word names the slot `4 · packet + lane`) and ends at the first lane from
/// there whose id has [`RUN_END`] set; the last packet is padded with [`EMPTY`] lanes.
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(16))]
pub struct TriPacket {
    /// `v[3 * vertex + axis][lane]`.
    pub v: [[f32; LANES]; 9],
    /// Triangle ids; [`RUN_END`] on a leaf's last one, [`EMPTY`] on padding lanes.
    pub prim: [u32; LANES],
}

pub(crate) const EMPTY_PACKET: TriPacket = TriPacket {
    v: [[0.0; LANES]; 9],
    prim: [EMPTY; LANES],
};

/// A node of the copy with `W` lanes: [`Chunk`] (BVH2 and BVH4) or [`Chunk8`] (BVH8).
pub(crate) trait Lanes: bytemuck::Pod + Send + Sync + std::fmt::Debug {
    /// Children per node.
    const W: usize;
    /// A node with every lane empty (degenerate boxes, [`EMPTY`] words).
    const EMPTY: Self;
    /// Sets lane `l`'s box words (image order) and child word.
    fn set(&mut self, l: usize, boxw: [f32; 6], child: u32);
    /// Lane `l`'s child word.
    fn child(&self, l: usize) -> u32;
    /// Sets lane `l`'s child word.
    fn set_child(&mut self, l: usize, child: u32);
    /// Entry distances (lanes 0–3 in the first vector, 4–7 in the second) and the mask of
    /// the non-empty lanes the ray meets on `[t_lo, t_hi]`.
    fn test<I: Isa>(&self, isa: I, rs: &RaySimd, t_lo: f32, t_hi: f32) -> ([f32x4; 2], u32);
}

macro_rules! lanes_impl {
    ($t:ty, $w:expr, |$n:ident, $isa:ident, $rs:ident, $lo:ident, $hi:ident| $test:expr) => {
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
        }
    };
}
lanes_impl!(Chunk, LANES, |n, _isa, rs, t_lo, t_hi| {
    let (e, m) = rs.test(&n.planes, &n.child, t_lo, t_hi);
    ([e, f32x4::splat(0.0)], m)
});
lanes_impl!(Chunk8, 8, |n, isa, rs, t_lo, t_hi| isa
    .test8(rs, n, t_lo, t_hi));

/// The instruction set a traversal runs with: [`Sse2`] (every x86-64 CPU; the portable
/// `wide` code elsewhere) or [`Avx2`] (one 8-wide box test per BVH8 node, and the whole
/// traversal compiled for AVX2). Answers are the same bits with either.
pub(crate) trait Isa: Copy {
    /// Entry distances (lanes 0–3, then 4–7) and the mask of the non-empty lanes of `n` that
    /// the ray meets on `[t_lo, t_hi]`.
    fn test8(self, rs: &RaySimd, n: &Chunk8, t_lo: f32, t_hi: f32) -> ([f32x4; 2], u32);
}

/// Baseline x86-64 (SSE2), or the portable `wide` code on other targets: 4-wide vectors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Sse2;

impl Isa for Sse2 {
    #[inline(always)]
    fn test8(self, rs: &RaySimd, n: &Chunk8, t_lo: f32, t_hi: f32) -> ([f32x4; 2], u32) {
        let half = |h: usize| {
            rs.test_rows(
                |p| half_of(&n.planes[p], h),
                half_of(&n.child, h),
                t_lo,
                t_hi,
            )
        };
        let ((e0, m0), (e1, m1)) = (half(0), half(1));
        ([e0, e1], m0 | m1 << LANES)
    }
}

impl Isa for Avx2 {
    #[inline(always)]
    fn test8(self, rs: &RaySimd, n: &Chunk8, t_lo: f32, t_hi: f32) -> ([f32x4; 2], u32) {
        let (e, m) = self.slab8(
            &n.planes, &n.child, rs.near, rs.far, rs.os, rs.invs, t_lo, t_hi, EXIT_WIDEN,
        );
        (bytemuck::cast(e), m)
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
    fn token(self) -> Option<Avx2> {
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

/// The nodes of a [`CpuBvh`], one per node of the image, the root first.
#[derive(Clone, Debug)]
pub enum CpuNodes {
    /// BVH2 (two lanes used) or BVH4.
    Four(Pages<Chunk>),
    /// BVH8.
    Eight(Pages<Chunk8>),
}

/// The CPU-side copy of one BVH image (see the module docs).
#[derive(Clone, Debug)]
pub struct CpuBvh {
    /// The nodes, children of a node next to one another, subtrees depth-first.
    pub nodes: CpuNodes,
    /// The leaves' triangles in leaf order, four to a packet.
    pub packets: Pages<TriPacket>,
    /// The AVX2 token when the traversal uses AVX2.
    avx2: Option<Avx2>,
}

/// The most triangles of a subtree that the copy turns into one leaf (four packets).
///
/// The paper's BVH2 has small leaves (1.8 triangles on average on dragon_box, SAH with equal
/// node and triangle costs), and each leaf visit is a cache miss on its packet; testing up
/// to 16 triangles four at a time is cheaper than descending two more node levels. Chosen
/// by measurement (docs/performance.md, "Leaf merging": 0, 4, 8, 12, 16, 24 and 32 on
/// dragon_box and sponza_dabrovic); answers do not depend on it.
pub const MERGE_MAX: usize = 16;

/// What [`copy`] makes: nodes and packets.
struct Copied<N> {
    nodes: Vec<N>,
    packets: Vec<TriPacket>,
}

/// Copies the image of node layout `L` into nodes of type `N` (`N::W >= L::ARITY`).
fn copy<L: NodeLayout, N: Lanes>(img: &MemoryImage) -> Copied<N> {
    let words = &img.words[..];
    let triangles = img.triangle_slice();
    let mut out = Copied {
        nodes: vec![N::EMPTY],
        packets: Vec::new(),
    };
    // (image word of a node, node index it is copied to)
    let mut todo: Vec<(usize, usize)> = vec![(0, 0)];
    // Triangle slots used (4 per packet).
    let mut slots = 0usize;
    while let Some((w, at)) = todo.pop() {
        let node = L::read(words, w);
        let mut addr = node.offset() as usize;
        let mut lane = 0;
        let mut internal = Vec::new();
        for k in 0..L::ARITY {
            let kind = node.kind(k);
            if kind == ChildKind::Empty {
                continue;
            }
            // A leaf's entries; an internal child whose subtree holds few triangles becomes
            // one leaf of them.
            let entries = match kind {
                ChildKind::Leaf => {
                    let run = words[addr] as usize;
                    let len = words[run..]
                        .iter()
                        .position(|&e| e & RUN_END != 0)
                        .map_or(0, |p| p + 1);
                    Some(words[run..run + len].to_vec())
                }
                _ => gather::<L>(words, addr, MERGE_MAX),
            };
            let child = match entries {
                // A subtree without triangles (only a forged saved tree has one) holds
                // nothing to hit.
                Some(e) if e.is_empty() => EMPTY,
                Some(e) => {
                    let first = slots as u32;
                    assert!(first < LEAF, "too many triangle references");
                    pack_entries(&mut out.packets, &mut slots, e, triangles);
                    LEAF | first
                }
                None => {
                    internal.push((addr, lane));
                    EMPTY
                }
            };
            out.nodes[at].set(lane, *node.box_words(k), child);
            addr += L::child_words(kind) as usize;
            lane += 1;
        }
        // Children of one node next to one another, then their subtrees depth-first.
        let mut subtrees = Vec::with_capacity(internal.len());
        for (cw, l) in internal {
            let idx = out.nodes.len();
            out.nodes.push(N::EMPTY);
            out.nodes[at].set_child(l, idx as u32);
            subtrees.push((cw, idx));
        }
        todo.extend(subtrees.into_iter().rev());
    }
    out
}

impl CpuBvh {
    /// Copies the image of node layout `L` (depth-first, children of a node next to one
    /// another), for the instructions of [`SimdLevel::detect`].
    pub fn from_image<L: NodeLayout>(img: &MemoryImage) -> Self {
        Self::with_level::<L>(img, SimdLevel::detect())
    }

    /// [`CpuBvh::from_image`] for the given instructions (SSE2 when this CPU lacks AVX2).
    pub fn with_level<L: NodeLayout>(img: &MemoryImage, level: SimdLevel) -> Self {
        let avx2 = level.token();
        if L::ARITY <= LANES {
            let c = copy::<L, Chunk>(img);
            Self {
                nodes: CpuNodes::Four(Pages::from_slice(&c.nodes)),
                packets: Pages::from_slice(&c.packets),
                avx2,
            }
        } else {
            let c = copy::<L, Chunk8>(img);
            Self {
                nodes: CpuNodes::Eight(Pages::from_slice(&c.nodes)),
                packets: Pages::from_slice(&c.packets),
                avx2,
            }
        }
    }

    /// The instructions the traversal uses.
    pub fn level(&self) -> SimdLevel {
        if self.avx2.is_some() {
            SimdLevel::Avx2
        } else {
            SimdLevel::Sse2
        }
    }

    /// Bytes of the copy (nodes and leaf-ordered triangles).
    pub fn bytes(&self) -> usize {
        let nodes = match &self.nodes {
            CpuNodes::Four(n) => n.len() * size_of::<Chunk>(),
            CpuNodes::Eight(n) => n.len() * size_of::<Chunk8>(),
        };
        nodes + self.packets.len() * size_of::<TriPacket>()
    }

    /// Closest hit (`ANY = false`) or some hit (`ANY = true`) of `ray`; `None` when the ray
    /// must take the image traversal instead (its `t_min` or cull limit is NaN).
    #[inline]
    pub fn traverse<const ANY: bool>(&self, ray: &Ray) -> Option<Option<Hit>> {
        if (ray.t_min - cull_limit(ray.t_max)).is_nan() {
            return None;
        }
        let mut stack = STACK.take();
        stack.clear();
        let packets = &self.packets[..];
        let hit = match &self.nodes {
            CpuNodes::Four(n) => dispatch::<_, ANY>(self.avx2, n, packets, ray, &mut stack),
            CpuNodes::Eight(n) => dispatch::<_, ANY>(self.avx2, n, packets, ray, &mut stack),
        };
        STACK.set(stack);
        Some(hit)
    }
}

/// [`run`] with SSE2, or with AVX2 inside [`Avx2::vectorize`] when `avx2` holds the token.
#[inline(always)]
fn dispatch<N: Lanes, const ANY: bool>(
    avx2: Option<Avx2>,
    nodes: &[N],
    packets: &[TriPacket],
    ray: &Ray,
    stack: &mut Vec<Entry>,
) -> Option<Hit> {
    match avx2 {
        None => run::<N, Sse2, ANY>(Sse2, nodes, packets, ray, stack),
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

/// [`run`] with AVX2, as a [`Kernel`] for [`Avx2::vectorize`].
struct Run<'a, N, const ANY: bool> {
    isa: Avx2,
    nodes: &'a [N],
    packets: &'a [TriPacket],
    ray: &'a Ray,
    stack: &'a mut Vec<Entry>,
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

/// The traversal (see the module docs) of `nodes` and `packets` with instructions `I`.
#[inline(always)]
fn run<N: Lanes, I: Isa, const ANY: bool>(
    isa: I,
    nodes: &[N],
    packets: &[TriPacket],
    ray: &Ray,
    stack: &mut Vec<Entry>,
) -> Option<Hit> {
    let r = ray.precompute();
    let rs = RaySimd::new(&r);
    let mut best: Option<Hit> = None;
    let mut best_t = ray.t_max;
    let mut limit = cull_limit(best_t);
    let mut cur = 0u32;
    loop {
        if cur & LEAF == 0 {
            let node = &nodes[cur as usize];
            let (dv, mask) = node.test(isa, &rs, ray.t_min, limit);
            let dist: [[f32; LANES]; 2] = dv.map(|v| v.to_array());
            let child = |i: usize| node.child(i);
            let d = |i: usize| dist[i / LANES][i % LANES];
            if mask != 0 {
                let first = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                if rest == 0 {
                    cur = child(first);
                    continue;
                }
                if ANY {
                    // Any hit ends the ray: no order is better than another, so the
                    // first hit child is next and the others are pushed unsorted.
                    let mut m = rest;
                    while m != 0 {
                        let i = m.trailing_zeros() as usize;
                        m &= m - 1;
                        let c = child(i);
                        prefetch_child(nodes, packets, c);
                        stack.push(Entry { t: d(i), child: c });
                    }
                    cur = child(first);
                    continue;
                }
                let second = rest.trailing_zeros() as usize;
                if rest & (rest - 1) == 0 {
                    // Two hits: the nearer next, the other on the stack.
                    let (near, far) = if d(second) < d(first) {
                        (second, first)
                    } else {
                        (first, second)
                    };
                    let c = child(far);
                    prefetch_child(nodes, packets, c);
                    stack.push(Entry {
                        t: d(far),
                        child: c,
                    });
                    cur = child(near);
                    continue;
                }
                // Three or more: each goes to the stack slot of its rank (the number of
                // hit children before it by entry distance, ties by slot), nearest on
                // top; then the nearest is taken.
                let count = ones(mask);
                let mut m = mask;
                while m != 0 {
                    let i = m.trailing_zeros() as usize;
                    m &= m - 1;
                    prefetch_child(nodes, packets, child(i));
                }
                let base = stack.len();
                stack.resize(
                    base + count,
                    Entry {
                        t: 0.0,
                        child: EMPTY,
                    },
                );
                let mut m = mask;
                while m != 0 {
                    let i = m.trailing_zeros() as usize;
                    m &= m - 1;
                    let di = d(i);
                    // The hit lanes nearer than `i`, or as near and in an earlier slot,
                    // from one comparison per four lanes.
                    let splat = f32x4::splat(di);
                    let mut before = 0u32;
                    for (c, v) in dv.iter().enumerate().take(N::W.div_ceil(LANES)) {
                        let lt = v.cmp_lt(splat).move_mask() as u32;
                        let eq = v.cmp_eq(splat).move_mask() as u32;
                        let earlier = ((1u32 << i) - 1) >> (LANES * c);
                        before |= (lt | (eq & earlier)) << (LANES * c);
                    }
                    let rank = ones(before & mask);
                    stack[base + count - 1 - rank] = Entry {
                        t: di,
                        child: child(i),
                    };
                }
                cur = stack.pop().map_or(EMPTY, |e| e.child);
                continue;
            }
        } else {
            let slot = (cur & !LEAF) as usize;
            if test_leaf::<ANY>(packets, slot, &rs, &r, &mut best, &mut best_t) {
                return best;
            }
            limit = cull_limit(best_t);
        }
        // Next: the nearest stacked entry not beyond the limit.
        loop {
            let Some(e) = stack.pop() else {
                return best;
            };
            if e.t <= limit {
                cur = e.child;
                break;
            }
        }
    }
}

/// Set bits of an 8-bit mask: the x86-64 baseline has no `popcnt`, and `count_ones` becomes
/// a dozen instructions there; a 256-byte table is one load.
#[inline(always)]
fn ones(mask: u32) -> usize {
    const TABLE: [u8; 256] = {
        let mut t = [0u8; 256];
        let mut i = 0;
        while i < 256 {
            t[i] = (i as u32).count_ones() as u8;
            i += 1;
        }
        t
    };
    TABLE[(mask & 0xff) as usize] as usize
}

/// Prefetches the first line of child word `c`'s node or the first packet of its leaf.
#[inline(always)]
fn prefetch_child<N>(nodes: &[N], packets: &[TriPacket], c: u32) {
    if c & LEAF == 0 {
        super::simd::prefetch(&nodes[c as usize]);
    } else {
        super::simd::prefetch(&packets[(c & !LEAF) as usize / LANES]);
    }
}

/// Tests the leaf whose first triangle is at `slot` of `packets` (it ends at the first id
/// from there with [`RUN_END`]) on `[ray.t_min, best_t]`, keeping the closest hit by
/// [`Hit::closer_than`] in `best` and `best_t`. Returns true when `ANY` and a hit was
/// accepted.
#[inline(always)]
pub(crate) fn test_leaf<const ANY: bool>(
    packets: &[TriPacket],
    slot: usize,
    rs: &RaySimd,
    r: &RayPre,
    best: &mut Option<Hit>,
    best_t: &mut f32,
) -> bool {
    let mut i = slot / LANES;
    // Lanes at or after the leaf's first.
    let mut from = (0b1111 << (slot % LANES)) & 0b1111;
    loop {
        let pk = &packets[i];
        // Lanes up to the leaf's last (the first id from `from` on with bit 31 set:
        // RUN_END or padding).
        let ends = f32x4::new(bytemuck::cast(pk.prim)).move_mask() as u32 & from;
        let lanes = if ends == 0 {
            from
        } else {
            from & ((ends & ends.wrapping_neg()) << 1).wrapping_sub(1)
        };
        // Lanes the scalar test could accept; it decides each of them, from the edge
        // functions computed here unless one is zero (then it recomputes them in f64).
        let e = rs.triangle_edges(pk);
        let mut m = e.candidates & lanes;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let p = PrimId(pk.prim[l] & !RUN_END);
            // The triangle's own words, from the packet (already in cache).
            let vertex =
                |k: usize| Vec3::new(pk.v[3 * k][l], pk.v[3 * k + 1][l], pk.v[3 * k + 2][l]);
            let tri = Triangle::new(vertex(0), vertex(1), vertex(2));
            let h = if e.zero & (1 << l) != 0 {
                tri.intersect(r, r.ray.t_min, *best_t)
            } else {
                tri.intersect_from_edges(r, [e.u[l], e.v[l], e.w[l]], r.ray.t_min, *best_t)
            };
            if let Some(h) = h
                && Hit::keep_closest(best, p, h)
            {
                if ANY {
                    return true;
                }
                *best_t = h.t;
            }
        }
        if ends != 0 {
            return false;
        }
        i += 1;
        from = 0b1111;
    }
}

/// The index entries of the leaves of the subtree whose node is at image word `w` (a node's
/// leaves, then its internal children's subtrees in child order), [`RUN_END`] on the last
/// one only; `None` when there are more
/// than `limit`. Iterative: a saved tree may hold long chains of nodes.
fn gather<L: NodeLayout>(words: &[u32], w: usize, limit: usize) -> Option<Vec<u32>> {
    let mut out = Vec::new();
    let mut todo = vec![w];
    while let Some(w) = todo.pop() {
        let node = L::read(words, w);
        let mut addr = node.offset() as usize;
        let mut inner = Vec::new();
        for k in 0..L::ARITY {
            let kind = node.kind(k);
            match kind {
                ChildKind::Empty => continue,
                ChildKind::Leaf => {
                    let run = words[addr] as usize;
                    for &e in &words[run..] {
                        out.push(e & !RUN_END);
                        if e & RUN_END != 0 || out.len() > limit {
                            break;
                        }
                    }
                }
                ChildKind::Internal => inner.push(addr),
            }
            if out.len() > limit {
                return None;
            }
            addr += L::child_words(kind) as usize;
        }
        todo.extend(inner.into_iter().rev());
    }
    if let Some(last) = out.last_mut() {
        *last |= RUN_END;
    }
    Some(out)
}

/// Appends the triangles of the index-run entries `entries` (ids with [`RUN_END`] on each
/// run's last) to `packets`, slot after slot from `*slots`, padding nothing: the caller
/// pads the last packet by starting from [`EMPTY_PACKET`]s.
pub(crate) fn pack_entries(
    packets: &mut Vec<TriPacket>,
    slots: &mut usize,
    entries: impl IntoIterator<Item = u32>,
    triangles: &[Triangle],
) {
    for e in entries {
        if *slots & (LANES - 1) == 0 {
            packets.push(EMPTY_PACKET);
        }
        let pk = packets.last_mut().expect("pushed");
        let tri = &triangles[(e & !RUN_END) as usize];
        let l = *slots % LANES;
        for (r, row) in pk.v.iter_mut().enumerate() {
            row[l] = tri.v[r / 3][r % 3];
        }
        pk.prim[l] = e;
        *slots += 1;
    }
}

#[derive(Clone, Copy)]
struct Entry {
    t: f32,
    child: u32,
}

/// What [`RaySimd::triangle_edges`] finds for the four triangles of a packet.
struct Edges {
    u: [f32; LANES],
    v: [f32; LANES],
    w: [f32; LANES],
    /// Lanes with an edge function equal to zero.
    zero: u32,
    /// Lanes [`Triangle::intersect`] might accept.
    candidates: u32,
}

thread_local! {
    /// The traversal stack's buffer, one per thread, reused from ray to ray.
    static STACK: Cell<Vec<Entry>> = const { Cell::new(Vec::new()) };
}

/// The ray's constants broadcast to all lanes, the plane rows its signs pick, and the
/// watertight test's axes and shear.
pub(crate) struct RaySimd {
    o: [f32x4; 3],
    inv: [f32x4; 3],
    /// The origin and reciprocal direction as scalars.
    os: [f32; 3],
    invs: [f32; 3],
    /// Plane rows of the near and far planes per axis.
    near: [usize; 3],
    far: [usize; 3],
    k: [usize; 3],
    sx: f32x4,
    sy: f32x4,
}

impl RaySimd {
    /// The constants of the precomputed ray `r`.
    #[inline(always)]
    pub(crate) fn new(r: &RayPre) -> Self {
        let o = r.ray.origin;
        let inv = r.inv_dir;
        let s = |a: usize| 3 * r.neg[a] as usize;
        Self {
            o: [f32x4::splat(o.x), f32x4::splat(o.y), f32x4::splat(o.z)],
            inv: [
                f32x4::splat(inv.x),
                f32x4::splat(inv.y),
                f32x4::splat(inv.z),
            ],
            os: [o.x, o.y, o.z],
            invs: [inv.x, inv.y, inv.z],
            near: [s(0), 1 + s(1), 2 + s(2)],
            far: [3 - s(0), 4 - s(1), 5 - s(2)],
            k: r.k,
            sx: f32x4::splat(r.shear.x),
            sy: f32x4::splat(r.shear.y),
        }
    }

    /// The first stage of [`Triangle::intersect`] (shear, edge functions `u`, `v`, `w`, the
    /// same IEEE operations in the same order) on the four triangles of `pk` at once: the
    /// edge functions, the lanes where one of them is zero (the scalar test recomputes
    /// those in f64), and the lanes the scalar test might accept: all but those where no
    /// edge function is zero and their signs differ, which it rejects at that stage.
    #[inline(always)]
    fn triangle_edges(&self, pk: &TriPacket) -> Edges {
        let [kx, ky, kz] = self.k;
        let rel = |vertex: usize, axis: usize| f32x4::new(pk.v[3 * vertex + axis]) - self.o[axis];
        let (ax, ay, az) = (rel(0, kx), rel(0, ky), rel(0, kz));
        let (bx, by, bz) = (rel(1, kx), rel(1, ky), rel(1, kz));
        let (cx, cy, cz) = (rel(2, kx), rel(2, ky), rel(2, kz));
        let ax = ax - self.sx * az;
        let ay = ay - self.sy * az;
        let bx = bx - self.sx * bz;
        let by = by - self.sy * bz;
        let cx = cx - self.sx * cz;
        let cy = cy - self.sy * cz;
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = f32x4::splat(0.0);
        let any_zero = (u.cmp_eq(zero) | v.cmp_eq(zero) | w.cmp_eq(zero)).move_mask() as u32;
        let neg = u.cmp_lt(zero) | v.cmp_lt(zero) | w.cmp_lt(zero);
        let pos = u.cmp_gt(zero) | v.cmp_gt(zero) | w.cmp_gt(zero);
        let reject = (neg & pos).move_mask() as u32 & !any_zero;
        Edges {
            u: u.to_array(),
            v: v.to_array(),
            w: w.to_array(),
            zero: any_zero,
            candidates: 0b1111 & !reject,
        }
    }

    /// Entry distances of four boxes (`planes[p][lane]`) clipped to `[t_lo, t_hi]`, and the mask of
    /// the non-empty lanes the ray meets (`entry <= exit`).
    #[inline(always)]
    fn test(
        &self,
        planes: &[[f32; LANES]; 6],
        child: &[u32; LANES],
        t_lo: f32,
        t_hi: f32,
    ) -> (f32x4, u32) {
        self.test_rows(|p| planes[p], *child, t_lo, t_hi)
    }

    /// [`RaySimd::test`] with plane `p`'s row given by `row(p)`.
    #[inline(always)]
    fn test_rows(
        &self,
        row: impl Fn(usize) -> [f32; LANES],
        child: [u32; LANES],
        t_lo: f32,
        t_hi: f32,
    ) -> (f32x4, u32) {
        let mut entry = f32x4::splat(t_lo);
        let mut exit = f32x4::splat(t_hi);
        let widen = f32x4::splat(EXIT_WIDEN);
        for a in 0..3 {
            let tn = (f32x4::new(row(self.near[a])) - self.o[a]) * self.inv[a];
            let tf = (f32x4::new(row(self.far[a])) - self.o[a]) * self.inv[a] * widen;
            entry = keep_max(tn, entry);
            exit = keep_min(tf, exit);
        }
        let hit = entry.cmp_le(exit).move_mask() as u32;
        let empty = i32x4::new(bytemuck::cast::<[u32; LANES], [i32; LANES]>(child))
            .cmp_eq(i32x4::splat(-1))
            .move_mask() as u32;
        (entry, hit & !empty)
    }
}

/// Whether SSE's `maxps`/`minps` are available: `maxps x, b` is exactly
/// `x > b ? x : b` and `minps x, b` is `x < b ? x : b` (`wide`'s `fast_max`/`fast_min` use
/// them where SSE is on), one instruction where the portable form takes a compare and a blend.
const SSE: bool = cfg!(all(
    any(target_arch = "x86", target_arch = "x86_64"),
    target_feature = "sse"
));

/// `if x > bound { x } else { bound }` per lane: a NaN `x` keeps the bound.
#[inline(always)]
fn keep_max(x: f32x4, bound: f32x4) -> f32x4 {
    if SSE {
        x.fast_max(bound)
    } else {
        keep_max_portable(x, bound)
    }
}

/// [`keep_max`] by compare and blend, on any target.
#[inline(always)]
fn keep_max_portable(x: f32x4, bound: f32x4) -> f32x4 {
    x.cmp_gt(bound).blend(x, bound)
}

/// `if x < bound { x } else { bound }` per lane: a NaN `x` keeps the bound.
#[inline(always)]
fn keep_min(x: f32x4, bound: f32x4) -> f32x4 {
    if SSE {
        x.fast_min(bound)
    } else {
        keep_min_portable(x, bound)
    }
}

/// [`keep_min`] by compare and blend, on any target.
#[inline(always)]
fn keep_min_portable(x: f32x4, bound: f32x4) -> f32x4 {
    x.cmp_lt(bound).blend(x, bound)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wide::traverse::tests::coord;
    use dualsplit_geometry::Pcg32;

    /// The box test of a node of type `N` with SSE2, and with AVX2 where this CPU has it,
    /// gives lane by lane `RayPre::slab`'s hit or miss and entry distance (up to the sign of
    /// a zero) for every non-NaN interval, empty lanes never hit; `cases` random nodes.
    fn node_tests_match_ray_slab<N: Lanes>(seed: (u64, u64), cases: usize) {
        let mut rng = Pcg32::new(seed.0, seed.1);
        let ends = [0.0, -0.0, 0.5, 1e-3, f32::INFINITY, f32::NEG_INFINITY, 3.0];
        let avx2 = Avx2::detect();
        for case in 0..cases {
            let v = |rng: &mut Pcg32| Vec3::new(coord(rng), coord(rng), coord(rng));
            let r = Ray::new(v(&mut rng), v(&mut rng)).precompute();
            let mut n = N::EMPTY;
            let mut boxes = Vec::new();
            for l in 0..N::W {
                if rng.below(5) == 0 {
                    continue;
                }
                let (p, q) = (v(&mut rng), v(&mut rng));
                let (lo, hi) = (p.min(q), p.max(q));
                n.set(l, [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z], l as u32);
                boxes.push((l, lo, hi));
            }
            let t_lo = ends[rng.below(ends.len() as u32) as usize];
            let t_hi = ends[rng.below(ends.len() as u32) as usize];
            let rs = RaySimd::new(&r);
            let mut results = vec![n.test(Sse2, &rs, t_lo, t_hi)];
            results.extend(avx2.map(|t| n.test(t, &rs, t_lo, t_hi)));
            for (dv, mask) in results {
                let entry: [f32; 8] = bytemuck::cast(dv);
                let mut want = 0;
                for &(l, lo, hi) in &boxes {
                    let (e, x) = r.slab(lo, hi, t_lo, t_hi);
                    if e <= x {
                        want |= 1 << l;
                        assert_eq!(entry[l], e, "case {case} lane {l}");
                    }
                }
                assert_eq!(mask, want, "case {case}: {r:?}");
            }
        }
    }

    /// A BVH2/BVH4 node's 4-lane test.
    #[test]
    fn chunk_test_matches_ray_slab() {
        node_tests_match_ray_slab::<Chunk>((11, 5), 50_000);
    }

    /// A BVH8 node's 8-lane test: two SSE halves, or one 8-wide AVX2 test.
    #[test]
    fn chunk8_test_matches_ray_slab() {
        node_tests_match_ray_slab::<Chunk8>((12, 6), 30_000);
    }

    /// The packet's first stage drops a lane only where `Triangle::intersect` misses: on
    /// triangles and rays with coordinates from a small set (edges through the ray, zero
    /// edge functions, degenerate triangles) and random ones.
    #[test]
    fn triangle_candidates_keep_every_hit() {
        let mut rng = Pcg32::new(3, 9);
        let mut hits = 0;
        for case in 0..50_000 {
            let v = |rng: &mut Pcg32| Vec3::new(coord(rng), coord(rng), coord(rng));
            let r = Ray::new(v(&mut rng), v(&mut rng)).precompute();
            let tris: Vec<Triangle> = (0..LANES)
                .map(|_| Triangle::new(v(&mut rng), v(&mut rng), v(&mut rng)))
                .collect();
            let mut packets = Vec::new();
            let mut slots = 0;
            pack_entries(&mut packets, &mut slots, [0, 1, 2, 3 | RUN_END], &tris);
            let m = RaySimd::new(&r).triangle_edges(&packets[0]).candidates;
            for (l, t) in tris.iter().enumerate() {
                if t.intersect(&r, f32::NEG_INFINITY, f32::INFINITY).is_some() {
                    hits += 1;
                    assert!(m & (1 << l) != 0, "case {case} lane {l}: {t:?} {r:?}");
                }
            }
        }
        assert!(hits > 1000, "{hits} hits");
    }

    /// A packet lane's answer (no answer outside the candidates; the full scalar test where
    /// an edge function is zero; else the scalar test finished from the packet's edge
    /// functions) is `Triangle::intersect`'s, bit for bit, on rays and triangles with
    /// coordinates from a small set and random ones, on random `t` ranges.
    #[test]
    fn packet_answers_are_intersect_answers() {
        let mut rng = Pcg32::new(17, 2);
        let ends = [0.0, 0.5, 1.0, 2.0, f32::INFINITY];
        let (mut hits, mut from_edges) = (0, 0);
        for case in 0..100_000 {
            let v = |rng: &mut Pcg32| Vec3::new(coord(rng), coord(rng), coord(rng));
            let r = Ray::new(v(&mut rng), v(&mut rng)).precompute();
            let tris: Vec<Triangle> = (0..LANES)
                .map(|_| Triangle::new(v(&mut rng), v(&mut rng), v(&mut rng)))
                .collect();
            let (mut packets, mut slots) = (Vec::new(), 0);
            pack_entries(&mut packets, &mut slots, [0, 1, 2, 3 | RUN_END], &tris);
            let e = RaySimd::new(&r).triangle_edges(&packets[0]);
            let lo = ends[rng.below(2) as usize];
            let hi = ends[rng.below(ends.len() as u32) as usize];
            let bits = |h: Option<dualsplit_geometry::TriangleHit>| {
                h.map(|h| (h.t.to_bits(), h.u.to_bits(), h.v.to_bits()))
            };
            for (l, t) in tris.iter().enumerate() {
                let want = t.intersect(&r, lo, hi);
                let got = if e.candidates & (1 << l) == 0 {
                    None
                } else if e.zero & (1 << l) != 0 {
                    t.intersect(&r, lo, hi)
                } else {
                    from_edges += 1;
                    t.intersect_from_edges(&r, [e.u[l], e.v[l], e.w[l]], lo, hi)
                };
                hits += want.is_some() as u32;
                assert_eq!(bits(got), bits(want), "case {case} lane {l}: {t:?} {r:?}");
            }
        }
        assert!(
            hits > 1000 && from_edges > 10_000,
            "{hits} hits, {from_edges}"
        );
    }

    /// `PackedHit` gives back every hit and the miss, bit for bit.
    #[test]
    fn packed_hits_round_trip() {
        let hits = [
            None,
            Some(Hit {
                t: 0.0,
                prim: PrimId(0),
                u: 0.0,
                v: 1.0,
            }),
            Some(Hit {
                t: f32::MAX,
                prim: PrimId(RUN_END - 1),
                u: -0.0,
                v: f32::MIN_POSITIVE,
            }),
            Some(Hit {
                t: 3.25,
                prim: PrimId(12_345),
                u: 0.125,
                v: 0.75,
            }),
        ];
        let bits =
            |h: Option<Hit>| h.map(|h| (h.t.to_bits(), h.prim, h.u.to_bits(), h.v.to_bits()));
        for h in hits {
            assert_eq!(bits(PackedHit::pack(h).unpack()), bits(h));
        }
    }

    /// `keep_max`/`keep_min` keep the bound for a NaN lane, as the scalar compare does.
    #[test]
    fn keep_ignores_nan() {
        let x = f32x4::new([f32::NAN, 2.0, -1.0, f32::INFINITY]);
        let b = f32x4::new([1.0, 1.0, 1.0, 1.0]);
        assert_eq!(keep_max(x, b).to_array(), [1.0, 2.0, 1.0, f32::INFINITY]);
        assert_eq!(keep_min(x, b).to_array(), [1.0, 1.0, -1.0, 1.0]);
        // The compare-and-blend forms other targets use agree.
        assert_eq!(
            keep_max_portable(x, b).to_array(),
            keep_max(x, b).to_array()
        );
        assert_eq!(
            keep_min_portable(x, b).to_array(),
            keep_min(x, b).to_array()
        );
    }
}
