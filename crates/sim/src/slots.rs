//! A reservation table of one resource that accepts one operation per cycle: a 128-cycle
//! bitmap window, so a request can take a free cycle *before* a later reservation (a plain
//! next-free counter cannot fill such holes, which serialises threads whose issue cycles
//! are slightly out of order; notes §5.2 "fluffy time").

use crate::Cycle;

const WINDOW: u64 = 128;

/// Occupied cycles of one resource.
#[derive(Clone, Copy, Debug, Default)]
pub struct Slots {
    base: Cycle,
    mask: u128,
}

impl Slots {
    /// Reserves the first free cycle at or after `c` and returns it.
    #[inline]
    pub fn reserve(&mut self, c: Cycle) -> Cycle {
        if c >= self.base + WINDOW {
            // Keep the last 64 cycles of history before `c`.
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
            // Nothing free in the window from `c`: slide it by half.
            self.mask >>= WINDOW / 2;
            self.base += WINDOW / 2;
        }
    }

    /// Reserves `len` consecutive free cycles starting at the first possible cycle at or
    /// after `c` and returns the start: reservations made this way are at least `len` apart
    /// (a minimum spacing such as t_RRD between activations). `len` ≤ 64.
    pub fn reserve_span(&mut self, c: Cycle, len: u64) -> Cycle {
        debug_assert!((1..=WINDOW / 2).contains(&len));
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
        let span: u128 = (1u128 << len) - 1;
        let mut s = c.max(self.base);
        loop {
            if s + len > self.base + WINDOW {
                self.mask >>= WINDOW / 2;
                self.base += WINDOW / 2;
                continue;
            }
            let off = s - self.base;
            if (self.mask >> off) & span == 0 {
                self.mask |= span << off;
                return s;
            }
            s += 1;
        }
    }

    /// The first free cycle at or after `c`, without reserving it.
    #[inline]
    pub fn peek(&self, c: Cycle) -> Cycle {
        let mut copy = *self;
        copy.reserve(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn spans_keep_their_spacing_and_fill_gaps() {
        let mut s = Slots::default();
        assert_eq!(s.reserve_span(100, 13), 100);
        assert_eq!(s.reserve_span(100, 13), 113);
        // A gap of 13 before 100 is usable; one of 12 is not.
        assert_eq!(s.reserve_span(80, 13), 80);
        assert_eq!(s.reserve_span(90, 13), 126);
        assert_eq!(s.reserve_span(10_000, 13), 10_000);
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
