//! A TM's pools of shared functional units.
//!
//! Hardware (Lin et al. 2020, §2.3; SimTRaX `ReadConfig.cc` and `samples/configs/*.config`,
//! whose lines read `UNIT latency count`): a thread processor owns its basic datapath (integer
//! ALU, FP add/sub, FP multiply); the rest of a TM's functional units are pools shared by
//! its threads. A pool of `width` fully pipelined units accepts up to `width` operations per
//! cycle from all of the TM's threads together; an operation that finds the pool full in its
//! cycle waits for the next cycle with a free unit (an *FU-contention* stall in SimTRaX's
//! `IssueUnit.cc`). The reciprocal/divide unit, the ray pipelines and the L1 are the TM's
//! own units (`hw/tm.rs`), not pools.

use crate::config::UnitConfig;
use crate::hw::Cycle;
use crate::hw::window::Window;

/// One of a TM's pools, a row of [`Pools`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pool {
    /// FP compare (`feq`, `flt`, `fle`, `fclass`): SimTRaX `FPCMP`.
    FpCmp = 0,
    /// FP min/max: SimTRaX `FPMIN`.
    FpMinMax = 1,
    /// Int ↔ FP conversions: SimTRaX `CONV`.
    Conv = 2,
    /// Branches and jumps: SimTRaX `BLT`.
    Branch = 3,
    /// Integer multiply: SimTRaX `INTMUL`.
    IntMul = 4,
    /// Integer add and bitwise, when shared (`units.int_units` > 0): SimTRaX `INTADD`.
    IntAlu = 5,
    /// FP add, when shared (`units.fpadd_units` > 0): SimTRaX `FPADD`.
    FpAdd = 6,
    /// FP multiply, when shared (`units.fpmul_units` > 0): SimTRaX `FPMUL`.
    FpMul = 7,
}

const POOLS: usize = 8;

/// The pools of one TM, one per shared class of SimTRaX's unit list: pool `p` has
/// `width[p]` fully pipelined units, each accepting one operation per cycle, and its
/// results are ready `latency[p]` cycles after issue. The per-cycle use counts of all
/// lie in one [`Window`] (requests are made at most `tp::LOOKAHEAD` cycles after the
/// current event time and never before it).
#[derive(Clone, Debug)]
pub struct Pools {
    width: [u8; POOLS],
    latency: [u64; POOLS],
    used: Window,
}

impl Pools {
    /// The pools of one TM as `units` configures them.
    pub fn new(units: &UnitConfig) -> Self {
        let pools = [
            (units.fpcmp_units, units.fpcmp_latency),
            (units.fpminmax_units, units.fpminmax_latency),
            (units.conv_units, units.conv_latency),
            (units.branch_units, units.branch_latency),
            (units.intmul_units, units.intmul_latency),
            (units.int_units, units.int_latency),
            (units.fpadd_units, units.fpadd_latency),
            (units.fpmul_units, units.fpmul_latency),
        ];
        Self {
            // At most 64 units (`ranges.rs`), so a count fits a byte.
            width: pools.map(|(w, _)| w.clamp(1, u8::MAX as u32) as u8),
            latency: pools.map(|(_, l)| l),
            used: Window::new(POOLS),
        }
    }

    /// Takes a unit of pool `p` in the first cycle at or after `at` with one free; returns
    /// that cycle.
    #[inline]
    pub fn reserve(&mut self, p: Pool, at: Cycle) -> Cycle {
        let i = p as usize;
        Cycle(self.used.reserve(i, at.get(), self.width[i]))
    }

    /// Pool `p`'s result latency.
    #[inline]
    pub fn latency(&self, p: Pool) -> u64 {
        self.latency[p as usize]
    }
}

