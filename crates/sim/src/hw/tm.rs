//! A thread multiprocessor (TM): the units its thread processors share.
//!
//! Hardware (Lin et al. 2020, §2.3 and §4, Table 1; SimTRaX `L1Cache.cc`,
//! `FunctionalUnit`s): each TM has
//!
//! * an **L1 data cache** ([`L1`]);
//! * **ray-box, ray-triangle and dual-split pipelines** ([`Pipelines`]);
//! * a **reciprocal unit** (`fpinv_units` of them), shared by the TM's threads, one op per
//!   cycle, result after `fpinv_latency`;
//! * the **shared functional-unit pools** of the compiled kernels' threads ([`Pools`]: FP
//!   compare, min/max, conversion, branch, integer multiply).
//!
//! Every unit is a reservation table: a request learns the cycle it gets the unit (the first
//! free cycle at or after it asks) and the cycle its result is ready. The methods take the
//! cycle the thread issues the request and return both; either thread model drives the TM
//! through them.

use crate::config::SimConfig;
use crate::hw::Cycle;
use crate::hw::addr::WordAddr;
use crate::hw::counts::UnitStats;
use crate::hw::fu::{Pool, Pools};
use crate::hw::icache::{Fetch, ICaches};
use crate::hw::issued::Issued;
use crate::hw::l1::{Backing, L1};
use crate::hw::memory::CacheStats;
use crate::hw::pipe::{Pipe, Pipelines, TmPipes};
use crate::hw::slots::{Slots, earliest};

/// One TM's L1, pipelines, reciprocal units and functional-unit pools.
pub struct Tm {
    l1: L1,
    pipes: Pipelines,
    fpinv: Vec<Slots>,
    fpinv_latency: u64,
    /// The shared pools of the compiled kernels' threads.
    pools: Pools,
    /// The instruction caches' fetch slots (compiled kernels).
    icache: ICaches,
    units: UnitStats,
}

impl Tm {
    /// An idle TM with a cold L1; `pipes` its ray-box pipelines (the "+" configurations use
    /// the node arity; [`TmPipes`]).
    pub fn new(cfg: &SimConfig, pipes: impl Into<TmPipes>) -> Self {
        Self {
            l1: L1::new(&cfg.l1),
            pipes: Pipelines::new(&cfg.units, pipes.into()),
            fpinv: vec![Slots::default(); cfg.units.fpinv_units as usize],
            fpinv_latency: cfg.units.fpinv_latency,
            pools: Pools::new(&cfg.units),
            icache: ICaches::new(&cfg.units),
            units: UnitStats::default(),
        }
    }

    /// A load through the TM's L1 ([`L1::load`]).
    #[inline(always)]
    pub fn load<B: Backing>(
        &mut self,
        l2: &mut B,
        addr: WordAddr,
        words: u64,
        at: Cycle,
        now: Cycle,
    ) -> Issued {
        self.l1.load(l2, addr, words, at, now)
    }

    /// Whether the TM's L1 holds every line of the words ([`L1::holds_all`]).
    #[inline]
    pub fn holds_all(&self, addr: WordAddr, words: u64) -> bool {
        self.l1.holds_all(addr, words)
    }

    /// A store through the TM's L1 and the L2 ([`L1::store`]).
    #[inline]
    pub fn store<B: Backing>(
        &mut self,
        l2: &mut B,
        addr: WordAddr,
        words: u64,
        at: Cycle,
        now: Cycle,
    ) -> Issued {
        self.l1.store(l2, addr, words, at, now)
    }

    /// `n` ops on the TM's pipelines ([`Pipelines::issue`]).
    #[inline(always)]
    pub fn pipe(&mut self, pipe: Pipe, n: u8, parallel: bool, at: Cycle) -> Issued {
        self.pipes.issue(pipe, n, parallel, at, &mut self.units)
    }

    /// A fetch of the instruction at `pc` from instruction cache `cache`, from cycle `at`
    /// ([`ICaches::try_fetch`]); the thread then keeps it or gives it back.
    #[inline(always)]
    pub fn fetch(&mut self, cache: usize, pc: u32, at: Cycle) -> Fetch {
        self.icache.try_fetch(cache, pc, at)
    }

    /// The fetch `f`'s instruction issues: the fetch is counted ([`Fetch::keep`]).
    #[inline(always)]
    pub fn keep(&mut self, f: Fetch) {
        f.keep(&mut self.icache);
    }

