//! Structural checks of a loaded image: everything a traversal indexes with, so that a file
//! forged with a recomputed checksum gives a [`Violation`] instead of a panic, a hang or a
//! read of the wrong memory (`docs/tree-format.md`, "Checks on load").
//!
//! Both checks walk the tree once from its root, depth first in the encoders' order, and
//! replay the encoders' bump allocation (`wide/encode.rs`, `dst/encode.rs`: a node's child
//! block, or a DST node's children, go at the next free node word when the node is
//! emitted; a leaf's run at the next free index word when the leaf is): every child offset
//! and every run start must be exactly where that allocation puts it, and the allocation
//! must end exactly at the end of each region. So the blocks and runs are disjoint and in
//! order, every node is reached exactly once (no cycle, no shared subtree, which could make
//! one ray's traversal exponential), every node and run lies inside its region, and the walk
//! is linear with no bookkeeping beyond its stack. Every run ends with [`RUN_END`] before
//! the end of the index region, every entry is a triangle id below the triangle count, and
//! the counts the header records are the walk's.
//!
//! What is not checked: box and plane values (a NaN or a box that does not hold its
//! children costs a traversal wrong answers for that file, never memory safety or
//! termination), and whether every triangle is referenced (`dualsplit check` reports both).

use super::header::Extra;
use crate::dst::{DstStats, HeaderOffset};
use crate::image::{ChildKind, MemoryImage, NodeLayout, RUN_END};
use crate::observer::DstNodeKind;
use crate::tree::{AnyTree, TreeKind};
use std::ops::Range;

/// What is wrong with an image and where.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Violation {
    /// The image word (node region, or index region for a run entry) the fault is at.
    pub word: usize,
    /// What is wrong.
    pub what: String,
}

fn violation(word: usize, what: String) -> Violation {
    Violation { word, what }
}

/// The index-region side of the replayed allocation: runs must follow each other.
struct Runs<'a> {
    img: &'a Regions<'a>,
    /// The image word where the next run must start.
    next: usize,
}

impl<'a> Runs<'a> {
    fn new(img: &'a Regions<'a>) -> Self {
        Runs {
            next: img.indices.start,
            img,
        }
    }

    /// Takes the run starting at image word `start` for the leaf at node word `leaf`: it
    /// must start where the previous one ended, hold triangle ids below the triangle count
    /// and end with [`RUN_END`] inside the index region. Returns its length.
    #[inline(always)]
    fn take(&mut self, leaf: usize, start: usize) -> Result<usize, Violation> {
        let (r, tris) = (&self.img.indices, self.img.triangles);
        if start != self.next {
            return Err(violation(
                leaf,
                format!(
                    "leaf's index run starts at word {start}; in the layout the next run is at word {}",
                    self.next
                ),
            ));
        }
        let mut j = start;
        loop {
            if j >= r.end {
                return Err(violation(
                    leaf,
                    format!(
                        "leaf's index run from word {start} does not end (no RUN_END) before the end of the index region {r:?}"
                    ),
                ));
            }
            let e = self.img.words[j];
            let p = (e & !RUN_END) as usize;
            if p >= tris {
                return Err(violation(
                    j,
                    format!("index entry names triangle {p}, the file has {tris}"),
                ));
            }
            j += 1;
            if e & RUN_END != 0 {
                self.next = j;
                return Ok(j - start);
            }
        }
    }

    /// After the walk: every index word is in a run.
    fn finish(&self) -> Result<(), Violation> {
        let r = &self.img.indices;
        if self.next != r.end {
            return Err(violation(
                self.next,
                format!("index words {}..{} are in no leaf's run", self.next, r.end),
            ));
        }
        Ok(())
    }
}

