//! Emission of the DST memory image (dst-spec §3): node words depth-first with the two
//! children of every splitting node adjacent (left, then right at left + left size), a
//! carving node's child placed by bump allocation, leaves as runs in one triangle-index list
//! (the last entry of a run has bit 31 set), then the triangles, 36 B each in id order.

use super::from_bvh2::{CarveKind, Chain, plan_split};
use super::header::{HeaderOffset, OFFSET_LIMIT};
use super::stats::{DstStats, bvh2_size_bytes};
use super::{Dst, DstConfig, DstError};
use crate::build::Bvh2;
use crate::image::MemoryImage;
use dualsplit_geometry::{Aabb, Triangle};
use rayon::prelude::*;

/// Bit 31 of an index entry: the last triangle of a leaf's run.
pub(super) const RUN_END: u32 = 1 << 31;

/// Subtrees entered below a splitting node at this depth (the root is at depth 0) are
/// encoded as independent tasks in parallel (rayon), up to 2^PARALLEL_DEPTH of them; each is
/// relocated once when the sequential top-level pass reaches it.
const PARALLEL_DEPTH: u32 = 6;

/// The subtrees encoded in parallel, in depth-first order: BVH node and incoming chain.
type Tasks = Vec<(u32, Chain)>;

struct Encoder<'a> {
    bvh: &'a Bvh2,
    triangles: usize,
    cfg: &'a DstConfig,
    words: Vec<u32>,
    indices: Vec<u32>,
    stats: DstStats,
    visited: usize,
}

impl<'a> Encoder<'a> {
    /// Bump-allocates `n` node words.
    fn reserve(&mut self, n: usize) -> usize {
        let at = self.words.len();
        self.words.resize(at + n, 0);
        at
    }

    /// Appends BVH leaf `n`'s triangles as one run; returns the run's first entry.
    fn push_run(&mut self, n: u32) -> Result<u64, DstError> {
        let node = &self.bvh.nodes[n as usize];
        let (first, count) = (node.first as usize, node.count as usize);
        let ids = self
            .bvh
            .prim_ids
            .get(first..first + count)
            .ok_or(DstError::BadBvhLink {
                node: n,
                child: node.first,
                nodes: self.bvh.prim_ids.len(),
            })?;
        let start = self.indices.len() as u64;
        for (i, &p) in ids.iter().enumerate() {
            if p as usize >= self.triangles {
                return Err(DstError::PrimOutOfRange {
                    node: n,
                    prim: p,
                    triangles: self.triangles,
                });
            }
            if p & RUN_END != 0 {
                return Err(DstError::TriangleIdOverflow {
                    given: p as u64,
                    limit: RUN_END as u64,
                });
            }
            self.indices
                .push(if i + 1 == count { p | RUN_END } else { p });
        }
        self.stats.index_entries += count as u64;
        Ok(start)
    }

    fn put(&mut self, at: usize, h: HeaderOffset, p0: f32, p1: f32) {
        self.words[at] = h.bits();
        self.words[at + 1] = p0.to_bits();
        self.words[at + 2] = p1.to_bits();
    }

    fn check_node(&mut self, n: u32) -> Result<(), DstError> {
        self.visited += 1;
        let nodes = self.bvh.nodes.len();
        if self.visited > nodes {
            return Err(DstError::BadBvhLink {
                node: n,
                child: n,
                nodes,
            });
        }
        self.check_links(n)
    }

    /// Checks node `n`'s box and child links (what planning and emission index with).
    fn check_links(&self, n: u32) -> Result<(), DstError> {
        let nodes = self.bvh.nodes.len();
        let node = &self.bvh.nodes[n as usize];
        if !node.bounds.is_finite() {
            return Err(DstError::NonFiniteBounds {
                node: n,
                bounds: node.bounds,
            });
        }
        if !node.is_leaf() {
            for c in node.children() {
                if c == 0 || c as usize >= nodes {
                    return Err(DstError::BadBvhLink {
                        node: n,
                        child: c,
                        nodes,
                    });
                }
            }
        }
        Ok(())
    }

    /// Lists, in depth-first order, the subtrees [`Encoder::emit`] takes from its task
    /// results: both children of every splitting node at depth `PARALLEL_DEPTH - 1`.
    fn collect(&self, n: u32, depth: u32, tasks: &mut Tasks) -> Result<(), DstError> {
        self.check_links(n)?;
        if self.bvh.nodes[n as usize].is_leaf() {
            return Ok(());
        }
        let plan = plan_split(self.bvh, n, self.cfg);
        if depth + 1 == PARALLEL_DEPTH {
            tasks.push((plan.left, plan.left_chain));
            tasks.push((plan.right, plan.right_chain));
            return Ok(());
        }
        self.collect(plan.left, depth + 1, tasks)?;
        self.collect(plan.right, depth + 1, tasks)
    }

