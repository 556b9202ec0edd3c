//! The thread processor (TP): one hardware thread replaying the macro-ops its kernel
//! recorded (`recorder.rs`).
//!
//! Hardware (Lin et al. 2020, §2.3, §4; SimTRaX `ThreadProcessor.cc`): single issue, in
//! order, one instruction per cycle. Loads are non-blocking: each word takes one issue slot
//! and the thread goes on issuing; any other op first waits until every outstanding result
//! (loads, pipeline ops, reciprocals, the atomic) has arrived, because the next step of a
//! traversal kernel consumes the previous step's data. Loads, pipeline ops and reciprocals
//! go to the thread's TM (`hw/tm.rs`), the pixel counter to the chip's atomic unit
//! (`hw/atomic.rs`). The thread counts where its cycles go ([`Stalls`]).

use crate::engine::HOPS;
use crate::hw::Cycle;
use crate::hw::atomic::AtomicUnit;
use crate::hw::issued::Issued;
use crate::hw::l1::Resident;
use crate::hw::memory::L2;
use crate::hw::tm::Tm;
use crate::hw::{Stall, Stalls, WordAddr};
use crate::model::fast::op::Op;

/// How far [`Thread::run`] got.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ran {
    /// Its next op starts after the current cycle.
    Asleep,
    /// Its program is done.
    Finished,
    /// Its next op is a load that needs the L2, left to the commit phase.
    Commit,
}

/// A thread's program and position in it. Aligned to a host cache line: the record is
/// 64 bytes and the thread array is large enough to be `mmap`ed (page + 16 bytes), where
/// every unaligned record would straddle two lines.
#[derive(Clone, Debug)]
#[repr(align(64))]
pub struct Thread {
    tm: u32,
    /// The cycle of its next issue slot.
    t: Cycle,
    /// The cycle its last outstanding result arrives.
    ready: Cycle,
    /// What its last outstanding result comes from: the cause a wait for it counts under.
    cause: Stall,
    /// The macro-ops of its current work item.
    ops: Vec<Op>,
    pc: usize,
    /// A copy of `ops[pc]` noted when the thread went to sleep (`None`: not noted), so
    /// that the touch pass finds a load's tags from the record alone, in parallel with the
    /// op buffer's line instead of after it. Only a hint: a stale copy would cost host
    /// misses, never change a result.
    next: Option<Op>,
}

impl Thread {
    /// An idle thread on TM `tm`.
    pub fn new(tm: usize) -> Self {
        Self {
            tm: tm as u32,
            t: Cycle::ZERO,
            ready: Cycle::ZERO,
            cause: Stall::Memory,
            ops: Vec::new(),
            pc: 0,
            next: None,
        }
    }

    /// The TM the thread runs on.
    #[inline]
    pub fn tm(&self) -> usize {
        self.tm as usize
    }

    /// The cycle of its next issue slot.
    #[inline]
    pub fn next_issue(&self) -> Cycle {
        self.t
    }

    /// True when every op of the current program has issued.
    pub fn program_done(&self) -> bool {
        self.pc >= self.ops.len()
    }

    /// Cycle when every outstanding result has arrived.
    pub fn results_ready(&self) -> Cycle {
        self.ready.max(self.t)
    }

    /// The current program's op buffer (taken out, so it can be refilled and given back
    /// with [`Thread::load_program`]).
    pub fn take_ops(&mut self) -> Vec<Op> {
        std::mem::take(&mut self.ops)
    }

    /// Whether the current program has no ops.
    pub fn has_no_program(&self) -> bool {
        self.ops.is_empty()
    }

    /// Replaces the program (the previous one must be done).
    pub fn load_program(&mut self, ops: Vec<Op>) {
        self.next = ops.first().copied();
        self.ops = ops;
        self.pc = 0;
    }

    /// Takes a value from the atomic unit: one issue slot, the value returns after the
    /// unit's latency (it is needed before the next instruction that consumes results).
    pub fn atomic(&mut self, unit: &mut AtomicUnit, stalls: &mut Stalls) {
        let r = unit.increment(self.t);
        stalls.count(Stall::Atomic, r.busy);
        self.t = r.next_issue;
        self.result(r.ready, Stall::Atomic);
    }