/// The result latency of an instruction of class `fu` on a functional unit (the TP's own
/// ALU, FP adder and multiplier and local store, the TM's pools and its reciprocal unit);
/// `None` for the memory, pipeline and atomic classes, whose answers the memory system and
/// the pipelines time.
pub fn unit_latency(fu: FuClass, cfg: &UnitConfig) -> Option<u64> {
    use FuClass as F;
    Some(match fu {
        F::IntAlu | F::FpMove | F::Halt => cfg.int_latency,
        F::FpAdd => cfg.fpadd_latency,
        F::FpMul | F::FpFma => cfg.fpmul_latency,
        F::LocalLoad | F::LocalStore => cfg.local_store_latency,
        F::FpCmp => cfg.fpcmp_latency,
        F::FpMinMax => cfg.fpminmax_latency,
        F::FpConv => cfg.conv_latency,
        F::Branch => cfg.branch_latency,
        F::IntMul => cfg.intmul_latency,
        F::IntDiv | F::FpDiv | F::FpSqrt | F::Rcp => cfg.fpinv_latency,
        F::Load | F::Store | F::BoxPipe(_) | F::TriPipe | F::DstPipe | F::Atomic => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SimConfig;

    #[test]
    fn a_full_cycle_sends_the_next_request_to_the_next_cycle() {
        let mut units = SimConfig::lin2020().units;
        units.intmul_units = 2;
        units.branch_units = 1;
        let mut p = Pools::new(&units);
        let m = Pool::IntMul;
        assert_eq!(p.reserve(m, Cycle(10)), Cycle(10));
        assert_eq!(p.reserve(m, Cycle(10)), Cycle(10));
        assert_eq!(p.reserve(m, Cycle(10)), Cycle(11));
        assert_eq!(p.reserve(m, Cycle(11)), Cycle(11));
        assert_eq!(p.reserve(m, Cycle(10)), Cycle(12));
        assert_eq!(p.reserve(m, Cycle(9)), Cycle(9));
        // Another pool counts apart.
        assert_eq!(p.reserve(Pool::Branch, Cycle(10)), Cycle(10));
        assert_eq!(p.reserve(Pool::Branch, Cycle(10)), Cycle(11));
    }

    #[test]
    fn a_cycle_far_later_finds_its_pool_free() {
        let mut units = SimConfig::lin2020().units;
        units.intmul_units = 1;
        let mut p = Pools::new(&units);
        let m = Pool::IntMul;
        assert_eq!(p.reserve(m, Cycle(3)), Cycle(3));
        let later = Cycle(3 + crate::hw::window::HISTORY);
        assert_eq!(p.reserve(m, later), later);
        assert_eq!(p.reserve(m, later), later + 1);
    }
}

/// The functional unit an instruction issues to (SimTRaX's FU classes: `sim/ReadConfig.cc`
/// and the unit lines of `samples/configs/bigcache.config`, plus the ray-tracing units of
/// `docs/isa.md`). Loads and stores are
/// [`FuClass::Load`]/[`FuClass::Store`] in the decoded `Info`; the executor turns them into
/// [`FuClass::LocalLoad`]/[`FuClass::LocalStore`] when the address is in the local store.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FuClass {
    /// Integer add/logic/shift/compare, `lui`, `auipc`, CSR access, `fence`, and the
    /// ray-register and latch moves (`rt.set*`, `rt.boxget`, `rt.dstget`).
    IntAlu,
    /// `mul`, `mulh`, `mulhsu`, `mulhu`.
    IntMul,
    /// `div`, `divu`, `rem`, `remu`.
    IntDiv,
    /// `fadd.s`, `fsub.s`.
    FpAdd,
    /// `fmul.s`.
    FpMul,
    /// `fmadd.s`, `fmsub.s`, `fnmsub.s`, `fnmadd.s` (one rounding).
    FpFma,
    /// `fdiv.s`.
    FpDiv,
    /// `fsqrt.s`.
    FpSqrt,
    /// `feq.s`, `flt.s`, `fle.s`, `fclass.s`.
    FpCmp,
    /// `fmin.s`, `fmax.s`.
    FpMinMax,
    /// `fcvt.w[u].s`, `fcvt.s.w[u]`.
    FpConv,
    /// `fsgnj[n|x].s`, `fmv.x.w`, `fmv.w.x` (bit moves).
    FpMove,
    /// Branches and jumps (`beq` … `bgeu`, `jal`, `jalr`).
    Branch,
    /// A load (`lb` … `lw`, `flw`) from global memory (image, parameters, frame buffer,
    /// program): through the L1.
    Load,
    /// A store to global memory (the frame buffer): write-around.
    Store,
    /// A load from the TP's local store (1 cycle).
    LocalLoad,
    /// A store to the TP's local store.
    LocalStore,
    /// `rt.box` (`n = 1`) or `rt.boxn` (`n = 2, 4, 8` boxes on `n` pipelines).
    BoxPipe(u8),
    /// `rt.tri`.
    TriPipe,
    /// `rt.dst`.
    DstPipe,
    /// `rt.rcp` (the reciprocal unit, FPINV).
    Rcp,
    /// `rt.atominc` (global register file).
    Atomic,
    /// `ebreak`: the thread ends.
    Halt,
}

/// Number of distinct [`FuClass`] indices (see [`fu_index`]).
pub const FU_CLASSES: usize = 23;

/// A dense index for each [`FuClass`] (`BoxPipe(n)` shares one index for all `n`).
#[inline]
pub fn fu_index(fu: FuClass) -> usize {
    use FuClass::*;
    match fu {
        IntAlu => 0,
        IntMul => 1,
        IntDiv => 2,
        FpAdd => 3,
        FpMul => 4,
        FpFma => 5,
        FpDiv => 6,
        FpSqrt => 7,
        FpCmp => 8,
        FpMinMax => 9,
        FpConv => 10,
        FpMove => 11,
        Branch => 12,
        Load => 13,
        Store => 14,
        LocalLoad => 15,
        LocalStore => 16,
        BoxPipe(_) => 17,
        TriPipe => 18,
        DstPipe => 19,
        Rcp => 20,
        Atomic => 21,
        Halt => 22,
    }
}

/// Instructions retired, by [`FuClass`] (indexed by [`fu_index`]).
pub type ClassCounts = [u64; FU_CLASSES];
