//! The thread processor (TP) that executes compiled kernels: one RV32IMF hardware thread
//! with the ray-tracing instructions of `docs/isa.md` (`rv32/` decodes and executes them).
//!
//! Hardware (Lin et al. 2020, §2.3; SimTRaX `IssueUnit.cc`, `ThreadState.cc`,
//! `BranchUnit.cc`):
//!
//! * **Single issue, in order**: the instruction at the pc issues when every source
//!   register is ready (a per-register scoreboard of ready cycles: a *dependency* stall
//!   otherwise) and its unit accepts it in that cycle (a *busy-unit* stall otherwise). It
//!   executes at issue; its result is in the destination register `latency` cycles later.
//!   Branches resolve at issue, with no penalty (no predictor). One instruction per cycle.
//! * **Its own datapath** (§2.3: "its own program counter, register file, and basic
//!   datapath functional units (integer ALU, floating point add/sub/mult)") and its private
//!   local store (the stack; `units.local_store_latency`).
//! * **The TM's shared units**: the FP compare, min/max, conversion, branch and integer
//!   multiply pools (`hw/fu.rs`), the reciprocal/divide unit, the L1 and the ray-box,
//!   ray-triangle and dual-split pipelines (`hw/tm.rs`); the chip's atomic unit (`hw/atomic.rs`).
//! * **Loads are non-blocking**: a load takes one L1 bank slot per word and the thread goes
//!   on issuing; only an instruction that reads the loaded register waits.
//! * **Ray-tracing instructions with a memory operand** (`rt.box`, `rt.boxn`, `rt.tri`,
//!   `rt.dst`) read their words through the L1 like a load of the same words, then wait in
//!   the issue stage until the last word has arrived and the pipeline accepts them.
//!
//! Every stalled cycle is counted once, under the cause of the wait that ended last: the
//! producer of the operand waited for (memory, a pipeline, or another unit's latency:
//! *dependency*), or the unit that was busy.
//!
//! Host speed: instructions on the TP's own units touch no shared state, so the TP runs
//! them ahead of the current event time (up to [`LOOKAHEAD`] cycles; its clock simply
//! advances); it goes back to the scheduler only before an instruction on a shared unit
//! whose cycle has not come yet. Results are the same as waking the thread every cycle.

use crate::config::UnitConfig;
use crate::engine::Wake;
use crate::hw::atomic::AtomicUnit;
use crate::hw::fu::{ClassCounts, FuClass, Pool, fu_index};
use crate::hw::issued::Issued;
use crate::hw::l1::{Backing, Resident};
use crate::hw::pipe::Pipe;
use crate::hw::tm::Tm;
use crate::hw::{Cycle, Stall, Stalls, WordAddr};
use crate::model::rv32::hart::executed_class;
use crate::model::rv32::placement::Placement;
use crate::model::rv32::uop::{
    BOX_SLOT, DST_SLOT, NO_SLOT, PIPE_SLOT, RAY_SLOT, SLOTS, Unit, Uop, Uops,
};
use crate::model::rv32::{
    ExecError, Hart, LOCAL_STORE_ADDR, Latches, MemAccess, Memory, Op, Program,
};

/// The farthest a TP runs instructions on its own units and pools ahead of the current
/// event time.
pub const LOOKAHEAD: u64 = 256;

/// The latch bits an instruction reads.
const READS_ANY_LATCH: u8 =
    Latches::READS_RAY | Latches::READS_BOX | Latches::READS_DST | Latches::READS_PIPE;

/// The producers of the scoreboard's slots at the start: a latch's is fixed (`R` is
/// written by the TP's own moves, `B` and `D` by a ray pipeline, `P` by loads).
const LATCH_PRODUCERS: [Stall; SLOTS] = {
    let mut p = [Stall::Dependency; SLOTS];
    p[BOX_SLOT] = Stall::PipelineLatency;
    p[DST_SLOT] = Stall::PipelineLatency;
    p[PIPE_SLOT] = Stall::Memory;
    p
};