    /// Emits BVH node `n` (entered with the carving `chain`) into the words reserved at `at`.
    /// Subtrees at depth `PARALLEL_DEPTH` are not emitted here but taken, in depth-first
    /// order, from `done` (encoded in parallel beforehand) and appended; the layout is the
    /// one a fully sequential depth-first emission gives.
    fn emit(
        &mut self,
        n: u32,
        chain: &Chain,
        mut at: usize,
        depth: u32,
        done: &mut std::vec::IntoIter<Result<Encoder<'a>, DstError>>,
    ) -> Result<(), DstError> {
        self.check_node(n)?;
        let is_leaf = self.bvh.nodes[n as usize].is_leaf();
        let steps = chain.steps();
        for (i, step) in steps.iter().enumerate() {
            let fold = is_leaf && i + 1 == steps.len();
            // A carving node's child is a carving or splitting node (3 words), or the leaf
            // is folded into it (L = 1).
            let (offset, next) = if fold {
                self.stats.carving_leaves += 1;
                (self.push_run(n)?, at)
            } else {
                let c = self.reserve(3);
                (c as u64, c)
            };
            let h = match step.kind {
                CarveKind::Single(axis) => {
                    self.stats.single_carving += 1;
                    HeaderOffset::single_carve(axis, fold, offset)?
                }
                CarveKind::Dual(pair, corner) => {
                    self.stats.dual_carving += 1;
                    HeaderOffset::dual_carve(pair, corner, fold, offset)?
                }
            };
            self.put(at, h, step.p0, step.p1);
            at = next;
        }
        if is_leaf {
            if steps.is_empty() {
                self.stats.leaves += 1;
                let first = self.push_run(n)?;
                self.words[at] = HeaderOffset::leaf(first)?.bits();
            }
            return Ok(());
        }
        let plan = plan_split(self.bvh, n, self.cfg);
        let size = |enc: &Self, c: u32, chain: &Chain| {
            if enc.bvh.nodes[c as usize].is_leaf() && chain.is_empty() {
                1
            } else {
                3
            }
        };
        let (sl, sr) = (
            size(self, plan.left, &plan.left_chain),
            size(self, plan.right, &plan.right_chain),
        );
        let p = self.reserve(sl + sr);
        self.stats.splitting += 1;
        let (lb, rb) = (
            self.bvh.nodes[plan.left as usize].bounds,
            self.bvh.nodes[plan.right as usize].bounds,
        );
        let h = HeaderOffset::split(plan.axis, sl as u32, p as u64)?;
        self.put(at, h, lb.max[plan.axis], rb.min[plan.axis]);
        if depth + 1 == PARALLEL_DEPTH {
            // Both subtrees were encoded in parallel into their own buffers; they are
            // appended in a fixed order (the result does not depend on thread timing).
            let mut next = || done.next().expect("one task result per collected subtree");
            let l = next()?;
            self.append(l, p)?;
            let r = next()?;
            return self.append(r, p + sl);
        }
        self.emit(plan.left, &plan.left_chain, p, depth + 1, done)?;
        self.emit(plan.right, &plan.right_chain, p + sl, depth + 1, done)
    }

