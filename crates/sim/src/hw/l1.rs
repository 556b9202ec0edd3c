//! A TM's L1 data cache controller (Lin et al. 2020, §2.3, Table 1; SimTRaX `L1Cache.cc`):
//! direct-mapped by default, `l1.banks` word banks (bank = word address mod the bank count,
//! one access per bank per cycle); a hit returns its word `l1.hit_latency` cycles after its
//! bank slot, a miss goes to the shared [`L2`] and the line is installed when its fill
//! arrives; a miss to a line in flight waits for that fill (no second L2 access). Stores
//! are write-around and go through the L2 to DRAM's write queue. When the L2 refuses a miss (its bank taken, `l2.refuse_conflicts`),
//! the load is retried until the L2 accepts it, as SimTRaX's issue unit retries a refused
//! instruction (`sim/L1Cache.cc:318-322`, `sim/IssueUnit.cc:769-787`): modelled as the
//! thread issuing nothing before the cycle after the L2 bank's first free cycle (the cycle
//! a retry succeeds when no other request takes the bank first).

use crate::config::CacheConfig;
use crate::hw::Cycle;
use crate::hw::addr::{LineAddr, WordAddr};
use crate::hw::issued::Issued;
use crate::hw::memory::{Cache, CacheStats, L2, Lookup};
use crate::hw::slots::{self, BankSlots};

/// What serves an L1's misses: the [`L2`], or nothing ([`Resident`]).
pub trait Backing {
    /// Reads `line` for a miss of word `word` whose L1 slot was `at` ([`L2::read`]).
    fn read(
        &mut self,
        line: LineAddr,
        word: WordAddr,
        at: Cycle,
        now: Cycle,
    ) -> (Cycle, Option<Cycle>);
    /// Writes word `word` of `line`, whose L1 slot was `at` ([`L2::write`]).
    fn write(&mut self, line: LineAddr, word: WordAddr, at: Cycle, now: Cycle) -> Option<Cycle>;
}

impl Backing for L2 {
    #[inline(always)]
    fn read(
        &mut self,
        line: LineAddr,
        word: WordAddr,
        at: Cycle,
        now: Cycle,
    ) -> (Cycle, Option<Cycle>) {
        L2::read(self, line, word, at, now)
    }

    #[inline]
    fn write(&mut self, line: LineAddr, word: WordAddr, at: Cycle, now: Cycle) -> Option<Cycle> {
        L2::write(self, line, word, at, now)
    }
}

/// No backing: for a load whose lines the L1 holds ([`L1::holds_all`]), which therefore
/// never misses. The parallel engine's first phase loads through it, without the L2.
pub struct Resident;

impl Backing for Resident {
    fn read(&mut self, line: LineAddr, _: WordAddr, _: Cycle, _: Cycle) -> (Cycle, Option<Cycle>) {
        unreachable!("line {line:?} was checked to be held (L1::holds_all) and missed")
    }

    fn write(&mut self, line: LineAddr, _: WordAddr, _: Cycle, _: Cycle) -> Option<Cycle> {
        unreachable!("a store to line {line:?} outside the commit phase")
    }
}

/// One TM's L1: tags, bank reservation tables and counters.
pub struct L1 {
    cache: Cache,
    banks: BankSlots,
    /// `l1.banks − 1` (a power of two).
    bank_mask: u64,
    /// log2(words per line).
    line_word_shift: u32,
    latency: u64,
    accesses: u64,
    hits: u64,
    merged: u64,
    /// The latest cycle an L2 bank accepted a refused miss of the load being placed.
    accepted: Cycle,
}

