//! Kernel costs: the instruction sequence each traversal step stands for, per configuration,
//! and the recording observer that turns a traversal's events into macro-operations.
//!
//! The traversal code is the real one (`dualsplit_accel::Structures`, contract 2 of
//! `docs/architecture.md`); this module only translates what it reports: every `fetch`
//! becomes word loads at the image's byte addresses, every node step a pipeline op plus the
//! instructions around it, every triangle test a ray-triangle pipeline op. The counts are
//! justified one by one in `docs/simulator.md` ("Instruction counts per kernel step").

use crate::SimAccel;
use dualsplit_accel::{DstNodeKind, NodeStep, Observer};
use serde::{Deserialize, Serialize};

/// Instruction mix of one kernel step, by functional-unit class (energy and issue slots).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Mix {
    /// Integer add, bitwise, compare-and-branch, move.
    pub int: u32,
    /// FP add/sub.
    pub fpadd: u32,
    /// FP multiply.
    pub fpmul: u32,
    /// FP min/max/compare.
    pub fpcmp: u32,
    /// FP reciprocal / inverse square root (shared unit, long latency).
    pub fpinv: u32,
    /// Local-store (stack) accesses.
    pub local: u32,
}

impl Mix {
    const fn new(int: u32, fpadd: u32, fpmul: u32, fpcmp: u32, fpinv: u32, local: u32) -> Self {
        Self {
            int,
            fpadd,
            fpmul,
            fpcmp,
            fpinv,
            local,
        }
    }
    /// Instructions issued (each takes one issue slot of the thread).
    pub const fn total(&self) -> u32 {
        self.int + self.fpadd + self.fpmul + self.fpcmp + self.fpinv + self.local
    }
    fn add(&mut self, o: Mix) {
        self.int += o.int;
        self.fpadd += o.fpadd;
        self.fpmul += o.fpmul;
        self.fpcmp += o.fpcmp;
        self.fpinv += o.fpinv;
        self.local += o.local;
    }
}

/// Ray setup: `inv_dir = 1/dir` (3 reciprocals on the shared unit), t_min/t_max/best
/// initialisation, stack pointer and root offset (Lin et al. 2020, §3).
pub const RAY_SETUP: Mix = Mix::new(8, 0, 0, 0, 3, 0);
/// After a closest-hit ray: shading a hit (normal, light sample, bounce direction) or the
/// sky; charged once per ray as its result hand-off (`PixelJob::submit`).
pub const RAY_FINISH: Mix = Mix::new(18, 14, 20, 6, 2, 0);
/// Stack push: store offset and entry distance, bump the pointer.
pub const PUSH: Mix = Mix::new(1, 0, 0, 0, 0, 2);
/// Stack pop: decrement, load offset and entry distance, compare with the best t, branch.
pub const POP: Mix = Mix::new(3, 0, 0, 1, 0, 2);
/// Leaf entry: decode the triangle count and index offset, loop set-up.
pub const LEAF: Mix = Mix::new(4, 0, 0, 0, 0, 0);
/// Per triangle test besides the pipeline op: loop counter, branch on the result.
pub const TRI_TEST: Mix = Mix::new(3, 0, 0, 0, 0, 0);
/// Extra when the triangle is accepted: update best t, triangle id, u, v.
pub const TRI_ACCEPT: Mix = Mix::new(4, 0, 0, 0, 0, 0);

/// BVH node, serial box tests: per valid child, branch on its hit flag and keep its
/// distance and offset (the box op itself is a pipeline instruction).
pub const BVH_PER_CHILD: Mix = Mix::new(2, 0, 0, 0, 0, 0);
/// BVH node overhead: decode the child-type bits and offsets, loop branch.
pub const BVH_NODE: Mix = Mix::new(4, 0, 0, 0, 0, 0);
/// Per hit child: compute its address (shift, add) and pick near/far (compare-and-swap for
/// sorting costs 1 FP compare and 2 moves per pair, added per pair below).
pub const BVH_PER_HIT: Mix = Mix::new(2, 0, 0, 0, 0, 0);
/// One compare-exchange of the entry-distance sort.
pub const BVH_SORT_PAIR: Mix = Mix::new(2, 0, 0, 1, 0, 0);

/// DST on the dual-split pipeline: branch on the 2-bit code, move next offset / new t_min
/// t_max into place (Lin et al. 2020, §3, Fig. 6).
pub const DST_HW_STEP: Mix = Mix::new(3, 0, 0, 0, 0, 0);