/// The scoreboard slots of the latches `l` reads, in the order `R`, `B`, `D`, `P` (the
/// always-ready slot for one it does not read).
#[inline]
fn latch_slots(l: Latches) -> [usize; 4] {
    let slot = |flag: u8, slot: usize| if l.has(flag) { slot } else { NO_SLOT };
    [
        slot(Latches::READS_RAY, RAY_SLOT),
        slot(Latches::READS_BOX, BOX_SLOT),
        slot(Latches::READS_DST, DST_SLOT),
        slot(Latches::READS_PIPE, PIPE_SLOT),
    ]
}

/// A ray-tracing instruction whose memory words are on their way: it issues on its
/// pipeline once they have arrived.
#[derive(Clone, Copy, Debug)]
struct Waiting {
    pipe: Pipe,
    n: u8,
    /// Scoreboard index of its destination register (if any).
    dst: Option<usize>,
    latches: Latches,
}

/// How an executed instruction's L1 access ends.
#[derive(Clone, Copy, Debug)]
enum Access {
    /// A load: its result goes to `dst` (scoreboard index), and to `P` when `writes_pipe`.
    Load {
        dst: Option<usize>,
        writes_pipe: bool,
    },
    /// A ray-tracing instruction with a memory operand: it issues once its words are in.
    Pipe(Waiting),
}

/// An executed instruction whose L1 access misses, left to the commit phase: its access,
/// how it ends, and the cycle it issued.
#[derive(Clone, Copy, Debug)]
struct Pending {
    acc: MemAccess,
    access: Access,
    t: Cycle,
}

/// One thread processor.
pub struct Tp {
    hart: Hart,
    tm: u32,
    /// The instruction cache it fetches from.
    icache: u32,
    /// The cycle of its next issue slot.
    t: Cycle,
    /// Scoreboard: the cycle each register's pending result arrives (`x0..x31`,
    /// `f0..f31`), then the same for the ray registers `R`, the box latch `B`, the DST
    /// latch `D` and the pipeline input registers `P` (the latest of the loads that wrote
    /// them), a slot that is always ready ([`NO_SLOT`], read for an absent operand) and one
    /// written for an absent result (`uop::SINK_SLOT`); and what produces each (the slots
    /// of `uop.rs`).
    ready: [Cycle; SLOTS],
    producer: [Stall; SLOTS],
    /// The latest result of any instruction so far.
    last: Cycle,
    waiting: Option<Waiting>,
    /// Its L1 access that misses, executed in the local phase, timed in the commit phase.
    pending: Option<Pending>,
    /// Rays traced: each sets the ray registers' origin once (`rt.setorg`).
    rays: u64,
}

impl Tp {
    /// A TP on TM `tm`, fetching from that TM's instruction cache `icache`, about to run
    /// `prog` from its entry point.
    pub fn new(prog: &Program, tm: usize, icache: usize, local_store_bytes: u32) -> Self {
        Self {
            hart: Hart::new(prog, local_store_bytes),
            tm: tm as u32,
            icache: icache as u32,
            t: Cycle::ZERO,
            ready: [Cycle::ZERO; SLOTS],
            producer: LATCH_PRODUCERS,
            last: Cycle::ZERO,
            waiting: None,
            pending: None,
            rays: 0,
        }
    }

    /// The TM the TP belongs to.
    #[inline]
    pub fn tm(&self) -> usize {
        self.tm as usize
    }

    /// Rays traced so far.
    pub fn rays(&self) -> u64 {
        self.rays
    }

