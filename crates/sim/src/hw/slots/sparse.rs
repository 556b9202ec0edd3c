//! [`SparseSlots`]: reservations that can lie far ahead (DRAM buses, activation spacing), in
//! a growing bitmap ring.

use super::Slot;

/// A reservation table for resources whose reservations can lie far in the future (DRAM
/// channel buses and activation spacing: a backed-up bank schedules its reads hundreds of
/// nanoseconds ahead). Unlike [`Slots`](super::Slots), a far-future reservation never moves a window past
/// earlier free cycles, so a read to an idle bank of the same channel still gets the first
/// free cycle after its own ready time. Every reservation is kept in a bitmap ring that
/// grows to cover the furthest one; the owner says which cycles no request can reach any
/// more ([`SparseSlots::forget_before`], from the current event time), and the ring
/// recycles them, so it only spans the backlog ahead of the present. A search skips taken
/// words 64 cycles per step (a saturated bus is a run of full words) and otherwise walks the
/// gaps (`SparseSlots::find`); a request whose own cycles are free (most of them) is
/// settled by one word test inline.
///
/// The ring holds `P` bit planes per cycle. Plane 0 is the reservations; with `P = 2`,
/// plane 1 marks reservations still *pending* ([`SparseSlots::reserve_pending`]): a DRAM
/// channel's in-flight reads, each identified by its data-bus slot, so the read queue's
/// bookkeeping lives in the host cache line of the bus reservation it belongs to instead
/// of a separate heap (USIMM's per-channel read queue, `memory_controller.cc`).
#[derive(Clone, Debug)]
pub struct SparseSlots<const P: usize = 1> {
    /// First cycle covered (a multiple of 64); the ring covers `[lo, lo + 64 · words.len())`
    /// and every reservation ever made at or after `lo` lies in it.
    lo: Slot,
    /// `words[(x / 64) mod len][p]` bit `x mod 64`: cycle `x` is taken (`p = 0`) or pending
    /// (`p = 1`); power-of-two length.
    words: Box<[[u64; P]]>,
    /// No request starts before this cycle (`forget_before`).
    floor: Slot,
    /// Pending cycles (plane 1).
    pending: u32,
    /// The earliest pending cycle, while `pending > 0`.
    first_pending: Slot,
    /// No span of `known_len` cycles starting in `[known_from, known_to)` fits (each
    /// overlaps a reservation): what the last searches found, so the next request in that
    /// range starts searching at `known_to`. Reservations are never removed at or after
    /// the floor, so a start that does not fit never fits later.
    known_from: Slot,
    known_to: Slot,
    known_len: u64,
}

impl<const P: usize> Default for SparseSlots<P> {
    fn default() -> Self {
        Self {
            lo: 0,
            words: vec![[0; P]; 16].into_boxed_slice(),
            floor: 0,
            pending: 0,
            first_pending: 0,
            known_from: 0,
            known_to: 0,
            known_len: 0,
        }
    }
}

impl<const P: usize> SparseSlots<P> {
    /// Forgets reservations before `floor`: no later request starts before `floor`, so they
    /// can no longer collide with one (results are unchanged).
    #[inline]
    pub fn forget_before(&mut self, floor: Slot) {
        self.floor = self.floor.max(floor);
    }

    #[inline]
    fn end(&self) -> Slot {
        self.lo + ((self.words.len() as u64) << 6)
    }

    /// Ring index of cycle `x`'s word.
    #[inline]
    fn index(&self, x: Slot) -> usize {
        (x >> 6) as usize & (self.words.len() - 1)
    }

    #[inline]
    fn word(&self, x: Slot) -> u64 {
        self.words[self.index(x)][0]
    }

    /// Makes the ring cover cycle `hi` (recycling cycles before the floor, growing if that
    /// is not enough).
    #[inline]
    fn cover(&mut self, hi: Slot) {
        if hi >= self.end() {
            self.cover_slow(hi);
        }
    }

    #[inline(never)]
    fn cover_slow(&mut self, hi: Slot) {
        let n = self.words.len();
        let new_lo = (self.floor & !63).max(self.lo);
        let (old_w, new_w) = (self.lo >> 6, new_lo >> 6);
        for j in old_w..old_w + (new_w - old_w).min(n as u64) {
            let w = &mut self.words[j as usize & (n - 1)];
            // Pending cycles are retired before the floor passes them (the owner's contract).
            debug_assert!(w[1..].iter().all(|&p| p == 0), "pending cycle recycled");
            *w = [0; P];
        }
        self.lo = new_lo;
        while hi >= self.end() {
            let n = self.words.len();
            let mut words = vec![[0; P]; n * 2].into_boxed_slice();
            for j in self.lo >> 6..(self.lo >> 6) + n as u64 {
                words[j as usize & (2 * n - 1)] = self.words[j as usize & (n - 1)];
            }
            self.words = words;
        }
    }

