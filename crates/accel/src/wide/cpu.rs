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
//! leaf holding them all, under the same box ([`merge_limit`]: `DUALSPLIT_MERGE_MAX=0` keeps
//! the image's leaves, for measuring). The answers are the image traversal's, ray
//! for ray and bit for bit:
//!
//! * the box test is [`super::traverse`]'s arithmetic lane by lane for entries: `(p - o) *
//!   inv` (computed as `(o - p) * -inv`, the same bits up to the sign of a zero), the
//!   interval clipped by compare-and-select (x86's `maxps`/`minps` keep the running bound
//!   when a plane distance is NaN, exactly as the scalar `if tn > entry`); rays whose
//!   interval ends are NaN take the image traversal. Far planes are widened by
//!   [`EXIT_WIDEN`] in the pre-multiplied form `(p - o) * (inv * EXIT_WIDEN)`, one
//!   multiplication per plane fewer than the image's `((p - o) * inv) * EXIT_WIDEN` (the
//!   one exception to "the same single multiplication" of the geometry crate's rules).
//!   The two can differ in the last bit (the roundings fall on different products), so
//!   the copy may reach a leaf the image does not, or not reach one it does, when an entry
//!   lies between the two exits. Both are the same product of the same four correctly
//!   rounded factors (the subtraction, the reciprocal, the product with [`EXIT_WIDEN`],
//!   the final product), so the bound behind [`EXIT_WIDEN`] (Ize 2013) holds for both: for
//!   `t ≥ 0` each is at least the exact exit, and a box the exact ray meets on the
//!   interval is reached by both. A zero direction component gives `inv = ±∞` and `inv *
//!   EXIT_WIDEN = ±∞` (NaN at `p == o`), as before; a subnormal one (`|d| < 2.9e-39`) can
//!   round `inv * EXIT_WIDEN` up to `±∞`, which makes a positive exit `+∞` (still
//!   conservative) and a negative one `−∞` (a box behind the origin, a miss for `t_min ≥
//!   0` either way). So where the two forms disagree the leaf holds no hit either
//!   traversal would keep: this relies on the same property as merged leaves below (a hit
//!   the triangle test accepts lies in a box the conservative test reaches), and it is
//!   checked by the equivalence tests (`tests/bvh_scenes.rs`);
//! * the triangle test is [`Triangle::intersect`] on the same triangle words (a SIMD first
//!   stage computes its edge functions with the same operations on the negated relative
//!   coordinates `o - p`, the same bits wherever they are not zero, drops only triangles it
//!   would reject at that stage, and the scalar [`Triangle::intersect_from_edges`] finishes
//!   the others), and hits are kept by [`Hit::closer_than`]'s `(t, prim)` order, which makes
//!   the closest hit independent of the order in which triangles are tested;
//! * nodes are culled against the same [`cull_limit`] of the best `t`, which keeps every
//!   box that can hold an equally near hit with a smaller id; a merged leaf is entered
//!   whenever its subtree's root would be, and then tests every triangle the subtree could
//!   have led to (and more), so it can add no closer hit and lose none.
//!
//! Two more changes of order, none of answers: a node's children sit in its lanes by their
//! chance of stopping a shadow ray, largest first (`order.rs`: `min(SA, 2A)` of the child's
//! box and triangles), and the visiting order of a node's hit children differs (nearest
//! first, the rest pushed sorted by entry distance, ties by slot, the later first; with
//! AVX2, three or more hit children of a BVH8 node are sorted by a vector network on a key
//! that orders distances differing only in their last three bits by slot, the later first;
//! for shadow rays the hit children in slot order). A shadow ray computes the watertight
//! test's axes and shear only once it reaches a leaf: its node steps until then run with
//! the box test's constants alone (the same box tests), and most shadow rays of some scenes
//! reach no leaf.
//!
//! A ray's query either borrows a thread-local stack and finds the copy's arrays
//! ([`CpuBvh::traverse`]) or runs in a [`CpuQuery`] ([`CpuBvh::query`]), which holds the
//! arrays, the instruction set and a stack of its own across the rays of one thread (what
//! [`Tracer`](crate::Tracer) and the batch queries use); the traversal is the same.
//!
//! Instructions ([`SimdLevel`]): with AVX2 (detected at run time) a BVH8 node is one 8-wide
//! test and the whole traversal is compiled for AVX2 (`simd.rs`); otherwise SSE2, which
//! every x86-64 CPU has (two 4-wide tests per BVH8 node), or `wide`'s portable code
//! elsewhere. Hit children about to be pushed are prefetched (every line of the node or
//! packet), and node and packet arrays of [`PAGES_MIN_BYTES`] or more live in transparent
//! huge pages from their first byte ([`Pages`]). Figures: `docs/performance.md`, "CPU
//! traversal".
//!
//! | file | what it holds |
//! |---|---|
//! | `layout.rs` | the nodes ([`Chunk`], [`Chunk8`]), child words and triangle packets |
//! | `lanes.rs` | a node read as lanes, with its box test (the `Lanes` trait) |
//! | `copy.rs` | copying the image into them |
//! | `merge.rs` | leaf merging: subtrees of at most [`MERGE_MAX`] triangles as one leaf |
//! | `order.rs` | the order of a node's children: the likeliest to stop a shadow ray first |
//! | `isa.rs` | the instruction sets ([`SimdLevel`]) |
//! | `dispatch.rs` | the dispatch of a ray to the loop compiled for one of them |
//! | `traverse.rs` | the traversal loop, its stack and the leaf test |
//! | `ray.rs` | the ray's SIMD constants, the 4-wide box test and the packet's first stage |
//!
//! [`EXIT_WIDEN`]: dualsplit_geometry::EXIT_WIDEN
//! [`Triangle::intersect`]: dualsplit_geometry::Triangle::intersect
//! [`Triangle::intersect_from_edges`]: dualsplit_geometry::Triangle::intersect_from_edges
//! [`Hit::closer_than`]: dualsplit_geometry::Hit::closer_than
//! [`PAGES_MIN_BYTES`]: crate::image::PAGES_MIN_BYTES