/// DST decoded in software (DST*), per node kind (Lin et al. 2020, §3, Figs. 2–4): the
/// header decode (shift/mask of the 6-bit header, type test and branch: 5 int), axis
/// select of origin and inverse direction (2 int), plane distances `(p - o[a]) * inv[a]`
/// (fpadd + fpmul per plane), near/far ordering by the direction sign (1 cmp, 2 int), the
/// interval update and child decisions, and the child offset arithmetic.
pub fn dst_sw_step(kind: DstNodeKind, code: u8) -> Mix {
    match kind {
        // 2 planes on one axis: header 5, axis 2, 2×(sub, mul), sign order 1 cmp + 2 int,
        // t_min/t_max against both planes: 4 cmp + 3 branches, offsets 3 int.
        DstNodeKind::Split => Mix::new(15, 2, 2, 5, 0, 0),
        // slab on one axis: header 5, axis 2, 2×(sub, mul), order 1 cmp + 2 int,
        // t_min = max, t_max = min (2), empty test 1 cmp + branch, offset 2.
        DstNodeKind::SingleCarve => Mix::new(12, 2, 2, 4, 0, 0),
        // one plane on each of two axes: header 5, two axis selects 4, 2×(sub, mul),
        // corner type decides which side of each plane (2 cmp + 4 int), interval update 2,
        // empty test 1 cmp + branch, offset 2.
        DstNodeKind::DualCarve => Mix::new(16, 2, 2, 5, 0, 0),
        // Leaf word: header decode 5 (shift, mask, type test, branch, offset mask). The
        // triangle run's set-up is the leaf entry that follows (`LEAF`, reported by the
        // traversal as `NodeStep::Leaf`), so it is not counted twice here.
        DstNodeKind::Leaf => Mix::new(5, 0, 0, 0, 0, 0),
    }
    .with_code(code)
}

impl Mix {
    fn with_code(mut self, code: u8) -> Self {
        // Code 0 (miss) leaves through an early branch: no offset arithmetic for the child.
        if code == 0 {
            self.int = self.int.saturating_sub(2);
        }
        self
    }
}

/// A fixed-function pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Pipe {
    /// Ray-box (Kopta et al. 2013; Lin et al. 2020, Table 2).
    Box,
    /// Ray-triangle.
    Triangle,
    /// Dual-split (Lin et al. 2020, §3, Table 2).
    DualSplit,
}

/// A macro-operation of a simulated thread (notes §5.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `n` single-issue instructions that use the results of earlier loads/pipeline ops;
    /// `fpinv` of them go to the shared reciprocal unit.
    Issue {
        /// Instructions.
        n: u32,
        /// Of which reciprocal / inverse-square-root ops.
        fpinv: u32,
    },
    /// `words` non-blocking word loads from byte address `addr` (one issue slot each).
    Load {
        /// Byte address of the first word (word-aligned).
        addr: u64,
        /// Consecutive words.
        words: u32,
    },
    /// `n` operations on a pipeline; `parallel` sends them to `n` pipes in one issue slot
    /// (the "+" configurations), otherwise one issue slot each on the TM's pipes.
    Pipe {
        /// Which pipeline.
        pipe: Pipe,
        /// Operations.
        n: u8,
        /// All at once on parallel pipes.
        parallel: bool,
    },
}

/// Instruction and event counts gathered functionally (they do not depend on timing).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct InstrCounts {
    /// Instructions by class (loads and pipeline ops are counted separately below).
    pub mix: Mix,
    /// Load instructions (one L1 access each, per word).
    pub loads: u64,
    /// Ray-box pipeline ops.
    pub box_ops: u64,
    /// Ray-box pipeline issue instructions.
    pub box_issues: u64,
    /// Ray-triangle pipeline ops.
    pub tri_ops: u64,
    /// Dual-split pipeline ops.
    pub dst_ops: u64,
    /// Internal node steps (BVH nodes; DST splitting and carving nodes).
    pub node_steps: u64,
    /// Global atomic increments (pixel hand-out).
    pub atomics: u64,
}

impl InstrCounts {
    /// All issued instructions.
    pub fn total(&self) -> u64 {
        self.mix_total() + self.loads + self.box_issues + self.tri_ops + self.dst_ops + self.atomics
    }
    fn mix_total(&self) -> u64 {
        self.mix.total() as u64
    }
    /// Adds `o` into `self`.
    pub fn add(&mut self, o: &InstrCounts) {
        self.mix.add(o.mix);
        self.loads += o.loads;
        self.box_ops += o.box_ops;
        self.box_issues += o.box_issues;
        self.tri_ops += o.tri_ops;
        self.dst_ops += o.dst_ops;
        self.node_steps += o.node_steps;
        self.atomics += o.atomics;
    }
}

/// The observer the simulator passes to the traversal: appends macro-ops to a thread's
/// program and counts instructions.
pub struct Recorder<'a> {
    accel: SimAccel,
    ops: &'a mut Vec<Op>,
    /// Counts so far.
    pub counts: InstrCounts,
    /// Byte address added to every fetch (where the image lives in simulated memory).
    pub base: u64,
}

impl<'a> Recorder<'a> {
    /// Records into `ops` for configuration `accel`.
    pub fn new(accel: SimAccel, ops: &'a mut Vec<Op>) -> Self {
        Self {
            accel,
            ops,
            counts: InstrCounts::default(),
            base: 0,
        }
    }

    /// Appends instructions of mix `m` (merged into a preceding `Issue`).
    pub fn issue(&mut self, m: Mix) {
        self.counts.mix.add(m);
        let n = m.total();
        if let Some(Op::Issue { n: pn, fpinv }) = self.ops.last_mut() {
            *pn += n;
            *fpinv += m.fpinv;
        } else {
            self.ops.push(Op::Issue { n, fpinv: m.fpinv });
        }
    }

