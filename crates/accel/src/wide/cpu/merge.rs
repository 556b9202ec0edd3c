//! Leaf merging: a subtree of at most [`MERGE_MAX`] triangles becomes one leaf of the copy.

use crate::image::{ChildKind, NodeLayout, RUN_END};

/// The most triangles of a subtree that the copy turns into one leaf (four packets).
///
/// The paper's BVH2 has small leaves (1.8 triangles on average on dragon_box, SAH with equal
/// node and triangle costs), and each leaf visit is a cache miss on its packet; testing up
/// to 16 triangles four at a time is cheaper than descending two more node levels. Chosen
/// by measurement (docs/performance.md, "Leaf merging": 0, 4, 8, 12, 16, 24 and 32 on
/// dragon_box and sponza_dabrovic); answers do not depend on it.
pub const MERGE_MAX: usize = 16;

/// The index entries of the leaves of the subtree whose node is at image word `w` (a node's
/// leaves, then its internal children's subtrees in child order), [`RUN_END`] on the last
/// one only; `None` when there are more
/// than `limit`. Iterative: a saved tree may hold long chains of nodes.
pub(super) fn gather<L: NodeLayout>(words: &[u32], w: usize, limit: usize) -> Option<Vec<u32>> {
    let mut out = Vec::new();
    let mut todo = vec![w];
    while let Some(w) = todo.pop() {
        let node = L::read(words, w);
        let mut addr = node.offset() as usize;
        let mut inner = Vec::new();
        for k in 0..L::ARITY {
            let kind = node.kind(k);
            match kind {
                ChildKind::Empty => continue,
                ChildKind::Leaf => {
                    let run = words[addr] as usize;
                    for &e in &words[run..] {
                        out.push(e & !RUN_END);
                        if e & RUN_END != 0 || out.len() > limit {
                            break;
                        }
                    }
                }
                ChildKind::Internal => inner.push(addr),
            }
            if out.len() > limit {
                return None;
            }
            addr += L::child_words(kind) as usize;
        }
        todo.extend(inner.into_iter().rev());
    }
    if let Some(last) = out.last_mut() {
        *last |= RUN_END;
    }
    Some(out)
}
