//! The timing engine: TMs of in-order single-issue threads replaying macro-ops against
//! reservation tables (L1 banks, L2 banks, pipelines, shared units, DRAM banks and buses;
//! `slots.rs`), driven by a timing wheel of thread wake-up times (notes §5.2).
//!
//! A thread runs while its next operation can start at the current event time; when it must
//! wait (for data, a busy unit, or because its issue slots run ahead), it goes back into the
//! wheel at the cycle it can continue. Threads waking in the same cycle run in the order they
//! were scheduled, so runs are deterministic. Operations reserve resources at their own start
//! cycle (never before the current event time); because events are processed in time order,
//! reservations are made in (nearly) causal order.
//!
//! Host speed (docs/performance.md, "Simulator speed"): a load reserves the L1 banks of a
//! whole line segment with one bitmap test (`BankSlots`); tables forget cycles before the
//! current event time; before running a wake-up cycle's threads, `run_chip` reads each
//! one's next op and L1/L2 tag so those host cache misses overlap; the wheel's buckets are
//! intrusive lists through one link per thread, and cache tags are 16 bytes while lines and
//! cycles fit 32 bits (`memory::cache`), and ops are 8 bytes (`kernel::Op`), so the host
//! memory the replay streams through stays small. Wake-ups that would only wait for
//! operands or run plain instructions are played ahead when a thread goes to sleep, and the
//! wheel forwards the thread through those cycles in its place without running it
//! ([`run_chip`]; about half of all wake-ups). A line segment whose banks are free is
//! placed with one bitmap test and, when its line sits in the direct-mapped L1, answered
//! without a call ([`memory::Cache::find_direct`](crate::memory::Cache::find_direct)); the
//! touch pass reads the L2's tag only for a load whose L1 way holds another line. A wake-up
//! usually runs one op, so [`Thread::run`] keeps only the common ops inline (a plain
//! instruction run, a load whose segments find their banks free, all of a segment's words
//! counted at once, a pipeline op on the TM's only pipe, its table and latency chosen by
//! one index) and calls out of line for the rest (reciprocals, bank conflicts, several
//! pipes), so each call saves few registers; going back to sleep is inlined into
//! `run_chip`. None of this changes a simulated result.

use crate::Cycle;
use crate::config::SimConfig;
use crate::kernel::{Op, Pipe};
use crate::memory::{Cache, Dram, Lookup};
use crate::slots::{self, BankSlots, Slots};
use serde::{Deserialize, Serialize};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Why a thread waited (stall breakdown, in thread-cycles).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Stalls {
    /// Waiting for load data (L1 hit latency, L2, DRAM).
    pub memory: u64,
    /// Waiting for a pipeline result (latency).
    pub pipeline_latency: u64,
    /// Waiting for a free pipeline (contention with the TM's other threads).
    pub pipeline_busy: u64,
    /// Waiting for the shared reciprocal unit's result or a free slot on it.
    pub fpinv: u64,
    /// An L1 bank already used this cycle (bank conflict).
    pub l1_bank: u64,
    /// Waiting for the global atomic unit (pixel hand-out).
    pub atomic: u64,
    /// Finished early while other threads still ran.
    pub idle: u64,
}

/// Counters of the cache hierarchy.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CacheStats {
    /// L1 accesses (one per load word).
    pub l1_accesses: u64,
    /// L1 hits on a line already filled.
    pub l1_hits: u64,
    /// L1 misses merged into a fill already in flight (no L2 access).
    pub l1_merged: u64,
    /// L2 accesses (L1 misses that were not merged).
    pub l2_accesses: u64,
    /// L2 hits on a line already filled.
    pub l2_hits: u64,
    /// L2 misses merged into a DRAM read already in flight.
    pub l2_merged: u64,
    /// Cycles L2 requests waited for a busy L2 bank.
    pub l2_bank_wait: u64,
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

struct Tm {
    l1: Cache,
    l1_banks: BankSlots,
    /// Ray-box, ray-triangle and dual-split pipelines, indexed by [`Pipe`] (`pipe as
    /// usize`), so a pipeline op selects its table and latency by one index.
    pipes: [Vec<Slots>; 3],
    fpinv: Vec<Slots>,
}

/// The chip's shared state: TMs, L2, DRAM, and the global atomic unit.
pub struct Chip {
    cfg: SimConfig,
    /// `l1.banks - 1`, `l2.banks - 1` (power-of-two bank counts) and log2(words per line).
    l1_bank_mask: u64,
    l2_bank_mask: u64,
    line_word_shift: u32,
    /// Latency of each pipeline kind, indexed by [`Pipe`].
    pipe_latency: [u64; 3],
    tms: Vec<Tm>,
    l2: Cache,
    l2_banks: Vec<Slots>,
    /// The DRAM.
    pub dram: Dram,
    atomic_free: Cycle,
    /// Cache counters.
    pub caches: CacheStats,
    /// Unit counters.
    pub units: UnitStats,
    /// Stall counters.
    pub stalls: Stalls,
}

/// Which resource a thread's pending result comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Cause {
    Memory,
    Pipeline,
    Fpinv,
    Atomic,
}

impl Chip {
    /// A cold chip; `box_pipes` ray-box pipelines per TM (the "+" configurations use the
    /// node arity).
    pub fn new(cfg: &SimConfig, box_pipes: u32) -> Self {
        let tm = || Tm {
            l1: Cache::new(cfg.l1.size_bytes, cfg.l1.line_bytes, cfg.l1.associativity),
            l1_banks: BankSlots::new(cfg.l1.banks),
            pipes: [
                vec![Slots::default(); box_pipes.max(1) as usize],
                vec![Slots::default(); cfg.units.tri_pipes as usize],
                vec![Slots::default(); cfg.units.dst_pipes as usize],
            ],
            fpinv: vec![Slots::default(); cfg.units.fpinv_units as usize],
        };
        Self {
            cfg: cfg.clone(),
            l1_bank_mask: cfg.l1.banks as u64 - 1,
            l2_bank_mask: cfg.l2.banks as u64 - 1,
            line_word_shift: (cfg.l1.line_bytes / 4).trailing_zeros(),
            pipe_latency: [
                cfg.units.box_latency,
                cfg.units.tri_latency,
                cfg.units.dst_latency,
            ],
            tms: (0..cfg.tms).map(|_| tm()).collect(),
            l2: Cache::new(cfg.l2.size_bytes, cfg.l2.line_bytes, cfg.l2.associativity),
            l2_banks: vec![Slots::default(); cfg.l2.banks as usize],
            dram: Dram::new(&cfg.dram),
            atomic_free: 0,
            caches: CacheStats::default(),
            units: UnitStats::default(),
            stalls: Stalls::default(),
        }
    }