    /// The fetch `f`'s instruction does not issue now ([`Fetch::give_back`]).
    #[inline(always)]
    pub fn give_back(&mut self, f: Fetch) {
        f.give_back(&mut self.icache);
    }

    /// One operation on pool `p`, requested at `at`: the cycle it takes a unit
    /// ([`Pools::reserve`]).
    #[inline(always)]
    pub fn reserve_pool(&mut self, p: Pool, at: Cycle) -> Cycle {
        self.pools.reserve(p, at)
    }

    /// Pool `p`'s result latency.
    #[inline(always)]
    pub fn pool_latency(&self, p: Pool) -> u64 {
        self.pools.latency(p)
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

    /// Reads (without effect) the L1 tag `addr`'s load will look up ([`L1::touch`]).
    #[inline]
    pub fn touch(&self, addr: WordAddr) -> u64 {
        self.l1.touch(addr)
    }

    /// Adds the TM's counters to `caches` and `units`.
    pub fn add_stats(&self, caches: &mut CacheStats, units: &mut UnitStats) {
        self.l1.add_stats(caches);
        units.box_ops += self.units.box_ops;
        units.tri_ops += self.units.tri_ops;
        units.dst_ops += self.units.dst_ops;
        units.fpinv_ops += self.units.fpinv_ops;
    }

    /// One word load at bank slot `slot` (already reserved): the cycle the data is in the
    /// register.
    #[cfg(test)]
    pub(crate) fn load_word(
        &mut self,
        l2: &mut crate::hw::memory::L2,
        word: u64,
        slot: Cycle,
    ) -> Cycle {
        self.l1.load_word(l2, word, slot)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::memory::L2;

    /// SimTRaX refuses an L2 request whose bank is taken in its cycle and the thread retries
    /// (`sim/L2Cache.cc:180-185`): the load's issue is held until the bank accepts it.
    #[test]
    fn a_refused_l2_request_holds_the_threads_issue() {
        let c = Cycle;
        for (refuse, next, busy) in [(true, c(12), 1), (false, c(11), 0)] {
            let mut cfg = SimConfig::lin2020();
            cfg.l2.refuse_conflicts = refuse;
            let mut l2 = L2::new(&cfg);
            let (mut a, mut b) = (Tm::new(&cfg, 1), Tm::new(&cfg, 1));
            // Words 0 and 128 miss in two TMs in cycle 10: both on L2 bank 0 (word
            // address mod 128), so the second request gets the bank in cycle 11.
            let first = a.load(&mut l2, WordAddr::new(0), 1, c(10), c(10));
            assert_eq!(first.next_issue, c(11));
            let r = b.load(&mut l2, WordAddr::new(128), 1, c(10), c(10));
            assert_eq!((r.next_issue, r.busy), (next, busy), "refuse = {refuse}");
        }
    }

    /// The TM's interface as a thread model other than the macro-op replay drives it:
    /// typed requests at a cycle, the cycle the result is ready.
    #[test]
    fn the_tm_answers_requests_at_a_cycle() {
        let cfg = SimConfig::lin2020();
        let mut l2 = L2::new(&cfg);
        let mut tm = Tm::new(&cfg, 1);
        // A cold 3-word load at byte 0: L1 1 + L2 5 + closed row 30; words at 0, 1, 2.
        let c = Cycle;
        let r = tm.load(&mut l2, WordAddr::from_byte(0), 3, c(0), c(0));
        assert_eq!((r.next_issue, r.ready, r.busy), (c(3), c(36), 0));
        // The same words again: L1 hits, the last at cycle 102, data at 103.
        let r = tm.load(&mut l2, WordAddr::new(0), 3, c(100), c(100));
        assert_eq!((r.next_issue, r.ready), (c(103), c(103)));
        // A store to bank 0 in cycle 200 and a load of word 16 (bank 0) in the same cycle:
        // the load waits one cycle for the bank; a store allocates no line.
        let s = tm.store(&mut l2, WordAddr::new(32), 1, c(200), c(200));
        assert_eq!((s.next_issue, s.ready, s.busy), (c(201), c(200), 0));
        // It went through the L2 (no read queued: the DRAM drained it at once).
        let mut stats = Default::default();
        l2.add_stats(&mut stats);
        assert_eq!(stats.l2_stores, 1);
        assert_eq!(l2.dram_stats().writes, 1);
        let r = tm.load(&mut l2, WordAddr::new(16), 1, c(200), c(200));
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