    /// Taken-bits of cycles `[s, s + len)`, `1 ≤ len ≤ 64`, `lo ≤ s < end` (bit i: s + i;
    /// cycles past the ring are free).
    #[inline]
    fn window(&self, s: Slot, len: u64) -> u64 {
        let sh = s & 63;
        let mut m = self.word(s) >> sh;
        if sh + len > 64 && (s | 63) + 1 < self.end() {
            m |= self.word(s + 64) << (64 - sh);
        }
        m & (u64::MAX >> (64 - len))
    }

    /// Marks cycles `[s, s + len)` taken (`1 ≤ len ≤ 64`, inside the ring).
    #[inline]
    fn mark(&mut self, s: Slot, len: u64) {
        let sh = s & 63;
        let m = u64::MAX >> (64 - len);
        let i = self.index(s);
        self.words[i][0] |= m << sh;
        if sh + len > 64 {
            let j = self.index(s + 64);
            self.words[j][0] |= m >> (64 - sh);
        }
    }

    /// First start `s ≥ c` where `[s, s + len)` overlaps no reservation (`c ≥` the floor).
    ///
    /// Walks the gaps: the first free cycle from `s` (whole taken words are skipped 64
    /// cycles at a time), then the first taken cycle `x` in `[s, s + len)`; if there is
    /// one, no start in `[s, x]` fits (each such span contains `x`), so the search goes on
    /// from `x + 1`. A saturated backlog (runs of taken words) costs one step per word, a
    /// fragmented one one step per gap.
    fn find(&self, c: Slot, len: u64) -> Slot {
        debug_assert!(c >= self.lo && (1..=64).contains(&len));
        let mut s = c;
        let end = self.end();
        loop {
            while s < end {
                let free = !self.word(s) >> (s & 63);
                if free != 0 {
                    s += free.trailing_zeros() as u64;
                    break;
                }
                s = (s | 63) + 1;
            }
            if s >= end || len == 1 {
                return s;
            }
            let taken = self.window(s, len);
            if taken == 0 {
                return s;
            }
            s += taken.trailing_zeros() as u64 + 1;
        }
    }

    /// The first free cycle at or after `c`, without reserving it.
    pub fn peek(&self, c: Slot) -> Slot {
        debug_assert!(c >= self.floor);
        self.find(c.max(self.lo), 1)
    }

    /// The first start at or after `c` where a span of `len` cycles (`1 ≤ len ≤ 64`)
    /// overlaps no other span, without reserving it.
    pub fn peek_span(&self, c: Slot, len: u64) -> Slot {
        debug_assert!(c >= self.floor && (1..=64).contains(&len));
        self.find(c.max(self.lo), len)
    }

    /// Reserves the first free cycle at or after `c` and returns it.
    #[inline]
    pub fn reserve(&mut self, c: Slot) -> Slot {
        debug_assert!(c >= self.floor);
        // Fast path (most requests): `c` inside the ring and free.
        if c >= self.lo && c < self.end() {
            let i = self.index(c);
            let bit = 1u64 << (c & 63);
            if self.words[i][0] & bit == 0 {
                self.words[i][0] |= bit;
                return c;
            }
        }
        self.reserve_slow(c, 1)
    }

    /// Reserves a span of `len` cycles (`1 ≤ len ≤ 64`) at the first start at or after `c`
    /// where it overlaps no other span (spans are all `len` long, so starts end up at least
    /// `len` apart: a minimum spacing such as t_RRD between activations).
    #[inline]
    pub fn reserve_span(&mut self, c: Slot, len: u64) -> Slot {
        debug_assert!(c >= self.floor && (1..=64).contains(&len));
        // Fast path: the first start not known not to fit (`c`, or the end of the known
        // range when `c` lies in it) is inside the ring and free.
        let known = len == self.known_len && self.known_from <= c && c <= self.known_to;
        let s = if known { self.known_to } else { c };
        if s >= self.lo && s + len <= self.end() && self.window(s, len) == 0 {
            self.mark(s, len);
            if known {
                self.known_to = s + len;
            }
            return s;
        }
        self.reserve_slow(c, len)
    }

    #[inline(never)]
    fn reserve_slow(&mut self, c: Slot, len: u64) -> Slot {
        let c = c.max(self.lo);
        let known = len == self.known_len && self.known_from <= c && c <= self.known_to;
        let s = self.find(if known { self.known_to } else { c }, len);
        self.cover(s + len - 1);
        self.mark(s, len);
        // No start in [c, s) fits (the search), nor in [s, s + len) now; joined to the
        // known range when they touch.
        if !known {
            (self.known_from, self.known_len) = (c, len);
        }
        self.known_to = s + len;
        s
    }
}

impl SparseSlots<2> {
    /// Reserves the first free cycle at or after `c` (as [`SparseSlots::reserve`]) and
    /// marks it pending until it is retired ([`SparseSlots::retire_before`],
    /// [`SparseSlots::retire_first`]). The owner retires every pending cycle before it
    /// raises the floor past it.
    #[inline]
    pub fn reserve_pending(&mut self, c: Slot) -> Slot {
        let s = self.reserve(c);
        let i = self.index(s);
        self.words[i][1] |= 1 << (s & 63);
        if self.pending == 0 || s < self.first_pending {
            self.first_pending = s;
        }
        self.pending += 1;
        s
    }