    /// One word load by TM `tm` whose L1 bank slot is `slot` (already reserved): returns the
    /// cycle the data is in the register.
    #[cfg(test)]
    fn load_word(&mut self, tm: usize, word: u64, slot: Cycle) -> Cycle {
        self.load_word_fill(tm, word, slot, 0).0
    }

    /// As [`Chip::load_word`], also returning the fill cycle now in the line's L1 tag;
    /// `now` (≤ `slot`) is the current event time: no later access starts before it. (The
    /// common case, a line the direct-mapped L1 holds, is answered by [`Thread::run`]'s
    /// load path without a call; this is the call.)
    #[inline(never)]
    fn load_word_fill(&mut self, tm: usize, word: u64, slot: Cycle, now: Cycle) -> (Cycle, Cycle) {
        self.caches.l1_accesses += 1;
        let line = word >> self.line_word_shift;
        let l1_lat = self.cfg.l1.hit_latency;
        match self.tms[tm].l1.lookup_general(line, slot) {
            Lookup::Present { fill } if fill <= slot => {
                self.caches.l1_hits += 1;
                (slot + l1_lat, fill)
            }
            Lookup::Present { fill } => {
                self.caches.l1_merged += 1;
                (fill.max(slot + l1_lat), fill)
            }
            Lookup::Absent => {
                let bank_addr = if self.cfg.l2.line_interleaved {
                    line
                } else {
                    word
                };
                let b = (bank_addr & self.l2_bank_mask) as usize;
                let s2 = self.l2_banks[b].reserve(slot);
                self.caches.l2_bank_wait += s2 - slot;
                self.caches.l2_accesses += 1;
                let at = s2 + l1_lat + self.cfg.l2.hit_latency;
                let ready = match self.l2.lookup(line, s2) {
                    Lookup::Present { fill } if fill <= s2 => {
                        self.caches.l2_hits += 1;
                        at
                    }
                    Lookup::Present { fill } => {
                        self.caches.l2_merged += 1;
                        fill.max(at)
                    }
                    Lookup::Absent => {
                        let (done, _) = self.dram.read_at(line, at, now);
                        self.l2.install(line, done, s2);
                        done
                    }
                };
                self.tms[tm].l1.install(line, ready, slot);
                (ready, ready)
            }
        }
    }
}

