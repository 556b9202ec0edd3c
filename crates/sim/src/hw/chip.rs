//! The chip: its units, and the requests a thread makes of them.
//!
//! Hardware (Lin et al. 2020, §2.3, §4, Table 1): `tms` thread multiprocessors of
//! `tps_per_tm` thread processors each; each TM has its L1, pipelines, reciprocal unit and
//! functional-unit pools ([`Tm`]); all TMs share the L2 and the DRAM ([`L2`]) and the global
//! atomic unit from which threads take their pixels ([`AtomicUnit`]). The event loop takes
//! them apart ([`Chip::parts`], `engine::run`): a thread reaches its TM's units through the
//! [`Tm`]'s methods, and the L2 and atomic unit in the commit phase.

use crate::config::SimConfig;
use crate::hw::atomic::AtomicUnit;
use crate::hw::counts::UnitStats;
use crate::hw::memory::{CacheStats, DramStats, L2};
use crate::hw::pipe::TmPipes;
use crate::hw::stalls::Stalls;
use crate::hw::tm::Tm;

/// The chip's units.
pub struct Chip {
    tms: Vec<Tm>,
    l2: L2,
    atomic: AtomicUnit,
    stalls: Stalls,
}

/// The chip's counters.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ChipStats {
    /// L1 and L2 counters, summed over the TMs.
    pub caches: CacheStats,
    /// Pipeline and reciprocal-unit ops, summed over the TMs.
    pub units: UnitStats,
    /// Where the threads' cycles went, summed over the threads.
    pub stalls: Stalls,
    /// DRAM counters.
    pub dram: DramStats,
}

impl Chip {
    /// A cold chip; `pipes` the ray-box pipelines of each TM (the "+" configurations use
    /// the node arity; [`TmPipes`]).
    pub fn new(cfg: &SimConfig, pipes: impl Into<TmPipes>) -> Self {
        let pipes = pipes.into();
        Self {
            tms: (0..cfg.tms).map(|_| Tm::new(cfg, pipes)).collect(),
            l2: L2::new(cfg),
            atomic: AtomicUnit::new(cfg.units.atomic_latency),
            stalls: Stalls::default(),
        }
    }

    /// The number of TMs.
    pub fn tm_count(&self) -> usize {
        self.tms.len()
    }

    /// The TMs, the L2, the atomic unit and the stall counters, apart (the event loop
    /// hands the TMs to host threads and the rest to the commit phase).
    pub fn parts(&mut self) -> (&mut [Tm], &mut L2, &mut AtomicUnit, &mut Stalls) {
        (
            &mut self.tms,
            &mut self.l2,
            &mut self.atomic,
            &mut self.stalls,
        )
    }

    /// The counters so far.
    pub fn stats(&self) -> ChipStats {
        let mut s = ChipStats {
            stalls: self.stalls,
            dram: self.l2.dram_stats(),
            ..ChipStats::default()
        };
        for tm in &self.tms {
            tm.add_stats(&mut s.caches, &mut s.units);
        }
        self.l2.add_stats(&mut s.caches);
        s
    }

    /// One word load by TM `tm` whose L1 bank slot is `slot` (already reserved): the cycle
    /// the data is in the register.
    #[cfg(test)]
    pub(crate) fn load_word(&mut self, tm: usize, word: u64, slot: u64) -> u64 {
        self.tms[tm]
            .load_word(&mut self.l2, word, crate::hw::Cycle(slot))
            .get()
    }
}
