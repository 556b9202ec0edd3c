//! The memory hierarchy: per-TM L1 data caches, one shared L2, GDDR5 DRAM.
//!
//! Timing is by reservation ("immediate response", notes §5.2): an access learns its
//! completion cycle when it is made. Each cache line's tag entry stores the cycle its fill
//! arrives, so a later access to a line still in flight waits for that fill (miss merging);
//! the line a miss replaces stays readable until that fill arrives, and a line in flight
//! whose tag a later conflicting miss has taken stays on the cache's in-flight list (the
//! MSHRs), as in SimTRaX (`cache.rs`).

pub mod cache;
pub mod dram;

pub use cache::{Cache, Lookup};
pub use dram::{Dram, DramAccess, DramStats};