    /// Executes instructions while they can issue by `now` (those on the TP's own units
    /// and pools by `now + LOOKAHEAD`).
    ///
    /// `COMMIT` false is the event loop's local phase: `mem` is read-only, `l2` is never
    /// reached and there is no atomic unit. Before an instruction that needs more (an L1
    /// miss, a global store, `rt.atominc`, a read of the frame buffer) it returns
    /// [`Wake::Commit`]; a load found to miss after it executed is kept as the pending
    /// access. `COMMIT` true is the commit phase: the TP finishes its pending access, or
    /// runs the instruction it stopped before, with the whole chip, and goes back to sleep
    /// until its next issue slot.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn run<const COMMIT: bool, M: Memory, B: Backing>(
        &mut self,
        prog: &Program,
        uops: &Uops,
        mem: &mut M,
        cfg: &UnitConfig,
        tm: &mut Tm,
        stalls: &mut Stalls,
        mut shared: Option<(&mut B, &mut AtomicUnit)>,
        placement: &Placement,
        counts: &mut ClassCounts,
        now: Cycle,
    ) -> Result<Wake, ExecError> {
        if COMMIT && let Some(p) = self.pending.take() {
            let (l2, _) = shared.as_mut().expect("the commit phase has the L2");
            let i = l1_load(tm, *l2, placement, &p.acc, p.t, now, stalls);
            let w = self.finish_access(tm, i, p.access, now, stalls);
            return Ok(w.unwrap_or(Wake::At(self.t)));
        }
        if let Some(w) = self.waiting.take() {
            // Its words have arrived (the thread slept until then): the pipeline op issues.
            let r = tm.pipe(w.pipe, w.n, w.n > 1, self.t);
            stalls.count(Stall::PipelineBusy, r.busy);
            self.finish_pipe(r, w);
        }
        let mut executed = false;
        loop {
            if COMMIT && executed {
                // The commit phase runs one instruction; the rest run in local phases.
                return Ok(Wake::At(self.t));
            }
            let Some(u) = uops.fetch(self.hart.pc) else {
                // The executor names the faulting pc.
                return Err(self
                    .hart
                    .step(prog, mem)
                    .expect_err("fetch outside the text"));
            };
            let ins = &u.ins;
            let info = &ins.info;
            // The instruction is fetched when the previous one has issued (SimTRaX holds a
            // fetched instruction until it issues).
            let fetch_from = self.t;
            // Operands: the registers, then the latches read.
            let l = info.latches;
            let mut at = self
                .t
                .max(self.ready[u.src[0] as usize])
                .max(self.ready[u.src[1] as usize])
                .max(self.ready[u.src[2] as usize]);
            if l.bits() & READS_ANY_LATCH != 0 {
                at = at.max(
                    latch_slots(l)
                        .iter()
                        .fold(Cycle::ZERO, |a, &k| a.max(self.ready[k])),
                );
            }
            if at > self.t {
                stalls.count(self.producer_of(u, at), at - self.t);
                self.t = at;
            }
            let pc = self.hart.pc;
            let fetch = tm.fetch(self.icache as usize, pc, fetch_from);
            let fetched = fetch.at;
            if fetched > self.t {
                stalls.count(Stall::Icache, fetched - self.t);
                self.t = fetched;
            }
            let (shared_unit, global_store) = match u.unit {
                // A load or store is the L1's unless it addresses the local store.
                Unit::Memory => {
                    let addr = self.hart.x[ins.rs1 as usize].wrapping_add(ins.imm as u32);
                    let global = addr < LOCAL_STORE_ADDR;
                    (global, global && info.fu == FuClass::Store)
                }
                Unit::Other { shared } => (shared, false),
                Unit::Own(_) | Unit::Pool(_) => (false, false),
            };
            if (shared_unit && self.t > now) || self.t > now + LOOKAHEAD {
                // Not issued yet: its fetch is made again when the thread next runs.
                tm.give_back(fetch);
                return Ok(Wake::At(self.t));
            }
            if !COMMIT && (global_store || info.fu == FuClass::Atomic) {
                // The frame buffer and the global registers are the commit phase's.
                tm.give_back(fetch);
                return Ok(Wake::Commit);
            }
            // Register operations run inline; the rest out of line.
            let acc = match self.hart.exec_register(ins) {
                Some(_) => Ok(MemAccess::NONE),
                None => self.hart.exec_access(ins, prog, mem),
            };
            let acc = match acc {
                Ok(acc) => acc,
                Err(ExecError::Elsewhere { .. }) if !COMMIT => {
                    // A read of the frame buffer: nothing was executed.
                    tm.give_back(fetch);
                    return Ok(Wake::Commit);
                }
                Err(e) => return Err(e),
            };
            tm.keep(fetch);
            executed = true;
            self.rays += (ins.op == Op::RtSetOrg) as u64;
            let t = self.t;
            // (issue cycle, result latency, producer) for units that take one slot.
            let (slot, lat, p) = match u.unit {
                Unit::Own(lat) => {
                    counts[u.class as usize] += 1;
                    (t, lat, Stall::Dependency)
                }
                Unit::Pool(pl) => {
                    counts[u.class as usize] += 1;
                    pool(tm, pl, t, stalls)
                }
                Unit::Memory | Unit::Other { .. } => {
                    // The executed class (a load or store whose address is the local store's).
                    let fu = executed_class(info.fu, &acc);
                    counts[fu_index(fu)] += 1;
                    let dst = info.dst.index();
                    match fu {
                        FuClass::LocalLoad | FuClass::LocalStore => {
                            (t, cfg.local_store_latency, Stall::Dependency)
                        }
                        FuClass::IntDiv | FuClass::FpDiv | FuClass::FpSqrt | FuClass::Rcp => {
                            let i = tm.reciprocal(t);
                            stalls.count(Stall::FuBusy, i.busy);
                            one_slot(i, Stall::Dependency)
                        }
                        FuClass::Atomic => {
                            let (_, atomic) = shared
                                .as_mut()
                                .expect("the commit phase has the atomic unit");
                            let i = atomic.increment(t);
                            stalls.count(Stall::Atomic, i.busy);
                            one_slot(i, Stall::Atomic)
                        }
                        FuClass::Store => {
                            let (l2, _) = shared.as_mut().expect("the commit phase has the L2");
                            let i = tm.store(
                                *l2,
                                WordAddr::from_byte(placement.physical(acc.addr)),
                                acc.words as u64,
                                t,
                                now,
                            );
                            stalls.count(Stall::L1Bank, i.busy);
                            self.t = i.next_issue;
                            self.last = self.last.max(i.ready);
                            continue;
                        }
                        FuClass::Load
                        | FuClass::BoxPipe(_)
                        | FuClass::TriPipe
                        | FuClass::DstPipe => {
                            let access = match info.fu {
                                FuClass::BoxPipe(n) => Access::Pipe(Waiting {
                                    pipe: Pipe::Box,
                                    n,
                                    dst,
                                    latches: l,
                                }),
                                FuClass::TriPipe | FuClass::DstPipe => Access::Pipe(Waiting {
                                    pipe: if info.fu == FuClass::TriPipe {
                                        Pipe::Triangle
                                    } else {
                                        Pipe::DualSplit
                                    },
                                    n: 1,
                                    dst,
                                    latches: l,
                                }),
                                _ => Access::Load {
                                    dst,
                                    writes_pipe: l.has(Latches::WRITES_PIPE),
                                },
                            };
                            if let Access::Pipe(w) = access
                                && l.has(Latches::READS_PIPE)
                            {
                                // A register form: its words are in P (waited for above).
                                let p = tm.pipe(w.pipe, w.n, w.n > 1, t);
                                stalls.count(Stall::PipelineBusy, p.busy);
                                self.finish_pipe(p, w);
                                continue;
                            }
                            let i = match shared.as_mut() {
                                Some((l2, _)) => l1_load(tm, *l2, placement, &acc, t, now, stalls),
                                None => {
                                    let words = acc.words as u64;
                                    let addr = WordAddr::from_byte(placement.physical(acc.addr));
                                    if !tm.holds_all(addr, words) {
                                        // A miss: the L2 is the commit phase's.
                                        self.pending = Some(Pending { acc, access, t });
                                        return Ok(Wake::Commit);
                                    }
                                    l1_load(tm, &mut Resident, placement, &acc, t, now, stalls)
                                }
                            };
                            if let Some(w) = self.finish_access(tm, i, access, now, stalls) {
                                return Ok(w);
                            }
                            continue;
                        }
                        FuClass::Halt => {
                            self.last = self.last.max(self.t);
                            return Ok(Wake::Done(self.last));
                        }
                        FuClass::IntAlu
                        | FuClass::IntMul
                        | FuClass::FpAdd
                        | FuClass::FpMul
                        | FuClass::FpFma
                        | FuClass::FpCmp
                        | FuClass::FpMinMax
                        | FuClass::FpConv
                        | FuClass::FpMove
                        | FuClass::Branch => {
                            unreachable!("{fu:?} issues on its own unit or a pool")
                        }
                    }
                }
            };
            self.t = slot + 1;
            let (d, ready) = (u.dst as usize, slot + lat);
            self.ready[d] = ready;
            self.producer[d] = p;
            self.last = self.last.max(ready);
            if l.has(Latches::WRITES_RAY) {
                self.ready[RAY_SLOT] = slot + lat;
            }
            if l.has(Latches::WRITES_PIPE) {
                // rt.ldp from the local store.
                self.ready[PIPE_SLOT] = self.ready[PIPE_SLOT].max(slot + lat);
            }
        }
    }

    /// The timing `i` of an executed instruction's L1 access: a load's result in its
    /// register, or a ray-tracing instruction's pipeline op once its words have arrived.
    /// Returns the wake-up when the instruction holds the issue stage past `now` for its
    /// words, `None` when the thread goes on at its next issue slot.
    fn finish_access(
        &mut self,
        tm: &mut Tm,
        i: Issued,
        access: Access,
        now: Cycle,
        stalls: &mut Stalls,
    ) -> Option<Wake> {
        match access {
            Access::Load { dst, writes_pipe } => {
                self.t = i.next_issue;
                self.write(dst, i.ready, Stall::Memory);
                if writes_pipe {
                    self.ready[PIPE_SLOT] = self.ready[PIPE_SLOT].max(i.ready);
                }
            }
            Access::Pipe(w) => {
                // The words are in the unit's operand latches at `i.ready`; the instruction
                // holds the issue stage until then.
                let arrive = i.ready.max(i.next_issue);
                stalls.count(Stall::Memory, arrive - i.next_issue);
                self.t = arrive;
                if arrive > now {
                    self.waiting = Some(w);
                    return Some(Wake::At(arrive));
                }
                let p = tm.pipe(w.pipe, w.n, w.n > 1, arrive);
                stalls.count(Stall::PipelineBusy, p.busy);
                self.finish_pipe(p, w);
            }
        }
        None
    }

    /// The producer of the first operand of `u` (the registers in order, then the
    /// latches `R`, `B`, `D`, `P`) whose result arrives at `at`, the last of them: the
    /// cause a wait for the operands is counted under.
    #[cold]
    fn producer_of(&self, u: &Uop, at: Cycle) -> Stall {
        let regs = u.src.map(usize::from);
        regs.iter()
            .chain(latch_slots(u.ins.info.latches).iter())
            .find(|&&k| self.ready[k] == at)
            .map_or(Stall::Dependency, |&k| self.producer[k])
    }

    /// A pipeline op issued with timing `r`: its results in the destination register and
    /// the latches it writes.
    fn finish_pipe(&mut self, r: Issued, w: Waiting) {
        self.t = r.next_issue;
        self.write(w.dst, r.ready, Stall::PipelineLatency);
        if w.latches.has(Latches::WRITES_BOX) {
            self.ready[BOX_SLOT] = r.ready;
        }
        if w.latches.has(Latches::WRITES_DST) {
            self.ready[DST_SLOT] = r.ready;
        }
    }

    #[inline]
    fn write(&mut self, dst: Option<usize>, at: Cycle, p: Stall) {
        if let Some(i) = dst {
            self.ready[i] = at;
            self.producer[i] = p;
        }
        self.last = self.last.max(at);
    }
}

