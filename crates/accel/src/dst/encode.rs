//! Emission of the DST memory image (`docs/dst-encoding.md`, §2): node words depth-first with the two
//! children of every splitting node adjacent (left, then right at left + left size), a
//! carving node's child placed by bump allocation, leaves as runs in one triangle-index list
//! (the last entry of a run has bit 31 set), then the triangle region (the scene's
//! triangles, shared with the other images: [`crate::image::SharedTriangles`]).
//!
//! Two passes, both parallel (rayon) over the subtrees below depth [`PARALLEL_DEPTH`]:
//!
//! 1. **Plan**: every splitting decision ([`plan_split`]) in depth-first order, with the
//!    number of node words and index entries each subtree will take. Decisions are kept as
//!    compact records ([`Rec`], the chains packed in eight bytes each).
//! 2. **Emit**: with every subtree's size known, the image is cut into disjoint slices
//!    (`split_at_mut`) at the parallel cut, one per subtree, and each subtree writes its
//!    words and index runs in place at their final addresses through a [`Cursor`] (bump
//!    indices; slots are word indices). Nothing is relocated or copied afterwards.
//!
//! The image's words live in one allocation ([`crate::image::Words`]: huge pages where the
//! kernel allows, so first-touch page faults do not dominate). The layout is the one a fully
//! sequential depth-first emission with bump allocation gives, whatever the thread count
//! (`tests/dst_convert_reference.rs`).
//!
//! Loading a saved tree replays that sequential allocation and rejects any other layout
//! (`saved/structure.rs`): a change here changes the saved-tree format.

use super::header::{HeaderOffset, OFFSET_LIMIT};
use super::plan::{Chain, Planner, StepTable, plane_values};
use super::stats::DstStats;
use super::{Dst, DstConfig, DstError};
use crate::build::Bvh2;
use crate::image::{MemoryImage, RUN_END, SharedTriangles};
use dualsplit_geometry::Aabb;

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

/// [`Slot`] of a subtree's root, which lives in [`Out::slot`] rather than in its words.
const ROOT: usize = usize::MAX;

/// A slot to be written: [`ROOT`] or the index of its first word in [`Cursor::words`].
type Slot = usize;

/// Sequential emission into one subtree's [`Out`]: node words and index entries are
/// bump-allocated by moving `next` and `next_entry`, and slots are word indices, so nothing
/// is split or moved per node.
struct Cursor<'w> {
    out: Out<'w>,
    /// Words of `out.words` allocated so far.
    next: usize,
    /// Entries of `out.entries` written so far.
    next_entry: usize,
}

impl<'w> Cursor<'w> {
    fn new(out: Out<'w>) -> Self {
        Cursor {
            out,
            next: 0,
            next_entry: 0,
        }
    }

    /// Allocates `n` node words; returns their index in the cursor's words.
    #[inline(always)]
    fn take(&mut self, n: usize) -> usize {
        let i = self.next;
        self.next += n;
        i
    }

    /// Absolute word address of index `i` of the cursor's words.
    #[inline(always)]
    fn addr(&self, i: usize) -> u64 {
        self.out.at + i as u64
    }

    /// Absolute index-list position of the next entry.
    #[inline(always)]
    fn entry_addr(&self) -> u64 {
        self.out.entries_at + self.next_entry as u64
    }

    /// The words of slot `slot` (from its start to the end of its region).
    #[inline(always)]
    fn slot(&mut self, slot: Slot) -> &mut [u32] {
        if slot == ROOT {
            self.out.slot
        } else {
            &mut self.out.words[slot..]
        }
    }

    /// Writes a 12-byte node (header-offset word, P0, P1) into `slot`.
    #[inline(always)]
    fn put(&mut self, slot: Slot, h: HeaderOffset, p0: f32, p1: f32) {
        let node: &mut [u32; 3] = (&mut self.slot(slot)[..3]).try_into().expect("3 words");
        *node = [h.bits(), p0.to_bits(), p1.to_bits()];
    }

