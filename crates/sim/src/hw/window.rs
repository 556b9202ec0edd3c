//! Per-cycle use counts of a group of resources over a sliding window of cycles: the
//! instruction caches' fetch slots (`hw/icache.rs`) and the TM's functional-unit pools
//! (`hw/fu.rs`). Each resource (a *row*) accepts up to a limit of operations per cycle.
//!
//! The window holds [`HISTORY`] cycles, `[base, base + HISTORY)`, in a ring. A cycle before
//! the window counts as unused: requests are made at most `tp::LOOKAHEAD` (256) cycles after
//! the current event time and never before it, so when a request past the window slides it
//! forward (to end half a window after that request), no live cycle falls out of it.
//!
//! Host layout: one cycle's counts of every row lie side by side (`[cycle][row]`, one byte
//! each), so a thread issuing at consecutive cycles reads consecutive bytes, and a TM's
//! tables take `HISTORY × rows` bytes (rows rounded up to a power of two). Rows that
//! different threads use may be split into *planes* (`[plane][cycle][row]`; the TM's
//! instruction caches, each read by its own threads): a host cache line then holds more
//! cycles of the rows a thread reads.

/// Cycles a window remembers: four times the `rv32` model's run-ahead (`tp::LOOKAHEAD`), so
/// that the requests of threads running ahead and of threads at the event clock always lie
/// in one window.
pub const HISTORY: u64 = 1024;

/// Use counts of `rows` resources per cycle over a sliding window of [`HISTORY`] cycles.
#[derive(Clone, Debug)]
pub struct Window {
    base: u64,
    /// Bytes per cycle (`rows` rounded up to a power of two, so an index is a shift).
    shift: u32,
    /// log2 of a plane's bytes (`HISTORY << shift`).
    plane_shift: u32,
    /// `planes · HISTORY << shift` counts, plane-major, then cycle-major.
    counts: Box<[u8]>,
}

impl Window {
    /// An empty window over `rows` resources (at least one).
    pub fn new(rows: usize) -> Self {
        Self::with_planes(1, rows)
    }

    /// An empty window over `planes` planes of `rows` resources each; row `r` of plane `p`
    /// is row [`Window::row`]`(p, r)`.
    pub fn with_planes(planes: usize, rows: usize) -> Self {
        let shift = rows.max(1).next_power_of_two().trailing_zeros();
        let plane_shift = HISTORY.trailing_zeros() + shift;
        Self {
            base: 0,
            shift,
            plane_shift,
            counts: vec![0; planes.max(1) << plane_shift].into_boxed_slice(),
        }
    }

    /// The row number of row `r` of plane `p`: the plane's offset in the counts, so that
    /// an index is the same one `or` for every row.
    #[inline]
    pub fn row(&self, p: usize, r: usize) -> usize {
        (p << self.plane_shift) | r
    }

    #[inline(always)]
    fn index(&self, row: usize, c: u64) -> usize {
        (((c % HISTORY) as usize) << self.shift) | row
    }

    /// The ring index of `row` in cycle `c`, when `c` lies in the window.
    #[inline(always)]
    fn slot(&self, row: usize, c: u64) -> Option<usize> {
        // One compare: a cycle before the window wraps to a large difference.
        (c.wrapping_sub(self.base) < HISTORY).then(|| self.index(row, c))
    }

    /// Uses of `row` in cycle `c` (0 for a cycle outside the window).
    #[inline]
    pub fn count(&self, row: usize, c: u64) -> u8 {
        self.slot(row, c).map_or(0, |i| self.counts[i])
    }

    /// The first cycle at or after `c` in which `row` has been used fewer than `limit`
    /// times.
    #[inline]
    pub fn first_free(&self, row: usize, c: u64, limit: u8) -> u64 {
        let mut s = c;
        while self.count(row, s) >= limit {
            s += 1;
        }
        s
    }

    /// Counts one use of `row` in cycle `s` (a cycle before the window is not counted),
    /// sliding the window forward when `s` lies past it.
    #[inline]
    pub fn take(&mut self, row: usize, s: u64) {
        if s < self.base {
            return;
        }
        if s >= self.base + HISTORY {
            self.slide(s);
        }
        let i = self.index(row, s);
        self.counts[i] += 1;
    }

    /// Takes `row` in the first cycle at or after `c` with fewer than `limit` uses; returns
    /// that cycle.
    #[inline]
    pub fn reserve(&mut self, row: usize, c: u64, limit: u8) -> u64 {
        let (s, taken) = self.reserve_in_window(row, c, limit);
        if !taken {
            self.take(row, s);
        }
        s
    }

