//! The compressed BVH8's node for the one BVH image traversal
//! ([`crate::wide::traverse`], which it runs unchanged: the same slab test, sort, stack and
//! leaf loop): how a node and a leaf are read and reported.
//!
//! Per internal node: fetch the whole 80-byte node (one read: the quantized boxes are
//! interleaved axis by axis, so no child's box is a contiguous range) and decode each
//! non-empty slot's box as it is tested; the node reports `NodeStep::Bvh { arity: 8, .. }`.
//! Per leaf: there is no leaf word (the node addresses the run), so the run is fetched
//! directly.
//!
//! A decoded box contains the exact box, and the slab test is monotone in the box planes,
//! so every box the BVH8 enters is entered here too (with an entry distance no larger):
//! the set of triangles tested only grows, and the `(t, prim)` minimum, which every BVH
//! traversal finds, stays the same.

use super::node::{CwNode, Meta};
use crate::image::MemoryImage;
use crate::observer::Observer;
use crate::wide::traverse::{ImageNodes, Slot, traverse_nodes};
use dualsplit_geometry::{Hit, Ray};

impl ImageNodes for CwNode {
    const ARITY: usize = 8;
    type Open<'a> = &'a CwNode;
    type BoxWords<'a> = [f32; 6];

    #[inline(always)]
    fn open<'a, O: Observer>(words: &'a [u32], w: usize, obs: &mut O) -> &'a CwNode {
        obs.fetch(MemoryImage::addr(w), 80);
        CwNode::read(words, w)
    }

    #[inline(always)]
    fn slot<'a, O: Observer>(
        node: &mut Self::Open<'a>,
        k: usize,
        _: &mut O,
    ) -> Option<Slot<Self::BoxWords<'a>>> {
        let (word, leaf) = match node.slot(k) {
            Meta::Empty => return None,
            Meta::Internal => (node.child_node(k), false),
            Meta::Leaf { offset, .. } => (node.leaf_run(offset), true),
        };
        Some(Slot {
            box_words: node.box_words(k),
            word,
            leaf,
        })
    }

    #[inline(always)]
    fn leaf_run<O: Observer>(_: &[u32], word: usize, _: &mut O) -> usize {
        word
    }
}

/// Traverses a compressed-BVH8 image. `ANY`: stop at the first hit (shadow rays).
#[inline]
pub fn traverse<O: Observer, const ANY: bool>(
    img: &MemoryImage,
    ray: &Ray,
    obs: &mut O,
) -> Option<Hit> {
    traverse_nodes::<CwNode, O, ANY>(img, ray, obs)
}
