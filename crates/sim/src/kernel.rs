//! Kernel costs: the instruction sequence each traversal step stands for, per configuration,
//! and the recording observer that turns a traversal's events into macro-operations.
//!
//! The traversal code is the real one (`dualsplit_accel::Structures`, contract 2 of
//! `docs/architecture.md`); this module only translates what it reports: every `fetch`
//! becomes word loads at the image's byte addresses, every node step a pipeline op plus the
//! instructions around it, every triangle test a ray-triangle pipeline op. The counts are
//! justified one by one in `docs/simulator.md` ("Instruction counts per kernel step").

use crate::SimAccel;
use dualsplit_accel::dst::pipeline::ReturnCode;
use dualsplit_accel::{ByteAddr, DstNodeKind, NodeStep, Observer};
use dualsplit_geometry::PrimId;
use serde::{Deserialize, Serialize};

/// Instruction mix of one kernel step, by functional-unit class (energy and issue slots);
/// also the frame's totals in [`InstrCounts::mix`], hence 64-bit counters (a 512×512
/// DST* path-traced frame issues more than 2^32 instructions).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Mix {
    /// Integer add, bitwise, compare-and-branch, move.
    pub int: u64,
    /// FP add/sub.
    pub fpadd: u64,
    /// FP multiply.
    pub fpmul: u64,
    /// FP min/max/compare.
    pub fpcmp: u64,
    /// FP reciprocal / inverse square root (shared unit, long latency).
    pub fpinv: u64,
    /// Local-store (stack) accesses.
    pub local: u64,
}

