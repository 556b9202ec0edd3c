//! The program as the TP's timing reads it: each decoded instruction beside what its issue
//! needs, resolved once per frame against the unit configuration (the scoreboard slots it
//! reads and writes, and the unit it issues on), so that the TP's per-instruction loop
//! (`tp.rs`) does no register mapping and no class dispatch for the instructions on its
//! own units and the TM's pools.

use crate::config::UnitConfig;
use crate::hw::fu::{FuClass, Pool, fu_index};
use crate::model::rv32::{Instr, Program, Reg};

/// Scoreboard slots: the 64 registers `x0..x31`, `f0..f31`, then the latches `R`, `B`, `D`,
/// `P`, one slot that is always ready (read for an absent operand) and one that is never
/// read (written for an absent result). The scoreboard has [`SLOTS`] entries, one per `u8`,
/// so that indexing it with a slot number needs no bounds check.
pub(crate) const RAY_SLOT: usize = 64;
pub(crate) const BOX_SLOT: usize = 65;
pub(crate) const DST_SLOT: usize = 66;
pub(crate) const PIPE_SLOT: usize = 67;
pub(crate) const NO_SLOT: usize = 68;
pub(crate) const SINK_SLOT: usize = 69;
pub(crate) const SLOTS: usize = 1 << u8::BITS;

/// The unit an instruction issues on, as far as it is known before it executes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Unit {
    /// The TP's own unit with this result latency (paper §2.3): integer ALU, FP add and
    /// multiply when the configuration gives each TP its own.
    Own(u64),
    /// One of the TM's pools (`hw/fu.rs`).
    Pool(Pool),
    /// A load or store: the L1's or the local store's, by its address.
    Memory,
    /// Any other: a unit shared with other threads that issues only when its cycle has come
    /// (`shared`), or `ebreak`.
    Other { shared: bool },
}

/// One instruction and its issue.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Uop {
    pub(crate) ins: Instr,
    /// Scoreboard slots of the registers it reads ([`NO_SLOT`] for none).
    pub(crate) src: [u8; 3],
    /// Scoreboard slot of the register it writes ([`SINK_SLOT`] for none).
    pub(crate) dst: u8,
    /// [`fu_index`] of its decoded class.
    pub(crate) class: u8,
    pub(crate) unit: Unit,
}

/// A program's instructions with their issue, for one unit configuration.
pub(crate) struct Uops {
    text_base: u32,
    ops: Vec<Uop>,
}

impl Uops {
    /// `prog`'s instructions as the TPs of `cfg` issue them.
    pub(crate) fn new(prog: &Program, cfg: &UnitConfig) -> Self {
        let slot = |r: Reg, none: usize| r.index().unwrap_or(none) as u8;
        let ops = prog
            .code()
            .iter()
            .map(|ins| {
                let info = &ins.info;
                Uop {
                    ins: *ins,
                    src: info.src.map(|r| slot(r, NO_SLOT)),
                    dst: slot(info.dst, SINK_SLOT),
                    class: fu_index(info.fu) as u8,
                    unit: unit(info.fu, cfg),
                }
            })
            .collect();
        Self {
            text_base: prog.text_base(),
            ops,
        }
    }

    /// The instruction at byte address `pc` (as [`Program::fetch`]).
    #[inline(always)]
    pub(crate) fn fetch(&self, pc: u32) -> Option<&Uop> {
        let off = pc.wrapping_sub(self.text_base);
        if off & 3 != 0 {
            return None;
        }
        self.ops.get((off >> 2) as usize)
    }
}

/// The unit of an instruction of class `fu` under `cfg`.
fn unit(fu: FuClass, cfg: &UnitConfig) -> Unit {
    match fu {
        // A TP's own units (paper §2.3), or TM pools as SimTRaX's configs share them.
        FuClass::IntAlu | FuClass::FpMove if cfg.int_units > 0 => Unit::Pool(Pool::IntAlu),
        FuClass::FpAdd if cfg.fpadd_units > 0 => Unit::Pool(Pool::FpAdd),
        FuClass::FpMul | FuClass::FpFma if cfg.fpmul_units > 0 => Unit::Pool(Pool::FpMul),
        FuClass::IntAlu | FuClass::FpMove => Unit::Own(cfg.int_latency),
        FuClass::FpAdd => Unit::Own(cfg.fpadd_latency),
        FuClass::FpMul | FuClass::FpFma => Unit::Own(cfg.fpmul_latency),
        FuClass::FpCmp => Unit::Pool(Pool::FpCmp),
        FuClass::FpMinMax => Unit::Pool(Pool::FpMinMax),
        FuClass::FpConv => Unit::Pool(Pool::Conv),
        FuClass::Branch => Unit::Pool(Pool::Branch),
        FuClass::IntMul => Unit::Pool(Pool::IntMul),
        FuClass::Load | FuClass::Store => Unit::Memory,
        // The L1's operand reads, the ray pipelines, the reciprocal unit and the atomic unit
        // keep reservation tables bound to the current time.
        FuClass::BoxPipe(_)
        | FuClass::TriPipe
        | FuClass::DstPipe
        | FuClass::IntDiv
        | FuClass::FpDiv
        | FuClass::FpSqrt
        | FuClass::Rcp
        | FuClass::Atomic => Unit::Other { shared: true },
        FuClass::LocalLoad | FuClass::LocalStore | FuClass::Halt => Unit::Other { shared: false },
    }
}
