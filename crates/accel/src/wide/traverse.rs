//! The one traversal of every BVH image (BVH2, BVH4, BVH8, and the compressed BVH8 through
//! its node, `cwbvh/traverse.rs`): closest hit and any hit, reading nodes, leaf words, index
//! runs and triangles from the [`MemoryImage`] and telling the [`Observer`] every fetch and
//! step (the one-traversal contract: README, "What is where"). It is generic over the node
//! (`ImageNodes`): how a node and a leaf are read and their fetches reported, and its slots.
//!
//! Per internal node: fetch the node's header, fetch and slab-test every non-empty child box against
//! `[ray.t_min, cull_limit(best_t)]` (the arithmetic of [`dualsplit_geometry::RayPre::slab`],
//! whose far-plane exits are widened by `1 + 2γ₃` (Ize 2013) so a ray aimed at a vertex on a
//! box corner is never rounded away, evaluated on the node's stored box words by `BoxSlab`:
//! planes picked by index from the ray's signs, bounds clipped by compare-and-select, which
//! x86-64 does in one instruction where `f32::max`/`min` take six), report `NodeStep::Bvh`,
//! sort the hit children by entry distance (near first, ties in slot order), continue with
//! the nearest and push the others far-first with their entry distance. A popped entry
//! whose entry distance is beyond `cull_limit(best_t)` is discarded. Per leaf: fetch the
//! leaf word, then the index run (its last entry carries [`RUN_END`]), report `NodeStep::Leaf`,
//! then fetch and test each triangle on `[ray.t_min, best_t]`, keeping the closest by
//! [`Hit::closer_than`]'s `(t, prim)` order.
//! Any hit returns at the first accepted triangle and culls against `ray.t_max`.

use crate::image::{ChildKind, MemoryImage, NodeLayout, RUN_END, words_box};
use crate::observer::{NodeStep, Observer};
use dualsplit_geometry::{Hit, PrimId, Ray, RayPre, cull_limit, widen_exit};
use std::borrow::Borrow;
use std::cell::Cell;

#[derive(Clone, Copy)]
struct Entry {
    t: f32,
    /// A node's word, or a leaf's (the [`ImageNodes::leaf_run`] of the layout reads it).
    word: u32,
    leaf: bool,
}

thread_local! {
    /// The traversal stack's buffer, one per thread, reused from ray to ray: a ray costs no
    /// allocation (the simulator traces millions of rays one at a time, and an allocation
    /// and a free per ray would cost it ≈ 3 % of its functional side). A traversal that
    /// finds it taken (an observer tracing a ray inside a
    /// traversal) allocates its own.
    static STACK: Cell<Vec<Entry>> = const { Cell::new(Vec::new()) };
}

/// What the one BVH image traversal ([`traverse_nodes`]) needs of a node layout: how a node
/// and a leaf are read and reported, and the node's slots in order. Every [`NodeLayout`]
/// (BVH2, BVH4, BVH8) is one; the compressed BVH8's node is another.
pub(crate) trait ImageNodes {
    /// Child slots.
    const ARITY: usize;
    /// A node being expanded: the node, and where its slots' children lie.
    type Open<'a>;
    /// A slot's box words as [`ImageNodes::slot`] gives them: a reference into the image
    /// for a layout that stores them, the decoded words for one that does not.
    type BoxWords<'a>: Borrow<[f32; 6]>;
    /// Reads the node at word `w` and reports its fetch (the part not reported per slot).
    fn open<'a, O: Observer>(words: &'a [u32], w: usize, obs: &mut O) -> Self::Open<'a>;
    /// Slot `k` of an open node (slots are asked in order, each once): `None` when empty,
    /// else its box's six words (min.xyz, max.xyz), its child's word and whether it is a
    /// leaf; reports the box's fetch where it is fetched apart.
    fn slot<'a, O: Observer>(
        node: &mut Self::Open<'a>,
        k: usize,
        obs: &mut O,
    ) -> Option<Slot<Self::BoxWords<'a>>>;
    /// The word of the index run of the leaf at word `word`, reporting what is fetched to
    /// find it.
    fn leaf_run<O: Observer>(words: &[u32], word: usize, obs: &mut O) -> usize;
}

/// A non-empty slot of an open node ([`ImageNodes::slot`]).
pub(crate) struct Slot<B> {
    /// The box as six words: min.xyz, max.xyz.
    pub box_words: B,
    /// The child's word.
    pub word: u32,
    /// The child is a leaf.
    pub leaf: bool,
}

