//! Simulated time: the core clock ([`Cycle`]) and the DRAM clock ([`Tick`]).
//!
//! The chip runs at `clock_ghz` (1 GHz in Lin et al. 2020, Table 1); the GDDR5 model counts
//! in ticks of `dram.ticks_per_cycle` per core cycle (0.5 ns: USIMM's memory clock in
//! SimTRaX's `gddr5_8ch.cfg`). A point in time and a duration are different things: a
//! `Cycle` plus a duration (`u64` cycles) is a `Cycle`, two `Cycle`s differ by a duration.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::ops::{Add, AddAssign, Sub};

/// A core clock cycle (a point in simulated time).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
#[serde(transparent)]
pub struct Cycle(pub u64);

impl Cycle {
    /// Cycle 0, when the frame starts.
    pub const ZERO: Cycle = Cycle(0);
    /// The latest representable cycle.
    pub const MAX: Cycle = Cycle(u64::MAX);

    /// The cycle number.
    #[inline(always)]
    pub const fn get(self) -> u64 {
        self.0
    }

    /// The first DRAM tick of this cycle, at `ticks_per_cycle` ticks per cycle.
    #[inline(always)]
    pub const fn to_ticks(self, ticks_per_cycle: u64) -> Tick {
        Tick(self.0 * ticks_per_cycle)
    }

    /// Cycles from `earlier` to `self`, 0 when `earlier` is later.
    #[inline(always)]
    pub const fn saturating_since(self, earlier: Cycle) -> u64 {
        self.0.saturating_sub(earlier.0)
    }
}

impl Add<u64> for Cycle {
    type Output = Cycle;
    #[inline(always)]
    fn add(self, d: u64) -> Cycle {
        Cycle(self.0 + d)
    }
}

impl AddAssign<u64> for Cycle {
    #[inline(always)]
    fn add_assign(&mut self, d: u64) {
        self.0 += d;
    }
}

impl Sub<u64> for Cycle {
    type Output = Cycle;
    #[inline(always)]
    fn sub(self, d: u64) -> Cycle {
        Cycle(self.0 - d)
    }
}

/// The duration from `rhs` to `self`, in cycles.
impl Sub for Cycle {
    type Output = u64;
    #[inline(always)]
    fn sub(self, rhs: Cycle) -> u64 {
        self.0 - rhs.0
    }
}

impl fmt::Display for Cycle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

/// A DRAM clock tick (a point in the memory's time).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Tick(pub u64);

impl Tick {
    /// The latest representable tick.
    pub const MAX: Tick = Tick(u64::MAX);

    /// The tick `d` ticks later, or [`Tick::MAX`] when that overflows.
    #[inline(always)]
    pub const fn saturating_add(self, d: u64) -> Tick {
        Tick(self.0.saturating_add(d))
    }

    /// The tick number.
    #[inline(always)]
    pub const fn get(self) -> u64 {
        self.0
    }

    /// The first core cycle at or after this tick.
    #[inline(always)]
    pub const fn to_cycle_ceil(self, ticks_per_cycle: u64) -> Cycle {
        Cycle(self.0.div_ceil(ticks_per_cycle))
    }
}

impl Add<u64> for Tick {
    type Output = Tick;
    #[inline(always)]
    fn add(self, d: u64) -> Tick {
        Tick(self.0 + d)
    }
}

impl Sub<u64> for Tick {
    type Output = Tick;
    #[inline(always)]
    fn sub(self, d: u64) -> Tick {
        Tick(self.0 - d)
    }
}

/// The duration from `rhs` to `self`, in ticks.
impl Sub for Tick {
    type Output = u64;
    #[inline(always)]
    fn sub(self, rhs: Tick) -> u64 {
        self.0 - rhs.0
    }
}