/// Checks a BVH image with node layout `L` and the counts its header records.
fn check_bvh<L: NodeLayout>(
    img: &Regions,
    internal_nodes: u64,
    leaves: u64,
) -> Result<(), Violation> {
    let nodes = img.nodes.clone();
    if nodes.start != 0 || nodes.len() < L::WORDS {
        return Err(violation(
            0,
            format!(
                "node region {nodes:?} cannot hold a {}-word root node",
                L::WORDS
            ),
        ));
    }
    let words = img.words;
    let mut runs = Runs::new(img);
    let (mut n_internal, mut n_leaves) = (0u64, 0u64);
    // The next free node word of the replayed allocation.
    let mut next = L::WORDS;
    // (word, is a leaf word): children are pushed in reverse, so they are walked in slot
    // order, as the encoder emits them.
    let mut stack = vec![(0usize, false)];
    while let Some((at, leaf)) = stack.pop() {
        if leaf {
            n_leaves += 1;
            runs.take(at, words[at] as usize)?;
            continue;
        }
        n_internal += 1;
        // Inside the node region: the root by the check above, any other node because its
        // parent's child block is.
        let node = L::read(words, at);
        let block_len: usize = (0..L::ARITY)
            .map(|k| L::child_words(node.kind(k)) as usize)
            .sum();
        let start = node.offset() as usize;
        if start.saturating_add(block_len) > nodes.end {
            return Err(violation(
                at,
                format!(
                    "node's child block {start}..{} leaves the node region {nodes:?}",
                    start.saturating_add(block_len)
                ),
            ));
        }
        if start != next {
            return Err(violation(
                at,
                format!(
                    "node's child block starts at word {start}; in the layout it is at word {next}"
                ),
            ));
        }
        next += block_len;
        const { assert!(L::ARITY <= 8) };
        let mut children = [(0usize, false); 8];
        let (mut n, mut addr) = (0, start);
        for k in 0..L::ARITY {
            let kind = node.kind(k);
            if kind != ChildKind::Empty {
                children[n] = (addr, kind == ChildKind::Leaf);
                n += 1;
                addr += L::child_words(kind) as usize;
            }
        }
        stack.extend(children[..n].iter().rev());
    }
    if next != nodes.end {
        return Err(violation(
            next,
            format!(
                "node words {next}..{} are in no node's child block",
                nodes.end
            ),
        ));
    }
    runs.finish()?;
    if (n_internal, n_leaves) != (internal_nodes, leaves) {
        return Err(violation(
            0,
            format!(
                "the tree has {n_internal} internal nodes and {n_leaves} leaves, \
                 its header says {internal_nodes} and {leaves}"
            ),
        ));
    }
    Ok(())
}

/// Bit `h` set for each valid 6-bit DST header code `h` (one shift instead of
/// [`HeaderOffset::decode`]'s field tests per node).
const VALID_HEADERS: u64 = {
    let mut m = 0u64;
    let mut i = 0;
    while i < HeaderOffset::ALL_VALID_HEADERS.len() {
        m |= 1 << HeaderOffset::ALL_VALID_HEADERS[i];
        i += 1;
    }
    m
};

/// Checks a DST image and the statistics its header records.
fn check_dst(img: &Regions, stats: &DstStats) -> Result<(), Violation> {
    let nodes = img.nodes.clone();
    let words = img.words;
    let mut found = DstStats::default();
    let mut runs = Runs::new(img);
    // (node word, the size its parent allocated for it: 1 or 3 words)
    let mut stack: Vec<(usize, u32)> = Vec::new();
    // The next free node word of the replayed allocation.
    let mut next = 0usize;
    if !nodes.is_empty() {
        if nodes.start != 0 {
            return Err(violation(0, format!("node region {nodes:?} not at word 0")));
        }
        let root = HeaderOffset::from_bits(words[0]).size_words();
        if root as usize > nodes.len() {
            return Err(violation(
                0,
                format!("{root}-word root node leaves the node region {nodes:?}"),
            ));
        }
        next = root as usize;
        stack.push((0, root));
    }
    // Allocates `size` words for a child at `c` of the node at `at`: `c` must be the next
    // free word.
    let alloc = |next: &mut usize, at: usize, c: usize, size: u32| {
        if c.saturating_add(size as usize) > nodes.end {
            return Err(violation(
                at,
                format!("child at word {c} outside the node region {nodes:?}"),
            ));
        }
        if c != *next {
            return Err(violation(
                at,
                format!("child at word {c}; in the layout it is at word {next}"),
            ));
        }
        *next += size as usize;
        Ok(())
    };
    while let Some((at, size)) = stack.pop() {
        if (VALID_HEADERS >> (words[at] >> 26)) & 1 == 0 {
            return Err(violation(
                at,
                format!("invalid node header word {:#010x}", words[at]),
            ));
        }
        let w = HeaderOffset::from_bits(words[at]);
        let len = w.size_words();
        if size != len {
            return Err(violation(
                at,
                format!("{len}-word node in a {size}-word slot"),
            ));
        }
        let mut run = |found: &mut DstStats| -> Result<(), Violation> {
            let start = img.indices.start.saturating_add(w.offset() as usize);
            found.index_entries += runs.take(at, start)? as u64;
            Ok(())
        };
        match w.node_kind() {
            DstNodeKind::Leaf => {
                found.leaves += 1;
                run(&mut found)?;
            }
            DstNodeKind::Split => {
                found.splitting += 1;
                let (left, ls) = (w.offset() as usize, w.left_size());
                let right = left + ls as usize;
                // The right child's size is its own header's (checked when it is walked).
                let rs = match words.get(right) {
                    Some(&r) if right < nodes.end => HeaderOffset::from_bits(r).size_words(),
                    _ => {
                        return Err(violation(
                            at,
                            format!(
                                "right child at word {right} outside the node region {nodes:?}"
                            ),
                        ));
                    }
                };
                alloc(&mut next, at, left, ls + rs)?;
                // Right first on the stack: the left subtree is walked first.
                stack.push((right, rs));
                stack.push((left, ls));
            }
            kind => {
                if kind == DstNodeKind::SingleCarve {
                    found.single_carving += 1;
                } else {
                    found.dual_carving += 1;
                }
                if w.is_leaf_flag() {
                    found.carving_leaves += 1;
                    run(&mut found)?;
                } else {
                    // A carving node's child is a carving or splitting node: 3 words.
                    let c = w.offset() as usize;
                    alloc(&mut next, at, c, 3)?;
                    stack.push((c, 3));
                }
            }
        }
    }
    if next != nodes.end {
        return Err(violation(
            next,
            format!("node words {next}..{} belong to no node", nodes.end),
        ));
    }
    runs.finish()?;
    let counts = |s: &DstStats| {
        [
            s.splitting,
            s.single_carving,
            s.dual_carving,
            s.leaves,
            s.carving_leaves,
            s.index_entries,
            s.node_bytes,
            s.index_bytes,
            s.total_bytes,
        ]
    };
    found.node_bytes = 4 * nodes.len() as u64;
    found.index_bytes = 4 * img.indices.len() as u64;
    found.total_bytes = found.node_bytes + found.index_bytes + 24;
    if counts(&found) != counts(stats) {
        return Err(violation(
            0,
            format!(
                "the tree has {:?} (splitting, single-axis carving, dual-axis carving, \
                 leaves, carving leaves, index entries, node bytes, index bytes, total \
                 bytes); its header says {:?}",
                counts(&found),
                counts(stats)
            ),
        ));
    }
    Ok(())
}

