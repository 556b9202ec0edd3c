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

/// Cycles a pool remembers around the current time. Requests are made at most
/// [`crate::model::rv32::tp::LOOKAHEAD`] cycles after the current event time and never before it, so
/// two live cycles are never this far apart and never share a ring entry.
const RING: usize = 1024;

/// One pool: `width` units, each accepting one operation per cycle.
#[derive(Clone, Debug)]
pub struct Pool {
    width: u32,
    latency: u64,
    /// Per ring entry: the cycle it counts and how many units that cycle has taken. An
    /// entry whose cycle is not the one asked about belongs to a cycle that is over.
    ring: Vec<(Cycle, u32)>,
}

impl Pool {
    /// A pool of `width` units whose results are ready `latency` cycles after issue.
    pub fn new(width: u32, latency: u64) -> Self {
        Self {
            width: width.max(1),
            latency,
            ring: vec![(Cycle::MAX, 0); RING],
        }
    }

    /// Takes a unit in the first cycle at or after `at` with one free; returns that cycle.
    #[inline]
    pub fn reserve(&mut self, at: Cycle) -> Cycle {
        let mut c = at;
        loop {
            let e = &mut self.ring[(c.get() % RING as u64) as usize];
            if e.0 != c {
                *e = (c, 0);
            }
            if e.1 < self.width {
                e.1 += 1;
                return c;
            }
            c += 1;
        }
    }

    /// The pool's result latency.
    #[inline]
    pub fn latency(&self) -> u64 {
        self.latency
    }
}

/// The pools of one TM, one per shared class of SimTRaX's unit list.
#[derive(Clone, Debug)]
pub struct Pools {
    /// FP compare (`feq`, `flt`, `fle`, `fclass`): SimTRaX `FPCMP`.
    pub fpcmp: Pool,
    /// FP min/max: SimTRaX `FPMIN`.
    pub fpminmax: Pool,
    /// Int ↔ FP conversions: SimTRaX `CONV`.
    pub conv: Pool,
    /// Branches and jumps: SimTRaX `BLT`.
    pub branch: Pool,
    /// Integer multiply: SimTRaX `INTMUL`.
    pub intmul: Pool,
}

impl Pools {
    /// The pools of one TM as `units` configures them.
    pub fn new(units: &UnitConfig) -> Self {
        Self {
            fpcmp: Pool::new(units.fpcmp_units, units.fpcmp_latency),
            fpminmax: Pool::new(units.fpminmax_units, units.fpminmax_latency),
            conv: Pool::new(units.conv_units, units.conv_latency),
            branch: Pool::new(units.branch_units, units.branch_latency),
            intmul: Pool::new(units.intmul_units, units.intmul_latency),
        }
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

    #[test]
    fn a_full_cycle_sends_the_next_request_to_the_next_cycle() {
        let mut p = Pool::new(2, 1);
        assert_eq!(p.reserve(Cycle(10)), Cycle(10));
        assert_eq!(p.reserve(Cycle(10)), Cycle(10));
        assert_eq!(p.reserve(Cycle(10)), Cycle(11));
        assert_eq!(p.reserve(Cycle(11)), Cycle(11));
        assert_eq!(p.reserve(Cycle(10)), Cycle(12));
        assert_eq!(p.reserve(Cycle(9)), Cycle(9));
    }

    #[test]
    fn a_cycle_far_later_reuses_a_ring_entry_from_zero() {
        let mut p = Pool::new(1, 1);
        assert_eq!(p.reserve(Cycle(3)), Cycle(3));
        let later = Cycle(3 + RING as u64);
        assert_eq!(p.reserve(later), later);
        assert_eq!(p.reserve(later), later + 1);
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
