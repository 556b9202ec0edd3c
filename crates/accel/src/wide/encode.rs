//! Writes a [`WideBvh`] into a byte-exact [`MemoryImage`] (layout in [`crate::image`]).
//!
//! Loading a saved tree replays this allocation (child blocks and runs bump-allocated in
//! depth-first slot order) and rejects any other layout (`saved/structure.rs`): a change
//! here changes the saved-tree format.

use super::{WideBvh, WideChild};
use crate::image::{ChildKind, ImageError, MemoryImage, NodeLayout, RUN_END, SharedTriangles};

/// Encodes `wide` with node layout `L`: nodes depth-first with all children of a node
/// stored consecutively (internal children as whole nodes, leaves as one leaf word), then
/// the leaves' index runs in depth-first leaf order, then `triangles`.
pub fn encode<L: NodeLayout>(
    wide: &WideBvh,
    prim_ids: &[u32],
    triangles: SharedTriangles,
) -> Result<MemoryImage, ImageError> {
    assert!(wide.arity <= L::ARITY, "tree wider than the node layout");
    let leaves = wide.leaf_count();
    let node_words = wide.nodes.len() * L::WORDS + leaves;
    let index_words = index_words(wide);
    let mut img = MemoryImage::with_triangles(node_words, index_words, triangles);
    let mut e = Encoder {
        wide,
        prim_ids,
        words: &mut img.words,
        next_node: L::WORDS,
        next_index: node_words,
    };
    e.emit::<L>(0, 0)?;
    debug_assert_eq!(e.next_node, node_words);
    debug_assert_eq!(e.next_index, node_words + index_words);
    Ok(img)
}

/// Triangle-index entries of `wide`'s leaves: the index region's words.
pub(crate) fn index_words(wide: &WideBvh) -> usize {
    wide.nodes
        .iter()
        .flat_map(|n| &n.children)
        .map(|c| match c.1 {
            WideChild::Leaf { count, .. } => count as usize,
            WideChild::Node(_) => 0,
        })
        .sum()
}

/// Writes the triangle ids `ids` as an index run from word `run` of `words`, [`RUN_END`] on
/// the last (the run of every BVH image, the compressed BVH8's too).
pub(crate) fn write_run(words: &mut [u32], run: usize, ids: &[u32]) -> Result<(), ImageError> {
    for (j, &p) in ids.iter().enumerate() {
        if p >= RUN_END {
            return Err(ImageError::PrimOverflow {
                given: p as u64,
                limit: RUN_END as u64 - 1,
            });
        }
        let last = if j + 1 == ids.len() { RUN_END } else { 0 };
        words[run + j] = p | last;
    }
    Ok(())
}

struct Encoder<'a> {
    wide: &'a WideBvh,
    prim_ids: &'a [u32],
    words: &'a mut [u32],
    next_node: usize,
    next_index: usize,
}

impl Encoder<'_> {
    fn emit<L: NodeLayout>(&mut self, node: usize, at: usize) -> Result<(), ImageError> {
        let wide = self.wide;
        let children = &wide.nodes[node].children;
        let kinds: Vec<(dualsplit_geometry::Aabb, ChildKind)> = children
            .iter()
            .map(|&(b, c)| {
                let k = match c {
                    WideChild::Node(_) => ChildKind::Internal,
                    WideChild::Leaf { .. } => ChildKind::Leaf,
                };
                (b, k)
            })
            .collect();
        let block = self.next_node;
        self.next_node += kinds
            .iter()
            .map(|&(_, k)| L::child_words(k) as usize)
            .sum::<usize>();
        let offset = u32::try_from(block).map_err(|_| ImageError::OffsetOverflow {
            structure: L::NAME,
            given: block as u64,
            bits: L::OFFSET_BITS,
            limit: (1u64 << L::OFFSET_BITS) - 1,
        })?;
        let n = L::encode(&kinds, offset)?;
        self.words[at..at + L::WORDS]
            .copy_from_slice(bytemuck::cast_slice(std::slice::from_ref(&n)));
        let mut addr = block;
        for (&(_, child), &(_, kind)) in children.iter().zip(&kinds) {
            match child {
                WideChild::Node(c) => self.emit::<L>(c as usize, addr)?,
                WideChild::Leaf { first, count } => {
                    let run = self.next_index;
                    if run as u64 >= RUN_END as u64 {
                        return Err(ImageError::OffsetOverflow {
                            structure: L::NAME,
                            given: run as u64,
                            bits: 31,
                            limit: RUN_END as u64 - 1,
                        });
                    }
                    self.words[addr] = run as u32;
                    let ids = &self.prim_ids[first as usize..(first + count) as usize];
                    write_run(self.words, run, ids)?;
                    self.next_index += ids.len();
                }
            }
            addr += L::child_words(kind) as usize;
        }
        Ok(())
    }
}
