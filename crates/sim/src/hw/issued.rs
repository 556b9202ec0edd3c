//! The answer of a unit to a request: when the thread issues next, when the result is
//! ready, and how long it waited for the unit.

use crate::hw::Cycle;

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
