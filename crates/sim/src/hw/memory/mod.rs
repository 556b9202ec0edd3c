//! The memory hierarchy behind the TMs' L1 data caches: one shared L2 ([`L2`]) and GDDR5
//! DRAM ([`Dram`]). The L1 tags use the same [`Cache`] and belong to each TM (`hw/l1.rs`).
//!
//! Timing is by reservation ("immediate response", Eyerman et al. 2021): an access learns
//! its completion cycle when it is made. Each cache line's tag entry stores the cycle its
//! fill arrives, so a later access to a line still in flight waits for that fill (miss
//! merging); the line a miss replaces stays readable until that fill arrives, and a line in
//! flight whose tag a later conflicting miss has taken stays on the cache's in-flight list
//! (the MSHRs), as in SimTRaX (`L1Cache.cc`, `L2Cache.cc`).

pub mod cache;
pub mod dram;
pub mod l2;

pub use cache::{Cache, Lookup};
pub use dram::{Dram, DramAccess, DramStats};
pub use l2::L2;

use serde::{Deserialize, Serialize};

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
    /// Store words passed through the L2 to DRAM's write queue (not in `l2_accesses`).
    #[serde(default)]
    pub l2_stores: u64,
}