    /// Pending cycles.
    #[inline]
    pub fn pending(&self) -> u32 {
        self.pending
    }

    /// Retires every pending cycle before `limit`.
    #[inline]
    pub fn retire_before(&mut self, limit: Slot) {
        if self.pending > 0 && self.first_pending < limit {
            self.retire_before_slow(limit);
        }
    }

    #[inline(never)]
    fn retire_before_slow(&mut self, limit: Slot) {
        let mut x = self.first_pending;
        loop {
            // `x < limit` is the earliest pending cycle: clear its word's bits below `limit`.
            let w0 = x & !63;
            let keep = if limit - w0 >= 64 {
                0
            } else {
                u64::MAX << (limit - w0)
            };
            let i = self.index(x);
            let bits = self.words[i][1];
            self.words[i][1] = bits & keep;
            self.pending -= (bits & !keep).count_ones();
            if self.pending == 0 {
                return;
            }
            x = if bits & keep != 0 {
                w0 + (bits & keep).trailing_zeros() as u64
            } else {
                self.next_pending(w0 + 64)
            };
            if x >= limit {
                self.first_pending = x;
                return;
            }
        }
    }

    /// Retires the earliest pending cycle and returns it (`None` when none is pending).
    #[inline]
    pub fn retire_first(&mut self) -> Option<Slot> {
        if self.pending == 0 {
            return None;
        }
        let s = self.first_pending;
        let i = self.index(s);
        // No pending bit below `s`'s: the rest of its word first.
        let rest = self.words[i][1] & !(1 << (s & 63));
        self.words[i][1] = rest;
        self.pending -= 1;
        if self.pending > 0 {
            self.first_pending = if rest != 0 {
                (s & !63) + rest.trailing_zeros() as u64
            } else {
                self.next_pending((s | 63) + 1)
            };
        }
        Some(s)
    }

    /// The first pending cycle at or after `from` (one exists: `pending > 0` and none
    /// before `from`).
    fn next_pending(&self, from: Slot) -> Slot {
        let mut x = from;
        loop {
            debug_assert!(x < self.end(), "no pending cycle from {from}");
            let bits = self.words[self.index(x)][1] >> (x & 63);
            if bits != 0 {
                return x + bits.trailing_zeros() as u64;
            }
            x = (x | 63) + 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sparse_far_future_reservations_keep_earlier_cycles_free() {
        let mut s = SparseSlots::<1>::default();
        assert_eq!(s.reserve(100_000), 100_000);
        // A plain window would have slid past cycle 1000.
        assert_eq!(s.reserve(1000), 1000);
        assert_eq!(s.reserve(1000), 1001);
        assert_eq!(s.peek(1000), 1002);
        assert_eq!(s.reserve(99_999), 99_999);
        assert_eq!(s.reserve(99_999), 100_001);
        let mut a = SparseSlots::<1>::default();
        assert_eq!(a.reserve_span(100_000, 13), 100_000);
        assert_eq!(a.reserve_span(100, 13), 100);
        assert_eq!(a.reserve_span(100, 13), 113);
        assert_eq!(a.reserve_span(80, 13), 80);
        assert_eq!(a.reserve_span(90, 13), 126);
        assert_eq!(a.reserve_span(60, 13), 60);
        assert_eq!(a.reserve_span(99_990, 13), 100_013);
        assert_eq!(a.reserve_span(99_980, 13), 99_980);
    }

    /// The gap walk: gaps shorter than the span are skipped one by one, whole taken words
    /// at once, and a gap of exactly the span's length fits.
    #[test]
    fn sparse_span_search_skips_short_gaps_and_full_words() {
        let mut s = SparseSlots::<1>::default();
        // One taken cycle every 10 up to 1000: no gap of 13 before 991.
        for x in (0..1000).step_by(10) {
            assert_eq!(s.reserve(x), x);
        }
        assert_eq!(s.reserve_span(0, 13), 991);
        assert_eq!(s.reserve_span(0, 9), 1);
        // Cycles 2000..2200 all taken, then a gap of exactly 13, then taken again.
        for x in (2000..2200).chain(2213..2300) {
            assert_eq!(s.reserve(x), x);
        }
        assert_eq!(s.reserve_span(1995, 13), 2200);
        assert_eq!(s.reserve_span(1995, 1), 1995);
        assert_eq!(s.reserve_span(1990, 13), 2300);
    }

    #[test]
    fn spans_keep_their_spacing_and_fill_gaps() {
        // Spans (t_RRD between activations) live in the DRAM's `SparseSlots`.
        let mut s = SparseSlots::<1>::default();
        assert_eq!(s.reserve_span(100, 13), 100);
        assert_eq!(s.reserve_span(100, 13), 113);
        // A gap of 13 before 100 is usable; one of 12 is not.
        assert_eq!(s.reserve_span(80, 13), 80);
        assert_eq!(s.reserve_span(90, 13), 126);
        assert_eq!(s.reserve_span(10_000, 13), 10_000);
    }
}
