//! Structural checks of BVH memory images: `dualsplit check` prints the report, tests assert
//! it is clean.

use crate::image::{ChildKind, MemoryImage, NodeLayout, RUN_END};
use dualsplit_geometry::Aabb;
use serde::Serialize;

/// At most this many error messages are kept (the count is always exact).
pub const MAX_MESSAGES: usize = 20;

/// What [`validate_image`] found.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ValidationReport {
    /// Structure name (its command-line name).
    pub structure: &'static str,
    /// Internal nodes reached from the root.
    pub internal_nodes: usize,
    /// Leaves reached.
    pub leaves: usize,
    /// Distinct triangles referenced by leaves.
    pub triangles_referenced: usize,
    /// Triangles in the image.
    pub triangles: usize,
    /// Deepest internal node (root = 0): the traversal-stack bound is `max_depth · (arity-1)`.
    pub max_depth: usize,
    /// Number of violations found.
    pub error_count: usize,
    /// The first [`MAX_MESSAGES`] violations, described.
    pub errors: Vec<String>,
}

impl ValidationReport {
    /// True when the report holds no violation.
    pub fn is_ok(&self) -> bool {
        self.error_count == 0
    }

    pub(crate) fn error(&mut self, msg: String) {
        self.error_count += 1;
        if self.errors.len() < MAX_MESSAGES {
            self.errors.push(msg);
        }
    }
}

/// Checks an image with node layout `L`: every node-region word belongs to exactly one node
/// or leaf word reached from the root (so every node is reachable exactly once and nothing
/// overlaps), every child block and index run lies inside its region, every index-region
/// entry belongs to exactly one run, every triangle is referenced exactly once, every child
/// box holds its node's child boxes or its leaf's triangles (bit-exact), empty slots hold the
/// degenerate box.
///
/// Any words give a report, never a panic or an endless walk: a node, leaf word or index
/// word reached a second time (a cycle, shared children, overlapping runs) is reported and
/// not followed again, so the walk takes time linear in the image. Loading a saved tree
/// runs the narrower check of what traversal relies on (`saved::structure`) instead.
pub fn validate_image<L: NodeLayout>(img: &MemoryImage) -> ValidationReport {
    let mut rep = ValidationReport {
        structure: L::NAME,
        triangles: img.triangle_slice().len(),
        ..Default::default()
    };
    let words = &img.words;
    let mut node_cover = vec![0u8; img.nodes.len()];
    let mut index_cover = vec![0u8; img.indices.len()];
    let mut tri_refs = vec![0u32; rep.triangles];
    let tris = img.triangle_slice();
    if img.nodes.len() < L::WORDS || img.nodes.start != 0 {
        rep.error(format!("node region {:?} too small for a root", img.nodes));
        return rep;
    }
    // Marks the words of `r` reached; false (and an error) when one already was. A node or
    // run reached twice is not followed again, so a forged image with a cycle or shared
    // children cannot make the walk loop or repeat itself: it stays linear.
    let cover = |rep: &mut ValidationReport, cover: &mut [u8], r: std::ops::Range<usize>| {
        let mut fresh = true;
        for w in r {
            cover[w] = cover[w].saturating_add(1);
            if cover[w] == 2 {
                rep.error(format!("word {w} reached twice"));
            }
            fresh &= cover[w] == 1;
        }
        fresh
    };
    // (node word, depth, bounds the node's children must lie in)
    let mut stack: Vec<(usize, usize, Option<Aabb>)> = vec![(0, 0, None)];
    while let Some((at, depth, parent)) = stack.pop() {
        if !cover(&mut rep, &mut node_cover, at..at + L::WORDS) {
            continue;
        }
        rep.internal_nodes += 1;
        rep.max_depth = rep.max_depth.max(depth);
        let node = *L::read(words, at);
        let mut addr = node.offset() as usize;
        let block_len: usize = (0..L::ARITY)
            .map(|k| L::child_words(node.kind(k)) as usize)
            .sum();
        if block_len > 0
            && (addr < img.nodes.start || addr.saturating_add(block_len) > img.nodes.end)
        {
            rep.error(format!(
                "node at word {at}: child block {addr}..{} outside the node region {:?}",
                addr.saturating_add(block_len),
                img.nodes
            ));
            continue;
        }
        for k in 0..L::ARITY {
            let kind = node.kind(k);
            let b = node.child_bounds(k);
            if kind == ChildKind::Empty {
                if b != Aabb::DEGENERATE {
                    rep.error(format!("node at word {at}: empty slot {k} has box {b:?}"));
                }
                continue;
            }
            if let Some(p) = parent.filter(|p| !p.contains_box(&b)) {
                rep.error(format!(
                    "node at word {at}: slot {k} box {b:?} not inside the parent's {p:?}"
                ));
            }
            match kind {
                ChildKind::Internal => stack.push((addr, depth + 1, Some(b))),
                ChildKind::Leaf => {
                    rep.leaves += 1;
                    if !cover(&mut rep, &mut node_cover, addr..addr + 1) {
                        addr += 1;
                        continue;
                    }
                    let run = words[addr] as usize;
                    let mut j = run;
                    loop {
                        if !img.indices.contains(&j) {
                            rep.error(format!(
                                "leaf word {addr}: run from {run} leaves the index region {:?}",
                                img.indices
                            ));
                            break;
                        }
                        if !cover(
                            &mut rep,
                            &mut index_cover,
                            j - img.indices.start..j - img.indices.start + 1,
                        ) {
                            break;
                        }
                        let p = (words[j] & !RUN_END) as usize;
                        if p >= tri_refs.len() {
                            rep.error(format!("index word {j}: triangle {p} out of range"));
                        } else {
                            tri_refs[p] += 1;
                            if !b.contains_box(&tris[p].bounds()) {
                                rep.error(format!(
                                    "leaf word {addr}: triangle {p} outside the leaf box {b:?}"
                                ));
                            }
                        }
                        if words[j] & RUN_END != 0 {
                            break;
                        }
                        j += 1;
                    }
                }
                ChildKind::Empty => unreachable!(),
            }
            addr += L::child_words(kind) as usize;
        }
    }
    let unreached = node_cover.iter().filter(|&&c| c == 0).count();
    if unreached > 0 {
        rep.error(format!(
            "{unreached} node-region words not reached from the root"
        ));
    }
    let unused = index_cover.iter().filter(|&&c| c == 0).count();
    if unused > 0 {
        rep.error(format!("{unused} index-region words in no leaf run"));
    }
    rep.triangles_referenced = tri_refs.iter().filter(|&&c| c > 0).count();
    for (p, &c) in tri_refs.iter().enumerate() {
        if c != 1 {
            rep.error(format!("triangle {p} referenced {c} times"));
        }
    }
    rep
}