mod copy;
mod dispatch;
mod isa;
mod lanes;
mod layout;
mod merge;
mod order;
mod ray;
mod traverse;

pub(crate) use copy::pack_entries;
pub(crate) use dispatch::PackedHit;
pub use isa::SimdLevel;
pub(crate) use isa::avx2_token;
pub use layout::{Chunk, Chunk8, EMPTY, LANES, LEAF, TriPacket};
pub use merge::{MERGE_LIMIT_MAX, MERGE_MAX, merge_limit, merge_limit_from_env};
pub(crate) use ray::RaySimd;
pub(crate) use traverse::test_leaf;

use super::simd::Avx2;
use crate::image::{MemoryImage, NodeLayout, Pages};
use copy::copy;
use dispatch::dispatch;
use dualsplit_geometry::{Hit, Ray, cull_limit};
use lanes::Lanes;
use traverse::{Entry, STACK};

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
    /// Stack entries a traversal can hold at once ([`stack_len`]).
    stack_len: usize,
}

/// The most entries the traversal's stack holds at once in a copy of nodes `width` lanes
/// wide whose deepest node has depth `depth`: at most `width - 1` unvisited siblings wait per
/// level of the current path, and a node with `width` hit children stacks them all before
/// taking the nearest.
fn stack_len(depth: usize, width: usize) -> usize {
    (depth + 1) * (width - 1) + width
}

impl CpuBvh {
    /// Copies the image of node layout `L` (depth-first, children of a node next to one
    /// another), for the instructions of [`SimdLevel::detect`].
    pub fn from_image<L: NodeLayout>(img: &MemoryImage) -> Self {
        Self::with_level::<L>(img, SimdLevel::detect())
    }

    /// [`CpuBvh::from_image`] for the given instructions (SSE2 when this CPU lacks AVX2).
    pub fn with_level<L: NodeLayout>(img: &MemoryImage, level: SimdLevel) -> Self {
        Self::with_options::<L>(img, level, merge_limit())
    }