    /// Splits what is left after the pair of child slots at `pair` (`sl` + `sr` words) into
    /// the outputs of the left child (its root slot and `left` of the rest) and the right
    /// child (its root slot and everything else).
    fn into_children(self, pair: usize, sl: usize, left: Size) -> (Out<'w>, Out<'w>) {
        let at = self.out.at;
        let (_, rest) = self.out.words.split_at_mut(pair);
        let (ls, rest) = rest.split_at_mut(sl);
        let (rs, rest) = rest.split_at_mut(self.next - pair - sl);
        let (lw, rw) = rest.split_at_mut(left.words as usize);
        let (le, re) = self.out.entries[self.next_entry..].split_at_mut(left.entries as usize);
        let entries_at = self.out.entries_at + self.next_entry as u64;
        let words_at = at + self.next as u64;
        (
            Out {
                slot: ls,
                words: lw,
                at: words_at,
                entries: le,
                entries_at,
            },
            Out {
                slot: rs,
                words: rw,
                at: words_at + left.words,
                entries: re,
                entries_at: entries_at + left.entries,
            },
        )
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

struct Encoder<'a, P> {
    bvh: &'a Bvh2,
    triangles: usize,
    cfg: &'a DstConfig,
    steps: StepTable,
    planner: &'a P,
}

/// What the sequential plan pass carries down a subtree.
struct SeqPlan<S> {
    /// The records of the internal nodes planned so far, depth-first.
    recs: Vec<Rec>,
    /// Nodes still allowed: a cycle in a malformed BVH runs it out instead of recursing
    /// forever.
    budget: usize,
    /// The planner's working memory, reused from node to node.
    scratch: S,
}

impl<P: Planner> Encoder<'_, P> {
    /// Checks BVH node `n`'s box and child links, or a leaf's triangle range (what planning
    /// and emission index with); for a leaf entered with `chain`, returns its size.
    #[inline(always)]
    fn check_node(&self, n: u32, chain: Chain) -> Result<Option<Size>, DstError> {
        let node = &self.bvh.nodes[n as usize];
        if !node.bounds.is_finite() {
            return Err(DstError::NonFiniteBounds {
                node: n,
                bounds: node.bounds,
            });
        }
        if !node.is_leaf() {
            let nodes = self.bvh.nodes.len();
            for c in node.children() {
                if c == 0 || c as usize >= nodes {
                    return Err(DstError::BadBvhLink {
                        node: n,
                        child: c,
                        nodes,
                    });
                }
            }
            return Ok(None);
        }
        let (first, count) = (node.first as usize, node.count as usize);
        if first + count > self.bvh.prim_ids.len() {
            return Err(DstError::BadBvhLink {
                node: n,
                child: node.first,
                nodes: self.bvh.prim_ids.len(),
            });
        }
        // The last carving node of a leaf's chain is the leaf (no word of its own).
        Ok(Some(Size {
            words: 3 * (chain.len() as u64).saturating_sub(1),
            entries: count as u64,
        }))
    }

    /// The record of internal BVH node `n` (its subtree sizes are filled in by
    /// [`Encoder::close`]).
    #[inline(always)]
    fn new_rec(&self, n: u32, scratch: &mut P::Scratch) -> Rec {
        let p = self.planner.plan_split(self.bvh, n, self.cfg, scratch);
        Rec {
            chains: [p.left_chain, p.right_chain],
            left_entries: 0,
            left_words: 0,
            axis: p.axis as u8,
            swap: p.swap,
        }
    }

    /// Completes the record of an internal node entered with `chain`, whose DST children
    /// are BVH nodes `[cl, cr]`, once its subtrees are planned (`l`, `r`: their sizes), and
    /// returns the size of its own subtree: its chain's words, both children's slots, and
    /// everything below.
    #[inline(always)]
    fn close(&self, chain: Chain, [cl, cr]: [u32; 2], rec: &mut Rec, l: Size, r: Size) -> Size {
        rec.set_left(l);
        let [ch_l, ch_r] = rec.chains;
        let own = 3 * chain.len() + slot_size(self.bvh, cl, ch_l) + slot_size(self.bvh, cr, ch_r);
        l.add(r).add(Size {
            words: own as u64,
            entries: 0,
        })
    }

    /// Plan pass, sequential: appends the records of `n`'s subtree to `s.recs` in
    /// depth-first order. Inlined into its caller, so that a leaf costs no call: only
    /// internal nodes recurse ([`Encoder::plan_inner`]).
    #[inline(always)]
    fn plan_seq(
        &self,
        n: u32,
        chain: Chain,
        s: &mut SeqPlan<P::Scratch>,
    ) -> Result<Size, DstError> {
        s.budget = s.budget.checked_sub(1).ok_or(DstError::BadBvhLink {
            node: n,
            child: n,
            nodes: self.bvh.nodes.len(),
        })?;
        match self.check_node(n, chain)? {
            Some(leaf) => Ok(leaf),
            None => self.plan_inner(n, chain, s),
        }
    }

    /// [`Encoder::plan_seq`] for internal node `n`, already checked.
    fn plan_inner(
        &self,
        n: u32,
        chain: Chain,
        s: &mut SeqPlan<P::Scratch>,
    ) -> Result<Size, DstError> {
        let slot = s.recs.len();
        let rec = self.new_rec(n, &mut s.scratch);
        s.recs.push(rec);
        let ([cl, cr], [ch_l, ch_r]) = (rec.children(self.bvh, n), rec.chains);
        let l = self.plan_seq(cl, ch_l, s)?;
        let r = self.plan_seq(cr, ch_r, s)?;
        Ok(self.close(chain, [cl, cr], &mut s.recs[slot], l, r))
    }