/// A BVH2/4/8 node being expanded: its children lie consecutively from its offset.
pub(crate) struct OpenNode<'a, L> {
    node: &'a L,
    /// The node's word.
    w: usize,
    /// The word of the next slot's child.
    addr: u32,
}

impl<L: NodeLayout> ImageNodes for L {
    const ARITY: usize = L::ARITY;
    type Open<'a> = OpenNode<'a, L>;
    type BoxWords<'a> = &'a [f32; 6];

    #[inline(always)]
    fn open<'a, O: Observer>(words: &'a [u32], w: usize, obs: &mut O) -> OpenNode<'a, L> {
        // The node's header (after its boxes in every layout), then each present child's
        // box as it is tested.
        let boxes = 6 * L::ARITY;
        obs.fetch(
            MemoryImage::addr(w + boxes),
            ((L::WORDS - boxes) * 4) as u32,
        );
        let node = L::read(words, w);
        OpenNode {
            node,
            w,
            addr: node.offset(),
        }
    }

    #[inline(always)]
    fn slot<'a, O: Observer>(
        n: &mut Self::Open<'a>,
        k: usize,
        obs: &mut O,
    ) -> Option<Slot<Self::BoxWords<'a>>> {
        let kind = n.node.kind(k);
        if kind == ChildKind::Empty {
            return None;
        }
        obs.fetch_box(MemoryImage::addr(n.w + 6 * k), 24);
        let word = n.addr;
        n.addr += L::child_words(kind);
        Some(Slot {
            box_words: n.node.box_words(k),
            word,
            leaf: kind == ChildKind::Leaf,
        })
    }

    #[inline(always)]
    fn leaf_run<O: Observer>(words: &[u32], w: usize, obs: &mut O) -> usize {
        obs.fetch(MemoryImage::addr(w), 4);
        words[w] as usize
    }
}

/// Traverses the image with node layout `L`. `ANY`: stop at the first hit (shadow rays).
/// Returns the closest hit (or, with `ANY`, the first hit found).
#[inline]
pub fn traverse<L: NodeLayout, O: Observer, const ANY: bool>(
    img: &MemoryImage,
    ray: &Ray,
    obs: &mut O,
) -> Option<Hit> {
    traverse_nodes::<L, O, ANY>(img, ray, obs)
}

/// [`traverse`] for any [`ImageNodes`] (the compressed BVH8's too).
#[inline]
pub(crate) fn traverse_nodes<N: ImageNodes, O: Observer, const ANY: bool>(
    img: &MemoryImage,
    ray: &Ray,
    obs: &mut O,
) -> Option<Hit> {
    // Untraceable rays (non-finite origin or direction, NaN interval end) miss
    // (`Ray::is_traceable`), in every structure alike.
    if !ray.is_traceable() {
        return None;
    }
    let mut stack = STACK.take();
    stack.clear();
    let hit = traverse_with::<N, O, ANY>(img, ray, obs, &mut stack);
    STACK.set(stack);
    hit
}

/// What testing a leaf's run did to the traversal ([`test_run`]).
pub(crate) enum RunOutcome {
    /// An any-hit traversal found its hit: it returns.
    AnyHit,
    /// A closer hit was kept: `best_t` moved, and the cull limit with it.
    Closer,
    /// Nothing changed.
    Same,
}

/// Tests the triangle-index run at word `run` of `img` (ended by [`RUN_END`]) on
/// `[ray.t_min, best_t]`, keeping the closest hit by `(t, prim)` in `best` and its `t` in
/// `best_t`, reporting the run's fetch, the leaf step, each triangle's fetch and test to
/// `obs`. The leaf test of every BVH image traversal (and the toy structure's).
#[inline(always)]
pub(crate) fn test_run<O: Observer, const ANY: bool>(
    img: &MemoryImage,
    run: usize,
    r: &RayPre,
    ray: &Ray,
    obs: &mut O,
    best: &mut Option<Hit>,
    best_t: &mut f32,
) -> RunOutcome {
    let words = &img.words[..];
    let mut count = 0;
    while words[run + count] & RUN_END == 0 {
        count += 1;
    }
    count += 1;
    obs.fetch(MemoryImage::addr(run), 4 * count as u32);
    obs.step(NodeStep::Leaf {
        count: count as u32,
    });
    let mut outcome = RunOutcome::Same;
    for &entry in &words[run..run + count] {
        let p = PrimId(entry & !RUN_END);
        let tri = img.fetch_triangle(p, obs);
        let Some(h) = tri.intersect(r, ray.t_min, *best_t) else {
            obs.triangle_test(p, false);
            continue;
        };
        let accept = Hit::keep_closest(best, p, h);
        obs.triangle_test(p, accept);
        if accept {
            if ANY {
                return RunOutcome::AnyHit;
            }
            *best_t = h.t;
            outcome = RunOutcome::Closer;
        }
    }
    outcome
}