/// A thread's program and position in it. Aligned to a host cache line: the record is
/// 64 bytes and the thread array is large enough to be `mmap`ed (page + 16 bytes), where
/// every unaligned record would straddle two lines.
#[derive(Clone, Debug)]
#[repr(align(64))]
pub struct Thread {
    tm: u32,
    /// The cycle of its next issue slot.
    pub t: Cycle,
    ready: Cycle,
    cause: Cause,
    /// The macro-ops of its current work item.
    pub ops: Vec<Op>,
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
            t: 0,
            ready: 0,
            cause: Cause::Memory,
            ops: Vec::new(),
            pc: 0,
            next: None,
        }
    }

    /// True when every op of the current program has issued.
    pub fn program_done(&self) -> bool {
        self.pc >= self.ops.len()
    }

    /// Cycle when every outstanding result has arrived.
    pub fn results_ready(&self) -> Cycle {
        self.ready.max(self.t)
    }

    /// Reads (without effect) the host memory the thread's next op will touch first: the
    /// op itself and, for a load, its line's L1 and L2 tags. `run_chip` calls it for every thread
    /// of a wake-up cycle before running them, so those host cache misses overlap instead
    /// of coming one after another. Returns a value to keep the reads.
    #[inline]
    fn touch(&self, chip: &Chip) -> u64 {
        let op = self.ops.get(self.pc).copied();
        let read = matches!(op, Some(Op::Load { .. })) as u64;
        match self.next.or(op) {
            Some(Op::Load { word, .. }) => {
                let line = word as u64 >> chip.line_word_shift;
                let l1 = chip.tms[self.tm as usize].l1.peek(line);
                // The L2's tag only when the L1's first way holds another line: most loads
                // hit the L1 and never read the L2's tags (1 MB at random).
                if l1 == line {
                    l1 ^ read
                } else {
                    l1 ^ chip.l2.peek(line) ^ read
                }
            }
            _ => read,
        }
    }

    /// Plays ahead the wake-ups of a thread going to sleep until `t` that would do nothing
    /// but move it to a later bucket (see [`run_chip_with`]), and returns them as delays:
    /// hop `k` is how much later than the wake-up at hop `k − 1` (at `t` for the first)
    /// that wake-up would have pushed it; after the last hop comes its next real wake-up.
    /// `[0, ..]` when there is nothing to skip. Two kinds of wake-up are skipped, both touching only the thread's
    /// own state:
    ///
    /// * its next op is not a load and needs a result due later (`ready > t`): the thread
    ///   only waits (the stall is counted now; the counters are sums);
    /// * its next op is an `Issue` without reciprocals, not the program's last, whose
    ///   operands are there: it reserves nothing, so it is executed now (`t += n`).
    ///
    /// The ops looked at are usually in the host cache line of the op just executed. (Not
    /// looking past a line boundary saved those misses but skipped fewer wake-ups: more
    /// instructions, the same misses, slower; docs/performance.md, "Fourth round".)
    #[inline]
    fn skip_ahead(&mut self, stalls: &mut Stalls) -> [u32; HOPS] {
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
                    self.t += n as Cycle;
                    *hop = n;
                }
                Some(_) => break,
            }
        }
        self.next = self.ops.get(self.pc).copied();
        hops
    }

    /// Replaces the program (the previous one must be done).
    pub fn load_program(&mut self, ops: Vec<Op>) {
        self.next = ops.first().copied();
        self.ops = ops;
        self.pc = 0;
    }

    fn wait(&mut self, until: Cycle, stalls: &mut Stalls) {
        if until > self.t {
            let d = until - self.t;
            match self.cause {
                Cause::Memory => stalls.memory += d,
                Cause::Pipeline => stalls.pipeline_latency += d,
                Cause::Fpinv => stalls.fpinv += d,
                Cause::Atomic => stalls.atomic += d,
            }
            self.t = until;
        }
    }

    fn result(&mut self, at: Cycle, cause: Cause) {
        if at > self.ready {
            self.ready = at;
            self.cause = cause;
        }
    }

    /// Takes a pixel from the global atomic counter: one issue slot, the value returns after
    /// the atomic latency (it is needed before the pixel's first ray).
    pub fn atomic(&mut self, chip: &mut Chip) {
        let s = self.t.max(chip.atomic_free);
        chip.stalls.atomic += s - self.t;
        chip.atomic_free = s + 1;
        self.t = s + 1;
        self.result(s + chip.cfg.units.atomic_latency, Cause::Atomic);
    }

    /// Runs ops while they can start at or before `now`; returns false when the program is
    /// finished. The thread's next event is then at `self.t`.
    ///
    /// The common ops are executed inline: a plain instruction run, a load whose line
    /// segments find their L1 banks free, a pipeline op on the TM's only pipe of its kind.
    /// The rest (reciprocals, bank conflicts, several pipes) is out of line, so the
    /// function stays small and saves few registers per wake-up (docs/performance.md,
    /// "Sixth round: engine").
    pub fn run(&mut self, chip: &mut Chip, now: Cycle) -> bool {
        while let Some(&op) = self.ops.get(self.pc) {
            if self.t > now {
                return true;
            }
            if !matches!(op, Op::Load { .. }) && self.ready > self.t {
                let r = self.ready;
                self.wait(r, &mut chip.stalls);
                if r > now {
                    // Sleep until the operands are there.
                    return true;
                }
            }
            self.pc += 1;
            match op {
                Op::Issue { n, fpinv: 0 } => self.t += n as Cycle,
                Op::Issue { n, fpinv } => self.issue_fpinv(n, fpinv, chip),
                Op::Load { word, words } => self.load(word, words, chip, now),
                Op::Pipe { pipe, n, parallel } => self.pipe(pipe, n, parallel, chip),
            }
        }
        false
    }

    /// An instruction run of which `fpinv` go to the TM's shared reciprocal units.
    #[inline(never)]
    fn issue_fpinv(&mut self, n: u32, fpinv: u16, chip: &mut Chip) {
        let tm = self.tm as usize;
        let mut c = self.t;
        for _ in 0..fpinv {
            let s = earliest(&mut chip.tms[tm].fpinv, c);
            chip.stalls.fpinv += s - c;
            chip.units.fpinv_ops += 1;
            let lat = chip.cfg.units.fpinv_latency;
            self.result(s + lat, Cause::Fpinv);
            c = s + 1;
        }
        self.t = c + (n - fpinv as u32) as Cycle;
    }

    /// `words` word loads from `word`, line segment by line segment: the first word looks
    /// the line up (L1 tags, then L2/DRAM on a miss); later words of the same line see
    /// exactly what a second tag lookup would (hit once the fill has arrived, merged
    /// before). Every word takes its own L1 bank slot, one issue slot after the previous
    /// word's.
    ///
    /// Most segments find every word's bank free in its cycle: one table test
    /// ([`BankSlots::try_run`]) places them all at `c .. c + k`, exactly where the general
    /// path ([`Thread::load_segment_conflict`]) puts them, and a line the direct-mapped L1
    /// holds is answered inline, all `k` words at once: a word at cycle `x` is a hit when
    /// the fill has arrived (`fill ≤ x`), merged before, and the data is in the register
    /// at `max(fill, x + L1 latency)`.
    #[inline(always)]
    fn load(&mut self, word: u32, words: u16, chip: &mut Chip, now: Cycle) {
        let tm = self.tm as usize;
        let shift = chip.line_word_shift;
        let l1_lat = chip.cfg.l1.hit_latency;
        let mut c = self.t;
        let mut w = word as u64;
        let end = w + words as u64;
        while w < end {
            let seg_end = (((w >> shift) + 1) << shift).min(end);
            let k = seg_end - w;
            let tmr = &mut chip.tms[tm];
            if !tmr.l1_banks.try_run(w & chip.l1_bank_mask, c, k) {
                c = self.load_segment_conflict(chip, w, k, c, now);
                w = seg_end;
                continue;
            }
            let line = w >> shift;
            let last = c + k - 1;
            let (fill, from) = match tmr.l1.find_direct(line) {
                Some(fill) => (fill, c),
                None => {
                    // The first word's lookup (its hit, merge or miss counted there),
                    // then the rest.
                    let (_, fill) = chip.load_word_fill(tm, w, c, now);
                    (fill, c + 1)
                }
            };
            // Words at `from ..= last` not counted yet: hits from the fill on.
            let n = last + 1 - from;
            let hits = slots::at_or_after(from, n, fill);
            chip.caches.l1_accesses += n;
            chip.caches.l1_hits += hits;
            chip.caches.l1_merged += n - hits;
            self.result(fill.max(last + l1_lat), Cause::Memory);
            c = last + 1;
            w = seg_end;
        }
        self.t = c;
    }

    /// A line segment of `k` words from `w` (issue from cycle `c`) some of whose banks are
    /// busy: the first word takes its bank's first free cycle
    /// ([`BankSlots::reserve_word`]) and looks the line up, the rest are placed after it
    /// by [`BankSlots::reserve_run`]. Returns the cycle after the
    /// last word.
    #[inline(never)]
    fn load_segment_conflict(
        &mut self,
        chip: &mut Chip,
        w: u64,
        k: u64,
        c: Cycle,
        now: Cycle,
    ) -> Cycle {
        let tm = self.tm as usize;
        let bank_mask = chip.l1_bank_mask;
        let l1_lat = chip.cfg.l1.hit_latency;
        let slot = chip.tms[tm].l1_banks.reserve_word(w & bank_mask, c, now);
        let mut bank_stall = slot - c;
        let (mut r, fill) = chip.load_word_fill(tm, w, slot, now);
        let mut c = slot + 1;
        if k > 1 {
            let rest = k - 1;
            let run = chip.tms[tm]
                .l1_banks
                .reserve_run((w + 1) & bank_mask, c, rest, now, fill);
            bank_stall += run.stall;
            let hits = run.at_or_after;
            c = run.last + 1;
            chip.caches.l1_accesses += rest;
            chip.caches.l1_hits += hits;
            chip.caches.l1_merged += rest - hits;
            r = r.max(fill.max(c - 1 + l1_lat));
        }
        self.result(r, Cause::Memory);
        chip.stalls.l1_bank += bank_stall;
        c
    }

    /// `n` ray-box, ray-triangle or dual-split ops. On the TM's only pipe of the kind
    /// (BVH2, BVH4, BVH8, DST: one of each) they issue one after another, each at the
    /// pipe's first free cycle; the rest is [`Thread::pipe_general`].
    #[inline(always)]
    fn pipe(&mut self, pipe: Pipe, n: u8, parallel: bool, chip: &mut Chip) {
        match pipe {
            Pipe::Box => chip.units.box_ops += n as u64,
            Pipe::Triangle => chip.units.tri_ops += n as u64,
            Pipe::DualSplit => chip.units.dst_ops += n as u64,
        }
        let lat = chip.pipe_latency[pipe as usize];
        let pipes = &mut chip.tms[self.tm as usize].pipes[pipe as usize];
        let mut c = self.t;
        let mut last = c;
        if let [only] = &mut pipes[..] {
            // One pipe: a parallel op of n > 1 serialises, n = 1 is the same either way.
            let mut busy = 0;
            for _ in 0..n {
                let s = only.reserve(c);
                busy += s - c;
                last = s;
                c = s + 1;
            }
            chip.stalls.pipeline_busy += busy;
        } else {
            (last, c) = pipe_general(pipes, n, parallel, c, &mut chip.stalls);
        }
        self.t = c;
        self.result(last + lat, Cause::Pipeline);
    }
}