/// The parts of an image the checks read: the node and index words, their regions, and the
/// number of triangles.
pub(crate) struct Regions<'a> {
    /// The node and index regions' words.
    pub words: &'a [u32],
    /// Word range of the node region.
    pub nodes: Range<usize>,
    /// Word range of the index region.
    pub indices: Range<usize>,
    /// Triangles in the triangle region.
    pub triangles: usize,
}

impl<'a> Regions<'a> {
    pub fn of(img: &'a MemoryImage) -> Self {
        Regions {
            words: &img.words,
            nodes: img.nodes.clone(),
            indices: img.indices.clone(),
            triangles: img.triangle_slice().len(),
        }
    }
}

/// Checks the regions of `tree`, whose header has `extra`: the BVH and DST walks here, the
/// compressed BVH8's and the quantized DST's own walks (their modules' `check_structure`).
pub(crate) fn check(tree: &AnyTree, extra: &Extra) -> Result<(), Violation> {
    let img = &Regions::of(tree.image());
    let kind = tree.kind();
    if img.nodes.end > img.words.len() || img.indices.end > img.words.len() {
        return Err(violation(
            0,
            format!(
                "regions {:?} and {:?} beyond the {} words",
                img.nodes,
                img.indices,
                img.words.len()
            ),
        ));
    }
    match *extra {
        Extra::Bvh {
            internal_nodes,
            leaves,
            ..
        } => match kind {
            TreeKind::Bvh2 => check_bvh::<crate::bvh2::Node2>(img, internal_nodes, leaves),
            TreeKind::Bvh4 => check_bvh::<crate::wide::Node4>(img, internal_nodes, leaves),
            _ => check_bvh::<crate::wide::Node8>(img, internal_nodes, leaves),
        },
        Extra::Dst { ref stats, .. } => check_dst(img, stats),
        Extra::Cwbvh {
            internal_nodes,
            leaves,
        } => match tree {
            AnyTree::Cwbvh(c) => counts(
                crate::cwbvh::check_structure(c.cwbvh().image()),
                internal_nodes,
                leaves,
            ),
            _ => Err(kind_mismatch(kind)),
        },
        Extra::DstQ { .. } => match tree {
            AnyTree::DstQ(q) => q
                .dstq()
                .check_structure()
                .map_err(|(word, what)| violation(word, what)),
            _ => Err(kind_mismatch(kind)),
        },
    }
}

/// A header whose fields are another kind's than the tree it describes (never made by
/// the loader, which builds the tree from the header).
fn kind_mismatch(kind: TreeKind) -> Violation {
    violation(0, format!("the header's fields are not a {kind}'s"))
}

/// A structure check's result (internal nodes and leaves reached, or the faulty word and
/// what is wrong there) against the counts the header records.
fn counts(
    walked: Result<(u64, u64), (usize, String)>,
    internal_nodes: u64,
    leaves: u64,
) -> Result<(), Violation> {
    let (n, l) = walked.map_err(|(word, what)| violation(word, what))?;
    if (n, l) != (internal_nodes, leaves) {
        return Err(violation(
            0,
            format!(
                "the walk reaches {n} internal nodes and {l} leaves; the header records {internal_nodes} and {leaves}"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_header_mask_is_decode() {
        assert_eq!(VALID_HEADERS.count_ones(), 37);
        for h in 0..64u32 {
            let word = h << 26;
            assert_eq!(
                (VALID_HEADERS >> h) & 1 == 1,
                HeaderOffset::decode(word, 0).is_ok(),
                "header {h:06b}"
            );
        }
    }
}
