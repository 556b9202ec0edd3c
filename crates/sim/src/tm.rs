//! A thread multiprocessor (TM): the units its thread processors share.
//!
//! Hardware (Lin et al. 2020, §2.3 and §4, Table 1; SimTRaX `L1Cache.cc`,
//! `FunctionalUnit`s): each TM has
//!
//! * an **L1 data cache** (direct-mapped by default) of `l1.banks` word banks: bank = word
//!   address mod the bank count, one access per bank per cycle; a hit returns its word
//!   `l1.hit_latency` cycles after its bank slot, a miss goes to the shared [`L2`] and the
//!   line is installed when its fill arrives; a miss to a line in flight waits for that fill
//!   (no second L2 access);
//! * **ray-box, ray-triangle and dual-split pipelines** (§2.3, §3): fully pipelined, one op
//!   per pipe per cycle, results after `box_latency`, `tri_latency`, `dst_latency`; the "+"
//!   configurations have one ray-box pipe per child (§4) and test all children of a node in
//!   one issue slot;
//! * a **reciprocal unit** (`fpinv_units` of them), shared by the TM's threads, one op per
//!   cycle, result after `fpinv_latency`.
//!
//! Every unit is a reservation table: a request learns the cycle it gets the unit (the first
//! free cycle at or after it asks) and the cycle its result is ready. The methods take the
//! cycle the thread issues the request and return both; any thread model (the macro-op
//! replay in `thread.rs`, an instruction interpreter) drives the TM through them.

use crate::Cycle;
use crate::config::SimConfig;
use crate::kernel::Pipe;
use crate::memory::{Cache, CacheStats, L2, Lookup};
use crate::slots::{self, BankSlots, Slots};
use serde::{Deserialize, Serialize};

/// A 4-byte word address (byte address / 4) in the simulated memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct WordAddr(pub u64);

impl WordAddr {
    /// The word holding byte address `byte`.
    pub fn from_byte(byte: u64) -> Self {
        Self(byte >> 2)
    }
}

/// The timing of a request to a unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Issued {
    /// The requesting thread's next issue slot (the cycle after the request's last slot).
    pub next_issue: Cycle,
    /// The cycle the result is in the thread's register.
    pub ready: Cycle,
    /// Cycles the request waited for a busy unit (L1 banks for loads and stores).
    pub busy: u64,
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
    /// Reciprocal-unit ops.
    pub fpinv_ops: u64,
}

/// One TM's L1, pipelines and reciprocal units.
pub struct Tm {
    l1: Cache,
    l1_banks: BankSlots,
    /// `l1.banks − 1` (a power of two).
    bank_mask: u64,
    /// log2(words per line).
    line_word_shift: u32,
    l1_latency: u64,
    /// Ray-box, ray-triangle and dual-split pipelines, indexed by [`Pipe`] (`pipe as
    /// usize`), with their latencies.
    pipes: [Vec<Slots>; 3],
    pipe_latency: [u64; 3],
    fpinv: Vec<Slots>,
    fpinv_latency: u64,
    l1_accesses: u64,
    l1_hits: u64,
    l1_merged: u64,
    units: UnitStats,
}

impl Tm {
    /// An idle TM with a cold L1; `box_pipes` ray-box pipelines (the "+" configurations use
    /// the node arity).
    pub fn new(cfg: &SimConfig, box_pipes: u32) -> Self {
        Self {
            l1: Cache::new(cfg.l1.size_bytes, cfg.l1.line_bytes, cfg.l1.associativity),
            l1_banks: BankSlots::new(cfg.l1.banks),
            bank_mask: cfg.l1.banks as u64 - 1,
            line_word_shift: (cfg.l1.line_bytes / 4).trailing_zeros(),
            l1_latency: cfg.l1.hit_latency,
            pipes: [
                vec![Slots::default(); box_pipes.max(1) as usize],
                vec![Slots::default(); cfg.units.tri_pipes as usize],
                vec![Slots::default(); cfg.units.dst_pipes as usize],
            ],
            pipe_latency: [
                cfg.units.box_latency,
                cfg.units.tri_latency,
                cfg.units.dst_latency,
            ],
            fpinv: vec![Slots::default(); cfg.units.fpinv_units as usize],
            fpinv_latency: cfg.units.fpinv_latency,
            l1_accesses: 0,
            l1_hits: 0,
            l1_merged: 0,
            units: UnitStats::default(),
        }
    }

