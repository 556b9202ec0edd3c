//! The global atomic unit: the chip-wide counter from which threads take their next pixel.
//!
//! Hardware (TRaX's global register file with its atomic increment, Spjut et al. 2009;
//! SimTRaX `AtomicInc`): one increment per cycle for the whole chip, its value back in the
//! thread's register `units.atomic_latency` cycles after the increment is made. Requests
//! are served in the order they are made; a request that finds the unit taken in its cycle
//! waits for the next free one.

use crate::hw::Cycle;
use crate::hw::issued::Issued;

/// The chip's atomic increment unit.
#[derive(Clone, Debug)]
pub struct AtomicUnit {
    /// The first cycle at which the unit accepts another increment.
    free: Cycle,
    latency: u64,
}

impl AtomicUnit {
    /// An idle unit whose result returns `latency` cycles after the increment.
    pub fn new(latency: u64) -> Self {
        Self {
            free: Cycle::ZERO,
            latency,
        }
    }

    /// An increment requested at `at`: made at the unit's first free cycle from `at` on.
    pub fn increment(&mut self, at: Cycle) -> Issued {
        let s = at.max(self.free);
        self.free = s + 1;
        Issued {
            next_issue: s + 1,
            ready: s + self.latency,
            busy: s - at,
        }
    }
}
