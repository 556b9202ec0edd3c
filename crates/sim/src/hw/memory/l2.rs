//! The shared L2 cache and the DRAM behind it.
//!
//! Hardware (Lin et al. 2020, §4, Table 1; SimTRaX `L2Cache.cc`): one L2 for all TMs,
//! `l2.banks` banks that each accept one access per cycle, direct-mapped by default, with
//! `l2.hit_latency` cycles from the bank slot to the data. The bank of an access is, as
//! SimTRaX has it (`sim/L2Cache.cc:170`), its word address mod the bank count, or its line
//! address mod the bank count (`l2.line_interleaved = true`, an option). A request that
//! finds its bank taken is refused (`l2.refuse_conflicts`, SimTRaX `sim/L2Cache.cc:180-185`)
//! and the thread retries each cycle; it is accepted in the bank's first free cycle, which
//! [`L2::read`] reports so the L1 can hold the thread's issue until then.
//! A miss goes to DRAM ([`Dram`]) when the tag lookup is done and the line is installed
//! when the DRAM's data arrives; a miss to a line already in flight waits for that fill.

use crate::config::SimConfig;
use crate::hw::Cycle;
use crate::hw::addr::{LineAddr, WordAddr};
use crate::hw::memory::{Cache, CacheStats, Dram, DramStats, Lookup};
use crate::hw::slots::Slots;

/// The L2: tags, banks and the DRAM it reads from.
pub struct L2 {
    tags: Cache,
    banks: Vec<Slots>,
    /// `banks − 1` (a power of two).
    bank_mask: u64,
    line_interleaved: bool,
    refuse_conflicts: bool,
    /// L1 hit latency + L2 hit latency: from the L2 bank slot to the data in the register.
    hit_latency: u64,
    dram: Dram,
    accesses: u64,
    hits: u64,
    merged: u64,
    bank_wait: u64,
    stores: u64,
}

impl L2 {
    /// A cold L2 and DRAM.
    pub fn new(cfg: &SimConfig) -> Self {
        Self {
            tags: Cache::new(cfg.l2.size_bytes, cfg.l2.line_bytes, cfg.l2.associativity),
            banks: vec![Slots::default(); cfg.l2.banks as usize],
            bank_mask: cfg.l2.banks as u64 - 1,
            line_interleaved: cfg.l2.line_interleaved,
            refuse_conflicts: cfg.l2.refuse_conflicts,
            hit_latency: cfg.l1.hit_latency + cfg.l2.hit_latency,
            dram: Dram::new(&cfg.dram),
            accesses: 0,
            hits: 0,
            merged: 0,
            bank_wait: 0,
            stores: 0,
        }
    }

    /// Reads `line` for an L1 miss of word `word` whose L1 slot was `at`; returns the cycle
    /// the data is in the requesting thread's register and, when the bank was taken at `at`
    /// and conflicts are refused, the cycle the bank accepted the retried request (the
    /// thread issues nothing before it). `now` (≤ `at`) is the current event time: no later
    /// request starts before it.
    pub fn read(
        &mut self,
        line: LineAddr,
        word: WordAddr,
        at: Cycle,
        now: Cycle,
    ) -> (Cycle, Option<Cycle>) {
        let bank_addr = if self.line_interleaved {
            line.get()
        } else {
            word.get()
        };
        let b = (bank_addr & self.bank_mask) as usize;
        let slot = Cycle(self.banks[b].reserve(at.get()));
        self.bank_wait += slot - at;
        self.accesses += 1;
        let refused = (self.refuse_conflicts && slot > at).then_some(slot);
        let data = slot + self.hit_latency;
        let ready = match self.tags.lookup(line, slot) {
            Lookup::Present { fill } if fill <= slot => {
                self.hits += 1;
                data
            }
            Lookup::Present { fill } => {
                self.merged += 1;
                fill.max(data)
            }
            Lookup::Absent => {
                let (done, _) = self.dram.read_at(line, data, now);
                self.tags.install(line, done, slot);
                done
            }
        };
        (ready, refused)
    }

    /// A store of word `word` (in `line`) whose L1 slot was `at`, passed on to DRAM's write
    /// queue as SimTRaX does (`sim/L2Cache.cc:322-395`: write-around, the L2's tags are
    /// not touched, the store takes its bank for the cycle and is refused on a conflict
    /// like a load). Returns the cycle the bank accepted it when it was refused (the
    /// thread issues nothing before it). The L2's energy is not charged for stores
    /// (SimTRaX `sim/main.cc:1185` counts `accesses − stores`).
    pub fn write(
        &mut self,
        line: LineAddr,
        word: WordAddr,
        at: Cycle,
        now: Cycle,
    ) -> Option<Cycle> {
        let bank_addr = if self.line_interleaved {
            line.get()
        } else {
            word.get()
        };
        let b = (bank_addr & self.bank_mask) as usize;
        let slot = Cycle(self.banks[b].reserve(at.get()));
        self.bank_wait += slot - at;
        self.stores += 1;
        self.dram.write(line, slot, now);
        (self.refuse_conflicts && slot > at).then_some(slot)
    }

    /// Adds the L2's counters to `c`.
    pub fn add_stats(&self, c: &mut CacheStats) {
        c.l2_accesses += self.accesses;
        c.l2_hits += self.hits;
        c.l2_merged += self.merged;
        c.l2_bank_wait += self.bank_wait;
        c.l2_stores += self.stores;
    }

    /// The DRAM's counters.
    pub fn dram_stats(&self) -> DramStats {
        self.dram.stats()
    }
}
