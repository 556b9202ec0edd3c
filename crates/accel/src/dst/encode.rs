//! Emission of the DST memory image (dst-spec §3): node words depth-first with the two
//! children of every splitting node adjacent (left, then right at left + left size), a
//! carving node's child placed by bump allocation, leaves as runs in one triangle-index list
//! (the last entry of a run has bit 31 set), then the triangles, 36 B each in id order.
//!
//! Two passes, both parallel (rayon) over the subtrees below depth [`PARALLEL_DEPTH`]:
//!
//! 1. **Plan**: every splitting decision ([`plan_split`]) in depth-first order, with the
//!    number of node words and index entries each subtree will take. Decisions are kept as
//!    compact records ([`Rec`], the chains packed in eight bytes each).
//! 2. **Emit**: with every subtree's size known, the image is cut into disjoint slices
//!    (`split_at_mut`), one per subtree, and each subtree writes its words and index runs
//!    in place at their final addresses. Nothing is relocated or copied afterwards.
//!
//! The layout is the one a fully sequential depth-first emission with bump allocation
//! gives, whatever the thread count (`tests/dst_convert_golden.rs`).

use super::from_bvh2::{Chain, ChainDp, StepTable, plan_split, plane_values};
use super::header::{HeaderOffset, OFFSET_LIMIT};
use super::stats::DstStats;
use super::{Dst, DstConfig, DstError};
use crate::build::Bvh2;
use crate::image::MemoryImage;
use dualsplit_geometry::{Aabb, Triangle};

/// Bit 31 of an index entry: the last triangle of a leaf's run.
pub(super) const RUN_END: u32 = 1 << 31;

/// Subtrees below this depth (the root is at depth 0) are planned and emitted as
/// independent rayon tasks, up to 2^PARALLEL_DEPTH of them.
const PARALLEL_DEPTH: u32 = 8;

/// What the plan pass decided at an internal BVH node, in the DST's child order (32 bytes).
#[derive(Clone, Copy, Debug)]
struct Rec {
    /// The incoming carving chains of the DST's left and right child.
    chains: [Chain; 2],
    /// Index entries of the left subtree.
    left_entries: u64,
    /// Node words bump-allocated by the left subtree below its root slot (saturated: a
    /// tree that large fails the 2^26-word offset check before emission).
    left_words: u32,
    /// Split axis.
    axis: u8,
    /// The BVH node's second child is the DST's left child.
    swap: bool,
}

const _: () = assert!(std::mem::size_of::<Rec>() == 32);

impl Rec {
    /// BVH nodes of the DST's left and right child of BVH node `n`.
    #[inline(always)]
    fn children(&self, bvh: &Bvh2, n: u32) -> [u32; 2] {
        let [x, y] = bvh.nodes[n as usize].children();
        if self.swap { [y, x] } else { [x, y] }
    }

    fn set_left(&mut self, size: Size) {
        self.left_words = u32::try_from(size.words).unwrap_or(u32::MAX);
        self.left_entries = size.entries;
    }
}

/// The plan of a subtree.
enum Plan {
    /// Planned sequentially: the records of its internal nodes in depth-first order.
    Seq(Vec<Rec>),
    /// An internal node above the parallel cut: its record and its two children's plans.
    Par(Rec, Box<[Plan; 2]>),
}

/// A subtree's size: node words bump-allocated below its root slot, and index entries.
#[derive(Clone, Copy, Default)]
struct Size {
    words: u64,
    entries: u64,
}

impl Size {
    fn add(self, o: Size) -> Size {
        Size {
            words: self.words + o.words,
            entries: self.entries + o.entries,
        }
    }
}

/// The output slices a subtree writes: its root slot (1 or 3 words, reserved by its
/// parent), its bump-allocated node words, its index entries, and their absolute
/// positions (node words from the start of the image, entries from the start of the list).
struct Out<'w> {
    slot: &'w mut [u32],
    words: &'w mut [u32],
    at: u64,
    entries: &'w mut [u32],
    entries_at: u64,
}

impl<'w> Out<'w> {
    /// Takes the next `n` node words (bump allocation); returns them and their address.
    fn take(&mut self, n: usize) -> (&'w mut [u32], u64) {
        let (head, rest) = std::mem::take(&mut self.words).split_at_mut(n);
        self.words = rest;
        let at = self.at;
        self.at += n as u64;
        (head, at)
    }

