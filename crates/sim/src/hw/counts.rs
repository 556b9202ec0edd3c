//! What a frame's threads issued, by the classes the energy model prices: the
//! instruction mix ([`Mix`]) and the instruction and event counts ([`InstrCounts`]), the
//! same for both thread models.

use crate::hw::fu::{ClassCounts, FuClass, fu_index};
use serde::{Deserialize, Serialize};

/// Instruction mix by functional-unit class (energy and issue slots), as frame totals in
/// [`InstrCounts::mix`]; 64-bit counters (a 512×512 DST* path-traced frame issues more than
/// 2^32 instructions).
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
    /// Instructions issued (each takes one issue slot of the thread).
    pub const fn total(&self) -> u64 {
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

/// A fixed-function pipeline.
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
    /// Quantized ray-box pipeline ops (CWBVH configurations; their issues count in
    /// `box_issues`).
    #[serde(default)]
    pub qbox_ops: u64,
    /// Quantized dual-split pipeline ops (DST-Q; their issues count in `dst_ops`' place:
    /// one op per issue).
    #[serde(default)]
    pub qdst_ops: u64,
    /// Internal node steps (BVH nodes; DST splitting and carving nodes).
    pub node_steps: u64,
    /// Global atomic increments (pixel hand-out).
    pub atomics: u64,
}

impl InstrCounts {
    /// The counts of a compiled-kernel frame from its instructions per
    /// [`FuClass`] (indexed by [`fu_index`]) and the TMs'
    /// pipeline op counts, in the classes the energy model prices: integer ALU, branch,
    /// integer multiply and conversion/move instructions as `int`; FP add as `fpadd`; FP
    /// multiply and fused multiply-add as `fpmul`; FP compare and min/max as `fpcmp`;
    /// divides, square roots and reciprocals (the TM's FPINV unit) as `fpinv`; local-store
    /// accesses as `local`; global loads and stores as `loads`.
    pub fn from_classes(c: &ClassCounts, units: &UnitStats) -> Self {
        use FuClass as F;
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
            dst_ops: units.dst_ops,
            qbox_ops: units.qbox_ops,
            qdst_ops: units.qdst_ops,
            node_steps: 0,
            atomics: n(F::Atomic),
        }
    }

    /// All issued instructions.
    pub fn total(&self) -> u64 {
        self.mix_total()
            + self.loads
            + self.box_issues
            + self.tri_ops
            + self.dst_ops
            + self.qdst_ops
            + self.atomics
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
        self.qbox_ops += o.qbox_ops;
        self.qdst_ops += o.qdst_ops;
        self.node_steps += o.node_steps;
        self.atomics += o.atomics;
    }
}

/// Pipeline and shared-unit operation counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct UnitStats {
    /// Ray-box pipeline ops.
    pub box_ops: u64,
    /// Ray-triangle pipeline ops.
    pub tri_ops: u64,
    /// Dual-split pipeline ops.
    pub dst_ops: u64,
    /// Quantized ray-box pipeline ops (CWBVH configurations).
    #[serde(default)]
    pub qbox_ops: u64,
    /// Quantized dual-split pipeline ops (DST-Q).
    #[serde(default)]
    pub qdst_ops: u64,
    /// Reciprocal-unit ops.
    pub fpinv_ops: u64,
}
