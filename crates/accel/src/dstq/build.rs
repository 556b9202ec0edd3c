//! `DstQ::from_dst`: reads the exact DST's nodes with their exact regions, groups them into
//! clusters (greedy by region surface area), and packs the clusters into lines and writes each: its frame, then
//! its records with conservatively rounded planes (`docs/dstq-encoding.md`, §2–§4).

use super::frame::{Frame, quantize_down, quantize_up};
use super::layout::ROOT_BIT;
use super::record::{ChildRef, LeftRecord, QHeader, RecordFormat, write_bits};
use super::{DstQ, DstQConfig, DstQError};
use crate::dst::{Dst, DstError, HeaderOffset};
use crate::image::MemoryImage;
use crate::observer::DstNodeKind;
use dualsplit_geometry::Aabb;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

const NONE: u32 = u32::MAX;

/// One exact DST node with the exact region it is entered with (intersection of the scene
/// box and every half-space on its path).
#[derive(Clone, Copy, Debug)]
pub(super) struct ExactNode {
    /// Its header word in the exact DST.
    pub hdr: HeaderOffset,
    /// Its planes P0, P1 (0 for a plain leaf).
    pub planes: [f32; 2],
    /// The region entering it.
    pub region: Aabb,
    /// Children (node ids; [`NONE`] when absent): split left/right, or the carving child.
    pub kids: [u32; 2],
}

impl ExactNode {
    fn child_count(&self) -> usize {
        self.kids.iter().filter(|&&k| k != NONE).count()
    }
}

/// The region left of `region` by the half-space planes of `hdr` for child `side`
/// (0 = left / carving child, 1 = right), with intersection semantics.
pub(super) fn child_region(hdr: HeaderOffset, planes: [f32; 2], region: Aabb, side: usize) -> Aabb {
    let mut r = region;
    match hdr.node_kind() {
        DstNodeKind::Leaf => {}
        DstNodeKind::Split => {
            let a = hdr.axis();
            if side == 0 {
                r.max[a] = r.max[a].min(planes[0]);
            } else {
                r.min[a] = r.min[a].max(planes[1]);
            }
        }
        DstNodeKind::SingleCarve => {
            let a = hdr.axis();
            r.max[a] = r.max[a].min(planes[0]);
            r.min[a] = r.min[a].max(planes[1]);
        }
        DstNodeKind::DualCarve => {
            for (a, p, lower) in plane_roles(hdr) {
                if lower {
                    r.min[a] = r.min[a].max(planes[p]);
                } else {
                    r.max[a] = r.max[a].min(planes[p]);
                }
            }
        }
    }
    r
}

/// For each plane slot of an internal node: (axis, slot, is a lower bound "≥" plane).
/// Splitting and single-axis carving nodes: P0 upper, P1 lower; dual-axis carving: by corner.
#[inline(always)]
pub(super) fn plane_roles(hdr: HeaderOffset) -> [(usize, usize, bool); 2] {
    match hdr.node_kind() {
        DstNodeKind::DualCarve => {
            let (a0, a1) = hdr.axis_pair().axes();
            let c = hdr.corner();
            [(a0, 0, c.first_lower), (a1, 1, c.second_lower)]
        }
        _ => {
            let a = hdr.axis();
            [(a, 0, false), (a, 1, true)]
        }
    }
}

/// Reads the exact DST into nodes in depth-first preorder (node 0 = root).
pub(super) fn read_exact(dst: &Dst) -> Result<Vec<ExactNode>, DstError> {
    let img = dst.image();
    let words = &img.words;
    let n_nodes = img.nodes.len();
    let mut out: Vec<ExactNode> = Vec::new();
    if n_nodes == 0 {
        return Ok(out);
    }
    // (word, region, parent id, child slot)
    let mut stack: Vec<(u32, Aabb, u32, usize)> = vec![(0, dst.scene_box(), NONE, 0)];
    while let Some((at, region, parent, slot)) = stack.pop() {
        if at as usize >= n_nodes || out.len() > n_nodes {
            return Err(DstError::OffsetOutOfRange {
                at,
                offset: at,
                limit: n_nodes as u32,
            });
        }
        let hdr = HeaderOffset::decode(words[at as usize], at)?;
        let size = hdr.size_words() as usize;
        if at as usize + size > n_nodes {
            return Err(DstError::OffsetOutOfRange {
                at,
                offset: at + size as u32,
                limit: n_nodes as u32,
            });
        }
        let planes = if size == 3 {
            [
                f32::from_bits(words[at as usize + 1]),
                f32::from_bits(words[at as usize + 2]),
            ]
        } else {
            [0.0; 2]
        };
        let id = out.len() as u32;
        out.push(ExactNode {
            hdr,
            planes,
            region,
            kids: [NONE; 2],
        });
        if parent != NONE {
            out[parent as usize].kids[slot] = id;
        }
        match hdr.node_kind() {
            DstNodeKind::Leaf => {}
            DstNodeKind::Split => {
                let l = hdr.offset();
                let r = l + hdr.left_size();
                // Right pushed first so the left subtree comes next in preorder.
                stack.push((r, child_region(hdr, planes, region, 1), id, 1));
                stack.push((l, child_region(hdr, planes, region, 0), id, 0));
            }
            _ => {
                if !hdr.is_leaf_flag() {
                    stack.push((hdr.offset(), child_region(hdr, planes, region, 0), id, 0));
                }
            }
        }
    }
    Ok(out)
}

