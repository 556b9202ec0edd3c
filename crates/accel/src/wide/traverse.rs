//! The one traversal of every BVH image (BVH2, BVH4, BVH8): closest hit and any hit,
//! reading nodes, leaf words, index runs and triangles from the [`MemoryImage`] and telling
//! the [`Observer`] every fetch and step (contract 2 of `docs/architecture.md`).
//!
//! Per internal node: fetch the node, slab-test every non-empty child box against
//! `[ray.t_min, cull_limit(best_t)]` ([`dualsplit_geometry::RayPre::slab`], whose far-plane
//! exits are widened by `1 + 2γ₃` (Ize 2013) so a ray aimed at a vertex on a box corner is
//! never rounded away), report `NodeStep::Bvh`, sort the hit children by entry
//! distance (near first, ties in slot order), continue with the nearest and push the others
//! far-first with their entry distance. A popped entry whose entry distance is beyond
//! `cull_limit(best_t)` is discarded. Per leaf: fetch the leaf word, then the index run (its
//! last entry has bit 31 set), report `NodeStep::Leaf`, then fetch and test each triangle on
//! `[ray.t_min, best_t]`, keeping the closest by [`Hit::closer_than`]'s `(t, prim)` order.
//! Any hit returns at the first accepted triangle and culls against `ray.t_max`.

use super::encode::LAST_IN_RUN;
use crate::image::{ChildKind, MemoryImage, NodeLayout};
use crate::observer::{NodeStep, Observer};
use dualsplit_geometry::{Hit, Ray, cull_limit};
use std::cell::Cell;

#[derive(Clone, Copy)]
struct Entry {
    t: f32,
    word: u32,
    leaf: bool,
}

thread_local! {
    /// The traversal stack's buffer, one per thread, reused from ray to ray: a ray costs no
    /// allocation (the simulator traces millions of rays one at a time; an allocation and
    /// a free per ray were ≈ 3 % of its functional side, `docs/performance.md`, "Fifth
    /// round"). A traversal that finds it taken (an observer tracing a ray inside a
    /// traversal) allocates its own.
    static STACK: Cell<Vec<Entry>> = const { Cell::new(Vec::new()) };
}

/// Traverses the image with node layout `L`. `ANY`: stop at the first hit (shadow rays).
/// Returns the closest hit (or, with `ANY`, the first hit found).
#[inline]
pub fn traverse<L: NodeLayout, O: Observer, const ANY: bool>(
    img: &MemoryImage,
    ray: &Ray,
    obs: &mut O,
) -> Option<Hit> {
    let mut stack = STACK.take();
    stack.clear();
    let hit = traverse_with::<L, O, ANY>(img, ray, obs, &mut stack);
    STACK.set(stack);
    hit
}

/// [`traverse`] with the stack's buffer given.
#[inline(always)]
fn traverse_with<L: NodeLayout, O: Observer, const ANY: bool>(
    img: &MemoryImage,
    ray: &Ray,
    obs: &mut O,
    stack: &mut Vec<Entry>,
) -> Option<Hit> {
    let r = ray.precompute();
    let words = &img.words[..];
    let mut best: Option<Hit> = None;
    let mut best_t = ray.t_max;
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
                if e.t <= cull_limit(best_t) {
                    break e;
                }
            },
        };
        if e.leaf {
            let w = e.word as usize;
            obs.fetch(MemoryImage::addr(w), 4);
            let run = words[w] as usize;
            let mut count = 0;
            while words[run + count] & LAST_IN_RUN == 0 {
                count += 1;
            }
            count += 1;
            obs.fetch(MemoryImage::addr(run), 4 * count as u32);
            obs.step(NodeStep::Leaf {
                count: count as u32,
            });
            for &entry in &words[run..run + count] {
                let p = entry & !LAST_IN_RUN;
                let tri = img.fetch_triangle(p, obs);
                let Some(h) = tri.intersect(&r, ray.t_min, best_t) else {
                    obs.triangle_test(p, false);
                    continue;
                };
                let accept = best.is_none_or(|b| !b.closer_than(h.t, p));
                obs.triangle_test(p, accept);
                if accept {
                    best = Some(Hit {
                        t: h.t,
                        prim: p,
                        u: h.u,
                        v: h.v,
                    });
                    if ANY {
                        return best;
                    }
                    best_t = h.t;
                }
            }
            continue;
        }
        let w = e.word as usize;
        obs.fetch(MemoryImage::addr(w), (L::WORDS * 4) as u32);
        let node = L::read(words, w);
        let limit = cull_limit(best_t);
        let mut hits = [Entry {
            t: 0.0,
            word: 0,
            leaf: false,
        }; 8];
        let (mut valid, mut nhit) = (0u8, 0usize);
        let mut addr = node.offset();
        for k in 0..L::ARITY {
            let kind = node.kind(k);
            if kind == ChildKind::Empty {
                continue;
            }
            valid += 1;
            let b = node.child_bounds(k);
            let (entry, exit) = r.slab(b.min, b.max, ray.t_min, limit);
            if entry <= exit {
                // Insertion sort by entry distance; equal distances keep slot order.
                let mut j = nhit;
                while j > 0 && hits[j - 1].t > entry {
                    hits[j] = hits[j - 1];
                    j -= 1;
                }
                hits[j] = Entry {
                    t: entry,
                    word: addr,
                    leaf: kind == ChildKind::Leaf,
                };
                nhit += 1;
            }
            addr += L::child_words(kind);
        }
        obs.step(NodeStep::Bvh {
            arity: L::ARITY as u8,
            valid,
            hits: nhit as u8,
        });
        if nhit == 0 {
            continue;
        }
        for h in hits[1..nhit].iter().rev() {
            stack.push(*h);
            obs.push();
        }
        cur = Some(hits[0]);
    }
}