/// The L1 load of an executed instruction's memory words from cycle `t`.
#[inline]
fn l1_load<B: Backing>(
    tm: &mut Tm,
    l2: &mut B,
    placement: &Placement,
    acc: &MemAccess,
    t: Cycle,
    now: Cycle,
    stalls: &mut Stalls,
) -> Issued {
    let words = acc.words as u64;
    let i = tm.load(
        l2,
        WordAddr::from_byte(placement.physical(acc.addr)),
        words,
        t,
        now,
    );
    stalls.count(Stall::L1Bank, i.busy);
    i
}

/// A one-slot request's timing as (issue cycle, latency, producer).
#[inline]
fn one_slot(i: Issued, p: Stall) -> (Cycle, u64, Stall) {
    let slot = i.next_issue - 1;
    (slot, i.ready - slot, p)
}

/// One operation on a pool from cycle `t`: (issue cycle, latency, producer).
#[inline]
fn pool(tm: &mut Tm, p: Pool, t: Cycle, stalls: &mut Stalls) -> (Cycle, u64, Stall) {
    let s = tm.reserve_pool(p, t);
    stalls.count(Stall::FuBusy, s - t);
    (s, tm.pool_latency(p), Stall::Dependency)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;
    use crate::hw::Chip;
    use crate::model::rv32::FrameMemory;
    use crate::model::rv32::PROGRAM_BASE;
    use crate::model::rv32::frame::run_tps;
    use crate::model::rv32::tests::asm::*;
    use dualsplit_accel::MemoryImage;

    /// Runs `words` (an `ebreak` appended) on `threads` TPs of one TM; returns the end
    /// cycle and the stalls.
    fn run(cfg: &SimConfig, words: &[u32], threads: u32) -> (u64, Stalls) {
        let mut w = words.to_vec();
        w.push(EBREAK);
        let prog = Program::from_words(PROGRAM_BASE, &w);
        let image = MemoryImage::with_triangles(64, 0, Vec::new().into());
        let mut mem = FrameMemory::new(&image, &[], 64);
        let mut chip = Chip::new(cfg, 1);
        let placement =
            crate::model::rv32::placement::Placement::new(0, 4 * w.len() as u64, 64, 64);
        let mut tps: Vec<Tp> = (0..threads).map(|_| Tp::new(&prog, 0, 0, 4096)).collect();
        let (end, _) = run_tps(
            &mut chip,
            &mut tps,
            &prog,
            &mut mem,
            &placement,
            cfg,
            1,
            &mut |_| {},
        )
        .unwrap();
        (end.get(), chip.stats().stalls)
    }

    fn fadd(rd: u32, rs1: u32, rs2: u32) -> u32 {
        fp(0x00, 0, rd, rs1, rs2)
    }

    #[test]
    fn independent_instructions_issue_one_per_cycle() {
        // addi ×3 at cycles 0, 1, 2; ebreak at 3; the last result is in at 3.
        let (end, s) = run(
            &SimConfig::lin2020(),
            &[addi(1, 0, 1), addi(2, 0, 2), addi(3, 0, 3)],
            1,
        );
        assert_eq!(end, 3);
        assert_eq!(s.dependency, 0);
    }

    #[test]
    fn a_dependent_fp_add_waits_for_the_adders_latency() {
        // fadd f1 at 0 (ready at 2), fadd f2 = f1 + f1 waits to 2 (1 dependency cycle),
        // ready at 4; ebreak at 3.
        let cfg = SimConfig::lin2020();
        assert_eq!(cfg.units.fpadd_latency, 2);
        let (end, s) = run(&cfg, &[fadd(1, 0, 0), fadd(2, 1, 1)], 1);
        assert_eq!(s.dependency, 1);
        assert_eq!(end, 4);
    }

    #[test]
    fn a_full_pool_delays_the_second_thread() {
        // Two threads multiply at cycle 0 on a TM with one integer multiplier: the second
        // issues at 1, its ebreak at 2.
        let mut cfg = SimConfig::lin2020();
        cfg.units.intmul_units = 1;
        let mul = r(0x33, 0, 1, 3, 1, 2);
        let (end, s) = run(&cfg, &[mul], 2);
        assert_eq!(s.fu_busy, 1);
        assert_eq!(end, 2);
    }

    #[test]
    fn shared_fp_adders_and_alus_delay_the_second_thread_own_ones_do_not() {
        // Two threads add floats at cycle 0 (fadd.s f3, f1, f2), then add integers.
        let fadd = r(0x53, 0, 0, 3, 1, 2);
        let mut cfg = SimConfig::lin2020();
        let (own, s) = run(&cfg, &[fadd], 2);
        assert_eq!(s.fu_busy, 0, "each TP's own adder (paper §2.3)");
        // One FP adder per TM (SimTRaX's configs share them): the second waits a cycle.
        cfg.units.fpadd_units = 1;
        let (end, s) = run(&cfg, &[fadd], 2);
        assert_eq!((end, s.fu_busy), (own + 1, 1));
        // The FP multiplier and the integer ALU likewise.
        cfg.units.fpmul_units = 1;
        let (_, s) = run(&cfg, &[r(0x53, 0, 8, 3, 1, 2)], 2);
        assert_eq!(s.fu_busy, 1);
        cfg.units.int_units = 1;
        let (_, s) = run(&cfg, &[addi(2, 1, 1)], 2);
        // The addi and the ebreak (an ALU op too) each wait once.
        assert!(s.fu_busy >= 1, "{s:?}");
    }

    #[test]
    fn a_register_form_waits_for_the_loads_into_p_like_a_load_use() {
        let cfg = SimConfig::lin2020();
        let boxp = r4(0x7B, 0, 0, 1, 0, 0, 0); // f1 = rt.boxp f0, f0
        // With P ready, rt.boxp issues at 0 on the ray-box pipeline; its result is in at 8.
        let (end, s) = run(&cfg, &[boxp], 1);
        assert_eq!((end, s.memory), (cfg.units.box_latency, 0));
        // lw x1, 0(x0); addi x2, x1, 1: the addi waits for the miss.
        let (end_lw, s_lw) = run(&cfg, &[i(0x03, 2, 1, 0, 0), addi(2, 1, 1)], 1);
        // rt.ldp P[0], 0(x0); rt.boxp: the same wait, then the pipeline's latency.
        let (end_p, s_p) = run(&cfg, &[i(0x5B, 0, 0, 0, 0), boxp], 1);
        assert!(s_lw.memory >= 28, "{s_lw:?}");
        assert_eq!(s_p.memory, s_lw.memory);
        assert_eq!(
            end_p - end_lw,
            cfg.units.box_latency - cfg.units.int_latency
        );
    }

    #[test]
    fn a_load_use_waits_for_memory_and_is_counted_as_memory() {
        // lw x1, 0(x0) misses everywhere; addi x2, x1, 1 waits for it.
        let cfg = SimConfig::lin2020();
        let (end, s) = run(&cfg, &[i(0x03, 2, 1, 0, 0), addi(2, 1, 1)], 1);
        // A closed-row DRAM read: at least t_rcd + t_cas = 28 ns at lin2020.
        assert!(s.memory >= 28, "{s:?}");
        assert_eq!(s.dependency, 0);
        // lw at 0, its data in at 1 + memory, addi then, ebreak the cycle after.
        assert_eq!(end, 1 + s.memory + 1);
    }

    #[test]
    fn local_store_accesses_do_not_touch_the_l1() {
        // sw x0, -4(sp) at 0; lw x1, -4(sp) at 1, in at 2; addi at 2; ebreak at 3.
        let cfg = SimConfig::lin2020();
        let (end, s) = run(
            &cfg,
            &[s(0x23, 2, 2, 0, -4), i(0x03, 2, 1, 2, -4), addi(3, 1, 1)],
            1,
        );
        assert_eq!(s.memory, 0);
        assert_eq!(end, 3);
    }
}