    /// Like [`Window::reserve`] when the cycle it finds lies in the window: takes `row` in
    /// the first cycle at or after `c` with fewer than `limit` uses and returns
    /// `(cycle, true)`. When that cycle lies past the window it takes nothing (the window
    /// does not slide) and returns `(cycle, false)`; [`Window::take`] then takes it.
    #[inline]
    pub fn reserve_in_window(&mut self, row: usize, c: u64, limit: u8) -> (u64, bool) {
        // Most requests find their own cycle free: one look-up.
        if let Some(i) = self.slot(row, c)
            && self.counts[i] < limit
        {
            self.counts[i] += 1;
            return (c, true);
        }
        self.reserve_later(row, c, limit)
    }

    /// [`Window::reserve_in_window`] when cycle `c` itself is full or past the window.
    #[inline(never)]
    fn reserve_later(&mut self, row: usize, c: u64, limit: u8) -> (u64, bool) {
        let s = self.first_free(row, c, limit);
        match self.slot(row, s) {
            Some(i) => {
                self.counts[i] += 1;
                (s, true)
            }
            None => (s, false),
        }
    }

    /// Takes back the use of `row` in cycle `s` that [`Window::reserve_in_window`] took
    /// (nothing was counted since), so the counts are as before it.
    #[inline]
    pub fn untake(&mut self, row: usize, s: u64) {
        let i = self.index(row, s);
        self.counts[i] -= 1;
    }

    /// Moves the window to end half a window after `s`, clearing the ring entries of the
    /// cycles it forgets.
    #[cold]
    fn slide(&mut self, s: u64) {
        let base = s + 1 - HISTORY / 2;
        let fresh = base.max(self.base + HISTORY);
        // The cycles [fresh, base + HISTORY) reuse ring entries of forgotten cycles: at most
        // two runs of the ring.
        let n = base + HISTORY - fresh;
        if n >= HISTORY {
            self.counts.fill(0);
        } else {
            let (from, rows) = ((fresh % HISTORY) as usize, self.shift);
            let end = from + n as usize;
            let len = HISTORY as usize;
            for plane in self.counts.chunks_exact_mut(1 << self.plane_shift) {
                plane[from << rows..end.min(len) << rows].fill(0);
                if end > len {
                    plane[..(end - len) << rows].fill(0);
                }
            }
        }
        self.base = base;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_count_apart_and_fill_to_their_limit() {
        let mut w = Window::new(3);
        assert_eq!(w.reserve(0, 5, 2), 5);
        assert_eq!(w.reserve(0, 5, 2), 5);
        assert_eq!(w.reserve(0, 5, 2), 6);
        assert_eq!(w.reserve(2, 5, 1), 5);
        assert_eq!(w.reserve(2, 5, 1), 6);
        assert_eq!(w.count(1, 5), 0);
        // An earlier cycle is still free.
        assert_eq!(w.reserve(0, 4, 2), 4);
    }

    #[test]
    fn planes_count_apart_and_slide_together() {
        let mut w = Window::with_planes(2, 3);
        let (a, b) = (w.row(0, 1), w.row(1, 1));
        assert_eq!(w.reserve(a, 5, 1), 5);
        assert_eq!(w.reserve(b, 5, 1), 5);
        assert_eq!(w.reserve(a, 5, 1), 6);
        assert_eq!((w.count(b, 6), w.count(w.row(1, 0), 5)), (0, 0));
        // Just past the window in plane 1: the window slides by half, and both planes forget
        // cycles 5 and 6, whose ring entries cycles `next + 5` and `next + 6` reuse.
        let next = HISTORY;
        assert_eq!(w.reserve(b, next + 10, 1), next + 10);
        assert_eq!((w.count(a, next + 5), w.count(a, next + 6)), (0, 0));
        assert_eq!((w.count(b, next + 5), w.count(b, next + 10)), (0, 1));
    }

    #[test]
    fn the_window_slides_and_forgets_old_cycles() {
        let mut w = Window::new(1);
        assert_eq!(w.reserve(0, 1000, 1), 1000);
        assert_eq!(w.reserve(0, 1300, 1), 1300);
        assert_eq!(w.reserve(0, 1000, 1), 1001);
        let far = 1000 + 5 * HISTORY;
        assert_eq!(w.reserve(0, far, 1), far);
        assert_eq!(w.reserve(0, far, 1), far + 1);
        // The ring entries of 1000 and 1001 were cleared, not reused.
        assert_eq!(w.count(0, far - HISTORY / 2 + 10), 0);
        assert_eq!(w.count(0, 1000), 0);
    }
}
