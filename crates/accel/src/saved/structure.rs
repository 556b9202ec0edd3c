//! Structural checks of a loaded image: everything a traversal indexes with, so that a file
//! forged with a recomputed checksum gives a [`Violation`] instead of a panic, a hang or a
//! read of the wrong memory (`docs/tree-format.md`, "Checks on load").
//!
//! Both checks walk the tree once from its root with a bitmap of the node words already
//! reached, so every node is reached exactly once: no cycle, no shared subtree (which could
//! make one ray's traversal exponential), linear time. Every node and child block must lie
//! inside the node region, every leaf's run must start inside the index region, and runs
//! must not overlap (each index word belongs to at most one run, so the runs' total length
//! is bounded by the region). The index region's entries are all triangle ids below the
//! triangle count, and its last entry ends a run ([`RUN_END`]), so every run that starts in
//! the region ends in it. The counts the header records are checked against the walk's.
//!
//! What is not checked: box and plane values (a NaN or a box that does not hold its
//! children costs a traversal wrong answers for that file, never memory safety or
//! termination), and whether every triangle is referenced (`dualsplit check` reports both).

use super::header::Extra;
use crate::dst::{DstStats, HeaderOffset};
use crate::image::{ChildKind, MemoryImage, NodeLayout, RUN_END};
use crate::observer::DstNodeKind;
use crate::tree::TreeKind;
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

/// One bit per word of a region.
struct Bitmap(Vec<u64>);

impl Bitmap {
    fn new(len: usize) -> Self {
        Bitmap(vec![0; len.div_ceil(64)])
    }
    /// Sets bit `i`; returns whether it was already set.
    #[inline(always)]
    fn set(&mut self, i: usize) -> bool {
        let (w, b) = (i / 64, 1u64 << (i % 64));
        let was = self.0[w] & b != 0;
        self.0[w] |= b;
        was
    }
}

/// Checks the index region: every entry a triangle id below the triangle count, the last
/// one ending a run.
fn check_indices(img: &Regions) -> Result<(), Violation> {
    let tris = img.triangles;
    let words = &img.words[img.indices.clone()];
    for (j, &e) in words.iter().enumerate() {
        let p = (e & !RUN_END) as usize;
        if p >= tris {
            return Err(violation(
                img.indices.start + j,
                format!("index entry names triangle {p}, the file has {tris}"),
            ));
        }
    }
    if let Some(&last) = words.last()
        && last & RUN_END == 0
    {
        return Err(violation(
            img.indices.end - 1,
            "the last index entry does not end a run (no RUN_END bit)".into(),
        ));
    }
    Ok(())
}

/// The runs of an image: each index word in at most one run.
struct Runs<'a> {
    img: &'a Regions<'a>,
    used: Bitmap,
}

impl<'a> Runs<'a> {
    fn new(img: &'a Regions<'a>) -> Self {
        Runs {
            img,
            used: Bitmap::new(img.indices.len()),
        }
    }

    /// Claims the run starting at image word `start` for the leaf at node word `leaf`;
    /// returns its length. [`check_indices`] has run, so a run that starts in the region
    /// ends in it.
    fn claim(&mut self, leaf: usize, start: usize) -> Result<usize, Violation> {
        let r = &self.img.indices;
        if !r.contains(&start) {
            return Err(violation(
                leaf,
                format!("leaf's index run starts at word {start}, outside the index region {r:?}"),
            ));
        }
        let mut j = start;
        loop {
            if self.used.set(j - r.start) {
                return Err(violation(
                    leaf,
                    format!("leaf's index run reaches word {j}, which another run holds"),
                ));
            }
            if self.img.words[j] & RUN_END != 0 {
                return Ok(j + 1 - start);
            }
            j += 1;
        }
    }
}