    /// A load of `words` consecutive words from `addr`, one word per issue slot from cycle
    /// `at` (`now ≤ at` is the current event time: no later request starts before it).
    /// Each word takes its L1 bank's first free cycle at or after its turn; the words of one
    /// line segment share one tag lookup (later words see what a second lookup would: a hit
    /// once the fill has arrived, merged before). `ready` is when the last word is in the
    /// register, `busy` the cycles lost to bank conflicts.
    ///
    /// Host speed: a segment whose banks are all free in its cycles is placed with one
    /// bitmap test ([`BankSlots::try_run`]) and its words are counted at once; only a bank
    /// conflict takes the word-by-word path.
    #[inline(always)]
    pub fn load(
        &mut self,
        l2: &mut L2,
        addr: WordAddr,
        words: u64,
        at: Cycle,
        now: Cycle,
    ) -> Issued {
        let shift = self.line_word_shift;
        let mut c = at;
        let mut w = addr.0;
        let end = w + words;
        let (mut ready, mut busy) = (Cycle::ZERO, 0);
        while w < end {
            let seg_end = (((w >> shift) + 1) << shift).min(end);
            let k = seg_end - w;
            let (last, r) = if self.l1_banks.try_run(w & self.bank_mask, c.get(), k) {
                let (r, fill) = self.first_word(l2, w, c, now);
                self.count_words(c + 1, k - 1, fill);
                (c + k - 1, r.max(fill))
            } else {
                let (last, r, stall) = self.segment_conflict(l2, w, k, c, now);
                busy += stall;
                (last, r)
            };
            ready = ready.max(r).max(last + self.l1_latency);
            c = last + 1;
            w = seg_end;
        }
        Issued {
            next_issue: c,
            ready,
            busy,
        }
    }

    /// A store of `words` words from `addr` issued from cycle `at`: write-around (the L1
    /// neither allocates nor updates a line; the data goes on to memory), each word taking
    /// its L1 bank slot like a load's. The thread does not wait for it: `ready` is the last
    /// word's bank slot. The memory beyond the L1 is not modelled for stores (as SimTRaX,
    /// which counts no write traffic).
    pub fn store(&mut self, addr: WordAddr, words: u64, at: Cycle, now: Cycle) -> Issued {
        let shift = self.line_word_shift;
        let (mut c, mut w, end, mut busy) = (at, addr.0, addr.0 + words, 0);
        while w < end {
            let seg_end = (((w >> shift) + 1) << shift).min(end);
            let k = seg_end - w;
            let run = (self.l1_banks).reserve_run(w & self.bank_mask, c.get(), k, now.get(), 0);
            busy += run.stall;
            c = Cycle(run.last + 1);
            w = seg_end;
        }
        Issued {
            next_issue: c,
            ready: Cycle(c.get().saturating_sub(1)).max(at),
            busy,
        }
    }

    /// `n` ops on the TM's pipelines of kind `pipe` from cycle `at`: with `parallel` and
    /// pipes enough, all `n` in one issue slot (the first cycle from `at` at which `n` pipes
    /// are free); otherwise one after another, each on the pipe free first. `ready` is the
    /// last op's result, `busy` the cycles waited for a free pipe.
    #[inline(always)]
    pub fn pipe(&mut self, pipe: Pipe, n: u8, parallel: bool, at: Cycle) -> Issued {
        match pipe {
            Pipe::Box => self.units.box_ops += n as u64,
            Pipe::Triangle => self.units.tri_ops += n as u64,
            Pipe::DualSplit => self.units.dst_ops += n as u64,
        }
        let lat = self.pipe_latency[pipe as usize];
        let pipes = &mut self.pipes[pipe as usize];
        let (last, next, busy) = if let [only] = &mut pipes[..] {
            // One pipe: a parallel op of n > 1 serialises, n = 1 is the same either way.
            let (mut c, mut last, mut busy) = (at, at, 0);
            for _ in 0..n {
                let s = Cycle(only.reserve(c.get()));
                busy += s - c;
                last = s;
                c = s + 1;
            }
            (last, c, busy)
        } else {
            pipe_general(pipes, n, parallel, at)
        };
        Issued {
            next_issue: next,
            ready: last + lat,
            busy,
        }
    }

