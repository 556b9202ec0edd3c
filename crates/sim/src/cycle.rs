//! Simulated time.

/// A core clock cycle.
pub type Cycle = u64;