    /// Splits off the outputs of a child subtree of `size` whose root slot is `slot`.
    fn child(&mut self, slot: &'w mut [u32], size: Size) -> Out<'w> {
        let (words, at) = self.take(size.words as usize);
        let (entries, rest) = std::mem::take(&mut self.entries).split_at_mut(size.entries as usize);
        self.entries = rest;
        let entries_at = self.entries_at;
        self.entries_at += size.entries;
        Out {
            slot,
            words,
            at,
            entries,
            entries_at,
        }
    }
}

/// Words of the root slot of BVH node `n` entered with `chain`: a plain leaf is one word,
/// anything else a 3-word node.
fn slot_size(bvh: &Bvh2, n: u32, chain: Chain) -> usize {
    if bvh.nodes[n as usize].is_leaf() && chain.is_empty() {
        1
    } else {
        3
    }
}

struct Encoder<'a> {
    bvh: &'a Bvh2,
    triangles: usize,
    cfg: &'a DstConfig,
    steps: StepTable,
}

impl Encoder<'_> {
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

    /// Plans BVH node `n` entered with `chain`: its record (internal nodes) and the size of
    /// its subtree. Checks the links and leaf ranges that emission relies on.
    fn plan_node(
        &self,
        n: u32,
        chain: Chain,
        dps: &mut [ChainDp; 2],
    ) -> Result<Result<Rec, Size>, DstError> {
        self.check_links(n)?;
        let node = &self.bvh.nodes[n as usize];
        let steps = chain.len() as u64;
        if node.is_leaf() {
            let (first, count) = (node.first as usize, node.count as usize);
            if first + count > self.bvh.prim_ids.len() {
                return Err(DstError::BadBvhLink {
                    node: n,
                    child: node.first,
                    nodes: self.bvh.prim_ids.len(),
                });
            }
            // The last carving node of a leaf's chain is the leaf (no word of its own).
            return Ok(Err(Size {
                words: 3 * steps.saturating_sub(1),
                entries: count as u64,
            }));
        }
        let p = plan_split(self.bvh, n, self.cfg, dps);
        Ok(Ok(Rec {
            chains: [p.left_chain, p.right_chain],
            left_entries: 0,
            left_words: 0,
            axis: p.axis as u8,
            swap: p.swap,
        }))
    }

    /// Completes internal node `n`'s record once its subtrees are planned (`l`, `r`: their
    /// sizes) and returns the size of its own subtree: its chain's words, both children's
    /// slots, and everything below.
    fn close(&self, n: u32, chain: Chain, rec: &mut Rec, l: Size, r: Size) -> Size {
        rec.set_left(l);
        let [cl, cr] = rec.children(self.bvh, n);
        let [ch_l, ch_r] = rec.chains;
        let own = 3 * chain.len() + slot_size(self.bvh, cl, ch_l) + slot_size(self.bvh, cr, ch_r);
        l.add(r).add(Size {
            words: own as u64,
            entries: 0,
        })
    }

    /// Plan pass, sequential: appends the records of `n`'s subtree to `recs` in depth-first
    /// order. `budget` counts the nodes still allowed (a cycle in a malformed BVH runs it
    /// out instead of recursing forever).
    fn plan_seq(
        &self,
        n: u32,
        chain: Chain,
        recs: &mut Vec<Rec>,
        budget: &mut usize,
        dps: &mut [ChainDp; 2],
    ) -> Result<Size, DstError> {
        *budget = budget.checked_sub(1).ok_or(DstError::BadBvhLink {
            node: n,
            child: n,
            nodes: self.bvh.nodes.len(),
        })?;
        let mut rec = match self.plan_node(n, chain, dps)? {
            Err(leaf) => return Ok(leaf),
            Ok(rec) => rec,
        };
        let slot = recs.len();
        recs.push(rec);
        let [cl, cr] = rec.children(self.bvh, n);
        let l = self.plan_seq(cl, rec.chains[0], recs, budget, dps)?;
        let r = self.plan_seq(cr, rec.chains[1], recs, budget, dps)?;
        let size = self.close(n, chain, &mut rec, l, r);
        recs[slot] = rec;
        Ok(size)
    }

    /// Plan pass: nodes above [`PARALLEL_DEPTH`] plan their two subtrees in parallel.
    fn plan(&self, n: u32, chain: Chain, depth: u32) -> Result<(Plan, Size), DstError> {
        if depth >= PARALLEL_DEPTH {
            // About twice an even share of the internal nodes, so the records rarely move.
            let mut recs = Vec::with_capacity(self.bvh.nodes.len() >> PARALLEL_DEPTH);
            let mut budget = self.bvh.nodes.len();
            let mut dps = [ChainDp::new(), ChainDp::new()];
            let size = self.plan_seq(n, chain, &mut recs, &mut budget, &mut dps)?;
            return Ok((Plan::Seq(recs), size));
        }
        let mut dps = [ChainDp::new(), ChainDp::new()];
        let mut rec = match self.plan_node(n, chain, &mut dps)? {
            Err(leaf) => return Ok((Plan::Seq(Vec::new()), leaf)),
            Ok(rec) => rec,
        };
        let [cl, cr] = rec.children(self.bvh, n);
        let (l, r) = rayon::join(
            || self.plan(cl, rec.chains[0], depth + 1),
            || self.plan(cr, rec.chains[1], depth + 1),
        );
        let ((lp, l), (rp, r)) = (l?, r?);
        let size = self.close(n, chain, &mut rec, l, r);
        Ok((Plan::Par(rec, Box::new([lp, rp])), size))
    }

    /// Writes BVH leaf `n`'s triangles as one run at the start of `out.entries`.
    fn write_run(&self, n: u32, out: &mut Out) -> Result<(), DstError> {
        let node = &self.bvh.nodes[n as usize];
        let (first, count) = (node.first as usize, node.count as usize);
        let ids = &self.bvh.prim_ids[first..first + count];
        for (i, (&p, e)) in ids.iter().zip(out.entries.iter_mut()).enumerate() {
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
            *e = if i + 1 == count { p | RUN_END } else { p };
        }
        Ok(())
    }

    /// Emits BVH node `n`'s incoming `chain` (and, for a leaf, the leaf itself) into
    /// `out`. For an internal node, returns the slot its splitting node goes into and what
    /// is left of `out` for its children.
    fn emit_head<'w>(
        &self,
        n: u32,
        chain: Chain,
        mut out: Out<'w>,
        stats: &mut DstStats,
    ) -> Result<Option<(&'w mut [u32], Out<'w>)>, DstError> {
        let node = &self.bvh.nodes[n as usize];
        let is_leaf = node.is_leaf();
        let steps = chain.len();
        let mut slot = std::mem::take(&mut out.slot);
        let planes = plane_values(&node.bounds);
        for i in 0..steps {
            let step = self.steps.get(chain.faces(i));
            // A carving node's child is a carving or splitting node (3 words), or the leaf
            // is folded into it (L = 1).
            let fold = is_leaf && i + 1 == steps;
            let (offset, child) = if fold {
                stats.carving_leaves += 1;
                self.write_run(n, &mut out)?;
                (out.entries_at, None)
            } else {
                let (c, at) = out.take(3);
                (at, Some(c))
            };
            if step.dual {
                stats.dual_carving += 1;
            } else {
                stats.single_carving += 1;
            }
            let h = step.header.carve_pointing_at(fold, offset)?;
            let [p0, p1] = step.planes.map(|p| planes[p as usize]);
            put(slot, h, p0, p1);
            if let Some(c) = child {
                slot = c;
            }
        }
        if !is_leaf {
            return Ok(Some((slot, out)));
        }
        stats.index_entries += node.count as u64;
        if steps == 0 {
            stats.leaves += 1;
            self.write_run(n, &mut out)?;
            slot[0] = HeaderOffset::leaf(out.entries_at)?.bits();
        }
        Ok(None)
    }

    /// Emits the subtree of BVH node `n` entered with `chain`, sequentially; the records of
    /// its internal nodes come from `recs` in depth-first order.
    fn emit(
        &self,
        n: u32,
        chain: Chain,
        out: Out,
        recs: &mut std::slice::Iter<Rec>,
        stats: &mut DstStats,
    ) -> Result<(), DstError> {
        if let Some((slot, mut out)) = self.emit_head(n, chain, out, stats)? {
            let rec = recs.next().expect("one record per internal node");
            let [cl, cr] = rec.children(self.bvh, n);
            let (l, r) = self.children_out(rec, [cl, cr], &mut out, slot, stats)?;
            self.emit(cl, rec.chains[0], l, recs, stats)?;
            self.emit(cr, rec.chains[1], r, recs, stats)?;
        }
        Ok(())
    }

    /// Writes the splitting node `rec` into `slot`, reserves its children's slots and cuts
    /// the rest of `out` into the two children's outputs.
    fn children_out<'w>(
        &self,
        rec: &Rec,
        [l, r]: [u32; 2],
        out: &mut Out<'w>,
        slot: &mut [u32],
        stats: &mut DstStats,
    ) -> Result<(Out<'w>, Out<'w>), DstError> {
        let sl = slot_size(self.bvh, l, rec.chains[0]);
        let sr = slot_size(self.bvh, r, rec.chains[1]);
        let (pair, at) = out.take(sl + sr);
        stats.splitting += 1;
        let axis = rec.axis as usize;
        let h = HeaderOffset::split(axis, sl as u32, at)?;
        let (lb, rb) = (
            self.bvh.nodes[l as usize].bounds,
            self.bvh.nodes[r as usize].bounds,
        );
        put(slot, h, lb.max[axis], rb.min[axis]);
        let (ls, rs) = pair.split_at_mut(sl);
        let left = out.child(
            ls,
            Size {
                words: rec.left_words as u64,
                entries: rec.left_entries,
            },
        );
        let rest = Size {
            words: out.words.len() as u64,
            entries: out.entries.len() as u64,
        };
        Ok((left, out.child(rs, rest)))
    }

    /// Emits a planned subtree; [`Plan::Par`] nodes emit their two subtrees in parallel.
    fn emit_plan(&self, plan: &Plan, n: u32, chain: Chain, out: Out) -> Result<DstStats, DstError> {
        let mut stats = DstStats::default();
        match plan {
            Plan::Seq(recs) => self.emit(n, chain, out, &mut recs.iter(), &mut stats)?,
            Plan::Par(rec, children) => {
                let (slot, mut out) = self
                    .emit_head(n, chain, out, &mut stats)?
                    .expect("a parallel plan node is internal");
                let [cl, cr] = rec.children(self.bvh, n);
                let (l, r) = self.children_out(rec, [cl, cr], &mut out, slot, &mut stats)?;
                let (a, b) = rayon::join(
                    || self.emit_plan(&children[0], cl, rec.chains[0], l),
                    || self.emit_plan(&children[1], cr, rec.chains[1], r),
                );
                stats.add_counts(&a?);
                stats.add_counts(&b?);
            }
        }
        Ok(stats)
    }
}