/// A pipeline op of `n` ops from cycle `c` on several pipes of its kind (the "+"
/// configurations' box pipes): in parallel when asked and there are pipes enough (all n
/// start together in one issue slot, at the first cycle from `c` at which n pipes are
/// free), else one after another, each on the pipe free first. Returns the last op's issue
/// cycle and the cycle after it.
#[inline(never)]
fn pipe_general(
    pipes: &mut [Slots],
    n: u8,
    parallel: bool,
    c: Cycle,
    stalls: &mut Stalls,
) -> (Cycle, Cycle) {
    let mut c = c;
    let mut last = c;
    if parallel && pipes.len() >= n as usize {
        let mut s = c;
        loop {
            let free = pipes.iter().filter(|p| p.peek(s) == s).count();
            if free >= n as usize {
                break;
            }
            s += 1;
        }
        stalls.pipeline_busy += s - c;
        let mut taken = 0;
        for p in pipes.iter_mut() {
            if taken < n && p.peek(s) == s {
                p.reserve(s);
                taken += 1;
            }
        }
        last = s;
        c = s + 1;
    } else {
        for _ in 0..n {
            let s = earliest(pipes, c);
            stalls.pipeline_busy += s - c;
            last = s;
            c = s + 1;
        }
    }
    (last, c)
}

/// Reserves the earliest free cycle at or after `c` on any of `units`.
#[inline]
fn earliest(units: &mut [Slots], c: Cycle) -> Cycle {
    if let [only] = units {
        return only.reserve(c);
    }
    let mut best = 0;
    let mut best_s = Cycle::MAX;
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
    units[best].reserve(c)
}

/// Supplies threads with work: called when a thread's program is done; returns the next
/// program or `None` when there is no work left.
pub trait WorkSource {
    /// The next program for thread `id` (its index in `run_chip`'s slice), whose previous
    /// program is done.
    fn next(&mut self, id: usize, thread: &mut Thread, chip: &mut Chip) -> Option<Vec<Op>>;
}

/// A timing wheel of thread wake-ups (notes §5.2): one bucket per cycle for the next
/// `WHEEL` cycles, an overflow heap beyond. Within a cycle, threads run in the order they
/// were scheduled (deterministic).
///
/// A bucket is an intrusive FIFO list through each thread's [`Link`] (a thread is in the
/// wheel at most once), so scheduling a wake-up writes two small arrays that stay in the
/// host's cache (56 KB for 2048 threads) instead of one of 4096 separately allocated
/// vectors.
struct Wheel {
    /// Per bucket: (first, last) thread of its list, `NONE` when empty.
    ends: Vec<(u32, u32)>,
    /// Per thread: its link and forward hops (12 bytes, one host cache line access for
    /// both).
    links: Vec<Link>,
    now: Cycle,
    in_wheel: usize,
    overflow: BinaryHeap<Reverse<(Cycle, u32)>>,
}

/// A thread's place in the wheel.
#[derive(Clone, Copy, Debug)]
struct Link {
    /// The thread after it in its bucket, `NONE` at the end.
    next: u32,
    /// Where its entry forwards it, as delays hop after hop (see [`Wheel::push_forward`]),
    /// `[0, ..]` for a wake-up.
    hops: [u32; HOPS],
}

const WHEEL: u64 = 4096;
const NONE: u32 = u32::MAX;
/// Most wake-ups one forward entry skips ([`Thread::skip_ahead`]): a wait for operands,
/// then an instruction run. Nothing skippable follows such a run: it needed its operands
/// and produces none, and consecutive runs are merged into one `Issue` by the recorder.
const HOPS: usize = 2;

impl Wheel {
    fn new(threads: usize) -> Self {
        Self {
            ends: vec![(NONE, NONE); WHEEL as usize],
            links: vec![
                Link {
                    next: NONE,
                    hops: [0; HOPS]
                };
                threads
            ],
            now: 0,
            in_wheel: 0,
            overflow: BinaryHeap::new(),
        }
    }

    #[inline(always)]
    fn push(&mut self, t: Cycle, id: u32) {
        debug_assert!(t >= self.now);
        if t - self.now < WHEEL {
            self.append((t % WHEEL) as usize, id);
        } else {
            self.push_overflow(t, id);
        }
    }