/// [`traverse_nodes`] with the stack's buffer given.
#[inline(always)]
fn traverse_with<N: ImageNodes, O: Observer, const ANY: bool>(
    img: &MemoryImage,
    ray: &Ray,
    obs: &mut O,
    stack: &mut Vec<Entry>,
) -> Option<Hit> {
    let r = ray.precompute();
    let slab = BoxSlab::new(&r);
    let words = &img.words[..];
    let mut best: Option<Hit> = None;
    let mut best_t = ray.t_max;
    // `cull_limit(best_t)`, updated with `best_t`.
    let mut limit = cull_limit(best_t);
    // The compare-and-select slab needs non-NaN interval ends (see `BoxSlab`); a NaN
    // `t_min` or cull limit (a ray with `t_max = -∞`) takes `RayPre::slab` itself.
    let mut fast = !(ray.t_min - limit).is_nan();
    let mut cur = Some(Entry {
        t: ray.t_min,
        word: 0,
        leaf: false,
    });
    loop {
        let e = match cur.take() {
            Some(e) => e,
            None => loop {
                let Some(e) = stack.pop() else {
                    return best;
                };
                obs.pop();
                if e.t <= limit {
                    break e;
                }
            },
        };
        if e.leaf {
            let run = N::leaf_run(words, e.word as usize, obs);
            match test_run::<O, ANY>(img, run, &r, ray, obs, &mut best, &mut best_t) {
                RunOutcome::AnyHit => return best,
                RunOutcome::Closer => {
                    limit = cull_limit(best_t);
                    fast = !(ray.t_min - limit).is_nan();
                }
                RunOutcome::Same => {}
            }
            continue;
        }
        let mut node = N::open(words, e.word as usize, obs);
        // The hit children: the nearest in `near`, the others on the stack above `base`,
        // nearest on top; order by entry distance, ties in slot order.
        let base = stack.len();
        let mut near: Option<Entry> = None;
        let (mut valid, mut nhit) = (0u8, 0u8);
        // One slot's test and sort step (a macro, so that the slots are unrolled with
        // constant slot numbers: the decode folds).
        macro_rules! child {
            ($k:expr) => {{
                if let Some(s) = N::slot(&mut node, $k, obs) {
                    valid += 1;
                    let (entry, exit) = if fast {
                        slab.test(s.box_words.borrow(), ray.t_min, limit)
                    } else {
                        let b = words_box(s.box_words.borrow());
                        r.slab(b.min, b.max, ray.t_min, limit)
                    };
                    // `entry <= exit`, false when either is NaN.
                    if entry <= exit {
                        nhit += 1;
                        let e = Entry {
                            t: entry,
                            word: s.word,
                            leaf: s.leaf,
                        };
                        match near {
                            None => near = Some(e),
                            // A later slot is nearer only when strictly nearer.
                            Some(n) if entry < n.t => {
                                // `n` precedes every stacked entry: it goes on top.
                                stack.push(n);
                                near = Some(e);
                            }
                            Some(_) => {
                                // Below the stacked entries that are nearer or equally near.
                                stack.push(e);
                                let mut j = stack.len() - 1;
                                while j > base && stack[j - 1].t <= entry {
                                    stack[j] = stack[j - 1];
                                    j -= 1;
                                }
                                stack[j] = e;
                            }
                        }
                    }
                }
            }};
        }
        match N::ARITY {
            2 => {
                child!(0);
                child!(1);
            }
            4 => {
                child!(0);
                child!(1);
                child!(2);
                child!(3);
            }
            8 => {
                child!(0);
                child!(1);
                child!(2);
                child!(3);
                child!(4);
                child!(5);
                child!(6);
                child!(7);
            }
            _ => {
                for k in 0..N::ARITY {
                    child!(k);
                }
            }
        }
        obs.step(NodeStep::Bvh {
            arity: N::ARITY as u8,
            valid,
            hits: nhit,
        });
        for _ in 1..nhit {
            obs.push();
        }
        cur = near;
    }
}