/// Writes a 12-byte node (header-offset word, P0, P1) into `slot`.
fn put(slot: &mut [u32], h: HeaderOffset, p0: f32, p1: f32) {
    slot[0] = h.bits();
    slot[1] = p0.to_bits();
    slot[2] = p1.to_bits();
}

impl Dst {
    /// Converts a BVH2 over `triangles` into a DST (Lin et al. 2020, §4.2). In
    /// [`super::Partitioning::Identical`] mode the region entering every splitting node and
    /// leaf is exactly its BVH node's box. Time and memory are linear in the BVH's nodes.
    ///
    /// Errors: malformed BVH links, non-finite boxes, triangle ids out of range, and
    /// offsets beyond the 26-bit field ([`DstError::OffsetOverflow`]).
    pub fn from_bvh2(bvh: &Bvh2, triangles: &[Triangle], cfg: &DstConfig) -> Result<Dst, DstError> {
        let enc = Encoder {
            bvh,
            triangles: triangles.len(),
            cfg,
            steps: StepTable::new(&cfg.costs)?,
        };
        let empty = bvh.prim_ids.is_empty() || bvh.nodes.is_empty();
        let (plan, root_slot, size) = if empty {
            (Plan::Seq(Vec::new()), 0, Size::default())
        } else {
            let (plan, size) = enc.plan(0, Chain::EMPTY, 0)?;
            (plan, slot_size(bvh, 0, Chain::EMPTY), size)
        };
        let n_nodes = root_slot as u64 + size.words;
        if n_nodes > OFFSET_LIMIT {
            return Err(DstError::OffsetOverflow {
                given: n_nodes,
                limit: OFFSET_LIMIT,
            });
        }
        let (n_nodes, n_idx) = (n_nodes as usize, size.entries as usize);
        // One allocation for the whole image (fresh pages, first touched by the threads
        // that fill them; huge pages where the kernel allows, see `image::Words`).
        let mut image = MemoryImage::with_triangles(n_nodes, n_idx, triangles);
        let (node_words, entries) = image.node_and_index_words_mut().split_at_mut(n_nodes);
        let mut stats = if empty {
            DstStats::default()
        } else {
            let (slot, node_words) = node_words.split_at_mut(root_slot);
            let out = Out {
                slot,
                words: node_words,
                at: root_slot as u64,
                entries,
                entries_at: 0,
            };
            enc.emit_plan(&plan, 0, Chain::EMPTY, out)?
        };
        let scene_box = if empty {
            Aabb::EMPTY
        } else {
            bvh.nodes[0].bounds
        };
        stats.node_bytes = image.node_bytes();
        stats.index_bytes = image.index_bytes();
        stats.total_bytes = stats.node_bytes + stats.index_bytes + 24;
        // The BVH2's size in the paper's layout (`stats::bvh2_size_bytes`): one 52-byte
        // node per internal node, and every internal node became one splitting node.
        stats.bvh2_bytes = if empty {
            0
        } else {
            52 * stats.splitting + 4 * bvh.prim_ids.len() as u64
        };
        Ok(Dst {
            image,
            scene_box,
            config: *cfg,
            stats,
        })
    }
}