    /// A wake-up beyond the wheel, into the overflow heap (rare).
    #[inline(never)]
    fn push_overflow(&mut self, t: Cycle, id: u32) {
        self.overflow.push(Reverse((t, id)));
    }

    /// A forward entry: thread `id` has nothing to do at `t` but move on `hops[0]` cycles
    /// later, then (if not 0) `hops[1]` cycles later, and so on. When a
    /// bucket holding a forward entry is handed out, its holder calls
    /// [`Wheel::take_forward`] and pushes the thread to the next hop at its place in the
    /// bucket, exactly where the thread would have pushed itself had it been woken and run;
    /// it is neither touched nor run. Plain [`Wheel::push`] when `hops[0]` is 0.
    fn push_forward(&mut self, t: Cycle, hops: [u32; HOPS], id: u32) {
        self.links[id as usize].hops = hops;
        self.push(t, id);
    }

    /// True when thread `id`'s entry just handed out is a forward.
    #[inline]
    fn is_forward(&self, id: u32) -> bool {
        self.links[id as usize].hops[0] != 0
    }

    /// The next hop of thread `id`'s forward entry just handed out (the entry is then one
    /// hop shorter), or `None` when the entry is a wake-up.
    #[inline]
    fn take_forward(&mut self, id: u32) -> Option<Cycle> {
        let h = &mut self.links[id as usize].hops;
        let d = h[0];
        if d == 0 {
            // A wake-up: no hops (they are filled from the first), nothing to write.
            return None;
        }
        h.copy_within(1.., 0);
        h[HOPS - 1] = 0;
        Some(self.now + d as Cycle)
    }

    /// Appends thread `id` to bucket `b`'s list.
    #[inline]
    fn append(&mut self, b: usize, id: u32) {
        self.links[id as usize].next = NONE;
        let (first, last) = &mut self.ends[b];
        if *first == NONE {
            *first = id;
        } else {
            self.links[*last as usize].next = id;
        }
        *last = id;
        self.in_wheel += 1;
    }

    /// Detaches the list of the next cycle with events and returns that cycle and the
    /// list's first thread; the list is walked in place with [`Wheel::after`] (in the order
    /// the threads were scheduled), and [`Wheel::taken`] is called once for each of its
    /// threads before the next call. Walking the links instead of copying them into a
    /// vector saves a store, a capacity test and a reload per entry.
    fn next_bucket(&mut self) -> Option<(Cycle, u32)> {
        if self.in_wheel == 0 {
            let &Reverse((t, _)) = self.overflow.peek()?;
            self.now = t;
        }
        loop {
            while let Some(&Reverse((t, id))) = self.overflow.peek() {
                if t - self.now < WHEEL {
                    self.overflow.pop();
                    self.append((t % WHEEL) as usize, id);
                } else {
                    break;
                }
            }
            let b = (self.now % WHEEL) as usize;
            let (first, _) = self.ends[b];
            if first != NONE {
                self.ends[b] = (NONE, NONE);
                return Some((self.now, first));
            }
            self.now += 1;
        }
    }

    /// The thread after `id` in a detached list (`NONE` at its end). Valid until `id` is
    /// pushed again, so it is read before `id` is run. A push never lands in the detached
    /// list: it is for a later cycle, and a thread is in the wheel at most once.
    #[inline]
    fn after(&self, id: u32) -> u32 {
        self.links[id as usize].next
    }

    /// One thread of the detached list has been handed out.
    #[inline]
    fn taken(&mut self) {
        self.in_wheel -= 1;
    }
}

/// Puts thread `id` back into the wheel at its next issue slot, as a forward entry when
/// `forwards` ([`Thread::skip_ahead`]); inlined at both call sites in [`run_chip_with`]
/// (as a closure it was a call per wake-up).
#[inline(always)]
fn sleep(th: &mut Thread, wheel: &mut Wheel, stalls: &mut Stalls, id: u32, forwards: bool) {
    let t = th.t;
    if forwards {
        let hops = th.skip_ahead(stalls);
        wheel.push_forward(t, hops, id);
    } else {
        th.next = None;
        wheel.push(t, id);
    }
}

/// Runs every thread to completion; returns the cycle the last result arrived.
pub fn run_chip(chip: &mut Chip, threads: &mut [Thread], work: &mut dyn WorkSource) -> Cycle {
    run_chip_with(chip, threads, work, true)
}

