//! Reservation tables. [`Slots`]: one resource that accepts one operation per cycle, a
//! 128-cycle bitmap window, so a request can take a free cycle *before* a later reservation
//! (a plain next-free counter cannot fill such holes, which serialises threads whose issue
//! cycles are slightly out of order: Sniper's "fluffy time", snipersim.org/w/Causality). [`BankSlots`]: the 16 word
//! banks of one TM's L1, one bitmap per bank/cycle diagonal, so the words of a line segment
//! are placed with one test. [`SparseSlots`]: DRAM buses and activation spacing, whose
//! reservations can lie far ahead, in a growing bitmap ring.

//!
//! | file | what it holds |
//! |---|---|
//! | `mod.rs` | [`Slots`] and [`earliest`] |
//! | `bank.rs` | [`BankSlots`] and what it places ([`Placed`], [`at_or_after`]) |
//! | `sparse.rs` | [`SparseSlots`] |

mod bank;
mod sparse;

pub use bank::{BankSlots, Placed, at_or_after};
pub use sparse::SparseSlots;

use crate::hw::Cycle;

/// A time slot of a table: a core cycle, a DRAM tick or a DRAM bus burst, as its owner
/// counts (the units convert their typed time at the call).
pub type Slot = u64;

const WINDOW: u64 = 128;

/// Occupied cycles of one resource. 32 bytes, aligned so a table never straddles two host
/// cache lines.
#[derive(Clone, Copy, Debug, Default)]
#[repr(align(32))]
pub struct Slots {
    base: Slot,
    /// The 128-cycle window as two 64-bit words (bit `i` of word `h`: cycle
    /// `base + 64 h + i` is taken), so the fast path tests and sets one word instead of
    /// shifting a 128-bit value (a dozen instructions on x86-64).
    words: [u64; 2],
}

impl Slots {
    /// The window as one 128-bit mask (bit i: cycle `base + i`).
    #[inline]
    fn mask(&self) -> u128 {
        u128::from(self.words[0]) | u128::from(self.words[1]) << 64
    }

    #[inline]
    fn set_mask(&mut self, mask: u128) {
        self.words = [mask as u64, (mask >> 64) as u64];
    }

    /// Reserves the first free cycle at or after `c` and returns it.
    #[inline]
    pub fn reserve(&mut self, c: Slot) -> Slot {
        // Fast path (most requests): `c` inside the window and a free cycle from `c` on in
        // the same 64-cycle word (bit j of `free`: cycle `c + j` is free; the zeros
        // shifted in at the top are not free). That is the first free cycle from `c`:
        // the window's later word holds only later cycles.
        let off = c.wrapping_sub(self.base);
        if off < WINDOW {
            let (h, i) = ((off >> 6) as usize & 1, off & 63);
            let w = self.words[h];
            let free = !w >> i;
            if free != 0 {
                let j = free.trailing_zeros() as u64;
                self.words[h] = w | 1 << (i + j);
                return c + j;
            }
        }
        self.reserve_slow(c)
    }

    /// A request outside the window or on a taken cycle: slides the window when `c` lies
    /// past it, then takes the first free cycle from `c` (from the window base if `c` lies
    /// before it), sliding by half while the window is full from there. The offset stays
    /// below `WINDOW` throughout, so the search is one shift and one bit scan per step.
    #[inline(never)]
    fn reserve_slow(&mut self, c: Slot) -> Slot {
        let mut mask = self.mask();
        let mut off = if c >= self.base + WINDOW {
            // Keep the last 64 cycles of history before `c`.
            let nb = c - WINDOW / 2;
            let shift = nb - self.base;
            mask = if shift >= WINDOW { 0 } else { mask >> shift };
            self.base = nb;
            WINDOW / 2
        } else {
            c.saturating_sub(self.base)
        };
        loop {
            let free = !mask >> off;
            if free != 0 {
                let s = off + free.trailing_zeros() as u64;
                self.set_mask(mask | 1u128 << s);
                return self.base + s;
            }
            // Nothing free in the window from `c`: slide it by half.
            mask >>= WINDOW / 2;
            self.base += WINDOW / 2;
            off = off.saturating_sub(WINDOW / 2);
        }
    }