/// A cluster waiting to be filled: its roots (1, or a split's 2 children), its frame box and
/// its cluster id.
struct Pending {
    roots: Vec<u32>,
    frame: Aabb,
    id: u32,
}

/// A filled cluster: its frame box, its records (node, bit position) and its size in bits.
struct Cluster {
    frame: Aabb,
    placed: Vec<(u32, u32)>,
    bits: u32,
}

/// Where an expanded node's children went: this cluster (the index of the first child in
/// the cluster's record list), or a cluster id.
#[derive(Clone, Copy)]
enum Child {
    Local(u32),
    Cluster(u32),
}

/// First-fit packing of clusters into `line_words`-word lines, so that no cluster crosses
/// a line boundary: the first of the last [`OPEN_LINES`] lines with room, else a new line.
/// Returns each cluster's word address and the number of lines.
fn pack(sizes: &[u32], line_words: u32) -> (Vec<u32>, u32) {
    const OPEN_LINES: usize = 16;
    let mut open: Vec<(u32, u32)> = Vec::new(); // (line, free words)
    let mut lines = 0u32;
    let addr = sizes
        .iter()
        .map(|&s| {
            let slot = open.iter().position(|&(_, free)| free >= s);
            let i = slot.unwrap_or_else(|| {
                if open.len() == OPEN_LINES {
                    open.remove(0);
                }
                open.push((lines, line_words));
                lines += 1;
                open.len() - 1
            });
            let (line, free) = open[i];
            open[i].1 -= s;
            line * line_words + (line_words - free)
        })
        .collect();
    (addr, lines)
}

/// Bits reserved for a node's record while filling: its final size, except that an
/// internal node whose child may still go to another cluster gets the 32-bit header; it
/// shrinks to the short header once its children are placed in the same cluster.
fn reserved_bits(n: &ExactNode, k: u32) -> u32 {
    if n.hdr.is_plain_leaf() {
        32
    } else {
        32 + 2 * k
    }
}

/// A node's final record size: a plain leaf 32 bits, an internal node 32 + 2k, or
/// 7 + W + 2k when its children are in its own cluster.
fn final_bits(nodes: &[ExactNode], child_at: &[Option<Child>], n: u32, fmt: &RecordFormat) -> u32 {
    let node = &nodes[n as usize];
    if node.hdr.is_plain_leaf() {
        32
    } else if let Some(Child::Local(_)) = child_at[n as usize] {
        fmt.short_header_bits() + 2 * fmt.k
    } else {
        32 + 2 * fmt.k
    }
}

/// The B field a split writes for its left child `n`.
fn left_record(nodes: &[ExactNode], child_at: &[Option<Child>], n: u32) -> LeftRecord {
    if nodes[n as usize].hdr.is_plain_leaf() {
        LeftRecord::Leaf
    } else if let Some(Child::Local(_)) = child_at[n as usize] {
        LeftRecord::Short
    } else {
        LeftRecord::Long
    }
}

fn union_region(nodes: &[ExactNode], ids: &[u32]) -> Aabb {
    ids.iter()
        .fold(Aabb::EMPTY, |b, &i| b.union(nodes[i as usize].region))
}

/// Surface-area priority of expanding node `n` into its cluster (larger first, then
/// preorder): the chance a ray entering the cluster reaches `n`'s children.
fn priority(n: &ExactNode, id: u32) -> (u32, Reverse<u32>) {
    let a = n.region.half_area();
    let key = if a.is_nan() { 0 } else { a.max(0.0).to_bits() };
    (key, Reverse(id))
}