/// [`run_chip`], with forward wake-ups (`forwards`) or without (the tests compare both).
///
/// A thread that goes to sleep until its next issue slot `t` often has nothing to do
/// there but go back to sleep: its next op is not a load and waits for a result due later
/// (after a 13-word load, the node's data), or it is a run of plain instructions that
/// reserves nothing (after a pipeline op's result). Such wake-ups are played ahead when the
/// thread goes to sleep ([`Thread::skip_ahead`]), and the thread is scheduled as a forward
/// entry at `t` ([`Wheel::push_forward`]): at each skipped cycle the wheel moves it on to
/// the next one in the same place in the bucket as the wake-up would have, without reading
/// the thread's record or op, so every bucket's order, hence every result, stays exact.
fn run_chip_with(
    chip: &mut Chip,
    threads: &mut [Thread],
    work: &mut dyn WorkSource,
    forwards: bool,
) -> Cycle {
    let mut wheel = Wheel::new(threads.len());
    for i in 0..threads.len() as u32 {
        wheel.push(0, i);
    }
    let mut finish = vec![0; threads.len()];
    while let Some((now, first)) = wheel.next_bucket() {
        let mut touched = 0;
        let mut id = first;
        while id != NONE {
            if !wheel.is_forward(id) {
                touched ^= threads[id as usize].touch(chip);
            }
            id = wheel.after(id);
        }
        std::hint::black_box(touched);
        let mut id = first;
        while id != NONE {
            let next = wheel.after(id);
            wheel.taken();
            if let Some(to) = wheel.take_forward(id) {
                wheel.push(to, id);
                id = next;
                continue;
            }
            let th = &mut threads[id as usize];
            loop {
                if th.run(chip, now) {
                    sleep(th, &mut wheel, &mut chip.stalls, id, forwards);
                    break;
                }
                // Program finished: the thread takes more work or retires once results are in.
                match work.next(id as usize, th, chip) {
                    Some(ops) => {
                        th.load_program(ops);
                        if th.t > now {
                            sleep(th, &mut wheel, &mut chip.stalls, id, forwards);
                            break;
                        }
                    }
                    None => {
                        finish[id as usize] = th.results_ready();
                        break;
                    }
                }
            }
            id = next;
        }
    }
    let end = finish.iter().copied().max().unwrap_or(0);
    chip.stalls.idle = finish.iter().map(|&f| end - f).sum();
    end
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::Op;

    struct Programs(Vec<Vec<Op>>);
    impl WorkSource for Programs {
        fn next(&mut self, _id: usize, t: &mut Thread, _c: &mut Chip) -> Option<Vec<Op>> {
            // One program per thread.
            if t.ops.is_empty() { self.0.pop() } else { None }
        }
    }

    fn one_thread(cfg: &SimConfig, box_pipes: u32, prog: Vec<Op>) -> (Cycle, Chip) {
        let mut chip = Chip::new(cfg, box_pipes);
        let mut th = vec![Thread::new(0)];
        let end = run_chip(&mut chip, &mut th, &mut Programs(vec![prog]));
        (end, chip)
    }

    fn use_data() -> Op {
        Op::Issue { n: 1, fpinv: 0 }
    }

    impl Wheel {
        /// The next cycle's threads in order, as `run_chip` walks them.
        fn take_bucket(&mut self, ids: &mut Vec<u32>) -> Option<Cycle> {
            let (now, mut id) = self.next_bucket()?;
            while id != NONE {
                ids.push(id);
                id = self.after(id);
                self.taken();
            }
            Some(now)
        }
    }

    /// The previous wheel: one vector per bucket.
    struct VecWheel {
        buckets: Vec<Vec<u32>>,
        now: Cycle,
        in_wheel: usize,
        overflow: BinaryHeap<Reverse<(Cycle, u32)>>,
    }

    impl VecWheel {
        fn new() -> Self {
            Self {
                buckets: vec![Vec::new(); WHEEL as usize],
                now: 0,
                in_wheel: 0,
                overflow: BinaryHeap::new(),
            }
        }

        fn push(&mut self, t: Cycle, id: u32) {
            if t - self.now < WHEEL {
                self.buckets[(t % WHEEL) as usize].push(id);
                self.in_wheel += 1;
            } else {
                self.overflow.push(Reverse((t, id)));
            }
        }

        fn next_bucket(&mut self) -> Option<(Cycle, Vec<u32>)> {
            if self.in_wheel == 0 {
                let &Reverse((t, _)) = self.overflow.peek()?;
                self.now = t;
            }
            loop {
                while let Some(&Reverse((t, id))) = self.overflow.peek() {
                    if t - self.now < WHEEL {
                        self.overflow.pop();
                        self.buckets[(t % WHEEL) as usize].push(id);
                        self.in_wheel += 1;
                    } else {
                        break;
                    }
                }
                let b = (self.now % WHEEL) as usize;
                if !self.buckets[b].is_empty() {
                    let ids = std::mem::take(&mut self.buckets[b]);
                    self.in_wheel -= ids.len();
                    return Some((self.now, ids));
                }
                self.now += 1;
            }
        }
    }

    /// The list wheel hands out the same threads in the same order as the vector wheel:
    /// random wake-up delays, some beyond the wheel (overflow), so a cycle's bucket mixes
    /// direct and migrated entries.
    #[test]
    fn wheel_lists_keep_the_order_of_bucket_vectors() {
        for seed in 0..10 {
            let mut rng = dualsplit_geometry::Pcg32::new(seed, 7);
            let n = 300;
            let mut w = Wheel::new(n);
            let mut v = VecWheel::new();
            for id in 0..n as u32 {
                w.push(0, id);
                v.push(0, id);
            }
            let mut ids = Vec::new();
            let mut steps = 0;
            while let Some(now) = w.take_bucket(&mut ids) {
                let (vnow, vids) = v.next_bucket().expect("vector wheel ran dry first");
                assert_eq!((now, &ids), (vnow, &vids), "seed {seed}, step {steps}");
                steps += 1;
                if steps < 20_000 {
                    for &id in &ids {
                        let d = match rng.below(10) {
                            0 => WHEEL + rng.below(3 * WHEEL as u32) as u64,
                            1 => WHEEL - 1 - rng.below(4) as u64,
                            _ => 1 + rng.below(40) as u64,
                        };
                        w.push(now + d, id);
                        v.push(now + d, id);
                    }
                }
                ids.clear();
            }
            assert!(v.next_bucket().is_none(), "seed {seed}");
            assert!(steps > 20_000, "seed {seed}: {steps}");
        }
    }

    /// Forward entries hand out every wake-up in the same order as a wheel without them,
    /// where a thread with nothing to do is woken at each hop and pushes itself on: random
    /// delays (some beyond the wheel) and random chains of 0–2 hops, so buckets mix real
    /// wake-ups, forwards and their targets.
    #[test]
    fn forward_entries_keep_the_order_of_plain_wake_ups() {
        for seed in 0..10 {
            let mut rng = dualsplit_geometry::Pcg32::new(seed, 11);
            let n = 300;
            let mut w = Wheel::new(n);
            let mut v = VecWheel::new();
            // The reference's pending hops per thread (it wakes the thread at each).
            let mut plan: Vec<Vec<Cycle>> = vec![Vec::new(); n];
            for id in 0..n as u32 {
                w.push(0, id);
                v.push(0, id);
            }
            let delay = |rng: &mut dualsplit_geometry::Pcg32| match rng.below(10) {
                0 => WHEEL + rng.below(3 * WHEEL as u32) as u64,
                1 => WHEEL - 1 - rng.below(4) as u64,
                _ => 1 + rng.below(40) as u64,
            };
            let (mut ids, mut steps, mut real, mut forwards) = (Vec::new(), 0, 0, 0);
            while let Some(now) = w.take_bucket(&mut ids) {
                let (vnow, vids) = v.next_bucket().expect("reference wheel ran dry first");
                assert_eq!((now, &ids), (vnow, &vids), "seed {seed}, step {steps}");
                steps += 1;
                for &id in &ids {
                    let to = w.take_forward(id);
                    let p = &mut plan[id as usize];
                    assert_eq!(to, (!p.is_empty()).then(|| p[0]), "seed {seed}, {id}");
                    if let Some(to) = to {
                        p.remove(0);
                        w.push(to, id);
                        v.push(to, id);
                        forwards += 1;
                        continue;
                    }
                    real += 1;
                    if real < 20_000 {
                        let t = now + delay(&mut rng);
                        let mut hops = [0; HOPS];
                        let mut at = t;
                        for h in hops.iter_mut().take(rng.below(HOPS as u32 + 1) as usize) {
                            *h = delay(&mut rng) as u32;
                            at += *h as Cycle;
                            p.push(at);
                        }
                        w.push_forward(t, hops, id);
                        v.push(t, id);
                    }
                }
                ids.clear();
            }
            assert!(v.next_bucket().is_none(), "seed {seed}");
            assert!(
                real > 20_000 && forwards > 10_000,
                "seed {seed}: {real} {forwards}"
            );
        }
    }

    /// Random programs of every op kind on 4 TMs × 8 threads (loads that hit, merge and
    /// miss, serial and parallel pipeline ops, reciprocal and plain instruction runs,
    /// atomics between programs): with forward entries every counter and the end cycle
    /// equal those of the plain wake-ups.
    #[test]
    fn forwards_change_no_result() {
        struct Random(dualsplit_geometry::Pcg32, Vec<u32>);
        impl WorkSource for Random {
            fn next(&mut self, id: usize, t: &mut Thread, c: &mut Chip) -> Option<Vec<Op>> {
                if self.1[id] == 0 {
                    return None;
                }
                self.1[id] -= 1;
                let r = &mut self.0;
                if r.below(2) == 0 {
                    t.atomic(c);
                }
                let mut ops = Vec::new();
                for _ in 0..1 + r.below(40) {
                    ops.push(match r.below(4) {
                        0 => Op::Load {
                            word: r.below(1 << 16),
                            words: 1 + r.below(20) as u16,
                        },
                        1 => Op::Pipe {
                            pipe: [Pipe::Box, Pipe::Triangle, Pipe::DualSplit][r.below(3) as usize],
                            n: 1 + r.below(4) as u8,
                            parallel: r.below(2) == 0,
                        },
                        _ => {
                            let n = r.below(20);
                            let fpinv = if r.below(4) == 0 { r.below(n + 1) } else { 0 };
                            Op::Issue {
                                n,
                                fpinv: fpinv as u16,
                            }
                        }
                    });
                }
                Some(ops)
            }
        }
        let mut cfg = SimConfig::lin2020();
        cfg.tms = 4;
        cfg.tps_per_tm = 8;
        for seed in 0..20 {
            let run = |forwards| {
                let mut chip = Chip::new(&cfg, 4);
                let mut th: Vec<Thread> = (0..32).map(|i| Thread::new(i / 8)).collect();
                let mut work = Random(dualsplit_geometry::Pcg32::new(seed, 3), vec![6; 32]);
                let end = run_chip_with(&mut chip, &mut th, &mut work, forwards);
                let dram = chip.dram.stats();
                (end, chip.stalls, chip.caches, chip.units, dram)
            };
            let plain = run(false);
            assert!(
                plain.1.memory > 0 && plain.1.pipeline_latency > 0,
                "{plain:?}"
            );
            assert_eq!(run(true), plain, "seed {seed}");
        }
    }

    /// A thread record and a reservation table each fit one host cache line (64 bytes).
    #[test]
    fn host_records_fit_a_cache_line() {
        assert_eq!(std::mem::size_of::<Thread>(), 64);
        assert_eq!(std::mem::align_of::<Thread>(), 64);
        assert_eq!(std::mem::size_of::<Slots>(), 32);
        assert_eq!(std::mem::align_of::<Slots>(), 32);
    }

    #[test]
    fn l1_hit_takes_one_cycle() {
        let cfg = SimConfig::lin2020();
        let mut chip = Chip::new(&cfg, 1);
        // Warm the line, then time a hit directly.
        let fill = chip.load_word(0, 0, 0);
        assert_eq!(chip.load_word(0, 1, fill), fill + 1);
        assert_eq!(chip.caches.l1_hits, 1);
    }

    #[test]
    fn cold_load_is_a_closed_row_read_and_reload_hits_l2() {
        let cfg = SimConfig::lin2020();
        let mut chip = Chip::new(&cfg, 1);
        // L1 1 + L2 3 + closed row (tRCD 14 + tCAS 14 + burst 2) = 34.
        assert_eq!(chip.load_word(0, 0, 100), 134);
        // Another TM: L1 miss, L2 hit: 1 + 3.
        assert_eq!(chip.load_word(1, 0, 200), 204);
        // Same TM, another line in the same DRAM row: row hit, 1 + 3 + 14 + 2 = 20.
        assert_eq!(chip.load_word(0, 16, 300), 320);
        assert_eq!(chip.caches.l2_hits, 1);
        assert_eq!(chip.dram.stats().row_hits, 1);
    }

    #[test]
    fn row_conflict_load() {
        let cfg = SimConfig::lin2020();
        let mut chip = Chip::new(&cfg, 1);
        chip.load_word(0, 0, 0);
        // Same channel and bank, next row: 128 lines × 16 channels × 16 banks × 16 words.
        let w = 128 * 16 * 16 * 16;
        // 1 + 3 + tRP 14 + tRCD 14 + tCAS 14 + burst 2 = 48.
        assert_eq!(chip.load_word(0, w, 1000), 1048);
        assert_eq!(chip.dram.stats().row_conflicts, 1);
    }

    #[test]
    fn l2_banks_interleave_by_word_or_by_line() {
        // Words 0 and 128 (lines 0 and 8) missing in two TMs in the same cycle: word
        // interleaving (SimTRaX) puts both on L2 bank 0, so the second waits one cycle; line
        // interleaving puts them on banks 0 and 8.
        let mut cfg = SimConfig::lin2020();
        for (by_line, wait) in [(false, 1), (true, 0)] {
            cfg.l2.line_interleaved = by_line;
            let mut chip = Chip::new(&cfg, 1);
            chip.load_word(0, 0, 10);
            chip.load_word(1, 128, 10);
            assert_eq!(
                chip.caches.l2_bank_wait, wait,
                "line_interleaved = {by_line}"
            );
        }
    }

    #[test]
    fn a_conflicting_miss_replaces_a_line_only_when_its_fill_arrives() {
        // SimTRaX installs lines at their arrival (L1Cache/L2Cache UpdateCache) and finds
        // lines in flight on its pending lists; model 2 wrote the tag at request time.
        let cfg = SimConfig::lin2020();
        let mut chip = Chip::new(&cfg, 1);
        // Line 0 cold: 134 (L1 1 + L2 3 + closed row 30).
        assert_eq!(chip.load_word(0, 0, 100), 134);
        // Line 1024 (word 16384) maps to the same L1 set (64 KB direct-mapped): a closed-row
        // read on channel 8, 34 cycles.
        assert_eq!(chip.load_word(0, 16384, 200), 234);
        // Line 0 is still in the L1 until 234: a 1-cycle hit, no L2 access.
        assert_eq!(chip.load_word(0, 1, 202), 203);
        assert_eq!(chip.caches.l2_accesses, 2);
        // Line 2048 (same set, channel 0 bank 1, closed row: data at tick 470, rounded up to
        // the 2 ns burst grid, 472 + 4 = 476 ticks) takes the set's tag while 1024 is still in
        // flight; 1024 stays on the in-flight list and a miss to it merges.
        assert_eq!(chip.load_word(0, 32768, 203), 238);
        assert_eq!(chip.load_word(0, 16385, 205), 234);
        assert_eq!(chip.caches.l2_accesses, 3);
        assert_eq!(chip.caches.l1_merged, 1);
        // Once 2048 has arrived, line 0 is gone: an L1 miss, L2 hit (1 + 3).
        assert_eq!(chip.load_word(0, 2, 240), 244);
        assert_eq!(chip.caches.l2_accesses, 4);
        assert_eq!(chip.dram.stats().reads, 3);
    }

    #[test]
    fn miss_to_line_in_flight_merges() {
        let cfg = SimConfig::lin2020();
        let mut chip = Chip::new(&cfg, 1);
        let r0 = chip.load_word(0, 0, 0);
        let r1 = chip.load_word(0, 1, 1);
        assert_eq!(r1, r0);
        assert_eq!(chip.caches.l1_merged, 1);
        assert_eq!(chip.caches.l2_accesses, 1);
        assert_eq!(chip.dram.stats().reads, 1);
    }

    #[test]
    fn thread_load_then_use_waits_for_data() {
        let cfg = SimConfig::lin2020();
        // Load at cycle 0 (cold: 34), use at 34, one issue: finish 35.
        let (end, chip) = one_thread(&cfg, 1, vec![Op::Load { word: 0, words: 1 }, use_data()]);
        assert_eq!(end, 35);
        assert_eq!(chip.stalls.memory, 33);
    }

    #[test]
    fn bank_conflict_costs_one_cycle() {
        let cfg = SimConfig::lin2020();
        // Two threads on one TM load words 0 and 16 (both bank 0) at cycle 0: the second
        // gets the bank at cycle 1.
        let mut chip = Chip::new(&cfg, 1);
        let mut th = vec![Thread::new(0), Thread::new(0)];
        let progs = vec![
            vec![Op::Load { word: 16, words: 1 }],
            vec![Op::Load { word: 0, words: 1 }],
        ];
        run_chip(&mut chip, &mut th, &mut Programs(progs));
        assert_eq!(chip.stalls.l1_bank, 1);
        // A single 16-word line load spans all 16 banks without conflict.
        let (_, chip) = one_thread(&cfg, 1, vec![Op::Load { word: 0, words: 16 }]);
        assert_eq!(chip.stalls.l1_bank, 0);
    }

    #[test]
    fn one_pipeline_op_takes_its_latency() {
        let cfg = SimConfig::lin2020();
        let box_op = |n, parallel| Op::Pipe {
            pipe: Pipe::Box,
            n,
            parallel,
        };
        // Issue at 0, result at 8, use at 8: end 9.
        let (end, _) = one_thread(&cfg, 1, vec![box_op(1, false), use_data()]);
        assert_eq!(end, 9);
        // Four serial box tests: issue 0..3, last result 11, use: 12.
        let (end, _) = one_thread(&cfg, 1, vec![box_op(4, false), use_data()]);
        assert_eq!(end, 12);
        // Four in parallel on four pipes: one issue, result 8, use: 9.
        let (end, _) = one_thread(&cfg, 4, vec![box_op(4, true), use_data()]);
        assert_eq!(end, 9);
        let dst = Op::Pipe {
            pipe: Pipe::DualSplit,
            n: 1,
            parallel: false,
        };
        let (end, chip) = one_thread(&cfg, 1, vec![dst, use_data()]);
        assert_eq!(end, 9);
        assert_eq!(chip.units.dst_ops, 1);
    }

    #[test]
    fn two_threads_share_one_pipeline() {
        let cfg = SimConfig::lin2020();
        let mut chip = Chip::new(&cfg, 1);
        let mut th = vec![Thread::new(0), Thread::new(0)];
        let op = Op::Pipe {
            pipe: Pipe::Box,
            n: 1,
            parallel: false,
        };
        let progs = vec![vec![op, use_data()], vec![op, use_data()]];
        let end = run_chip(&mut chip, &mut th, &mut Programs(progs));
        // The second thread gets the pipe at cycle 1: result 9, use ends at 10.
        assert_eq!(end, 10);
        assert_eq!(chip.stalls.pipeline_busy, 1);
    }

    #[test]
    fn fpinv_is_shared_and_long() {
        let cfg = SimConfig::lin2020();
        // 3 reciprocals at 0, 1, 2 (pipelined unit), last result 18; 5 more issues 3..7;
        // then use at 18: end 19.
        let (end, _) = one_thread(&cfg, 1, vec![Op::Issue { n: 8, fpinv: 3 }, use_data()]);
        assert_eq!(end, 19);
    }
}
