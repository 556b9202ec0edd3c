//! Writes a BVH8 ([`WideBvh`]) into a compressed-BVH8 memory image.
//!
//! Allocation, depth-first from the root at word 0: when a node is written, its internal
//! children get consecutive 20-word nodes (slot order) at the end of the node region so
//! far, and its leaves get consecutive runs (slot order) at the end of the index region so
//! far; then its internal children are written in slot order. So a node's internal children
//! are adjacent (`child_base`) and its leaf runs are adjacent (`triangle_base`), as the
//! node's addressing requires.

use super::node::{CwNode, LEAF_OFFSET_LIMIT, Meta, NODE_WORDS};
use crate::image::{ImageError, MemoryImage, SharedTriangles};
use crate::wide::encode::{index_words, write_run};
use crate::wide::{WideBvh, WideChild};

/// Structure name in errors and reports.
pub const NAME: &str = "cwbvh";

/// Encodes `wide` (arity ≤ 8) over `prim_ids` and `triangles`.
pub fn encode(
    wide: &WideBvh,
    prim_ids: &[u32],
    triangles: SharedTriangles,
) -> Result<MemoryImage, ImageError> {
    assert!(wide.arity <= 8, "tree wider than a BVH8 node");
    let node_words = wide.nodes.len().max(1) * NODE_WORDS;
    let index_words = index_words(wide);
    let mut img = MemoryImage::with_triangles(node_words, index_words, triangles);
    if wide.nodes.is_empty() {
        let root = CwNode::empty(NODE_WORDS as u32, node_words as u32);
        img.words[..NODE_WORDS].copy_from_slice(&root.to_words());
        return Ok(img);
    }
    let mut e = Encoder {
        wide,
        prim_ids,
        words: &mut img.words,
        next_node: NODE_WORDS,
        next_index: node_words,
    };
    // Depth-first with an explicit stack (children pushed in reverse slot order), so that
    // deep trees need no deep recursion; the allocation order is that of the recursion.
    let mut todo = vec![(0usize, 0usize)];
    while let Some((node, at)) = todo.pop() {
        let children = e.emit(node, at)?;
        todo.extend(children.into_iter().rev());
    }
    debug_assert_eq!(e.next_node, node_words);
    debug_assert_eq!(e.next_index, node_words + index_words);
    Ok(img)
}

struct Encoder<'a> {
    wide: &'a WideBvh,
    prim_ids: &'a [u32],
    words: &'a mut [u32],
    next_node: usize,
    next_index: usize,
}

/// `v` as a 32-bit word address, or the error naming the limit.
fn word32(v: usize) -> Result<u32, ImageError> {
    u32::try_from(v).map_err(|_| ImageError::OffsetOverflow {
        structure: NAME,
        given: v as u64,
        bits: 32,
        limit: u32::MAX as u64,
    })
}

impl Encoder<'_> {
    /// Writes node `node` at word `at`, allocates its children's nodes and runs, writes the
    /// runs, and returns its internal children with the words they go to.
    fn emit(&mut self, node: usize, at: usize) -> Result<Vec<(usize, usize)>, ImageError> {
        let children = &self.wide.nodes[node].children;
        let child_base = self.next_node;
        let triangle_base = self.next_index;
        let mut slots = Vec::with_capacity(children.len());
        let mut internal = Vec::new();
        for &(b, c) in children {
            match c {
                WideChild::Node(n) => {
                    internal.push((n as usize, self.next_node));
                    self.next_node += NODE_WORDS;
                    slots.push((b, Meta::Internal));
                }
                WideChild::Leaf { first, count } => {
                    let offset = self.next_index - triangle_base;
                    if offset > LEAF_OFFSET_LIMIT as usize {
                        return Err(ImageError::LeafSpan {
                            structure: NAME,
                            words: offset as u64,
                            limit: LEAF_OFFSET_LIMIT as u64,
                        });
                    }
                    let ids = &self.prim_ids[first as usize..(first + count) as usize];
                    assert!(!ids.is_empty(), "a leaf holds at least one triangle");
                    write_run(self.words, self.next_index, ids)?;
                    self.next_index += ids.len();
                    slots.push((b, Meta::leaf(offset as u32, count)));
                }
            }
        }
        let n = CwNode::encode(&slots, word32(child_base)?, word32(triangle_base)?);
        word32(self.next_index)?;
        self.words[at..at + NODE_WORDS].copy_from_slice(&n.to_words());
        Ok(internal)
    }
}