impl L1 {
    /// A cold L1 of configuration `cfg`.
    pub fn new(cfg: &CacheConfig) -> Self {
        Self {
            cache: Cache::new(cfg.size_bytes, cfg.line_bytes, cfg.associativity),
            banks: BankSlots::new(cfg.banks),
            bank_mask: cfg.banks as u64 - 1,
            line_word_shift: (cfg.line_bytes / 4).trailing_zeros(),
            latency: cfg.hit_latency,
            accesses: 0,
            hits: 0,
            merged: 0,
            accepted: Cycle::ZERO,
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
    pub fn load<B: Backing>(
        &mut self,
        l2: &mut B,
        addr: WordAddr,
        words: u64,
        at: Cycle,
        now: Cycle,
    ) -> Issued {
        let shift = self.line_word_shift;
        let mut c = at;
        let mut w = addr.get();
        let end = w + words;
        let (mut ready, mut busy) = (Cycle::ZERO, 0);
        while w < end {
            let seg_end = (((w >> shift) + 1) << shift).min(end);
            let k = seg_end - w;
            let (last, r) = if self.banks.try_run(w & self.bank_mask, c.get(), k) {
                let (r, fill) = self.first_word(l2, w, c, now);
                self.count_words(c + 1, k - 1, fill);
                (c + k - 1, r.max(fill))
            } else {
                let (last, r, stall) = self.segment_conflict(l2, w, k, c, now);
                busy += stall;
                (last, r)
            };
            ready = ready.max(r).max(last + self.latency);
            c = last + 1;
            w = seg_end;
        }
        let accepted = std::mem::replace(&mut self.accepted, Cycle::ZERO);
        if accepted >= c {
            busy += accepted + 1 - c;
            c = accepted + 1;
        }
        Issued {
            next_issue: c,
            ready,
            busy,
        }
    }

    /// A store of `words` words from `addr` issued from cycle `at`: write-around (the L1
    /// neither allocates nor updates a line), each word taking its L1 bank slot like a
    /// load's and then going through the L2 to DRAM's write queue ([`L2::write`]; SimTRaX
    /// `sim/L1Cache.cc:457-491`, `sim/L2Cache.cc:322-395`). The thread does not wait for
    /// the data: `ready` is the last word's bank slot; a store the L2 refused (its bank
    /// taken) holds the thread's issue until the bank accepts it, as a load's miss does.
    pub fn store<B: Backing>(
        &mut self,
        l2: &mut B,
        addr: WordAddr,
        words: u64,
        at: Cycle,
        now: Cycle,
    ) -> Issued {
        let shift = self.line_word_shift;
        let (mut c, mut w, end, mut busy) = (at, addr.get(), addr.get() + words, 0);
        let mut hold = Cycle::ZERO;
        while w < end {
            let seg_end = (((w >> shift) + 1) << shift).min(end);
            let k = seg_end - w;
            let run = (self.banks).reserve_run(w & self.bank_mask, c.get(), k, now.get(), 0);
            busy += run.stall;
            let line = LineAddr::new(w >> shift);
            for word in w..seg_end {
                if let Some(slot) = l2.write(line, WordAddr::new(word), Cycle(run.last), now) {
                    hold = hold.max(slot);
                }
            }
            c = Cycle(run.last + 1);
            w = seg_end;
        }
        let ready = Cycle(c.get().saturating_sub(1)).max(at);
        if hold > Cycle::ZERO {
            busy += (hold + 1).get().saturating_sub(c.get());
            c = c.max(hold + 1);
        }
        Issued {
            next_issue: c,
            ready,
            busy,
        }
    }

    /// Whether the L1 holds every line of the `words` words from `addr` as a tag, read
    /// without effect: then a load of them hits or merges, and never reaches the L2.
    #[inline]
    pub fn holds_all(&self, addr: WordAddr, words: u64) -> bool {
        let shift = self.line_word_shift;
        let (first, last) = (
            addr.get() >> shift,
            (addr.get() + words.max(1) - 1) >> shift,
        );
        // A loop, not `(first..=last).all(..)`: an inclusive range costs a flag per step.
        let mut line = first;
        while self.cache.holds(LineAddr::new(line)) {
            if line == last {
                return true;
            }
            line += 1;
        }
        false
    }

    /// Reads (without effect) the L1 tag of `addr`'s line and returns a value to keep the
    /// read: the event loop calls it for the coming loads of a wake-up cycle so the host
    /// cache misses of their lookups overlap. Changes nothing simulated. (The L2's tags
    /// are the commit phase's, which other host threads may be changing.)
    #[inline]
    pub fn touch(&self, addr: WordAddr) -> u64 {
        self.cache
            .peek(LineAddr::new(addr.get() >> self.line_word_shift))
    }

    /// The first word of a line segment, at its bank slot `slot`: the tag lookup, and on a
    /// miss the L2 read and the line's installation at its fill. Returns the cycle the word
    /// is in the register and the line's fill cycle.
    #[inline(always)]
    fn first_word<B: Backing>(
        &mut self,
        l2: &mut B,
        w: u64,
        slot: Cycle,
        now: Cycle,
    ) -> (Cycle, Cycle) {
        self.accesses += 1;
        let line = w >> self.line_word_shift;
        match self.cache.lookup(LineAddr::new(line), slot) {
            Lookup::Present { fill } if fill <= slot => {
                self.hits += 1;
                (slot + self.latency, fill)
            }
            Lookup::Present { fill } => {
                self.merged += 1;
                (fill.max(slot + self.latency), fill)
            }
            Lookup::Absent => self.miss(l2, line, w, slot, now),
        }
    }

    #[inline(never)]
    fn miss<B: Backing>(
        &mut self,
        l2: &mut B,
        line: u64,
        w: u64,
        slot: Cycle,
        now: Cycle,
    ) -> (Cycle, Cycle) {
        let (ready, refused) = l2.read(LineAddr::new(line), WordAddr::new(w), slot, now);
        if let Some(accepted) = refused {
            self.accepted = self.accepted.max(accepted);
        }
        self.cache.install(LineAddr::new(line), ready, slot);
        (ready, ready)
    }

    /// Counts `n` words of a line filled at `fill`, at consecutive cycles from `c`: hits
    /// from the fill on, merged before.
    #[inline(always)]
    fn count_words(&mut self, c: Cycle, n: u64, fill: Cycle) {
        let hits = slots::at_or_after(c.get(), n, fill.get());
        self.accesses += n;
        self.hits += hits;
        self.merged += n - hits;
    }

    /// A line segment of `k` words from `w` (issue from cycle `c`) some of whose banks are
    /// busy: the first word takes its bank's first free cycle and looks the line up, the
    /// rest are placed after it word by word. Returns the last word's cycle, the cycle the
    /// data is in the register, and the bank stall.
    #[inline(never)]
    fn segment_conflict<B: Backing>(
        &mut self,
        l2: &mut B,
        w: u64,
        k: u64,
        c: Cycle,
        now: Cycle,
    ) -> (Cycle, Cycle, u64) {
        let slot = Cycle(
            self.banks
                .reserve_word(w & self.bank_mask, c.get(), now.get()),
        );
        let mut stall = slot - c;
        let (r, fill) = self.first_word(l2, w, slot, now);
        let mut last = slot;
        if k > 1 {
            let run = self.banks.reserve_run(
                (w + 1) & self.bank_mask,
                slot.get() + 1,
                k - 1,
                now.get(),
                fill.get(),
            );
            stall += run.stall;
            last = Cycle(run.last);
            let hits = run.at_or_after;
            self.accesses += k - 1;
            self.hits += hits;
            self.merged += k - 1 - hits;
        }
        (last, r.max(fill), stall)
    }

    /// One word load at bank slot `slot` (already reserved): the cycle the data is in the
    /// register.
    #[cfg(test)]
    pub(crate) fn load_word(&mut self, l2: &mut L2, word: u64, slot: Cycle) -> Cycle {
        let ready = self.first_word(l2, word, slot, Cycle::ZERO).0;
        self.accepted = Cycle::ZERO;
        ready
    }
    /// Adds the L1's counters to `caches`.
    pub fn add_stats(&self, caches: &mut CacheStats) {
        caches.l1_accesses += self.accesses;
        caches.l1_hits += self.hits;
        caches.l1_merged += self.merged;
    }
}
