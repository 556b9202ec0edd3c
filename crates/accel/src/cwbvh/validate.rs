//! Walking a compressed-BVH8 image: the structural check ([`walk`]), the exact subtree
//! bounds it recomputes from the triangles, and the decoding of the image back into a
//! [`WideBvh`] of decoded boxes ([`decode_wide`]) for the CPU-side copy.

use super::encode::NAME;
use super::node::{CwNode, EMPTY_Q, Meta, NODE_WORDS};
use crate::image::{MemoryImage, RUN_END};
use crate::validate::{MAX_MESSAGES, ValidationReport};
use crate::wide::{WideBvh, WideChild, WideNode};
use dualsplit_geometry::Aabb;

/// What a child slot of a walked node refers to.
#[derive(Clone, Copy, Debug)]
enum ChildRef {
    /// An internal node, by its walk index (`None`: not followed, already reported).
    Node(Option<usize>),
    /// A leaf, with the exact bounds of its triangles.
    Leaf(Aabb),
}

/// A node still to be walked.
struct Pending {
    /// Its word.
    at: usize,
    /// Its depth (root 0).
    depth: usize,
    /// Its parent's walk index and the slot's position among the parent's children.
    parent: Option<(usize, usize)>,
}

/// A reached non-empty slot: its decoded box, the exact bounds of the triangles below it,
/// and the exact bounds of its node (the union over the node's slots).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SlotBounds {
    pub(crate) decoded: Aabb,
    pub(crate) exact: Aabb,
    pub(crate) node: Aabb,
}

/// What [`walk`] found: the report and every reached slot's bounds.
pub(crate) struct Walk {
    pub(crate) report: ValidationReport,
    pub(crate) slots: Vec<SlotBounds>,
}

/// Counts a violation and keeps its message (up to [`MAX_MESSAGES`]).
fn error(rep: &mut ValidationReport, msg: String) {
    rep.error_count += 1;
    if rep.errors.len() < MAX_MESSAGES {
        rep.errors.push(msg);
    }
}

/// True when the decoded box `d` holds `x` on every axis, a NaN plane of `d` counting as
/// unbounded (the slab test ignores it).
pub(crate) fn holds(d: &Aabb, x: &Aabb) -> bool {
    (0..3).all(|a| {
        (d.min[a].is_nan() || d.min[a] <= x.min[a]) && (d.max[a].is_nan() || x.max[a] <= d.max[a])
    })
}

