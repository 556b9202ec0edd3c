//! Copying a BVH image into the CPU-side nodes and triangle packets.

use super::lanes::Lanes;
use super::layout::{EMPTY, EMPTY_PACKET, LANES, LEAF, TriPacket};
use super::merge::gather;
use super::order::order_lanes;
use crate::image::{ChildKind, MemoryImage, NodeLayout, RUN_END};
use dualsplit_geometry::Triangle;

/// What [`copy`] makes: nodes and packets.
pub(super) struct Copied<N> {
    pub(super) nodes: Vec<N>,
    pub(super) packets: Vec<TriPacket>,
    /// The deepest node's depth (the root's is 0).
    pub(super) depth: usize,
}

/// Copies the image of node layout `L` into nodes of type `N` (`N::W >= L::ARITY`), each
/// internal child whose subtree holds at most `merge` triangles as one leaf, then puts
/// each node's children in the order of [`order_lanes`].
pub(super) fn copy<L: NodeLayout, N: Lanes>(img: &MemoryImage, merge: usize) -> Copied<N> {
    let words = &img.words[..];
    let triangles = img.triangle_slice();
    let mut out = Copied {
        nodes: vec![N::EMPTY],
        packets: Vec::new(),
        depth: 0,
    };
    // (image word of a node, node index it is copied to, its depth)
    let mut todo: Vec<(usize, usize, usize)> = vec![(0, 0, 0)];
    // Triangle slots used (4 per packet).
    let mut slots = 0usize;
    while let Some((w, at, depth)) = todo.pop() {
        out.depth = out.depth.max(depth);
        let node = L::read(words, w);
        let mut addr = node.offset() as usize;
        let mut lane = 0;
        let mut internal = Vec::new();
        for k in 0..L::ARITY {
            let kind = node.kind(k);
            if kind == ChildKind::Empty {
                continue;
            }
            // A leaf's entries; an internal child whose subtree holds few triangles becomes
            // one leaf of them.
            let entries = match kind {
                ChildKind::Leaf => {
                    let run = words[addr] as usize;
                    let len = words[run..]
                        .iter()
                        .position(|&e| e & RUN_END != 0)
                        .map_or(0, |p| p + 1);
                    Some(words[run..run + len].to_vec())
                }
                _ if merge == 0 => None,
                _ => gather::<L>(words, addr, merge),
            };
            let child = match entries {
                // A subtree without triangles (only a forged saved tree has one) holds
                // nothing to hit.
                Some(e) if e.is_empty() => EMPTY,
                Some(e) => {
                    // A leaf that would span one packet more than its size needs starts
                    // at the next packet's first lane (the lanes skipped stay padding):
                    // each packet a leaf spans is a test of four lanes and up to three
                    // cache lines (`docs/cpu-traversal.md`, Experiments).
                    let lane = slots % LANES;
                    if (lane + e.len()).div_ceil(LANES) > e.len().div_ceil(LANES) {
                        slots += LANES - lane;
                    }
                    let first = slots as u32;
                    assert!(first < LEAF, "too many triangle references");
                    pack_entries(&mut out.packets, &mut slots, e, triangles);
                    LEAF | first
                }
                None => {
                    internal.push((addr, lane));
                    EMPTY
                }
            };
            out.nodes[at].set(lane, *node.box_words(k), child);
            addr += L::child_words(kind) as usize;
            lane += 1;
        }
        // Children of one node next to one another, then their subtrees depth-first.
        let mut subtrees = Vec::with_capacity(internal.len());
        for (cw, l) in internal {
            let idx = out.nodes.len();
            out.nodes.push(N::EMPTY);
            out.nodes[at].set_child(l, idx as u32);
            subtrees.push((cw, idx, depth + 1));
        }
        todo.extend(subtrees.into_iter().rev());
    }
    // Empty lanes name the sentinel: a last packet of padding lanes, a leaf of one triangle
    // that no ray hits (see `Lanes::EMPTY`).
    out.packets.push(EMPTY_PACKET);
    let sentinel = LEAF | (LANES * (out.packets.len() - 1)) as u32;
    for n in &mut out.nodes {
        for l in 0..N::W {
            if n.child(l) == EMPTY {
                n.set_child(l, sentinel);
            }
        }
    }
    order_lanes(&mut out.nodes, &out.packets);
    out
}

/// Appends the triangles of the index-run entries `entries` (ids with [`RUN_END`] on each
/// run's last) to `packets`, slot after slot from `*slots`, padding nothing: the caller
/// pads the last packet by starting from [`EMPTY_PACKET`]s.
pub(crate) fn pack_entries(
    packets: &mut Vec<TriPacket>,
    slots: &mut usize,
    entries: impl IntoIterator<Item = u32>,
    triangles: &[Triangle],
) {
    for e in entries {
        if *slots & (LANES - 1) == 0 {
            packets.push(EMPTY_PACKET);
        }
        let pk = packets.last_mut().expect("pushed");
        let tri = &triangles[(e & !RUN_END) as usize];
        let l = *slots % LANES;
        for (r, row) in pk.v.iter_mut().enumerate() {
            row[l] = tri.v[r / 3][r % 3];
        }
        pk.prim[l] = e;
        *slots += 1;
    }
}