    /// Encodes the subtree of BVH node `n` into a fresh encoder whose root is at local word 0.
    /// `tasks` (how many subtrees share the BVH) sizes its buffers up front: twice an even
    /// share at ~3 words per BVH node, so they rarely grow (unused capacity is never
    /// touched, so over-reserving costs no page faults).
    fn sub_encoder(&self, n: u32, chain: &Chain, tasks: usize) -> Result<Encoder<'a>, DstError> {
        let size = if self.bvh.nodes[n as usize].is_leaf() && chain.is_empty() {
            1
        } else {
            3
        };
        let mut sub = Encoder {
            bvh: self.bvh,
            triangles: self.triangles,
            cfg: self.cfg,
            words: Vec::with_capacity(6 * self.bvh.nodes.len() / tasks + 16),
            indices: Vec::with_capacity(2 * self.bvh.prim_ids.len() / tasks + 16),
            stats: DstStats::default(),
            visited: 0,
        };
        sub.reserve(size);
        sub.emit(n, chain, 0, PARALLEL_DEPTH, &mut Vec::new().into_iter())?;
        Ok(sub)
    }

    /// Appends a sub-encoder's output: its root node goes to the words reserved at `at`, the
    /// rest after the current end; node offsets and index-run offsets are relocated.
    fn append(&mut self, sub: Encoder<'a>, at: usize) -> Result<(), DstError> {
        let root_size = if HeaderOffset::from_bits(sub.words[0]).is_plain_leaf() {
            1
        } else {
            3
        };
        let base = self.words.len();
        let index_base = self.indices.len() as u64;
        let map = |local: u32| -> u64 {
            if (local as usize) < root_size {
                (at + local as usize) as u64
            } else {
                (base + local as usize - root_size) as u64
            }
        };
        let mut words = sub.words;
        let mut todo = vec![0u32];
        while let Some(local) = todo.pop() {
            let w = HeaderOffset::from_bits(words[local as usize]);
            let off = w.offset();
            let new = if w.is_leaf_flag() {
                index_base + off as u64
            } else {
                todo.push(off);
                if w.is_split() {
                    todo.push(off + w.left_size());
                }
                map(off)
            };
            if new >= OFFSET_LIMIT {
                return Err(DstError::OffsetOverflow {
                    given: new,
                    limit: OFFSET_LIMIT,
                });
            }
            words[local as usize] = (w.bits() & !(OFFSET_LIMIT as u32 - 1)) | new as u32;
        }
        self.words[at..at + root_size].copy_from_slice(&words[..root_size]);
        self.words.extend_from_slice(&words[root_size..]);
        self.indices.extend_from_slice(&sub.indices);
        self.visited += sub.visited;
        let (a, b) = (&mut self.stats, sub.stats);
        a.splitting += b.splitting;
        a.single_carving += b.single_carving;
        a.dual_carving += b.dual_carving;
        a.leaves += b.leaves;
        a.carving_leaves += b.carving_leaves;
        a.index_entries += b.index_entries;
        Ok(())
    }
}

impl Dst {
    /// Converts a BVH2 over `triangles` into a DST (Lin et al. 2020, §4.2). In
    /// [`super::Partitioning::Identical`] mode the region entering every splitting node and
    /// leaf is exactly its BVH node's box. Time and memory are linear in the BVH's nodes.
    ///
    /// Errors: malformed BVH links, non-finite boxes, triangle ids out of range, and
    /// offsets beyond the 26-bit field ([`DstError::OffsetOverflow`]).
    pub fn from_bvh2(bvh: &Bvh2, triangles: &[Triangle], cfg: &DstConfig) -> Result<Dst, DstError> {
        let mut enc = Encoder {
            bvh,
            triangles: triangles.len(),
            cfg,
            // Room for the whole image, so appending the index list and triangles after
            // the nodes never reallocates.
            words: Vec::with_capacity(
                bvh.nodes.len() * 3 + bvh.prim_ids.len() + triangles.len() * 9,
            ),
            indices: Vec::with_capacity(bvh.prim_ids.len()),
            stats: DstStats::default(),
            visited: 0,
        };
        let empty = bvh.prim_ids.is_empty() || bvh.nodes.is_empty();
        let scene_box = if empty {
            Aabb::EMPTY
        } else {
            bvh.nodes[0].bounds
        };
        if !empty {
            let root_size = if bvh.nodes[0].is_leaf() { 1 } else { 3 };
            let at = enc.reserve(root_size);
            let mut tasks = Tasks::new();
            enc.collect(0, 0, &mut tasks)?;
            let done: Vec<_> = tasks
                .par_iter()
                .map(|(n, chain)| enc.sub_encoder(*n, chain, tasks.len()))
                .collect();
            enc.emit(0, &Chain::EMPTY, at, 0, &mut done.into_iter())?;
        }
        if enc.words.len() as u64 > super::OFFSET_LIMIT {
            return Err(DstError::OffsetOverflow {
                given: enc.words.len() as u64,
                limit: super::OFFSET_LIMIT,
            });
        }
        let n_nodes = enc.words.len();
        let n_idx = enc.indices.len();
        let mut words = enc.words;
        words.reserve_exact(n_idx + triangles.len() * 9);
        words.extend_from_slice(&enc.indices);
        words.extend_from_slice(bytemuck::cast_slice::<Triangle, u32>(triangles));
        let image = MemoryImage {
            nodes: 0..n_nodes,
            indices: n_nodes..n_nodes + n_idx,
            triangles: n_nodes + n_idx..words.len(),
            words,
        };
        let mut stats = enc.stats;
        stats.node_bytes = image.node_bytes();
        stats.index_bytes = image.index_bytes();
        stats.total_bytes = stats.node_bytes + stats.index_bytes + 24;
        stats.bvh2_bytes = if empty { 0 } else { bvh2_size_bytes(bvh) };
        Ok(Dst {
            image,
            scene_box,
            config: *cfg,
            stats,
        })
    }
}