/// Checks a compressed-BVH8 image: every node-region word belongs to exactly one node
/// reached from the root (nodes reached once, nothing overlapping, child blocks inside the
/// node region), every index-region word to exactly one leaf run, every triangle is
/// referenced exactly once; exponents are 1..=254; meta bytes are well formed (internal
/// `0b001_00000 | (24 + k)` exactly where `imask` says, leaf counts `min(n, 3)` matching
/// their runs, empty slots `0x00` with [`EMPTY_Q`]); and every decoded child box contains
/// the exact bounds of its subtree's triangles, recomputed bottom-up.
///
/// Any words give a report, never a panic or an endless walk (a node or run reached twice
/// is reported and not followed).
pub(crate) fn walk(img: &MemoryImage) -> Walk {
    let mut rep = ValidationReport {
        structure: NAME,
        triangles: img.triangle_slice().len(),
        ..Default::default()
    };
    let mut slots = Vec::new();
    let words = &img.words;
    let tris = img.triangle_slice();
    if img.nodes.start != 0 || img.nodes.len() < NODE_WORDS || img.indices.end > words.len() {
        error(
            &mut rep,
            format!(
                "node region {:?} too small for a root or regions {:?}, {:?} outside the {} words",
                img.nodes,
                img.nodes,
                img.indices,
                words.len()
            ),
        );
        return Walk { report: rep, slots };
    }
    let mut node_cover = vec![0u8; img.nodes.len()];
    let mut index_cover = vec![0u8; img.indices.len()];
    let mut tri_refs = vec![0u32; tris.len()];
    let cover = |rep: &mut ValidationReport, cover: &mut [u8], r: std::ops::Range<usize>| {
        let mut fresh = true;
        for w in r {
            cover[w] = cover[w].saturating_add(1);
            if cover[w] == 2 {
                error(rep, format!("word {w} reached twice"));
            }
            fresh &= cover[w] == 1;
        }
        fresh
    };
    // Walked nodes, preorder: per non-empty slot, its decoded box and what it refers to.
    let mut recs: Vec<Vec<(Aabb, ChildRef)>> = Vec::new();
    let mut stack = vec![Pending {
        at: 0,
        depth: 0,
        parent: None,
    }];
    while let Some(Pending { at, depth, parent }) = stack.pop() {
        if at < img.nodes.start || at.saturating_add(NODE_WORDS) > img.nodes.end {
            error(
                &mut rep,
                format!("node at word {at} outside the node region {:?}", img.nodes),
            );
            continue;
        }
        if !cover(&mut rep, &mut node_cover, at..at + NODE_WORDS) {
            continue;
        }
        let idx = recs.len();
        if let Some((pi, pos)) = parent {
            recs[pi][pos].1 = ChildRef::Node(Some(idx));
        }
        rep.internal_nodes += 1;
        rep.max_depth = rep.max_depth.max(depth);
        let node = *CwNode::read(words, at);
        for (a, &e) in node.e.iter().enumerate() {
            if !(1..=254).contains(&e) {
                error(
                    &mut rep,
                    format!("node at word {at}: axis {a} exponent {e} not in 1..=254"),
                );
            }
        }
        let n_internal = node.imask.count_ones() as usize;
        let base = node.child_base as usize;
        let block_ok = n_internal == 0
            || (base >= img.nodes.start && base + n_internal * NODE_WORDS <= img.nodes.end);
        if !block_ok {
            error(
                &mut rep,
                format!(
                    "node at word {at}: child block {base}..{} outside the node region {:?}",
                    base + n_internal * NODE_WORDS,
                    img.nodes
                ),
            );
        }
        let mut children = Vec::new();
        for k in 0..8 {
            let meta = node.meta[k];
            let slot = node.slot(k);
            if slot == Meta::Empty {
                let empty_q = (0..3).all(|a| (node.q_lo[a][k], node.q_hi[a][k]) == EMPTY_Q);
                if !empty_q {
                    error(
                        &mut rep,
                        format!("node at word {at}: empty slot {k} has quantized bounds"),
                    );
                }
                continue;
            }
            let decoded = node.child_bounds(k);
            match slot {
                Meta::Internal => {
                    if meta != Meta::Internal.byte(k) {
                        error(
                            &mut rep,
                            format!(
                                "node at word {at}: internal slot {k} has meta byte {meta:#04x}"
                            ),
                        );
                    }
                    children.push((decoded, ChildRef::Node(None)));
                    if block_ok {
                        stack.push(Pending {
                            at: node.child_node(k) as usize,
                            depth: depth + 1,
                            parent: Some((idx, children.len() - 1)),
                        });
                    }
                }
                Meta::Leaf { offset, count_hint } => {
                    rep.leaves += 1;
                    if ![0b001, 0b011, 0b111].contains(&(meta >> 5)) {
                        error(
                            &mut rep,
                            format!("node at word {at}: leaf slot {k} has meta byte {meta:#04x}"),
                        );
                    }
                    let run = node.leaf_run(offset) as usize;
                    let mut exact = Aabb::EMPTY;
                    let mut len = 0u32;
                    let mut j = run;
                    loop {
                        if !img.indices.contains(&j) {
                            error(
                                &mut rep,
                                format!(
                                    "node at word {at}: slot {k}'s run from {run} leaves the index region {:?}",
                                    img.indices
                                ),
                            );
                            break;
                        }
                        let i = j - img.indices.start;
                        if !cover(&mut rep, &mut index_cover, i..i + 1) {
                            break;
                        }
                        len += 1;
                        let p = (words[j] & !RUN_END) as usize;
                        if p >= tri_refs.len() {
                            error(
                                &mut rep,
                                format!("index word {j}: triangle {p} out of range"),
                            );
                        } else {
                            tri_refs[p] += 1;
                            exact = exact.union(tris[p].bounds());
                        }
                        if words[j] & RUN_END != 0 {
                            if len.min(3) != count_hint {
                                error(
                                    &mut rep,
                                    format!(
                                        "node at word {at}: leaf slot {k} says {count_hint} triangles (at most 3), its run holds {len}"
                                    ),
                                );
                            }
                            break;
                        }
                        j += 1;
                    }
                    children.push((decoded, ChildRef::Leaf(exact)));
                }
                Meta::Empty => unreachable!(),
            }
        }
        recs.push(children);
    }
    // Exact bounds bottom-up (a child's walk index is larger than its parent's).
    let mut exact = vec![Aabb::EMPTY; recs.len()];
    for idx in (0..recs.len()).rev() {
        let xs: Vec<(Aabb, Aabb)> = recs[idx]
            .iter()
            .map(|&(decoded, child)| {
                let x = match child {
                    ChildRef::Node(Some(c)) => exact[c],
                    ChildRef::Node(None) => Aabb::EMPTY,
                    ChildRef::Leaf(x) => x,
                };
                (decoded, x)
            })
            .collect();
        let b = xs.iter().fold(Aabb::EMPTY, |b, &(_, x)| b.union(x));
        for &(decoded, x) in &xs {
            if x == Aabb::EMPTY {
                continue;
            }
            if !holds(&decoded, &x) {
                error(
                    &mut rep,
                    format!(
                        "node {idx} (walk order): decoded child box {decoded:?} does not contain its subtree's bounds {x:?}"
                    ),
                );
            }
            slots.push(SlotBounds {
                decoded,
                exact: x,
                node: b,
            });
        }
        exact[idx] = b;
    }
    let unreached = node_cover.iter().filter(|&&c| c == 0).count();
    if unreached > 0 {
        error(
            &mut rep,
            format!("{unreached} node-region words not reached from the root"),
        );
    }
    let unused = index_cover.iter().filter(|&&c| c == 0).count();
    if unused > 0 {
        error(
            &mut rep,
            format!("{unused} index-region words in no leaf run"),
        );
    }
    rep.triangles_referenced = tri_refs.iter().filter(|&&c| c > 0).count();
    for (p, &c) in tri_refs.iter().enumerate() {
        if c != 1 {
            error(&mut rep, format!("triangle {p} referenced {c} times"));
        }
    }
    Walk { report: rep, slots }
}

