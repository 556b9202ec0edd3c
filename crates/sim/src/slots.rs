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
        // Fast path (most requests): `c` inside the window and free.
        let off = c.wrapping_sub(self.base);
        if off < WINDOW && self.mask & (1u128 << off) == 0 {
            self.mask |= 1u128 << off;
            return c;
        }
        self.reserve_slow(c)
    }

    #[inline(never)]
    fn reserve_slow(&mut self, c: Cycle) -> Cycle {
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

/// Reservations kept behind the request being served (requests arrive slightly out of
/// order; anything older than this can no longer collide with a new one).
const SPARSE_HISTORY: u64 = 4096;

/// A reservation table for resources whose reservations can lie far in the future (DRAM
/// channel buses and activation spacing: a backed-up bank schedules its reads hundreds of
/// nanoseconds ahead). Unlike [`Slots`], a far-future reservation never moves a window past
/// earlier free cycles, so a read to an idle bank of the same channel still gets the first
/// free cycle after its own ready time. Reservations are kept as sorted, disjoint, merged
/// half-open intervals (a saturated bus is one long interval, so a search is a binary
/// search plus a step or two) and pruned `SPARSE_HISTORY` cycles behind each request.
#[derive(Clone, Debug, Default)]
pub struct SparseSlots {
    taken: Vec<(Cycle, Cycle)>,
}

impl SparseSlots {
    fn prune(&mut self, c: Cycle) {
        let floor = c.saturating_sub(SPARSE_HISTORY);
        let old = self.taken.partition_point(|iv| iv.1 < floor);
        if old > 64 {
            self.taken.drain(..old);
        }
    }

    /// First start `s ≥ c` where `[s, s + len)` overlaps no reservation, and the index of
    /// the first interval ending after `s`'s predecessors.
    fn find(&self, c: Cycle, len: u64) -> (Cycle, usize) {
        let mut i = self.taken.partition_point(|iv| iv.1 <= c);
        let mut s = c;
        while let Some(&(lo, hi)) = self.taken.get(i) {
            if lo >= s + len {
                break;
            }
            s = s.max(hi);
            i += 1;
        }
        (s, i)
    }

    /// Marks `[s, s + len)` taken; `i` is the index of the first interval starting after it.
    fn insert(&mut self, s: Cycle, len: u64, i: usize) {
        let e = s + len;
        let joins_prev = i > 0 && self.taken[i - 1].1 == s;
        let joins_next = self.taken.get(i).is_some_and(|iv| iv.0 == e);
        match (joins_prev, joins_next) {
            (true, true) => {
                self.taken[i - 1].1 = self.taken[i].1;
                self.taken.remove(i);
            }
            (true, false) => self.taken[i - 1].1 = e,
            (false, true) => self.taken[i].0 = s,
            (false, false) => self.taken.insert(i, (s, e)),
        }
    }

    /// The first free cycle at or after `c`, without reserving it.
    pub fn peek(&self, c: Cycle) -> Cycle {
        self.find(c, 1).0
    }

    /// Reserves the first free cycle at or after `c` and returns it.
    pub fn reserve(&mut self, c: Cycle) -> Cycle {
        self.reserve_span(c, 1)
    }

    /// Reserves a span of `len` cycles at the first start at or after `c` where it overlaps
    /// no other span (spans are all `len` long, so starts end up at least `len` apart: a
    /// minimum spacing such as t_RRD between activations).
    pub fn reserve_span(&mut self, c: Cycle, len: u64) -> Cycle {
        self.prune(c);
        let (s, i) = self.find(c, len);
        self.insert(s, len, i);
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sparse_far_future_reservations_keep_earlier_cycles_free() {
        let mut s = SparseSlots::default();
        assert_eq!(s.reserve(100_000), 100_000);
        // A plain window would have slid past cycle 1000.
        assert_eq!(s.reserve(1000), 1000);
        assert_eq!(s.reserve(1000), 1001);
        assert_eq!(s.peek(1000), 1002);
        assert_eq!(s.reserve(99_999), 99_999);
        assert_eq!(s.reserve(99_999), 100_001);
        let mut a = SparseSlots::default();
        assert_eq!(a.reserve_span(100_000, 13), 100_000);
        assert_eq!(a.reserve_span(100, 13), 100);
        assert_eq!(a.reserve_span(100, 13), 113);
        assert_eq!(a.reserve_span(80, 13), 80);
        assert_eq!(a.reserve_span(90, 13), 126);
        assert_eq!(a.reserve_span(60, 13), 60);
        assert_eq!(a.reserve_span(99_990, 13), 100_013);
        assert_eq!(a.reserve_span(99_980, 13), 99_980);
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
