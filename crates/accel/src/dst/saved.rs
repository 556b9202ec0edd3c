//! The check on load of a saved DST (`docs/tree-format.md`, "Checks on load"): one walk
//! from the root that replays the encoder's bump allocation (`encode.rs`: a node's children
//! go at the next free node word when the node is emitted, a leaf's run at the next free
//! index word), so every node is reached once, inside its region, with a valid header.

use super::{DstStats, HeaderOffset};
use crate::observer::DstNodeKind;
use crate::saved::{Regions, Runs, Violation, violation};

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
pub(super) fn check_dst(img: &Regions, stats: &DstStats) -> Result<(), Violation> {
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
