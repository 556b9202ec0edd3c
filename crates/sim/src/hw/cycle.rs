//! Simulated time: the core clock ([`Cycle`]) and the DRAM clock ([`Tick`]).
//!
//! The chip runs at `clock_ghz` (1 GHz in Lin et al. 2020, Table 1); the GDDR5 model counts
//! in ticks of `dram.ticks_per_cycle` per core cycle (0.5 ns: the 2 GHz memory clock of the
//! USIMM device file SimTRaX uses, `1Gb_x16_amd2GHz.vi`; `docs/sources.md`). A point in time and a duration are different things: a
//! point plus a duration (`u64` cycles or ticks) is a point, two points differ by a
//! duration.

use serde::{Deserialize, Serialize};
use std::fmt;
use std::ops::{Add, AddAssign, Sub};

/// A core clock cycle (a point in simulated time).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
#[serde(transparent)]
pub struct Cycle(pub u64);

/// A DRAM clock tick (a point in the memory's time).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Tick(pub u64);

/// The arithmetic of a point in time counted in `u64` units.
macro_rules! time_point {
    ($t:ident, $unit:literal) => {
        impl $t {
            /// The first point, when the frame starts.
            pub const ZERO: $t = $t(0);
            /// The latest representable point.
            pub const MAX: $t = $t(u64::MAX);

            #[doc = concat!("The ", $unit, " number.")]
            #[inline(always)]
            pub const fn get(self) -> u64 {
                self.0
            }

            #[doc = concat!("The point `d` ", $unit, "s later, or `MAX` when that overflows.")]
            #[inline(always)]
            pub const fn saturating_add(self, d: u64) -> $t {
                $t(self.0.saturating_add(d))
            }
        }

        impl Add<u64> for $t {
            type Output = $t;
            #[inline(always)]
            fn add(self, d: u64) -> $t {
                $t(self.0 + d)
            }
        }

        impl AddAssign<u64> for $t {
            #[inline(always)]
            fn add_assign(&mut self, d: u64) {
                self.0 += d;
            }
        }

        impl Sub<u64> for $t {
            type Output = $t;
            #[inline(always)]
            fn sub(self, d: u64) -> $t {
                $t(self.0 - d)
            }
        }

        #[doc = concat!("The duration from `rhs` to `self`, in ", $unit, "s.")]
        impl Sub for $t {
            type Output = u64;
            #[inline(always)]
            fn sub(self, rhs: $t) -> u64 {
                self.0 - rhs.0
            }
        }

        impl fmt::Display for $t {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                self.0.fmt(f)
            }
        }
    };
}

time_point!(Cycle, "cycle");
time_point!(Tick, "tick");

impl Cycle {
    /// The first DRAM tick of this cycle, at `ticks_per_cycle` ticks per cycle.
    #[inline(always)]
    pub const fn to_ticks(self, ticks_per_cycle: u64) -> Tick {
        Tick(self.0 * ticks_per_cycle)
    }
}