    /// Plan pass: nodes above [`PARALLEL_DEPTH`] plan their two subtrees in parallel.
    fn plan(&self, n: u32, chain: Chain, depth: u32) -> Result<(Plan, Size), DstError> {
        if depth >= PARALLEL_DEPTH {
            let mut s = SeqPlan {
                // About twice an even share of the internal nodes, so the records rarely
                // move.
                recs: Vec::with_capacity(self.bvh.nodes.len() >> PARALLEL_DEPTH),
                budget: self.bvh.nodes.len(),
                scratch: self.planner.scratch(),
            };
            let size = self.plan_seq(n, chain, &mut s)?;
            return Ok((Plan::Seq(s.recs), size));
        }
        if let Some(leaf) = self.check_node(n, chain)? {
            return Ok((Plan::Seq(Vec::new()), leaf));
        }
        let mut rec = self.new_rec(n, &mut self.planner.scratch());
        let [cl, cr] = rec.children(self.bvh, n);
        let (l, r) = rayon::join(
            || self.plan(cl, rec.chains[0], depth + 1),
            || self.plan(cr, rec.chains[1], depth + 1),
        );
        let ((lp, l), (rp, r)) = (l?, r?);
        let size = self.close(chain, [cl, cr], &mut rec, l, r);
        Ok((Plan::Par(rec, Box::new([lp, rp])), size))
    }

    /// Writes BVH leaf `n`'s triangles as one run at the cursor's next entries; returns the
    /// run's position in the index list.
    #[inline(always)]
    fn write_run(&self, n: u32, cur: &mut Cursor) -> Result<u64, DstError> {
        let node = &self.bvh.nodes[n as usize];
        let (first, count) = (node.first as usize, node.count as usize);
        let ids = &self.bvh.prim_ids[first..first + count];
        let at = cur.entry_addr();
        let run = &mut cur.out.entries[cur.next_entry..cur.next_entry + count];
        for (&p, e) in ids.iter().zip(run.iter_mut()) {
            // One branch for both checks; which one failed is sorted out off the hot path.
            if (p as usize >= self.triangles) | (p & RUN_END != 0) {
                return Err(self.bad_prim(n, p));
            }
            *e = p;
        }
        // A leaf holds at least one triangle (`count > 0` is what makes it a leaf).
        if let Some(last) = run.last_mut() {
            *last |= RUN_END;
        }
        cur.next_entry += count;
        Ok(at)
    }

    /// The error for triangle id `p` of leaf `n`, which is out of range or has the run-end
    /// bit set (checked in that order).
    #[cold]
    fn bad_prim(&self, n: u32, p: u32) -> DstError {
        if p as usize >= self.triangles {
            DstError::PrimOutOfRange {
                node: n,
                prim: p,
                triangles: self.triangles,
            }
        } else {
            DstError::TriangleIdOverflow {
                given: p as u64,
                limit: RUN_END as u64,
            }
        }
    }

    /// Emits BVH node `n`'s incoming `chain` into `slot` (and, for a leaf, the leaf
    /// itself). For an internal node, returns the slot its splitting node goes into.
    #[inline(always)]
    fn emit_head(
        &self,
        n: u32,
        chain: Chain,
        mut slot: Slot,
        cur: &mut Cursor,
        stats: &mut DstStats,
    ) -> Result<Option<Slot>, DstError> {
        let node = &self.bvh.nodes[n as usize];
        let is_leaf = node.is_leaf();
        let steps = chain.len();
        let planes = plane_values(&node.bounds);
        for i in 0..steps {
            let step = self.steps.get(chain.faces(i));
            // A carving node's child is a carving or splitting node (3 words), or the leaf
            // is folded into it (L = 1).
            let fold = is_leaf && i + 1 == steps;
            let (offset, child) = if fold {
                stats.carving_leaves += 1;
                (self.write_run(n, cur)?, slot)
            } else {
                let c = cur.take(3);
                (cur.addr(c), c)
            };
            if step.dual {
                stats.dual_carving += 1;
            } else {
                stats.single_carving += 1;
            }
            let h = step.header.carve_pointing_at(fold, offset)?;
            let [p0, p1] = step.planes.map(|p| planes[p as usize & 7]);
            cur.put(slot, h, p0, p1);
            slot = child;
        }
        if !is_leaf {
            return Ok(Some(slot));
        }
        stats.index_entries += node.count as u64;
        if steps == 0 {
            stats.leaves += 1;
            let at = self.write_run(n, cur)?;
            cur.slot(slot)[0] = HeaderOffset::leaf(at)?.bits();
        }
        Ok(None)
    }