/// Checks a BVH image with node layout `L` and the counts its header records.
fn check_bvh<L: NodeLayout>(
    img: &Regions,
    internal_nodes: u64,
    leaves: u64,
) -> Result<(), Violation> {
    check_indices(img)?;
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
    let mut reached = Bitmap::new(nodes.end);
    let mut runs = Runs::new(img);
    let (mut n_internal, mut n_leaves) = (0u64, 0u64);
    reached.set(0);
    let mut stack = vec![0usize];
    while let Some(at) = stack.pop() {
        n_internal += 1;
        let node = L::read(words, at);
        let block_len: usize = (0..L::ARITY)
            .map(|k| L::child_words(node.kind(k)) as usize)
            .sum();
        let start = node.offset() as usize;
        if block_len > 0 && start.saturating_add(block_len) > nodes.end {
            return Err(violation(
                at,
                format!(
                    "node's child block {start}..{} leaves the node region {nodes:?}",
                    start.saturating_add(block_len)
                ),
            ));
        }
        let mut addr = start;
        // Internal children, pushed after the loop in reverse so that slot 0 is walked
        // first: the walk then follows the depth-first layout forward.
        const { assert!(L::ARITY <= 8) };
        let mut inner = [0usize; 8];
        let mut n_inner = 0;
        for k in 0..L::ARITY {
            let kind = node.kind(k);
            if kind == ChildKind::Empty {
                continue;
            }
            if reached.set(addr) {
                return Err(violation(
                    at,
                    format!(
                        "node's slot {k} child at word {addr} is reached twice (a cycle or a shared child)"
                    ),
                ));
            }
            match kind {
                ChildKind::Internal => {
                    inner[n_inner] = addr;
                    n_inner += 1;
                }
                ChildKind::Leaf => {
                    n_leaves += 1;
                    runs.claim(addr, words[addr] as usize)?;
                }
                ChildKind::Empty => {}
            }
            addr += L::child_words(kind) as usize;
        }
        stack.extend(inner[..n_inner].iter().rev());
    }
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
    check_indices(img)?;
    let nodes = img.nodes.clone();
    let words = img.words;
    let mut found = DstStats::default();
    let mut runs = Runs::new(img);
    let mut reached = Bitmap::new(nodes.end);
    // (node word, the size its parent gave it: a splitting node's left size, else 0)
    let mut stack: Vec<(usize, u32)> = Vec::new();
    if !nodes.is_empty() {
        if nodes.start != 0 {
            return Err(violation(0, format!("node region {nodes:?} not at word 0")));
        }
        reached.set(0);
        stack.push((0, 0));
    }
    let mut child = |stack: &mut Vec<(usize, u32)>, at: usize, c: u32, size: u32| {
        let c = c as usize;
        if c >= nodes.end {
            return Err(violation(
                at,
                format!("child at word {c} outside the node region {nodes:?}"),
            ));
        }
        if reached.set(c) {
            return Err(violation(
                at,
                format!("child at word {c} is reached twice (a cycle or a shared child)"),
            ));
        }
        stack.push((c, size));
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
        if at + len as usize > nodes.end {
            return Err(violation(
                at,
                format!("{len}-word node leaves the node region {nodes:?}"),
            ));
        }
        if size != 0 && size != len {
            return Err(violation(
                at,
                format!("{len}-word left child, its splitting node says {size} words"),
            ));
        }
        let run = |runs: &mut Runs, found: &mut DstStats| -> Result<(), Violation> {
            let start = img.indices.start.saturating_add(w.offset() as usize);
            found.index_entries += runs.claim(at, start)? as u64;
            Ok(())
        };
        match w.node_kind() {
            DstNodeKind::Leaf => {
                found.leaves += 1;
                run(&mut runs, &mut found)?;
            }
            DstNodeKind::Split => {
                found.splitting += 1;
                let (left, ls) = (w.offset(), w.left_size());
                // Right first on the stack: the left subtree is walked first.
                child(&mut stack, at, left + ls, 0)?;
                child(&mut stack, at, left, ls)?;
            }
            kind => {
                if kind == DstNodeKind::SingleCarve {
                    found.single_carving += 1;
                } else {
                    found.dual_carving += 1;
                }
                if w.is_leaf_flag() {
                    found.carving_leaves += 1;
                    run(&mut runs, &mut found)?;
                } else {
                    child(&mut stack, at, w.offset(), 0)?;
                }
            }
        }
    }
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
                "the tree has {} splitting, {} single-axis and {} dual-axis carving nodes, \
                 {} leaves, {} carving leaves, {} index entries, {} node and {} index bytes \
                 ({} in all); its header says {}, {}, {}, {}, {}, {}, {}, {} ({})",
                found.splitting,
                found.single_carving,
                found.dual_carving,
                found.leaves,
                found.carving_leaves,
                found.index_entries,
                found.node_bytes,
                found.index_bytes,
                found.total_bytes,
                stats.splitting,
                stats.single_carving,
                stats.dual_carving,
                stats.leaves,
                stats.carving_leaves,
                stats.index_entries,
                stats.node_bytes,
                stats.index_bytes,
                stats.total_bytes
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

/// Checks the regions of a tree of `kind` whose header has `extra`.
pub(crate) fn check(img: &Regions, kind: TreeKind, extra: &Extra) -> Result<(), Violation> {
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
    }
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