    fn pipe(&mut self, pipe: Pipe, n: u8, parallel: bool) {
        if n == 0 {
            return;
        }
        match pipe {
            Pipe::Box => {
                self.counts.box_ops += n as u64;
                self.counts.box_issues += if parallel { 1 } else { n as u64 };
            }
            Pipe::Triangle => self.counts.tri_ops += n as u64,
            Pipe::DualSplit => self.counts.dst_ops += n as u64,
        }
        self.ops.push(Op::Pipe { pipe, n, parallel });
    }

    /// Records the global atomic increment that hands a pixel to the thread.
    pub fn atomic(&mut self) {
        self.counts.atomics += 1;
    }

    fn parallel_boxes(&self) -> bool {
        matches!(
            self.accel,
            SimAccel::Bvh2Plus | SimAccel::Bvh4Plus | SimAccel::Bvh8Plus
        )
    }
}

impl Observer for Recorder<'_> {
    #[inline]
    fn fetch(&mut self, addr: u64, bytes: u32) {
        let a = self.base + addr;
        let first = a & !3;
        let words = ((a + bytes as u64).div_ceil(4) * 4 - first) / 4;
        if words == 0 {
            return;
        }
        self.counts.loads += words;
        self.ops.push(Op::Load {
            addr: first,
            words: words as u32,
        });
    }

    #[inline]
    fn step(&mut self, step: NodeStep) {
        match step {
            NodeStep::Bvh { valid, hits, .. } => {
                self.counts.node_steps += 1;
                let parallel = self.parallel_boxes();
                self.pipe(Pipe::Box, valid, parallel);
                let mut m = BVH_NODE;
                for _ in 0..valid {
                    m.add(BVH_PER_CHILD);
                }
                for _ in 0..hits {
                    m.add(BVH_PER_HIT);
                }
                let pairs = (hits as u32 * hits.saturating_sub(1) as u32) / 2;
                for _ in 0..pairs {
                    m.add(BVH_SORT_PAIR);
                }
                self.issue(m);
            }
            NodeStep::Dst { kind, code, .. } => {
                if kind != DstNodeKind::Leaf {
                    self.counts.node_steps += 1;
                }
                if self.accel == SimAccel::Dst {
                    self.pipe(Pipe::DualSplit, 1, false);
                    self.issue(DST_HW_STEP);
                } else {
                    self.issue(dst_sw_step(kind, code));
                }
            }
            NodeStep::Leaf { .. } => self.issue(LEAF),
        }
    }

    #[inline]
    fn triangle_test(&mut self, _prim: u32, hit: bool) {
        self.pipe(Pipe::Triangle, 1, false);
        self.issue(TRI_TEST);
        if hit {
            self.issue(TRI_ACCEPT);
        }
    }

    #[inline]
    fn push(&mut self) {
        self.issue(PUSH);
    }

    #[inline]
    fn pop(&mut self) {
        self.issue(POP);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fetch_covers_every_touched_word() {
        let mut ops = Vec::new();
        let mut r = Recorder::new(SimAccel::Bvh2, &mut ops);
        r.fetch(52, 52);
        r.fetch(6, 4); // straddles two words
        assert_eq!(r.counts.loads, 15);
        assert_eq!(
            ops,
            vec![
                Op::Load {
                    addr: 52,
                    words: 13
                },
                Op::Load { addr: 4, words: 2 }
            ]
        );
    }

    #[test]
    fn serial_and_parallel_box_issue() {
        for (accel, issues) in [(SimAccel::Bvh4, 3), (SimAccel::Bvh4Plus, 1)] {
            let mut ops = Vec::new();
            let mut r = Recorder::new(accel, &mut ops);
            r.step(NodeStep::Bvh {
                arity: 4,
                valid: 3,
                hits: 2,
            });
            assert_eq!(r.counts.box_ops, 3);
            assert_eq!(r.counts.box_issues, issues);
            // node 4 + 3 children × 2 + 2 hits × 2 + 1 sort pair × 3
            assert_eq!(r.counts.mix.total(), 4 + 6 + 4 + 3);
        }
    }

    #[test]
    fn dst_hw_is_one_pipeline_op_and_sw_is_instructions() {
        let step = NodeStep::Dst {
            kind: DstNodeKind::Split,
            code: 2,
            carving_leaf: false,
        };
        let mut ops = Vec::new();
        let mut r = Recorder::new(SimAccel::Dst, &mut ops);
        r.step(step);
        assert_eq!(r.counts.dst_ops, 1);
        assert_eq!(r.counts.mix.total(), DST_HW_STEP.total());
        let mut ops = Vec::new();
        let mut r = Recorder::new(SimAccel::DstSw, &mut ops);
        r.step(step);
        assert_eq!(r.counts.dst_ops, 0);
        assert_eq!(r.counts.mix.total(), 24);
    }
}