impl Mix {
    const fn new(int: u64, fpadd: u64, fpmul: u64, fpcmp: u64, fpinv: u64, local: u64) -> Self {
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
    pub const fn total(&self) -> u64 {
        self.int + self.fpadd + self.fpmul + self.fpcmp + self.fpinv + self.local
    }
    /// `self` taken `k` times (exact: the fields are integers).
    #[inline(always)]
    const fn times(self, k: u64) -> Mix {
        Mix::new(
            self.int * k,
            self.fpadd * k,
            self.fpmul * k,
            self.fpcmp * k,
            self.fpinv * k,
            self.local * k,
        )
    }
    #[inline(always)]
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

/// DST on the dual-split pipeline, per return code (Lin et al. 2020, §3, Fig. 6): the
/// pipeline instruction itself is the `Pipe` op; around it, the branch chain on the 2-bit
/// return code and the moves of its outputs (`docs/simulator.md` writes the sequence out):
///
/// ```text
///         dst   rc, …            ; pipeline op (header, p0, p1, ray, t_min, t_max)
///         beqz  rc, POP          ; code 0: 1
///         slti  t, rc, 2
///         beqz  t, NOT1
///         add   node, base, off  ; code 1: next node
///         mov   tmin, tmin_out
///         mov   tmax, tmax_out
///         j     LOOP             ; code 1: 7
/// NOT1:   slti  t, rc, 3
///         beqz  t, LEAFRUN       ; code 3: 5 (the run set-up is `LEAF`)
///         (push off_stack, tmin_out, tmax)   ; `DST_PUSH`
///         add   node, base, off
///         mov   tmax, tmax_out
///         j     LOOP             ; code 2: 8
/// ```
pub const fn dst_hw_step(code: ReturnCode) -> Mix {
    match code {
        ReturnCode::Miss => Mix::new(1, 0, 0, 0, 0, 0),
        ReturnCode::OneChild => Mix::new(7, 0, 0, 0, 0, 0),
        ReturnCode::BothChildren => Mix::new(8, 0, 0, 0, 0, 0),
        ReturnCode::Leaf => Mix::new(5, 0, 0, 0, 0, 0),
    }
}

/// DST stack push: the entry is the node and its ray interval `[t_min, t_max]` (Lin et al.
/// 2020, §3, Fig. 3): three local-store stores and the pointer bump.
pub const DST_PUSH: Mix = Mix::new(1, 0, 0, 0, 0, 3);
/// DST stack pop: decrement, empty test, three local-store loads, `t_min` against the cull
/// limit and branch, `t_max = min(t_max, limit)`.
pub const DST_POP: Mix = Mix::new(3, 0, 0, 2, 0, 3);

/// DST decoded in software (DST*), per node kind and outcome (Lin et al. 2020, §3, Figs.
/// 2–4): the header is dispatched with sign-bit branches (C is bit 31; L is tested as
/// `sll 5; bltz`), the axis is extracted with shifts and masks, the ray's origin and inverse
/// direction components are loaded from the thread's local store by axis index (registers
/// cannot be indexed), each plane costs `sub, mul` (`(p − o[a])·inv[a]`), an exit-role
/// distance one more `mul` (`widen_exit`), the role by the direction's sign is a branch,
/// min/max and the interval tests are FP compares, and a child is addressed from the 26-bit
/// offset (and B, the left size, for the right child). Every instruction is written out in
/// `docs/simulator.md` ("DST* decoder sequences").
pub const fn dst_sw_step(kind: DstNodeKind, code: ReturnCode) -> Mix {
    let hit = !matches!(code, ReturnCode::Miss);
    match kind {
        // dispatch 3, axis 1, index 2 + 2 local loads, 2 × (sub, mul), sign select (bltz,
        // mov, j, mul widen), 2 tests (2 cmp, 2 branches); then code 0: j POP (12 int);
        // a hit: offsets 7 (and, sll, add; srl, andi, sll, add), near/far address select 3
        // (bltz, 2 mov), t_max = min / t_min = max (1 cmp), mov node, j LOOP (23 int); code 2
        // adds the pushed entry's t_min = max(t_min, t2) (1 cmp).
        DstNodeKind::Split => match code {
            ReturnCode::Miss => Mix::new(12, 2, 3, 2, 0, 2),
            ReturnCode::OneChild => Mix::new(23, 2, 3, 3, 0, 2),
            ReturnCode::BothChildren | ReturnCode::Leaf => Mix::new(23, 2, 3, 4, 0, 2),
        },
        // dispatch 5 (bltz, srl, andi, addi, bnez), axis 2 (srl, andi), index 2 + 2 local,
        // 2 × (sub, mul), sign select 3 + mul, lo = max, hi = min (2 cmp), empty test (1 cmp,
        // 1 branch); code 0: j POP (14 int); a hit: commit t_min/t_max (2 mov), leaf flag
        // (sll, bltz), offset (and, sll, add), j (21 int).
        DstNodeKind::SingleCarve => {
            if hit {
                Mix::new(21, 2, 3, 3, 0, 2)
            } else {
                Mix::new(14, 2, 3, 3, 0, 2)
            }
        }
        // dispatch 5, axis pair 3 (srl, andi, addi), index 2 × (sll, add) + 4 local, 2 ×
        // (sub, mul), lo/hi = t_min/t_max (2 mov), per plane: sign bit, corner bit (srl, srl,
        // andi), bne (4 int), then exit: mul widen, min, j / entry: max (2 planes: 9 int,
        // 1 mul, 2 cmp on average), empty test (1 cmp, 1 branch); code 0: j POP (25 int);
        // a hit: commit 2, leaf flag 2, offset 3, j (32 int).
        DstNodeKind::DualCarve => {
            if hit {
                Mix::new(32, 2, 3, 3, 0, 4)
            } else {
                Mix::new(25, 2, 3, 3, 0, 4)
            }
        }
        // Leaf word: dispatch 3 (bltz, sll, bltz taken) and the offset mask (and). The run's
        // set-up is the leaf entry that follows (`LEAF`, reported by the traversal as
        // `NodeStep::Leaf`), so it is not counted twice here.
        DstNodeKind::Leaf => Mix::new(4, 0, 0, 0, 0, 0),
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

/// A macro-operation of a simulated thread: an instruction run, a load, or a pipeline op.
///
/// Eight bytes (a one-byte tag and narrow fields), so that the replay's op buffers take
/// half the host cache lines of a 16-byte op (`docs/simulator.md`, "How the simulator
/// runs fast").
/// The narrow fields are checked where ops are made ([`Op::load`], [`Recorder`]): a value
/// that does not fit is an [`OpRangeError`], never a silent wrap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `n` single-issue instructions that use the results of earlier loads/pipeline ops;
    /// `fpinv` of them go to the shared reciprocal unit.
    Issue {
        /// Of which reciprocal / inverse-square-root ops.
        fpinv: u16,
        /// Instructions.
        n: u32,
    },
    /// `words` non-blocking word loads from word address `word` (byte address / 4; one
    /// issue slot each). A 32-bit word address covers 16 GiB of simulated memory.
    Load {
        /// Consecutive words.
        words: u16,
        /// Word address of the first word (byte address / 4).
        word: u32,
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

const _: () = assert!(std::mem::size_of::<Op>() == 8, "Op must stay 8 bytes");

impl Op {
    /// A load of `words` words from word-aligned byte address `addr`, checked against the
    /// op's field widths (word address below 2^32, i.e. 16 GiB; at most 65 535 words).
    pub fn load(addr: u64, words: u64) -> Result<Op, OpRangeError> {
        let word = u32::try_from(addr / 4).map_err(|_| OpRangeError::Address { addr })?;
        let words = u16::try_from(words).map_err(|_| OpRangeError::Words { words })?;
        Ok(Op::Load { words, word })
    }
}

/// A traversal step that does not fit an 8-byte [`Op`] (a scene image beyond 16 GiB, a
/// fetch of more than 65 535 words, or an instruction run beyond the counters' widths).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum OpRangeError {
    /// The byte address's word index does not fit 32 bits.
    #[error("load at byte address {addr:#x} is beyond the simulator's 16 GiB address space")]
    Address {
        /// Byte address of the load.
        addr: u64,
    },
    /// More words in one fetch than a load op holds.
    #[error("a fetch of {words} words exceeds the 65 535 words of one load op")]
    Words {
        /// Words fetched.
        words: u64,
    },
    /// More reciprocal ops in one merged instruction run than an issue op holds.
    #[error("{fpinv} reciprocal ops in one instruction run exceed the 65 535 of one issue op")]
    Fpinv {
        /// Reciprocal ops of the run.
        fpinv: u64,
    },
    /// More instructions in one merged run than an issue op holds.
    #[error("{n} instructions in one run exceed the 2^32 − 1 of one issue op")]
    Issue {
        /// Instructions of the run.
        n: u64,
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
    /// The counts of a compiled-kernel frame from its instructions per
    /// [`FuClass`](crate::rv32::FuClass) (indexed by [`crate::rv32::fu_index`]) and the TMs'
    /// pipeline op counts, in the classes the energy model prices: integer ALU, branch,
    /// integer multiply and conversion/move instructions as `int`; FP add as `fpadd`; FP
    /// multiply and fused multiply-add as `fpmul`; FP compare and min/max as `fpcmp`;
    /// divides, square roots and reciprocals (the TM's FPINV unit) as `fpinv`; local-store
    /// accesses as `local`; global loads and stores as `loads`.
    pub fn from_classes(c: &crate::tp::ClassCounts, units: &crate::tm::UnitStats) -> Self {
        use crate::rv32::{FuClass as F, run::fu_index};
        let n = |f: F| c[fu_index(f)];
        InstrCounts {
            mix: Mix {
                int: n(F::IntAlu)
                    + n(F::Branch)
                    + n(F::IntMul)
                    + n(F::FpConv)
                    + n(F::FpMove)
                    + n(F::Halt),
                fpadd: n(F::FpAdd),
                fpmul: n(F::FpMul) + n(F::FpFma),
                fpcmp: n(F::FpCmp) + n(F::FpMinMax),
                fpinv: n(F::IntDiv) + n(F::FpDiv) + n(F::FpSqrt) + n(F::Rcp),
                local: n(F::LocalLoad) + n(F::LocalStore),
            },
            loads: n(F::Load) + n(F::Store),
            box_ops: units.box_ops,
            box_issues: n(F::BoxPipe(1)),
            tri_ops: n(F::TriPipe),
            dst_ops: n(F::DstPipe),
            node_steps: 0,
            atomics: n(F::Atomic),
        }
    }

    /// All issued instructions.
    pub fn total(&self) -> u64 {
        self.mix_total() + self.loads + self.box_issues + self.tri_ops + self.dst_ops + self.atomics
    }
    fn mix_total(&self) -> u64 {
        self.mix.total()
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

/// Kernel steps counted by kind: their instruction mixes are constants (or, for a BVH node,
/// linear in its child counts), so a step adds 1 to a counter and the mixes are multiplied
/// out once, when the counts are read ([`Tally::counts`]). Integer arithmetic: the totals
/// are exactly those of adding each step's mix as it happens.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Steps {
    push: u64,
    pop: u64,
    leaf: u64,
    tri_test: u64,
    tri_accept: u64,
    /// BVH node steps by (valid children, hit children), both at most 8: one counter to
    /// add per node.
    bvh: [[u64; 9]; 9],
    /// BVH node steps with more than 8 valid or hit children (no layout has them; counted
    /// apart so that the table above stays small): nodes, nodes with a valid child, and
    /// Σvalid, Σhits, Σpairs.
    bvh_wide: [u64; 5],
    /// DST steps by node kind (the enum's order) and return code.
    dst: [[u64; 4]; 4],
}

/// The DST node kinds in the enum's order: `kind as usize` indexes [`Steps::dst`] and the
/// step tables.
const DST_KINDS: [DstNodeKind; 4] = [
    DstNodeKind::Split,
    DstNodeKind::SingleCarve,
    DstNodeKind::DualCarve,
    DstNodeKind::Leaf,
];
const _: () = {
    let mut k = 0;
    while k < 4 {
        assert!(
            DST_KINDS[k] as usize == k,
            "DST_KINDS must follow DstNodeKind's order"
        );
        k += 1;
    }
};

/// Instructions of each DST step on the pipeline, by return code ([`dst_hw_step`]).
const DST_HW_TOTAL: [u64; 4] = {
    let mut t = [0; 4];
    let mut c = 0;
    while c < 4 {
        t[c] = dst_hw_step(ReturnCode::ALL[c]).total();
        c += 1;
    }
    t
};

/// Instructions of each DST* step, by node kind and return code ([`dst_sw_step`]).
const DST_SW_TOTAL: [[u64; 4]; 4] = {
    let mut t = [[0; 4]; 4];
    let mut k = 0;
    while k < 4 {
        let mut c = 0;
        while c < 4 {
            t[k][c] = dst_sw_step(DST_KINDS[k], ReturnCode::ALL[c]).total();
            c += 1;
        }
        k += 1;
    }
    t
};

/// Instructions of a BVH node step with `valid` valid and `hits` hit children (both at
/// most 8), by [`bvh_total`].
const BVH_STEP_TOTAL: [[u64; 9]; 9] = {
    let mut t = [[0; 9]; 9];
    let mut v = 0;
    while v < 9 {
        let mut h = 0;
        while h < 9 {
            t[v][h] = bvh_total(v as u64, h as u64, bvh_pairs(h as u64));
            h += 1;
        }
        v += 1;
    }
    t
};

/// Compare-exchanges of the entry-distance sort of `hits` children: `hits·(hits − 1)/2`.
const fn bvh_pairs(hits: u64) -> u64 {
    hits * hits.saturating_sub(1) / 2
}

/// Instructions of a BVH node step: node overhead, per valid child, per hit child and per
/// compare-exchange of the entry-distance sort (`hits·(hits − 1)/2` pairs).
#[inline(always)]
const fn bvh_total(valid: u64, hits: u64, pairs: u64) -> u64 {
    BVH_NODE.total()
        + BVH_PER_CHILD.total() * valid
        + BVH_PER_HIT.total() * hits
        + BVH_SORT_PAIR.total() * pairs
}

/// What the recorders of one frame count, summed over every ray: instruction and event
/// counts, kernel steps by kind, and the first step that did not fit an [`Op`].
#[derive(Clone, Debug)]
pub struct Tally {
    accel: SimAccel,
    /// Counts besides the kernel steps' instruction mixes.
    counts: InstrCounts,
    steps: Steps,
    error: Option<OpRangeError>,
}

impl Tally {
    /// Nothing counted yet, for configuration `accel`.
    pub fn new(accel: SimAccel) -> Self {
        Self {
            accel,
            counts: InstrCounts::default(),
            steps: Steps::default(),
            error: None,
        }
    }

    /// The counts so far, every kernel step's instruction mix included.
    pub fn counts(&self) -> InstrCounts {
        let s = &self.steps;
        let dst = self.accel.is_dst();
        let parallel = self.accel.parallel_boxes();
        let mut c = self.counts;
        // The BVH node steps' sums, from the (valid, hits) table.
        let [
            mut bvh_nodes,
            mut bvh_boxed,
            mut bvh_valid,
            mut bvh_hits,
            mut bvh_pairs_sum,
        ] = s.bvh_wide;
        for (v, row) in s.bvh.iter().enumerate() {
            for (h, &n) in row.iter().enumerate() {
                let (v, h) = (v as u64, h as u64);
                bvh_nodes += n;
                bvh_boxed += if v != 0 { n } else { 0 };
                bvh_valid += v * n;
                bvh_hits += h * n;
                bvh_pairs_sum += bvh_pairs(h) * n;
            }
        }
        // Pipeline ops and node steps: one box op per valid child (one issue slot per node
        // on parallel pipes), one triangle op per test, one dual-split op per DST step on
        // the pipeline; node steps are BVH nodes and DST steps other than leaf words.
        c.box_ops += bvh_valid;
        c.box_issues += if parallel { bvh_boxed } else { bvh_valid };
        c.tri_ops += s.tri_test;
        let dst_steps: u64 = s.dst.iter().flatten().sum();
        if self.accel == SimAccel::Dst {
            c.dst_ops += dst_steps;
        }
        c.node_steps +=
            bvh_nodes + dst_steps - s.dst[DstNodeKind::Leaf as usize].iter().sum::<u64>();
        let m = &mut c.mix;
        m.add(if dst { DST_PUSH } else { PUSH }.times(s.push));
        m.add(if dst { DST_POP } else { POP }.times(s.pop));
        m.add(LEAF.times(s.leaf));
        m.add(TRI_TEST.times(s.tri_test));
        m.add(TRI_ACCEPT.times(s.tri_accept));
        m.add(BVH_NODE.times(bvh_nodes));
        m.add(BVH_PER_CHILD.times(bvh_valid));
        m.add(BVH_PER_HIT.times(bvh_hits));
        m.add(BVH_SORT_PAIR.times(bvh_pairs_sum));
        for (kind, row) in DST_KINDS.into_iter().zip(&s.dst) {
            for (code, &n) in ReturnCode::ALL.into_iter().zip(row) {
                let step = if self.accel == SimAccel::Dst {
                    dst_hw_step(code)
                } else {
                    dst_sw_step(kind, code)
                };
                m.add(step.times(n));
            }
        }
        c
    }

    /// The first step that did not fit an [`Op`] (a program is then incomplete).
    pub fn error(&self) -> Option<OpRangeError> {
        self.error
    }

    /// Counts the global atomic increment that hands a pixel to a thread.
    pub fn atomic(&mut self) {
        self.counts.atomics += 1;
    }

    /// Keeps the first range error.
    #[cold]
    fn fail(&mut self, e: OpRangeError) {
        self.error.get_or_insert(e);
    }
}

/// The observer the simulator passes to the traversal: appends macro-ops to a thread's
/// program and counts instructions into a [`Tally`].
///
/// Consecutive instruction runs merge into one [`Op::Issue`]. The run being merged is kept
/// in the recorder, not in the op buffer, and written out when a load or pipeline op follows
/// or the recording ends ([`Recorder::finish`], [`Recorder::finish_open`]); a kernel step
/// adds its instruction count to the run and 1 to its kind's counter in the tally (one
/// add each instead of a read-modify-write of the buffer's last op). The ops and counts are exactly those of merging
/// into the buffer's last op and adding each step's mix; a test compares both on random
/// event streams.
pub struct Recorder<'a> {
    ops: &'a mut Vec<Op>,
    tally: &'a mut Tally,
    /// The open run: [`OPEN`] plus its instructions (below 2^32) while the last op recorded
    /// is the (unwritten) run, 0 when there is none.
    run: u64,
    /// The open run's reciprocal ops (below 2^16; 0 when there is no open run).
    run_fpinv: u64,
    /// DST configurations: the stack entries carry `[t_min, t_max]`.
    dst: bool,
    /// DST on the dual-split pipeline (not decoded in software).
    dst_hw: bool,
    /// The "+" configurations: all child boxes in one issue slot.
    parallel_boxes: bool,
}

/// The flag of [`Recorder`]'s open run (above any instruction count an op holds).
const OPEN: u64 = 1 << 63;

/// An instruction run being merged: the fields of its future [`Op::Issue`], already checked
/// against their widths.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Run {
    /// Instructions.
    pub n: u32,
    /// Of which reciprocal / inverse-square-root ops.
    pub fpinv: u16,
}

impl Run {
    /// The run as an op.
    pub fn op(self) -> Op {
        Op::Issue {
            n: self.n,
            fpinv: self.fpinv,
        }
    }
}

impl<'a> Recorder<'a> {
    /// Records into `ops`, counting into `tally`; a trailing `Issue` of `ops` is continued
    /// (the next instructions merge into it).
    pub fn new(tally: &'a mut Tally, ops: &'a mut Vec<Op>) -> Self {
        let run = match ops.last() {
            Some(&Op::Issue { n, fpinv }) => {
                ops.pop();
                Some(Run { n, fpinv })
            }
            _ => None,
        };
        Self::resume(tally, ops, run)
    }

    /// Records into `ops`, counting into `tally`, continuing the open run `run` (the trailing
    /// `Issue` of the previous recording, see [`Recorder::finish_open`]) as if it were the
    /// last op of `ops`.
    #[inline]
    pub fn resume(tally: &'a mut Tally, ops: &'a mut Vec<Op>, run: Option<Run>) -> Self {
        let accel = tally.accel;
        Self {
            ops,
            tally,
            run: run.map_or(0, |r| OPEN | r.n as u64),
            run_fpinv: run.map_or(0, |r| r.fpinv as u64),
            dst: accel.is_dst(),
            dst_hw: accel == SimAccel::Dst,
            parallel_boxes: accel.parallel_boxes(),
        }
    }

    /// The tally counted into (the open run's instructions are in its counts already).
    pub fn tally(&self) -> &Tally {
        self.tally
    }

    /// Ends the recording with the open run written to the ops.
    pub fn finish(mut self) {
        self.close_run();
    }

    /// Ends the recording leaving the open run out of the ops: it is returned, to be
    /// continued by the next recording ([`Recorder::resume`]) or written as the program's
    /// last op.
    #[inline]
    pub fn finish_open(mut self) -> Option<Run> {
        (self.run != 0).then(|| self.checked_run())
    }

    /// Appends instructions of mix `m` (merged into a preceding `Issue`).
    #[inline(always)]
    pub fn issue(&mut self, m: Mix) {
        self.tally.counts.mix.add(m);
        // Merged into the open run: the sums are checked against the op's widths (here,
        // not only when the run is written: a run that does not fit keeps its last count).
        let (n, fpinv) = ((self.run & !OPEN) + m.total(), self.run_fpinv + m.fpinv);
        if n > u32::MAX as u64 {
            self.tally.fail(OpRangeError::Issue { n });
        } else if fpinv > u16::MAX as u64 {
            self.tally.fail(OpRangeError::Fpinv { fpinv });
        } else {
            (self.run, self.run_fpinv) = (OPEN | n, fpinv);
        }
    }

    /// A BVH node step with more than 8 valid or hit children (no layout has them).
    #[cold]
    #[inline(never)]
    fn wide_bvh_step(&mut self, valid: u64, hits: u64) {
        let pairs = bvh_pairs(hits);
        let w = &mut self.tally.steps.bvh_wide;
        for (k, x) in [1, (valid != 0) as u64, valid, hits, pairs]
            .into_iter()
            .enumerate()
        {
            w[k] += x;
        }
        self.extend_run(bvh_total(valid, hits, pairs));
    }

    /// Merges `n` instructions without reciprocals into the open run (opening one if
    /// needed). The run's width is checked when it is written or handed on
    /// ([`Recorder::run_op`]): a kernel step adds a few instructions, so the 64-bit sum
    /// cannot wrap before that.
    #[inline(always)]
    fn extend_run(&mut self, n: u64) {
        self.run = (self.run | OPEN) + n;
    }

    /// The open run, its instruction count checked against the op's width (an
    /// [`OpRangeError::Issue`] is kept in the tally, and the run then carries the largest
    /// count an op holds).
    #[inline(always)]
    fn checked_run(&mut self) -> Run {
        let n = self.run & !OPEN;
        if n > u32::MAX as u64 {
            self.tally.fail(OpRangeError::Issue { n });
        }
        Run {
            n: n.min(u32::MAX as u64) as u32,
            fpinv: self.run_fpinv as u16,
        }
    }

    /// The open run as an `Issue` op (width-checked), now closed; `None` when there is none.
    #[inline(always)]
    fn take_run(&mut self) -> Option<Op> {
        if self.run == 0 {
            return None;
        }
        let run = self.checked_run().op();
        (self.run, self.run_fpinv) = (0, 0);
        Some(run)
    }

    /// Writes the open run (if any) as an `Issue` op, then `op` (a load or pipeline op).
    #[inline(always)]
    fn close_run_then(&mut self, op: Op) {
        match self.take_run() {
            Some(run) => self.ops.extend_from_slice(&[run, op]),
            None => self.ops.push(op),
        }
    }

    /// Writes the open run (if any) as an `Issue` op.
    #[inline(always)]
    fn close_run(&mut self) {
        if let Some(run) = self.take_run() {
            self.ops.push(run);
        }
    }

    /// Appends a pipeline op (counted from the steps, in [`Tally::counts`]).
    #[inline(always)]
    fn pipe(&mut self, pipe: Pipe, n: u8, parallel: bool) {
        self.close_run_then(Op::Pipe { pipe, n, parallel });
    }
}

impl Observer for Recorder<'_> {
    #[inline(always)]
    fn fetch(&mut self, ByteAddr(addr): ByteAddr, bytes: u32) {
        // Words from the one holding byte `addr` to the one holding byte `addr + bytes − 1`.
        let words = ((addr & 3) + bytes as u64).div_ceil(4);
        if words == 0 {
            return;
        }
        self.tally.counts.loads += words;
        match Op::load(addr & !3, words) {
            Ok(op) => self.close_run_then(op),
            Err(e) => self.tally.fail(e),
        }
    }

    #[inline(always)]
    fn step(&mut self, step: NodeStep) {
        match step {
            NodeStep::Bvh { valid, hits, .. } => {
                if valid != 0 {
                    self.pipe(Pipe::Box, valid, self.parallel_boxes);
                }
                if valid <= 8 && hits <= 8 {
                    self.tally.steps.bvh[valid as usize][hits as usize] += 1;
                    self.extend_run(BVH_STEP_TOTAL[valid as usize][hits as usize]);
                } else {
                    self.wide_bvh_step(valid as u64, hits as u64);
                }
            }
            NodeStep::Dst { kind, code, .. } => {
                let (k, c) = (kind as usize, code as usize);
                self.tally.steps.dst[k][c] += 1;
                if self.dst_hw {
                    self.pipe(Pipe::DualSplit, 1, false);
                    self.extend_run(DST_HW_TOTAL[c]);
                } else {
                    self.extend_run(DST_SW_TOTAL[k][c]);
                }
            }
            NodeStep::Leaf { .. } => {
                self.tally.steps.leaf += 1;
                self.extend_run(LEAF.total());
            }
        }
    }

    #[inline(always)]
    fn triangle_test(&mut self, _prim: PrimId, hit: bool) {
        self.pipe(Pipe::Triangle, 1, false);
        self.tally.steps.tri_test += 1;
        self.extend_run(TRI_TEST.total());
        if hit {
            self.tally.steps.tri_accept += 1;
            self.extend_run(TRI_ACCEPT.total());
        }
    }

    #[inline(always)]
    fn push(&mut self) {
        self.tally.steps.push += 1;
        self.extend_run(if self.dst { DST_PUSH } else { PUSH }.total());
    }

    #[inline(always)]
    fn pop(&mut self) {
        self.tally.steps.pop += 1;
        self.extend_run(if self.dst { DST_POP } else { POP }.total());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dualsplit_geometry::Pcg32;

    /// A plain recorder: every instruction run is merged into the op buffer's last op. The
    /// reference of
    /// `recorder_matches_merging_into_the_last_op`.
    struct Reference<'a> {
        accel: SimAccel,
        ops: &'a mut Vec<Op>,
        counts: InstrCounts,
        error: Option<OpRangeError>,
    }

    impl Reference<'_> {
        fn issue(&mut self, m: Mix) {
            self.counts.mix.add(m);
            let (pn, pf) = match self.ops.last() {
                Some(&Op::Issue { n, fpinv }) => (n as u64, fpinv as u64),
                _ => (0, 0),
            };
            let (n, fpinv) = (pn + m.total(), pf + m.fpinv);
            let op = match (u32::try_from(n), u16::try_from(fpinv)) {
                (Ok(n), Ok(fpinv)) => Op::Issue { n, fpinv },
                (Err(_), _) => return self.fail(OpRangeError::Issue { n }),
                (_, Err(_)) => return self.fail(OpRangeError::Fpinv { fpinv }),
            };
            match self.ops.last_mut() {
                Some(last @ Op::Issue { .. }) => *last = op,
                _ => self.ops.push(op),
            }
        }
        fn fail(&mut self, e: OpRangeError) {
            self.error.get_or_insert(e);
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
        fn is_dst(&self) -> bool {
            matches!(self.accel, SimAccel::Dst | SimAccel::DstSw)
        }
    }

    impl Observer for Reference<'_> {
        fn fetch(&mut self, ByteAddr(addr): ByteAddr, bytes: u32) {
            let first = addr & !3;
            let words = ((addr + bytes as u64).div_ceil(4) * 4 - first) / 4;
            if words == 0 {
                return;
            }
            self.counts.loads += words;
            match Op::load(first, words) {
                Ok(op) => self.ops.push(op),
                Err(e) => self.fail(e),
            }
        }
        fn step(&mut self, step: NodeStep) {
            match step {
                NodeStep::Bvh { valid, hits, .. } => {
                    self.counts.node_steps += 1;
                    let parallel = matches!(
                        self.accel,
                        SimAccel::Bvh2Plus | SimAccel::Bvh4Plus | SimAccel::Bvh8Plus
                    );
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
                        self.issue(dst_hw_step(code));
                    } else {
                        self.issue(dst_sw_step(kind, code));
                    }
                }
                NodeStep::Leaf { .. } => self.issue(LEAF),
            }
        }
        fn triangle_test(&mut self, _prim: PrimId, hit: bool) {
            self.pipe(Pipe::Triangle, 1, false);
            self.issue(TRI_TEST);
            if hit {
                self.issue(TRI_ACCEPT);
            }
        }
        fn push(&mut self) {
            self.issue(if self.is_dst() { DST_PUSH } else { PUSH });
        }
        fn pop(&mut self) {
            self.issue(if self.is_dst() { DST_POP } else { POP });
        }
    }

    /// One random traversal event (or an instruction run of the ray's set-up and finish).
    fn random_event<O: Observer>(
        rng: &mut Pcg32,
        obs: &mut O,
        issue: &mut impl FnMut(&mut O, Mix),
    ) {
        match rng.below(9) {
            0 => obs.fetch(ByteAddr(rng.below(1 << 20) as u64), rng.below(220)),
            1 => {
                let arity = [2u8, 4, 8][rng.below(3) as usize];
                let valid = rng.below(arity as u32 + 1) as u8;
                let hits = rng.below(valid as u32 + 1) as u8;
                obs.step(NodeStep::Bvh { arity, valid, hits });
            }
            2 => obs.step(NodeStep::Dst {
                kind: DST_KINDS[rng.below(4) as usize],
                code: ReturnCode::ALL[rng.below(4) as usize],
                carving_leaf: rng.below(2) == 1,
            }),
            3 => obs.step(NodeStep::Leaf {
                count: rng.below(8),
            }),
            4 => obs.triangle_test(PrimId(rng.below(1000)), rng.below(2) == 1),
            5 => obs.push(),
            6 => obs.pop(),
            7 => issue(obs, RAY_SETUP),
            _ => issue(obs, [RAY_FINISH, LEAF, PUSH][rng.below(3) as usize]),
        }
    }

    #[test]
    fn recorder_matches_merging_into_the_last_op() {
        for seed in 0..40u64 {
            for accel in SimAccel::ALL {
                let events = 1 + Pcg32::new(seed, 7).below(300);
                // The reference: one recording merging into the buffer's last op.
                let mut want = Vec::new();
                let mut reference = Reference {
                    accel,
                    ops: &mut want,
                    counts: InstrCounts::default(),
                    error: None,
                };
                let mut rng = Pcg32::new(seed, 1);
                for _ in 0..events {
                    random_event(&mut rng, &mut reference, &mut |o: &mut Reference, m| {
                        o.issue(m)
                    });
                }
                let (want_counts, want_error) = (reference.counts, reference.error);
                // The recorder, the stream cut into recordings at random points (as a
                // pixel's rays are), each continuing the previous one's open run.
                let mut got = Vec::new();
                let mut tally = Tally::new(accel);
                let mut run = None;
                let mut rng = Pcg32::new(seed, 1);
                let mut cuts = Pcg32::new(seed, 2);
                let mut left = events;
                while left > 0 {
                    let n = (1 + cuts.below(40)).min(left);
                    left -= n;
                    let mut r = Recorder::resume(&mut tally, &mut got, run);
                    for _ in 0..n {
                        random_event(&mut rng, &mut r, &mut |o: &mut Recorder, m| o.issue(m));
                    }
                    run = r.finish_open();
                }
                got.extend(run.map(Run::op));
                assert_eq!(want_error, None);
                assert_eq!(tally.error(), None);
                assert_eq!(got, want, "seed {seed}, {accel:?}");
                assert_eq!(tally.counts(), want_counts, "seed {seed}, {accel:?}");
                // `new` continues a trailing Issue; `finish` writes the open run.
                let mut again = Vec::new();
                let mut tally = Tally::new(accel);
                let mut rng = Pcg32::new(seed, 1);
                for _ in 0..events {
                    let mut r = Recorder::new(&mut tally, &mut again);
                    random_event(&mut rng, &mut r, &mut |o: &mut Recorder, m| o.issue(m));
                    r.finish();
                }
                assert_eq!(again, want, "seed {seed}, {accel:?}");
                assert_eq!(tally.counts(), want_counts, "seed {seed}, {accel:?}");
            }
        }
    }

    #[test]
    fn fetch_covers_every_touched_word() {
        let mut ops = Vec::new();
        let mut tally = Tally::new(SimAccel::Bvh2);
        let mut r = Recorder::new(&mut tally, &mut ops);
        r.fetch(ByteAddr(52), 52);
        r.fetch(ByteAddr(6), 4); // straddles two words
        assert_eq!(r.tally().counts().loads, 15);
        assert_eq!(
            ops,
            vec![
                Op::Load {
                    word: 13,
                    words: 13
                },
                Op::Load { word: 1, words: 2 }
            ]
        );
    }

    #[test]
    fn ops_are_8_bytes_and_out_of_range_values_are_errors() {
        assert_eq!(std::mem::size_of::<Op>(), 8);
        let top = 4 * u32::MAX as u64;
        assert_eq!(
            Op::load(top, 65_535),
            Ok(Op::Load {
                word: u32::MAX,
                words: 65_535
            })
        );
        assert_eq!(
            Op::load(top + 4, 1),
            Err(OpRangeError::Address { addr: top + 4 })
        );
        assert_eq!(
            Op::load(0, 65_536),
            Err(OpRangeError::Words { words: 65_536 })
        );
        // The recorder keeps the first error instead of wrapping.
        let mut ops = Vec::new();
        let mut tally = Tally::new(SimAccel::Bvh2);
        let mut r = Recorder::new(&mut tally, &mut ops);
        r.fetch(ByteAddr(8), 4);
        assert_eq!(r.tally().error(), None);
        r.fetch(ByteAddr(top + 8), 4);
        r.fetch(ByteAddr(0), 4 * 70_000);
        assert_eq!(
            r.tally().error(),
            Some(OpRangeError::Address { addr: top + 8 })
        );
        // Merged issue runs: reciprocal ops beyond u16, instructions beyond u32.
        let mut ops = Vec::new();
        let mut tally = Tally::new(SimAccel::Bvh2);
        let mut r = Recorder::new(&mut tally, &mut ops);
        let inv = Mix::new(0, 0, 0, 0, 30_000, 0);
        r.issue(inv);
        r.issue(inv);
        assert_eq!(r.tally().error(), None);
        r.issue(inv);
        assert_eq!(
            r.tally().error(),
            Some(OpRangeError::Fpinv { fpinv: 90_000 })
        );
        let mut ops = Vec::new();
        let mut tally = Tally::new(SimAccel::Bvh2);
        let mut r = Recorder::new(&mut tally, &mut ops);
        let big = Mix::new(3_000_000_000, 0, 0, 0, 0, 0);
        r.issue(big);
        r.issue(big);
        assert_eq!(
            r.tally().error(),
            Some(OpRangeError::Issue { n: 6_000_000_000 })
        );
        r.finish();
        assert_eq!(
            ops,
            vec![Op::Issue {
                n: 3_000_000_000,
                fpinv: 0
            }]
        );
    }

    #[test]
    fn a_run_beyond_the_op_width_is_an_error_when_written_or_handed_on() {
        // Kernel steps extend the open run unchecked; the width is checked when the run
        // becomes an op (a load follows, or the recording ends) or is handed to the next ray.
        let near = Run {
            n: u32::MAX - 3,
            fpinv: 0,
        };
        for hand_on in [false, true] {
            let mut ops = Vec::new();
            let mut tally = Tally::new(SimAccel::Bvh2);
            let mut r = Recorder::resume(&mut tally, &mut ops, Some(near));
            r.push(); // + 3: exactly u32::MAX
            assert_eq!(r.tally().error(), None);
            r.pop(); // + 6
            if hand_on {
                let run = r.finish_open();
                assert_eq!(run.map(|r| r.n), Some(u32::MAX));
            } else {
                r.fetch(ByteAddr(0), 4);
                assert_eq!(
                    ops[0],
                    Op::Issue {
                        n: u32::MAX,
                        fpinv: 0
                    }
                );
            }
            let n = u32::MAX as u64 + 6;
            assert_eq!(tally.error(), Some(OpRangeError::Issue { n }));
        }
        // Just fitting is no error.
        let mut ops = Vec::new();
        let mut tally = Tally::new(SimAccel::Bvh2);
        let mut r = Recorder::resume(&mut tally, &mut ops, Some(near));
        r.push();
        r.finish();
        assert_eq!(tally.error(), None);
        assert_eq!(
            ops,
            vec![Op::Issue {
                n: u32::MAX,
                fpinv: 0
            }]
        );
    }

    #[test]
    fn serial_and_parallel_box_issue() {
        for (accel, issues) in [(SimAccel::Bvh4, 3), (SimAccel::Bvh4Plus, 1)] {
            let mut ops = Vec::new();
            let mut tally = Tally::new(accel);
            let mut r = Recorder::new(&mut tally, &mut ops);
            r.step(NodeStep::Bvh {
                arity: 4,
                valid: 3,
                hits: 2,
            });
            assert_eq!(r.tally().counts().box_ops, 3);
            assert_eq!(r.tally().counts().box_issues, issues);
            // node 4 + 3 children × 2 + 2 hits × 2 + 1 sort pair × 3
            assert_eq!(r.tally().counts().mix.total(), 4 + 6 + 4 + 3);
        }
    }

    #[test]
    fn frame_totals_do_not_wrap_at_2_pow_32() {
        // A 512×512 DST* path-traced frame issues ~6·10^9 instructions: u32 counters would
        // wrap (energy and issue utilisation would come out too low).
        let mut c = InstrCounts::default();
        let big = InstrCounts {
            mix: Mix::new(3_000_000_000, 0, 0, 0, 0, 2_000_000_000),
            ..Default::default()
        };
        c.add(&big);
        c.add(&big);
        assert_eq!(c.mix.int, 6_000_000_000);
        assert_eq!(c.total(), 10_000_000_000);
    }

    #[test]
    fn dst_hw_is_one_pipeline_op_and_sw_is_instructions() {
        let step = NodeStep::Dst {
            kind: DstNodeKind::Split,
            code: ReturnCode::BothChildren,
            carving_leaf: false,
        };
        let mut ops = Vec::new();
        let mut tally = Tally::new(SimAccel::Dst);
        let mut r = Recorder::new(&mut tally, &mut ops);
        r.step(step);
        assert_eq!(r.tally().counts().dst_ops, 1);
        // Code 2: the branch chain to the "both children" case, next node, t_max, jump.
        assert_eq!(r.tally().counts().mix.total(), 8);
        let mut ops = Vec::new();
        let mut tally = Tally::new(SimAccel::DstSw);
        let mut r = Recorder::new(&mut tally, &mut ops);
        r.step(step);
        assert_eq!(r.tally().counts().dst_ops, 0);
        // 23 int, 2 local loads, 2 sub, 3 mul, 4 min/max/compare.
        assert_eq!(r.tally().counts().mix.total(), 34);
        assert_eq!(r.tally().counts().mix.local, 2);
        // The stack entries of both DSTs carry [t_min, t_max]: 3 local-store accesses.
        r.push();
        r.pop();
        assert_eq!(r.tally().counts().mix.local, 2 + 3 + 3);
    }
}