    /// One reciprocal on the TM's shared reciprocal unit(s), requested at `at`.
    #[inline]
    pub fn reciprocal(&mut self, at: Cycle) -> Issued {
        let s = earliest(&mut self.fpinv, at);
        self.units.fpinv_ops += 1;
        Issued {
            next_issue: s + 1,
            ready: s + self.fpinv_latency,
            busy: s - at,
        }
    }

    /// Reads (without effect) the L1 tag and, when the L1 holds another line there, the L2
    /// tag of `addr`'s line, and returns a value to keep the reads: the event loop calls it
    /// for the coming loads of a wake-up cycle so the host cache misses of their lookups
    /// overlap. Changes nothing simulated.
    #[inline]
    pub fn touch(&self, l2: &L2, addr: WordAddr) -> u64 {
        let line = addr.0 >> self.line_word_shift;
        let l1 = self.l1.peek(line);
        // Most loads hit the L1 and never read the L2's tags (1 MB at random).
        if l1 == line { l1 } else { l1 ^ l2.peek(line) }
    }

    /// Adds the TM's counters to `caches` and `units`.
    pub fn add_stats(&self, caches: &mut CacheStats, units: &mut UnitStats) {
        caches.l1_accesses += self.l1_accesses;
        caches.l1_hits += self.l1_hits;
        caches.l1_merged += self.l1_merged;
        units.box_ops += self.units.box_ops;
        units.tri_ops += self.units.tri_ops;
        units.dst_ops += self.units.dst_ops;
        units.fpinv_ops += self.units.fpinv_ops;
    }

    /// The first word of a line segment, at its bank slot `slot`: the tag lookup, and on a
    /// miss the L2 read and the line's installation at its fill. Returns the cycle the word
    /// is in the register and the line's fill cycle.
    #[inline(always)]
    fn first_word(&mut self, l2: &mut L2, w: u64, slot: Cycle, now: Cycle) -> (Cycle, Cycle) {
        self.l1_accesses += 1;
        let line = w >> self.line_word_shift;
        match self.l1.lookup(line, slot) {
            Lookup::Present { fill } if fill <= slot => {
                self.l1_hits += 1;
                (slot + self.l1_latency, fill)
            }
            Lookup::Present { fill } => {
                self.l1_merged += 1;
                (fill.max(slot + self.l1_latency), fill)
            }
            Lookup::Absent => self.miss(l2, line, w, slot, now),
        }
    }

    #[inline(never)]
    fn miss(&mut self, l2: &mut L2, line: u64, w: u64, slot: Cycle, now: Cycle) -> (Cycle, Cycle) {
        let ready = l2.read(line, w, slot, now);
        self.l1.install(line, ready, slot);
        (ready, ready)
    }

    /// Counts `n` words of a line filled at `fill`, at consecutive cycles from `c`: hits
    /// from the fill on, merged before.
    #[inline(always)]
    fn count_words(&mut self, c: Cycle, n: u64, fill: Cycle) {
        let hits = slots::at_or_after(c.get(), n, fill.get());
        self.l1_accesses += n;
        self.l1_hits += hits;
        self.l1_merged += n - hits;
    }

    /// A line segment of `k` words from `w` (issue from cycle `c`) some of whose banks are
    /// busy: the first word takes its bank's first free cycle and looks the line up, the
    /// rest are placed after it word by word. Returns the last word's cycle, the cycle the
    /// data is in the register, and the bank stall.
    #[inline(never)]
    fn segment_conflict(
        &mut self,
        l2: &mut L2,
        w: u64,
        k: u64,
        c: Cycle,
        now: Cycle,
    ) -> (Cycle, Cycle, u64) {
        let slot = Cycle(
            self.l1_banks
                .reserve_word(w & self.bank_mask, c.get(), now.get()),
        );
        let mut stall = slot - c;
        let (r, fill) = self.first_word(l2, w, slot, now);
        let mut last = slot;
        if k > 1 {
            let run = self.l1_banks.reserve_run(
                (w + 1) & self.bank_mask,
                slot.get() + 1,
                k - 1,
                now.get(),
                fill.get(),
            );
            stall += run.stall;
            last = Cycle(run.last);
            let hits = run.at_or_after;
            self.l1_accesses += k - 1;
            self.l1_hits += hits;
            self.l1_merged += k - 1 - hits;
        }
        (last, r.max(fill), stall)
    }

