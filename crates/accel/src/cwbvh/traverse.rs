//! The image traversal of a compressed BVH8 (closest hit and any hit), generic over the
//! [`Observer`]: [`crate::wide::traverse`]'s algorithm and box-test arithmetic on the
//! decoded child boxes.
//!
//! Per internal node: fetch the whole 80-byte node (one read: the quantized boxes are
//! interleaved axis by axis, so no child's box is a contiguous range), decode and slab-test
//! every non-empty slot against `[ray.t_min, cull_limit(best_t)]` (the compare-and-select
//! slab of the BVH traversal, far planes widened by `EXIT_WIDEN`; `RayPre::slab` when an
//! interval end is NaN), report `NodeStep::Bvh { arity: 8, .. }`, continue with the nearest
//! hit child and push the others far-first (ties in slot order). Per leaf: fetch its index
//! run (there is no leaf word: the node addresses the run), report `NodeStep::Leaf`, then
//! fetch and test each triangle on `[ray.t_min, best_t]`, keeping the closest by
//! `(t, prim)` ([`Hit::closer_than`]). Any hit returns at the first accepted triangle.
//!
//! A decoded box contains the exact box, and the slab test is monotone in the box planes,
//! so every box the BVH8 enters is entered here too (with an entry distance no larger):
//! the set of triangles tested only grows, and the `(t, prim)` minimum, which every BVH
//! traversal finds, stays the same.

use super::node::{CwNode, Meta};
use crate::image::MemoryImage;
use crate::observer::{NodeStep, Observer};
use crate::wide::traverse::{BoxSlab, RunOutcome, test_run};
use dualsplit_geometry::{Hit, Ray, cull_limit};
use std::cell::Cell;

#[derive(Clone, Copy)]
struct Entry {
    t: f32,
    /// A node's word, or a leaf's run word.
    word: u32,
    leaf: bool,
}

thread_local! {
    /// The traversal stack's buffer, reused from ray to ray (as in `wide::traverse`).
    static STACK: Cell<Vec<Entry>> = const { Cell::new(Vec::new()) };
}

/// Traverses a compressed-BVH8 image. `ANY`: stop at the first hit (shadow rays).
#[inline]
pub fn traverse<O: Observer, const ANY: bool>(
    img: &MemoryImage,
    ray: &Ray,
    obs: &mut O,
) -> Option<Hit> {
    // Untraceable rays miss (`Ray::is_traceable`), in every structure alike.
    if !ray.is_traceable() {
        return None;
    }
    let mut stack = STACK.take();
    stack.clear();
    let hit = traverse_with::<O, ANY>(img, ray, obs, &mut stack);
    STACK.set(stack);
    hit
}

#[inline(always)]
fn traverse_with<O: Observer, const ANY: bool>(
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
    let mut limit = cull_limit(best_t);
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
            let run = e.word as usize;
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
        let w = e.word as usize;
        obs.fetch(MemoryImage::addr(w), 80);
        let node = CwNode::read(words, w);
        let base = stack.len();
        let mut near: Option<Entry> = None;
        let (mut valid, mut nhit) = (0u8, 0u8);
        for k in 0..8 {
            let (word, leaf) = match node.slot(k) {
                Meta::Empty => continue,
                Meta::Internal => (node.child_node(k), false),
                Meta::Leaf { offset, .. } => (node.leaf_run(offset), true),
            };
            valid += 1;
            let bw = node.box_words(k);
            let (entry, exit) = if fast {
                slab.test(&bw, ray.t_min, limit)
            } else {
                let b = crate::image::words_box(&bw);
                r.slab(b.min, b.max, ray.t_min, limit)
            };
            // `entry <= exit`, false when either is NaN.
            let hit = entry <= exit;
            if !hit {
                continue;
            }
            nhit += 1;
            let e = Entry {
                t: entry,
                word,
                leaf,
            };
            match near {
                None => near = Some(e),
                Some(n) if entry < n.t => {
                    stack.push(n);
                    near = Some(e);
                }
                Some(_) => {
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
        obs.step(NodeStep::Bvh {
            arity: 8,
            valid,
            hits: nhit,
        });
        for _ in 1..nhit {
            obs.push();
        }
        cur = near;
    }
}
