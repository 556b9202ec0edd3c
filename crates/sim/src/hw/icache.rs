//! A TM's instruction caches as SimTRaX's issue unit has them (`sim/IssueUnit.cc:790-847`):
//! `units.icaches` caches per TM (the paper's §4: two), thread `i` of the TM fetching from
//! cache `i mod icaches`; each cache has `units.icache_banks` banks, the bank of an
//! instruction is its index (pc / 4) mod the bank count, and a bank serves at most
//! `units.icache_fetches` fetches per cycle (`fetch_per_cycle = 2`, `sim/IssueUnit.h:148`).
//! A thread whose bank is full retries its fetch the next cycle. Every fetch hits (SimTRaX
//! reads the decoded program; there are no misses). `icache_fetches = 0` removes the limit.

use crate::config::UnitConfig;
use crate::hw::Cycle;
use crate::hw::window::Window;

/// A fetch made by [`ICaches::try_fetch`]: the cycle it is made in, and whether it was
/// counted yet (or needs no counting: no limit).
#[derive(Clone, Copy, Debug)]
pub struct Fetch {
    /// The cycle of the fetch.
    pub at: Cycle,
    bank: u32,
    taken: bool,
}

impl Fetch {
    /// The instruction issues: the fetch is counted.
    #[inline]
    pub fn keep(self, ic: &mut ICaches) {
        // `taken` is set without a limit too: there is nothing to count.
        if !self.taken {
            ic.banks.take(self.bank as usize, self.at.get());
        }
    }

    /// The instruction does not issue now: the fetch is not counted.
    #[inline]
    pub fn give_back(self, ic: &mut ICaches) {
        if self.taken && ic.limit != 0 {
            ic.banks.untake(self.bank as usize, self.at.get());
        }
    }
}

/// The fetch counts of one TM's instruction caches.
#[derive(Clone, Debug)]
pub struct ICaches {
    /// One row per bank, each cache's banks in a plane of their own: a thread reads only
    /// its cache's counts, so each host cache line it loads holds more of the cycles it
    /// fetches in.
    banks: Window,
    caches: usize,
    bank_mask: u32,
    /// Fetches per bank per cycle; 0 = no limit.
    limit: u8,
}

impl ICaches {
    /// Idle caches as `units` configures them.
    pub fn new(units: &UnitConfig) -> Self {
        let limit = units.icache_fetches.min(u8::MAX as u32) as u8;
        let (planes, rows) = if limit == 0 {
            (1, 0)
        } else {
            (units.icaches as usize, units.icache_banks as usize)
        };
        Self {
            banks: Window::with_planes(planes, rows),
            caches: units.icaches as usize,
            bank_mask: units.icache_banks - 1,
            limit,
        }
    }

    /// The cache thread `thread` of its TM fetches from.
    pub fn cache_of(&self, thread: usize) -> usize {
        thread % self.caches
    }

    /// The bank of cache `cache` holding the instruction at byte address `pc`.
    #[inline]
    fn bank(&self, cache: usize, pc: u32) -> usize {
        self.banks.row(cache, ((pc >> 2) & self.bank_mask) as usize)
    }

    /// The fetch of a thread that may not issue the instruction yet: fetches the
    /// instruction at `pc` from cache `cache` in the first cycle at or after `c` its bank
    /// has a fetch left, when that cycle lies in the counts' window, and returns it. The
    /// caller then either issues ([`Fetch::keep`]) or gives the fetch back
    /// ([`Fetch::give_back`]) before anything else is fetched: either way the counts are
    /// those of looking for the free cycle first and counting the fetch only on issue.
    #[inline]
    pub fn try_fetch(&mut self, cache: usize, pc: u32, c: Cycle) -> Fetch {
        if self.limit == 0 {
            return Fetch {
                at: c,
                bank: 0,
                taken: true,
            };
        }
        let bank = self.bank(cache, pc);
        let (s, taken) = self.banks.reserve_in_window(bank, c.get(), self.limit);
        Fetch {
            at: Cycle(s),
            bank: bank as u32,
            taken,
        }
    }
}

#[cfg(test)]
impl ICaches {
    /// The cycle a fetch of `pc` by cache `cache` from cycle `c` would take, counting
    /// nothing.
    fn peek(&mut self, cache: usize, pc: u32, c: Cycle) -> Cycle {
        let f = self.try_fetch(cache, pc, c);
        f.give_back(self);
        f.at
    }

    /// Fetches `pc` by cache `cache` from cycle `c` and issues it; returns the fetch cycle.
    fn fetch(&mut self, cache: usize, pc: u32, c: Cycle) -> Cycle {
        let f = self.try_fetch(cache, pc, c);
        f.keep(self);
        f.at
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SimConfig;
    use crate::hw::window::HISTORY;

    #[test]
    fn a_bank_serves_two_fetches_a_cycle() {
        let mut ic = ICaches::new(&SimConfig::lin2020().units);
        let c = Cycle;
        // Three threads of cache 0 fetching pc 0 (bank 0) in cycle 5: the third waits.
        assert_eq!(ic.fetch(0, 0, c(5)), c(5));
        assert_eq!(ic.peek(0, 0, c(5)), c(5));
        assert_eq!(ic.fetch(0, 0, c(5)), c(5));
        assert_eq!(ic.peek(0, 0, c(5)), c(6));
        assert_eq!(ic.fetch(0, 0, c(5)), c(6));
        // Another bank (pc 4), the same bank of the other cache, and pc 64 (bank 0 again,
        // 16 banks) of cache 0.
        assert_eq!(ic.fetch(0, 4, c(5)), c(5));
        assert_eq!(ic.fetch(1, 0, c(5)), c(5));
        assert_eq!(ic.fetch(0, 64, c(5)), c(6));
        assert_eq!((ic.cache_of(0), ic.cache_of(1), ic.cache_of(2)), (0, 1, 0));
    }

    #[test]
    fn counts_survive_run_ahead_and_slide() {
        let mut ic = ICaches::new(&SimConfig::lin2020().units);
        let c = Cycle;
        // A thread 300 cycles ahead, then two at the clock: all three counted.
        assert_eq!(ic.fetch(0, 0, c(1300)), c(1300));
        assert_eq!(ic.fetch(0, 0, c(1000)), c(1000));
        assert_eq!(ic.fetch(0, 0, c(1000)), c(1000));
        assert_eq!(ic.fetch(0, 0, c(1000)), c(1001));
        assert_eq!(ic.fetch(0, 0, c(1300)), c(1300));
        assert_eq!(ic.fetch(0, 0, c(1300)), c(1301));
        // Far ahead: the window slides and the old counts are forgotten, not reused.
        assert_eq!(ic.fetch(0, 0, c(1000 + 5 * HISTORY)), c(1000 + 5 * HISTORY));
        assert_eq!(ic.peek(0, 0, c(1001 + 5 * HISTORY)), c(1001 + 5 * HISTORY));
        assert_eq!(ic.peek(0, 0, c(1000 + 5 * HISTORY)), c(1000 + 5 * HISTORY));
    }

    #[test]
    fn no_limit_when_fetches_are_zero() {
        let mut units = SimConfig::lin2020().units;
        units.icache_fetches = 0;
        let mut ic = ICaches::new(&units);
        for _ in 0..10 {
            assert_eq!(ic.fetch(0, 0, Cycle(3)), Cycle(3));
        }
    }
}