    /// The first free cycle at or after `c`, without reserving it.
    #[inline]
    pub fn peek(&self, c: Slot) -> Slot {
        let mut copy = *self;
        copy.reserve(c)
    }
}

/// Reserves the earliest free cycle at or after `c` on any of `units`.
#[inline]
pub fn earliest(units: &mut [Slots], c: Cycle) -> Cycle {
    let c = c.get();
    if let [only] = units {
        return Cycle(only.reserve(c));
    }
    let mut best = 0;
    let mut best_s = u64::MAX;
    for (i, u) in units.iter().enumerate() {
        let s = u.peek(c);
        if s < best_s {
            best = i;
            best_s = s;
            if s == c {
                break;
            }
        }
    }
    Cycle(units[best].reserve(c))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plain 128-bit-window table searched bit by bit (the test's reference).
    #[derive(Clone, Copy, Default)]
    struct OldSlots {
        base: Slot,
        mask: u128,
    }
    impl OldSlots {
        fn reserve(&mut self, c: Slot) -> Slot {
            let off = c.wrapping_sub(self.base);
            if off < WINDOW && self.mask & (1u128 << off) == 0 {
                self.mask |= 1u128 << off;
                return c;
            }
            if c >= self.base + WINDOW {
                let nb = c - WINDOW / 2;
                let shift = nb - self.base;
                self.mask = if shift >= WINDOW {
                    0
                } else {
                    self.mask >> shift
                };
                self.base = nb;
            }
            let c = c.max(self.base);
            loop {
                let off = c.saturating_sub(self.base);
                if off < WINDOW {
                    let free = !self.mask >> off;
                    if free != 0 {
                        let s = off + free.trailing_zeros() as u64;
                        if s < WINDOW {
                            self.mask |= 1u128 << s;
                            return self.base + s;
                        }
                    }
                }
                self.mask >>= WINDOW / 2;
                self.base += WINDOW / 2;
            }
        }
    }

    /// The simplified search reserves the cycles the former one did: contended requests
    /// (many per cycle, jittered behind and ahead of the window, occasional far jumps), and
    /// the window state matches after every request.
    #[test]
    fn slots_search_matches_the_former_search() {
        for seed in 0..50 {
            let mut rng = dualsplit_geometry::Pcg32::new(seed, 21);
            let (mut new, mut old) = (Slots::default(), OldSlots::default());
            let mut now = 0u64;
            let mut slid = 0;
            for i in 0..5000 {
                now += rng.below(3) as u64 * (rng.below(2) == 0) as u64;
                if rng.below(500) == 0 {
                    now += 100 + rng.below(300) as u64;
                }
                let c = (now + rng.below(40) as u64).saturating_sub(rng.below(200) as u64);
                let base = new.base;
                assert_eq!(
                    new.peek(c),
                    old.clone().reserve(c),
                    "seed {seed}, {i}: peek"
                );
                assert_eq!(new.reserve(c), old.reserve(c), "seed {seed}, {i}");
                assert_eq!(
                    (new.base, new.mask()),
                    (old.base, old.mask),
                    "seed {seed}, {i}"
                );
                slid += u64::from(new.base != base);
            }
            assert!(slid > 20, "seed {seed}: the window slid {slid} times");
        }
    }

    #[test]
    fn fills_holes_before_later_reservations() {
        let mut s = Slots::default();
        assert_eq!(s.reserve(10), 10);
        assert_eq!(s.reserve(10), 11);
        assert_eq!(s.reserve(20), 20);
        // A request at 5 takes 5, not 21.
        assert_eq!(s.reserve(5), 5);
        assert_eq!(s.reserve(10), 12);
    }

    #[test]
    fn far_future_requests_slide_the_window() {
        let mut s = Slots::default();
        assert_eq!(s.reserve(1000), 1000);
        assert_eq!(s.reserve(1000), 1001);
        assert_eq!(s.reserve(990), 990);
        assert_eq!(s.reserve(100_000), 100_000);
        let mut full = Slots::default();
        for i in 0..300 {
            assert_eq!(full.reserve(0), i);
        }
    }
}