/// The tree of a valid image as a [`WideBvh`] of arity 8 with the decoded child boxes, and
/// the `prim_ids` its leaves index (the runs' ids, in the order met).
pub(crate) fn decode_wide(img: &MemoryImage) -> (WideBvh, Vec<u32>) {
    let words = &img.words;
    let mut wide = WideBvh {
        arity: 8,
        nodes: vec![WideNode::default()],
    };
    let mut prim_ids = Vec::new();
    let mut todo = vec![(0usize, 0usize)];
    while let Some((at, idx)) = todo.pop() {
        let node = CwNode::read(words, at);
        let mut children = Vec::new();
        for k in 0..8 {
            let child = match node.slot(k) {
                Meta::Empty => continue,
                Meta::Internal => {
                    let c = wide.nodes.len();
                    wide.nodes.push(WideNode::default());
                    todo.push((node.child_node(k) as usize, c));
                    WideChild::Node(c as u32)
                }
                Meta::Leaf { offset, .. } => {
                    let first = prim_ids.len() as u32;
                    let mut j = node.leaf_run(offset) as usize;
                    loop {
                        prim_ids.push(words[j] & !RUN_END);
                        if words[j] & RUN_END != 0 {
                            break;
                        }
                        j += 1;
                    }
                    WideChild::Leaf {
                        first,
                        count: prim_ids.len() as u32 - first,
                    }
                }
            };
            children.push((node.child_bounds(k), child));
        }
        wide.nodes[idx].children = children;
    }
    (wide, prim_ids)
}