/// The slab test of [`RayPre::slab`] on a box's six stored words, with the near and far
/// planes picked by index from the ray's direction signs and the interval clipped by
/// compare-and-select instead of the NaN-permissive `f32::min`/`f32::max`.
///
/// The plane distances are the same IEEE operations (`(p - o[a]) * inv[a]`, far planes
/// widened by [`dualsplit_geometry::widen_exit`]), so the result equals `RayPre::slab`'s
/// whenever the interval ends `t_lo` and `t_hi` are not NaN: a NaN plane distance (a ray
/// lying in a slab's plane) loses every comparison, so the running bound is kept, exactly
/// as `f32::max`/`f32::min` ignore a NaN operand. Only the sign of a zero bound may
/// differ, which no comparison sees. Callers with a NaN interval end use `RayPre::slab`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxSlab {
    origin: [f32; 3],
    inv: [f32; 3],
    neg: [bool; 3],
}

impl BoxSlab {
    pub(crate) fn new(r: &RayPre) -> Self {
        Self {
            origin: r.ray.origin.to_array(),
            inv: r.inv_dir.to_array(),
            neg: r.neg,
        }
    }

    /// `(entry, exit)` of box words `w` (min.xyz, max.xyz) clipped to `[t_lo, t_hi]`.
    #[inline(always)]
    pub(crate) fn test(&self, w: &[f32; 6], t_lo: f32, t_hi: f32) -> (f32, f32) {
        let mut entry = t_lo;
        let mut exit = t_hi;
        for a in 0..3 {
            // Near plane: min on a positive axis, max on a negative one (bool → 0 or 3).
            let s = 3 * self.neg[a] as usize;
            let tn = (w[a + s] - self.origin[a]) * self.inv[a];
            let tf = widen_exit((w[a + 3 - s] - self.origin[a]) * self.inv[a]);
            if tn > entry {
                entry = tn;
            }
            if tf < exit {
                exit = tf;
            }
        }
        (entry, exit)
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use dualsplit_geometry::{Aabb, Pcg32, Vec3};

    /// A coordinate from a small set (so that box planes often pass exactly through the
    /// ray's origin and zero direction components make NaN plane distances) or random.
    /// Also the SIMD chunk test's (`cpu.rs`).
    pub(in crate::wide) fn coord(rng: &mut Pcg32) -> f32 {
        match rng.below(6) {
            0 => 0.0,
            1 => -0.0,
            2 => 1.0,
            3 => -1.0,
            _ => rng.range_f32(-4.0, 4.0),
        }
    }

    /// `BoxSlab::test` answers as `RayPre::slab` (the same values, up to the sign of a zero,
    /// and the same hit or miss) for every non-NaN interval, on boxes whose planes pass
    /// through the origin, degenerate boxes, axis-parallel rays and ±0 directions.
    #[test]
    fn box_slab_matches_ray_slab() {
        let mut rng = Pcg32::new(7, 3);
        for i in 0..200_000 {
            let origin = Vec3::new(coord(&mut rng), coord(&mut rng), coord(&mut rng));
            let dir = Vec3::new(coord(&mut rng), coord(&mut rng), coord(&mut rng));
            let r = Ray::new(origin, dir).precompute();
            let b = if rng.below(10) == 0 {
                Aabb::DEGENERATE
            } else {
                let (p, q) = (
                    Vec3::new(coord(&mut rng), coord(&mut rng), coord(&mut rng)),
                    Vec3::new(coord(&mut rng), coord(&mut rng), coord(&mut rng)),
                );
                Aabb::new(p.min(q), p.max(q))
            };
            let ends = [0.0, -0.0, 0.5, 1e-3, f32::INFINITY, f32::NEG_INFINITY, 3.0];
            let t_lo = ends[rng.below(ends.len() as u32) as usize];
            let t_hi = ends[rng.below(ends.len() as u32) as usize];
            let w = [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z];
            let (e, x) = BoxSlab::new(&r).test(&w, t_lo, t_hi);
            let (we, wx) = r.slab(b.min, b.max, t_lo, t_hi);
            assert_eq!((e, x, e <= x), (we, wx, we <= wx), "case {i}: {r:?} {b:?}");
            assert!(!e.is_nan() && !x.is_nan());
        }
    }
}