    /// [`CpuBvh::with_level`] merging subtrees of at most `merge` triangles into one leaf
    /// instead of [`merge_limit`]'s (0: the image's leaves).
    pub fn with_options<L: NodeLayout>(img: &MemoryImage, level: SimdLevel, merge: usize) -> Self {
        let avx2 = level.token();
        if L::ARITY <= LANES {
            let c = copy::<L, Chunk>(img, merge);
            Self {
                nodes: CpuNodes::Four(Pages::from_slice(&c.nodes)),
                packets: Pages::from_slice(&c.packets),
                avx2,
                stack_len: stack_len(c.depth, <Chunk as Lanes>::W),
            }
        } else {
            let c = copy::<L, Chunk8>(img, merge);
            Self {
                nodes: CpuNodes::Eight(Pages::from_slice(&c.nodes)),
                packets: Pages::from_slice(&c.packets),
                avx2,
                stack_len: stack_len(c.depth, <Chunk8 as Lanes>::W),
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
        STACK.with_borrow_mut(|stack| {
            if stack.len() < self.stack_len {
                stack.resize(self.stack_len, Entry::UNUSED);
            }
            let buf = &mut stack[..self.stack_len];
            traverse_on::<ANY>(self.query_nodes(), &self.packets, self.avx2, ray, buf)
        })
    }

    /// The nodes as a [`CpuQuery`] holds them.
    #[inline(always)]
    fn query_nodes(&self) -> QueryNodes<'_> {
        match &self.nodes {
            CpuNodes::Four(n) => QueryNodes::Four(n),
            CpuNodes::Eight(n) => QueryNodes::Eight(n),
        }
    }
}

/// [`CpuBvh::traverse`] on `stack` (at least the copy's bound long), whichever holds it.
#[inline(always)]
fn traverse_on<const ANY: bool>(
    nodes: QueryNodes<'_>,
    packets: &[TriPacket],
    avx2: Option<Avx2>,
    ray: &Ray,
    stack: &mut [Entry],
) -> Option<Option<Hit>> {
    // Untraceable rays miss (`Ray::is_traceable`), in every structure alike.
    if !ray.is_traceable() {
        return Some(None);
    }
    if (ray.t_min - cull_limit(ray.t_max)).is_nan() {
        return None;
    }
    Some(match nodes {
        QueryNodes::Four(n) => dispatch::<_, ANY>(avx2, n, packets, ray, stack),
        QueryNodes::Eight(n) => dispatch::<_, ANY>(avx2, n, packets, ray, stack),
    })
}

/// The node array of a [`CpuQuery`].
#[derive(Clone, Copy)]
enum QueryNodes<'a> {
    Four(&'a [Chunk]),
    Eight(&'a [Chunk8]),
}

/// A query context over a [`CpuBvh`] for tracing many rays one by one on one thread (the
/// counterpart of Embree's `RTCIntersectContext`): it holds the copy's arrays, its
/// instruction set and a traversal stack of its own, so a ray's query starts with the
/// traversal rather than with finding them ([`CpuBvh::traverse`] borrows a thread-local
/// stack and dereferences the arrays per ray). Answers are [`CpuBvh::traverse`]'s.
pub struct CpuQuery<'a> {
    nodes: QueryNodes<'a>,
    packets: &'a [TriPacket],
    avx2: Option<Avx2>,
    stack: Vec<Entry>,
}

impl CpuBvh {
    /// A query context for tracing rays one by one ([`CpuQuery`]).
    pub fn query(&self) -> CpuQuery<'_> {
        CpuQuery {
            nodes: self.query_nodes(),
            packets: &self.packets,
            avx2: self.avx2,
            stack: vec![Entry::UNUSED; self.stack_len],
        }
    }
}

impl CpuQuery<'_> {
    /// [`CpuBvh::traverse`] with this context's stack.
    #[inline]
    pub fn traverse<const ANY: bool>(&mut self, ray: &Ray) -> Option<Option<Hit>> {
        traverse_on::<ANY>(self.nodes, self.packets, self.avx2, ray, &mut self.stack)
    }
}

#[cfg(test)]
mod tests {
    use super::isa::Sse2;
    use super::lanes::Lanes;
    use super::ray::{keep_max, keep_max_portable, keep_min, keep_min_portable};
    use super::*;
    use crate::image::RUN_END;
    use crate::wide::traverse::tests::coord;
    use dualsplit_geometry::Pcg32;
    use dualsplit_geometry::{EXIT_WIDEN, PrimId, RayPre, Triangle, Vec3};
    use wide::f32x4;