    /// Runs ops while they can start at or before `now`: [`Ran::Asleep`] when the next
    /// one starts later (at [`Thread::next_issue`]), [`Ran::Finished`] when the program is
    /// done. Without `l2` (the event loop's local phase) a load whose lines the L1 does not
    /// hold is not made: [`Ran::Commit`], to be run again with the L2.
    ///
    /// The common ops are executed inline: a plain instruction run, a load, a pipeline op.
    /// Reciprocal runs are out of line, so the function stays small and saves few registers
    /// per wake-up.
    #[inline]
    pub fn run(
        &mut self,
        tm: &mut Tm,
        mut l2: Option<&mut L2>,
        stalls: &mut Stalls,
        now: Cycle,
    ) -> Ran {
        while let Some(&op) = self.ops.get(self.pc) {
            if self.t > now {
                return Ran::Asleep;
            }
            if !matches!(op, Op::Load { .. }) && self.ready > self.t {
                let r = self.ready;
                self.wait(r, stalls);
                if r > now {
                    // Sleep until the operands are there.
                    return Ran::Asleep;
                }
            }
            match op {
                Op::Issue { n, fpinv: 0 } => self.t += n as u64,
                Op::Issue { n, fpinv } => self.issue_fpinv(n, fpinv, tm, stalls),
                Op::Load { word, words } => {
                    let (addr, words) = (WordAddr::new(word as u64), words as u64);
                    let r = match l2.as_deref_mut() {
                        Some(l2) => tm.load(l2, addr, words, self.t, now),
                        None if tm.holds_all(addr, words) => {
                            tm.load(&mut Resident, addr, words, self.t, now)
                        }
                        // A miss: the L2 is the commit phase's.
                        None => return Ran::Commit,
                    };
                    stalls.count(Stall::L1Bank, r.busy);
                    self.done(r, Stall::Memory);
                }
                Op::Pipe { pipe, n, parallel } => {
                    // The pipe's latency as the kernel exposes it is measured, part of the
                    // issue runs (`model/fast/calibrate.rs`); here only its occupancy is timed.
                    let r = tm.pipe(pipe, n, parallel, self.t);
                    stalls.count(Stall::PipelineBusy, r.busy);
                    self.t = r.next_issue;
                }
            }
            self.pc += 1;
        }
        Ran::Finished
    }

    /// Reads (without effect) the host memory the thread's next op will touch first: the
    /// op itself and, for a load, its line's L1 and L2 tags. The event loop calls it for
    /// every thread of a wake-up cycle before running them, so those host cache misses
    /// overlap instead of coming one after another. Returns a value to keep the reads.
    #[inline]
    pub fn touch(&self, tm: &Tm) -> u64 {
        let op = self.ops.get(self.pc).copied();
        let read = matches!(op, Some(Op::Load { .. })) as u64;
        match self.next.or(op) {
            Some(Op::Load { word, .. }) => read ^ tm.touch(WordAddr::new(word as u64)),
            _ => read,
        }
    }

    /// Forgets the noted next op (the thread goes to sleep without a forward entry).
    #[inline]
    pub fn forget_next(&mut self) {
        self.next = None;
    }

    /// Plays ahead the wake-ups of a thread going to sleep until its next issue slot that
    /// would do nothing but move it to a later cycle, and returns them as delays: hop `k` is
    /// how much later than the wake-up at hop `k − 1` (at the next issue slot for the first)
    /// that wake-up would have pushed it; after the last hop comes its next real wake-up.
    /// `[0, ..]` when there is nothing to skip. Two kinds of wake-up are skipped, both
    /// touching only the thread's own state:
    ///
    /// * its next op is not a load and needs a result due later (`ready > t`): the thread
    ///   only waits (the stall is counted now; the counters are sums);
    /// * its next op is an `Issue` without reciprocals, not the program's last, whose
    ///   operands are there: it reserves nothing, so it is executed now (`t += n`).
    ///
    /// The ops looked at are usually in the host cache line of the op just executed.
    #[inline]
    pub fn skip_ahead(&mut self, stalls: &mut Stalls) -> [u32; HOPS] {
        let mut hops = [0; HOPS];
        for hop in &mut hops {
            match self.ops.get(self.pc) {
                Some(Op::Load { .. }) | None => break,
                Some(_) if self.ready > self.t => {
                    // A wait beyond 2^32 cycles is left to a plain wake-up.
                    let Ok(d) = u32::try_from(self.ready - self.t) else {
                        break;
                    };
                    let r = self.ready;
                    self.wait(r, stalls);
                    *hop = d;
                }
                Some(&Op::Issue { n, fpinv: 0 }) if n > 0 && self.pc + 1 < self.ops.len() => {
                    self.pc += 1;
                    self.t += n as u64;
                    *hop = n;
                }
                Some(_) => break,
            }
        }
        self.next = self.ops.get(self.pc).copied();
        hops
    }

    fn wait(&mut self, until: Cycle, stalls: &mut Stalls) {
        if until > self.t {
            let d = until - self.t;
            stalls.count(self.cause, d);
            self.t = until;
        }
    }

    fn result(&mut self, at: Cycle, cause: Stall) {
        if at > self.ready {
            self.ready = at;
            self.cause = cause;
        }
    }

    /// A request issued: the thread goes on at its next issue slot, its result pending.
    #[inline(always)]
    fn done(&mut self, r: Issued, cause: Stall) {
        self.t = r.next_issue;
        self.result(r.ready, cause);
    }

    /// An instruction run of `n` of which `fpinv` go to the TM's shared reciprocal units.
    #[inline(never)]
    fn issue_fpinv(&mut self, n: u32, fpinv: u16, tm: &mut Tm, stalls: &mut Stalls) {
        let mut c = self.t;
        for _ in 0..fpinv {
            let r = tm.reciprocal(c);
            stalls.count(Stall::Fpinv, r.busy);
            self.result(r.ready, Stall::Fpinv);
            c = r.next_issue;
        }
        self.t = c + (n - fpinv as u32) as u64;
    }
}