    /// One word load at bank slot `slot` (already reserved): the cycle the data is in the
    /// register.
    #[cfg(test)]
    pub(crate) fn load_word(&mut self, l2: &mut L2, word: u64, slot: Cycle) -> Cycle {
        self.first_word(l2, word, slot, Cycle::ZERO).0
    }
}

/// `n` ops from cycle `at` on several pipes of one kind (the "+" configurations' box
/// pipes): in parallel when asked and there are pipes enough (all n start together in one
/// issue slot, at the first cycle from `at` at which n pipes are free), else one after
/// another, each on the pipe free first. Returns the last op's issue cycle, the cycle after
/// it, and the cycles waited.
#[inline(never)]
fn pipe_general(pipes: &mut [Slots], n: u8, parallel: bool, at: Cycle) -> (Cycle, Cycle, u64) {
    let mut c = at;
    let mut last = c;
    let mut busy = 0;
    if parallel && pipes.len() >= n as usize {
        let mut s = c;
        loop {
            let free = pipes.iter().filter(|p| p.peek(s.get()) == s.get()).count();
            if free >= n as usize {
                break;
            }
            s += 1;
        }
        busy += s - c;
        let mut taken = 0;
        for p in pipes.iter_mut() {
            if taken < n && p.peek(s.get()) == s.get() {
                p.reserve(s.get());
                taken += 1;
            }
        }
        last = s;
        c = s + 1;
    } else {
        for _ in 0..n {
            let s = earliest(pipes, c);
            busy += s - c;
            last = s;
            c = s + 1;
        }
    }
    (last, c, busy)
}

/// Reserves the earliest free cycle at or after `c` on any of `units`.
#[inline]
fn earliest(units: &mut [Slots], c: Cycle) -> Cycle {
    let c = c.get();
    if let [only] = units {
        return Cycle(only.reserve(c));
    }
    let mut best = 0;
    let mut best_s = u64::MAX;
    for (i, u) in units.iter().enumerate() {
        let s = u.peek(c);
        if s < best_s {
            best = i;
            best_s = s;
            if s == c {
                break;
            }
        }
    }
    Cycle(units[best].reserve(c))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The TM's interface as a thread model other than the macro-op replay drives it:
    /// typed requests at a cycle, the cycle the result is ready.
    #[test]
    fn the_tm_answers_requests_at_a_cycle() {
        let cfg = SimConfig::lin2020();
        let mut l2 = L2::new(&cfg);
        let mut tm = Tm::new(&cfg, 1);
        // A cold 3-word load at byte 0: L1 1 + L2 3 + closed row 30; words at 0, 1, 2.
        let c = Cycle;
        let r = tm.load(&mut l2, WordAddr::from_byte(0), 3, c(0), c(0));
        assert_eq!((r.next_issue, r.ready, r.busy), (c(3), c(34), 0));
        // The same words again: L1 hits, the last at cycle 102, data at 103.
        let r = tm.load(&mut l2, WordAddr(0), 3, c(100), c(100));
        assert_eq!((r.next_issue, r.ready), (c(103), c(103)));
        // A store to bank 0 in cycle 200 and a load of word 16 (bank 0) in the same cycle:
        // the load waits one cycle for the bank; a store allocates no line.
        let s = tm.store(WordAddr(32), 1, c(200), c(200));
        assert_eq!((s.next_issue, s.ready, s.busy), (c(201), c(200), 0));
        let r = tm.load(&mut l2, WordAddr(16), 1, c(200), c(200));
        assert_eq!((r.next_issue, r.busy), (c(202), 1));
        // Dual-split op: result after 8 cycles; the pipe is taken in its cycle.
        let p = tm.pipe(Pipe::DualSplit, 1, false, c(300));
        assert_eq!((p.next_issue, p.ready), (c(301), c(308)));
        let p = tm.pipe(Pipe::DualSplit, 1, false, c(300));
        assert_eq!((p.next_issue, p.ready, p.busy), (c(302), c(309), 1));
        // Reciprocal: 16 cycles (lin2020 `fpinv_latency`).
        let f = tm.reciprocal(c(400));
        let ready = c(400 + cfg.units.fpinv_latency);
        assert_eq!((f.next_issue, f.ready), (c(401), ready));
        let (mut c, mut u) = (CacheStats::default(), UnitStats::default());
        tm.add_stats(&mut c, &mut u);
        assert_eq!((c.l1_accesses, c.l1_hits), (7, 3));
        assert_eq!((u.dst_ops, u.fpinv_ops), (2, 1));
    }
}