    /// `RayPre::slab` with the copy's far planes, `(p - o) * (inv * EXIT_WIDEN)` (the
    /// module docs): the entry is `slab`'s, the exit may differ from it in the last bit.
    fn slab_premultiplied(r: &RayPre, lo: Vec3, hi: Vec3, t_lo: f32, t_hi: f32) -> (f32, f32) {
        let (mut entry, mut exit) = (t_lo, t_hi);
        for a in 0..3 {
            let (n, f) = if r.neg[a] {
                (hi[a], lo[a])
            } else {
                (lo[a], hi[a])
            };
            let (o, inv) = (r.ray.origin[a], r.inv_dir[a]);
            let tn = (n - o) * inv;
            let tf = (f - o) * (inv * EXIT_WIDEN);
            if tn > entry {
                entry = tn;
            }
            if tf < exit {
                exit = tf;
            }
        }
        (entry, exit)
    }

    /// The box test of a node of type `N` with SSE2, and with AVX2 where this CPU has it,
    /// gives lane by lane `slab_premultiplied`'s hit or miss and `RayPre::slab`'s entry
    /// distance (up to the sign of a zero) for every non-NaN interval, empty lanes never
    /// hit; `cases` random nodes.
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
                    let (e, x) = slab_premultiplied(&r, lo, hi, t_lo, t_hi);
                    assert_eq!(e, r.slab(lo, hi, t_lo, t_hi).0, "case {case} lane {l}");
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
    /// functions, or with AVX2 the packet's completion) is `Triangle::intersect`'s, bit for
    /// bit, on rays and triangles with coordinates from a small set and random ones, and
    /// with coordinates over f32's whole range, on random `t` ranges.
    #[test]
    fn packet_answers_are_intersect_answers() {
        let avx2 = crate::wide::simd::Avx2::detect();
        let mut rng = Pcg32::new(17, 2);
        let ends = [0.0, 0.5, 1.0, 2.0, f32::INFINITY, f32::NAN];
        let (mut hits, mut from_edges) = (0, 0);
        for case in 0..200_000 {
            // Every other case spans f32's range: exponents from −130 (subnormal) to 127,
            // so that the f64 plane distance overflows, underflows and divides by zero.
            let c = |rng: &mut Pcg32| {
                if case % 2 == 0 {
                    coord(rng)
                } else {
                    let m = rng.range_f32(-2.0, 2.0);
                    m * 2f32.powi(rng.below(258) as i32 - 130)
                }
            };
            let v = |rng: &mut Pcg32| Vec3::new(c(rng), c(rng), c(rng));
            let r = Ray::new(v(&mut rng), v(&mut rng)).precompute();
            let tris: Vec<Triangle> = (0..LANES)
                .map(|_| Triangle::new(v(&mut rng), v(&mut rng), v(&mut rng)))
                .collect();
            let (mut packets, mut slots) = (Vec::new(), 0);
            pack_entries(&mut packets, &mut slots, [0, 1, 2, 3 | RUN_END], &tris);
            let rs = RaySimd::new(&r);
            let e = rs.triangle_edges(&packets[0]);
            // Either end may be NaN, which the scalar test's comparisons treat as no bound.
            let lo = [0.0, 0.5, f32::NAN][rng.below(3) as usize];
            let hi = ends[rng.below(ends.len() as u32) as usize];
            let done = avx2.map(|a| rs.complete(a, &packets[0], &e, &r, lo));
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
                // The AVX2 completion, on the lanes it is used for.
                if let Some(c) = &done
                    && e.candidates & !e.zero & (1 << l) != 0
                {
                    let above = c.t[l] > hi;
                    let got = (c.ok & (1 << l) != 0 && !above).then_some(
                        dualsplit_geometry::TriangleHit {
                            t: c.t[l],
                            u: c.u[l],
                            v: c.v[l],
                        },
                    );
                    assert_eq!(
                        bits(got),
                        bits(want),
                        "AVX2, case {case} lane {l}: {t:?} {r:?}"
                    );
                }
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