    /// Emits the subtree of BVH node `n` entered with `chain` into `slot`, sequentially;
    /// the records of its internal nodes come from `recs` in depth-first order. Inlined into
    /// its caller, so that a leaf costs no call: only internal nodes recurse
    /// ([`Encoder::emit_inner`]).
    #[inline(always)]
    fn emit(
        &self,
        n: u32,
        chain: Chain,
        slot: Slot,
        cur: &mut Cursor,
        recs: &mut std::slice::Iter<Rec>,
        stats: &mut DstStats,
    ) -> Result<(), DstError> {
        match self.emit_head(n, chain, slot, cur, stats)? {
            Some(slot) => self.emit_inner(n, slot, cur, recs, stats),
            None => Ok(()),
        }
    }

    /// [`Encoder::emit`] for internal node `n` once its chain is written: its splitting
    /// node into `slot`, then its two subtrees.
    fn emit_inner(
        &self,
        n: u32,
        slot: Slot,
        cur: &mut Cursor,
        recs: &mut std::slice::Iter<Rec>,
        stats: &mut DstStats,
    ) -> Result<(), DstError> {
        let rec = recs.next().expect("one record per internal node");
        let [cl, cr] = rec.children(self.bvh, n);
        let (pair, sl) = self.split_node(rec, [cl, cr], slot, cur, stats)?;
        self.emit(cl, rec.chains[0], pair, cur, recs, stats)?;
        self.emit(cr, rec.chains[1], pair + sl, cur, recs, stats)
    }

    /// Writes the splitting node `rec` into `slot` and allocates its children's slots;
    /// returns where they start and the left slot's size.
    #[inline(always)]
    fn split_node(
        &self,
        rec: &Rec,
        [l, r]: [u32; 2],
        slot: Slot,
        cur: &mut Cursor,
        stats: &mut DstStats,
    ) -> Result<(usize, usize), DstError> {
        let sl = slot_size(self.bvh, l, rec.chains[0]);
        let sr = slot_size(self.bvh, r, rec.chains[1]);
        let pair = cur.take(sl + sr);
        stats.splitting += 1;
        let axis = rec.axis as usize;
        let h = HeaderOffset::split(axis, sl as u32, cur.addr(pair))?;
        let (lb, rb) = (
            self.bvh.nodes[l as usize].bounds,
            self.bvh.nodes[r as usize].bounds,
        );
        cur.put(slot, h, lb.max[axis], rb.min[axis]);
        Ok((pair, sl))
    }

    /// Emits a planned subtree; [`Plan::Par`] nodes emit their two subtrees in parallel.
    fn emit_plan(&self, plan: &Plan, n: u32, chain: Chain, out: Out) -> Result<DstStats, DstError> {
        let mut stats = DstStats::default();
        let mut cur = Cursor::new(out);
        match plan {
            Plan::Seq(recs) => self.emit(n, chain, ROOT, &mut cur, &mut recs.iter(), &mut stats)?,
            Plan::Par(rec, children) => {
                let slot = self
                    .emit_head(n, chain, ROOT, &mut cur, &mut stats)?
                    .expect("a parallel plan node is internal");
                let [cl, cr] = rec.children(self.bvh, n);
                let (pair, sl) = self.split_node(rec, [cl, cr], slot, &mut cur, &mut stats)?;
                let left = Size {
                    words: rec.left_words as u64,
                    entries: rec.left_entries,
                };
                let (l, r) = cur.into_children(pair, sl, left);
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

/// Converts `bvh` into a DST over `triangles` with the decisions of `planner`: plans every
/// split, checks the image fits the 26-bit offsets, then emits it (see the module doc).
pub(super) fn encode<P: Planner>(
    bvh: &Bvh2,
    triangles: SharedTriangles,
    cfg: &DstConfig,
    planner: &P,
) -> Result<Dst, DstError> {
    let enc = Encoder {
        bvh,
        triangles: triangles.len(),
        cfg,
        steps: StepTable::new(&cfg.costs)?,
        planner,
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
    // One allocation for the node and index regions (fresh pages, first touched by
    // the threads that fill them; huge pages where the kernel allows, see
    // `image::Words`); the triangle region is the scene's, shared.
    let mut image = MemoryImage::with_triangles(n_nodes, n_idx, triangles);
    let (node_words, entries) = image.words.split_at_mut(n_nodes);
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
    Ok(Dst::from_parts(image, scene_box, *cfg, stats))
}