impl DstQ {
    /// Converts the exact DST `dst` (itself converted from the BVH2 with identical or
    /// similar partitioning): the same nodes and decisions, its planes quantized to
    /// `cfg.bits`-bit offsets inside clusters of `cfg.cluster_bytes` bytes, rounded so every
    /// region only grows (`docs/dstq-encoding.md`, §4). Lin et al. 2020, §5 (future work).
    pub fn from_dst(dst: &Dst, cfg: &DstQConfig) -> Result<Self, DstQError> {
        cfg.check()?;
        let k = cfg.bits;
        let cbits = cfg.cluster_bytes * 8;
        let cw = cfg.cluster_words() as usize;
        let nodes = read_exact(dst)?;
        let src = dst.image();
        let n_idx = src.indices.len();
        if nodes.is_empty() {
            let mut image = MemoryImage::with_triangles(0, n_idx, src.triangle_data.clone());
            image.words[..n_idx].copy_from_slice(&src.words[src.indices.clone()]);
            return Ok(Self::assemble(image, dst.scene_box(), *cfg));
        }
        // Pass 1: fill the clusters, parents before children.
        let mut queue = VecDeque::from([Pending {
            roots: vec![0],
            frame: dst.scene_box(),
            id: 0,
        }]);
        let mut clusters: Vec<Cluster> = Vec::new();
        let fmt = RecordFormat::new(k, cfg.cluster_bytes);
        let mut child_at: Vec<Option<Child>> = vec![None; nodes.len()];
        while let Some(p) = queue.pop_front() {
            debug_assert_eq!(p.id as usize, clusters.len());
            let mut placed: Vec<u32> = Vec::new();
            let mut heap = BinaryHeap::new();
            // Bits used: frame + reserved record sizes (short headers once known).
            let mut used = ROOT_BIT;
            for &r in &p.roots {
                placed.push(r);
                used += reserved_bits(&nodes[r as usize], k);
                if nodes[r as usize].child_count() > 0 {
                    heap.push(priority(&nodes[r as usize], r));
                }
            }
            while let Some((_, Reverse(n))) = heap.pop() {
                let node = &nodes[n as usize];
                let kids: Vec<u32> = node.kids.iter().copied().filter(|&c| c != NONE).collect();
                let need: u32 = kids
                    .iter()
                    .map(|&c| reserved_bits(&nodes[c as usize], k))
                    .sum();
                if used + need <= cbits {
                    child_at[n as usize] = Some(Child::Local(placed.len() as u32));
                    used = used + need - (32 - fmt.short_header_bits());
                    for &c in &kids {
                        placed.push(c);
                        if nodes[c as usize].child_count() > 0 {
                            heap.push(priority(&nodes[c as usize], c));
                        }
                    }
                } else {
                    let id = (clusters.len() + 1 + queue.len()) as u32;
                    child_at[n as usize] = Some(Child::Cluster(id));
                    queue.push_back(Pending {
                        frame: union_region(&nodes, &kids),
                        roots: kids,
                        id,
                    });
                }
            }
            // Final positions, in placement order (a split's children stay adjacent).
            let mut pos = ROOT_BIT;
            let placed: Vec<(u32, u32)> = placed
                .into_iter()
                .map(|n| {
                    let at = pos;
                    pos += final_bits(&nodes, &child_at, n, &fmt);
                    (n, at)
                })
                .collect();
            debug_assert_eq!(pos, used);
            clusters.push(Cluster {
                frame: p.frame,
                placed,
                bits: pos,
            });
        }
        // Pass 2: place the clusters (whole words) in lines of `cluster_bytes`.
        let sizes: Vec<u32> = clusters.iter().map(|c| c.bits.div_ceil(32)).collect();
        let (addr, lines) = pack(&sizes, cw as u32);
        let mut words: Vec<u32> = vec![0; lines as usize * cw];
        // Pass 3: write every cluster at its address.
        for (c, &base) in clusters.iter().zip(&addr) {
            let out = &mut words[base as usize..];
            let frame = Frame::of_box(c.frame.min.to_array(), c.frame.max.to_array(), k);
            out[..4].copy_from_slice(&frame.words(c.placed.len().min(255) as u8));
            for &(n, bit) in &c.placed {
                let node = &nodes[n as usize];
                let hdr = node.hdr;
                let child = || match child_at[n as usize] {
                    Some(Child::Local(i)) => ChildRef::Local(c.placed[i as usize].1),
                    Some(Child::Cluster(id)) => ChildRef::Cluster(addr[id as usize]),
                    None => unreachable!("every expanded node has a child"),
                };
                let q = match hdr.node_kind() {
                    DstNodeKind::Leaf => QHeader::leaf(hdr.offset() as u64)?,
                    DstNodeKind::Split => {
                        let left = left_record(&nodes, &child_at, node.kids[0]);
                        QHeader::split(hdr.axis(), left, child(), &fmt)?
                    }
                    _ if hdr.is_leaf_flag() => QHeader::carve_leaf(hdr, hdr.offset() as u64)?,
                    _ => QHeader::carve(hdr, child(), &fmt)?,
                };
                let hb = q.header_bits(&fmt);
                write_bits(out, bit as usize, hb, q.bits());
                if !hdr.is_plain_leaf() {
                    for (a, slot, lower) in plane_roles(hdr) {
                        let x = node.planes[slot];
                        let (o, e) = (frame.origin[a], frame.exp[a]);
                        let qv = if lower {
                            quantize_down(x, o, e, k)
                        } else {
                            quantize_up(x, o, e, k)
                        };
                        write_bits(out, (bit + hb + slot as u32 * k) as usize, k, qv);
                    }
                }
            }
        }
        let n_nodes = words.len();
        let mut image = MemoryImage::with_triangles(n_nodes, n_idx, src.triangle_data.clone());
        image.words[..n_nodes].copy_from_slice(&words);
        image.words[n_nodes..n_nodes + n_idx].copy_from_slice(&src.words[src.indices.clone()]);
        Ok(Self::assemble(image, dst.scene_box(), *cfg))
    }
}
