//! Structural checks of a loaded image: everything a traversal indexes with, so that a file
//! forged with a recomputed checksum gives a [`Violation`] instead of a panic, a hang or a
//! read of the wrong memory (`docs/tree-format.md`, "Checks on load").
//!
//! Each structure checks its own image ([`crate::structure::Structure::check_saved`]);
//! this file holds what those checks share ([`Regions`], [`Runs`], [`counts`]) and the walk
//! of an uncompressed BVH, generic over its node layout ([`check_bvh`]).
//!
//! The walks go once from the root, depth first in the encoder's order, and replay the
//! encoder's bump allocation (a node's child block goes at the next free node word when the
//! node is emitted; a leaf's run at the next free index word when the leaf is): every child offset
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

use crate::image::{ChildKind, MemoryImage, NodeLayout, RUN_END};
use std::ops::Range;

/// What is wrong with an image and where.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Violation {
    /// The image word (node region, or index region for a run entry) the fault is at.
    pub word: usize,
    /// What is wrong.
    pub what: String,
}

pub(crate) fn violation(word: usize, what: String) -> Violation {
    Violation { word, what }
}

/// The index-region side of the replayed allocation: runs must follow each other.
pub(crate) struct Runs<'a> {
    img: &'a Regions<'a>,
    /// The image word where the next run must start.
    next: usize,
}

impl<'a> Runs<'a> {
    pub(crate) fn new(img: &'a Regions<'a>) -> Self {
        Runs {
            next: img.indices.start,
            img,
        }
    }

    /// Takes the run starting at image word `start` for the leaf at node word `leaf`: it
    /// must start where the previous one ended, hold triangle ids below the triangle count
    /// and end with [`RUN_END`] inside the index region. Returns its length.
    #[inline(always)]
    pub(crate) fn take(&mut self, leaf: usize, start: usize) -> Result<usize, Violation> {
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
    pub(crate) fn finish(&self) -> Result<(), Violation> {
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
pub(crate) fn check_bvh<L: NodeLayout>(
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

/// Checks that the node and index regions of `img` lie inside its words (first, before a
/// structure's own walk indexes them).
pub(crate) fn check_regions(img: &Regions) -> Result<(), Violation> {
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
    Ok(())
}

/// A structure check's result (internal nodes and leaves reached, or the faulty word and
/// what is wrong there) against the counts the header records.
pub(crate) fn counts(
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
