//! [`BankSlots`]: the word banks of one TM's L1 as diagonal bitmaps.

use super::Slot;

/// The word banks of one TM's L1 (one access per bank per cycle), stored along
/// *diagonals*: word `w` of a load issued at cycle `x` uses bank `w mod banks`, and a load
/// issues one word per cycle, so the consecutive words of a line segment that meet no
/// conflict lie on one diagonal `d = (bank − cycle) mod banks`. Each diagonal is a bitmap
/// over cycles, so a whole segment's bank-conflict check is one masked word test instead of
/// one test per word.
///
/// Semantics: a word takes the first cycle at or after its request at which its bank is
/// free, exactly as one [`Slots`](super::Slots) per bank, but without a per-bank window: every
/// reservation at or after the current event time `now` is remembered (the ring of cycles
/// covered grows when a bank is booked further ahead than it covers). Requests are never
/// earlier than `now`, so cycles before it are recycled.
#[derive(Clone, Debug)]
pub struct BankSlots {
    /// `banks − 1` (power-of-two bank count).
    bank_mask: u64,
    /// First cycle covered (a multiple of 64); the ring covers `[lo, lo + 64 · words)`.
    lo: Slot,
    /// 64-cycle words per diagonal (a power of two).
    words: usize,
    /// log2(banks).
    bank_shift: u32,
    /// `lo + 64 · words`: the first cycle past the ring (kept so the fast path's bound is
    /// one compare).
    end: Slot,
    /// `bits[(x / 64 mod words) · banks + d]` bit `x mod 64`: bank `(d + x) mod banks` is
    /// taken at cycle `x`.
    bits: Vec<u64>,
}

/// A run of consecutive words placed by [`BankSlots::reserve_run`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placed {
    /// Cycle of the first word.
    pub first: Slot,
    /// Cycle of the last word.
    pub last: Slot,
    /// Cycles the words waited for busy banks (summed over words).
    pub stall: u64,
    /// Words placed at or after the `from` cycle given to `reserve_run`.
    pub at_or_after: u64,
}

/// How many of `n` words at consecutive cycles `c .. c + n` are at or after cycle `from`
/// (the words of a line segment that find its fill arrived: L1 hits).
#[inline]
pub fn at_or_after(c: Slot, n: u64, from: Slot) -> u64 {
    (c + n).saturating_sub(c.max(from)).min(n)
}

impl BankSlots {
    /// `banks` free banks (a power of two).
    pub fn new(banks: u32) -> Self {
        debug_assert!(banks.is_power_of_two());
        let words = 8;
        Self {
            bank_mask: banks as u64 - 1,
            bank_shift: banks.trailing_zeros(),
            lo: 0,
            words,
            end: 64 * words as u64,
            bits: vec![0; banks as usize * words],
        }
    }

    fn span(&self) -> u64 {
        64 * self.words as u64
    }

    /// Makes the ring cover `[c, hi]` (`now ≤ c`): recycles cycles before `now`, grows when
    /// that is not enough.
    #[inline]
    fn cover(&mut self, hi: Slot, now: Slot) {
        if hi < self.end {
            return;
        }
        self.cover_slow(hi, now);
    }

    #[inline(never)]
    fn cover_slow(&mut self, hi: Slot, now: Slot) {
        let banks = self.bank_mask as usize + 1;
        let new_lo = (now & !63).max(self.lo);
        let (old_w, new_w) = (self.lo >> 6, new_lo >> 6);
        // Words of cycles [lo, new_lo) are reused for [lo + span, new_lo + span).
        let n = (new_w - old_w).min(self.words as u64);
        let wm = self.words - 1;
        for j in old_w..old_w + n {
            let i = j as usize & wm;
            self.bits[i * banks..(i + 1) * banks].fill(0);
        }
        self.lo = new_lo;
        while hi >= self.lo + self.span() {
            let (w1, w2) = (self.words, self.words * 2);
            let mut bits = vec![0; self.bits.len() * 2];
            for j in self.lo >> 6..(self.lo >> 6) + w1 as u64 {
                let (i1, i2) = (j as usize & (w1 - 1), j as usize & (w2 - 1));
                bits[i2 * banks..(i2 + 1) * banks]
                    .copy_from_slice(&self.bits[i1 * banks..(i1 + 1) * banks]);
            }
            self.bits = bits;
            self.words = w2;
        }
        self.end = self.lo + self.span();
    }

    /// Index in `bits` of diagonal `d`'s word `i`.
    #[inline]
    fn at(&self, i: usize, d: usize) -> usize {
        (i << self.bank_shift) + d
    }

    /// Taken-bits of diagonal `d` for cycles `[c, c + k)`, `1 ≤ k ≤ 64` (bit i: cycle c + i).
    #[inline]
    fn taken(&self, d: usize, c: Slot, k: u64) -> u64 {
        let wm = self.words - 1;
        let i = (c >> 6) as usize & wm;
        let sh = c & 63;
        let mut m = self.bits[self.at(i, d)] >> sh;
        if sh + k > 64 {
            m |= self.bits[self.at((i + 1) & wm, d)] << (64 - sh);
        }
        m & (u64::MAX >> (64 - k))
    }

    /// Marks cycles `[c, c + k)` of diagonal `d` taken, `1 ≤ k ≤ 64`.
    #[inline]
    fn take(&mut self, d: usize, c: Slot, k: u64) {
        let wm = self.words - 1;
        let i = (c >> 6) as usize & wm;
        let sh = c & 63;
        let m = u64::MAX >> (64 - k);
        let a = self.at(i, d);
        self.bits[a] |= m << sh;
        if sh + k > 64 {
            let b = self.at((i + 1) & wm, d);
            self.bits[b] |= m >> (64 - sh);
        }
    }

    /// Places `n ≥ 1` consecutive words, the first on `bank`, each word one cycle after the
    /// previous one's cycle at the earliest and at the first cycle its bank is free: the
    /// same cycles as placing the words one by one on per-bank tables that remember every
    /// reservation. `c ≥ now` (the current event time).
    #[inline]
    pub fn reserve_run(&mut self, bank: u64, c: Slot, n: u64, now: Slot, from: Slot) -> Placed {
        debug_assert!(n >= 1 && c >= now && c >= self.lo);
        // Fast path (most runs): every word's bank is free in its cycle, one word test.
        if self.try_run(bank, c, n) {
            return Placed {
                first: c,
                last: c + n - 1,
                stall: 0,
                at_or_after: at_or_after(c, n, from),
            };
        }
        self.reserve_run_slow(bank, c, n, now, from)
    }

    /// Takes cycles `c .. c + n` for `n` consecutive words, the first on `bank`, if every
    /// word's bank is free in its cycle (and the ring covers them); returns whether it did.
    /// When it does, [`BankSlots::reserve_run`] would have placed the words exactly there
    /// (no stall); when it does not, nothing is taken.
    #[inline]
    pub fn try_run(&mut self, bank: u64, c: Slot, n: u64) -> bool {
        debug_assert!(n >= 1 && c >= self.lo);
        if n <= 64 && c + n <= self.end {
            let d = (bank.wrapping_sub(c) & self.bank_mask) as usize;
            if self.taken(d, c, n) == 0 {
                self.take(d, c, n);
                return true;
            }
        }
        false
    }

    #[inline(never)]
    fn reserve_run_slow(&mut self, bank: u64, c: Slot, n: u64, now: Slot, from: Slot) -> Placed {
        let mut bank = bank;
        let mut c = c;
        let mut left = n;
        let mut stall = 0;
        let mut at_or_after = 0;
        let mut first = None;
        loop {
            let k = left.min(64);
            self.cover(c + k - 1, now);
            let d = (bank.wrapping_sub(c) & self.bank_mask) as usize;
            let busy = self.taken(d, c, k);
            let free = if busy == 0 {
                k
            } else {
                busy.trailing_zeros() as u64
            };
            if free > 0 {
                self.take(d, c, free);
                first.get_or_insert(c);
                at_or_after += self::at_or_after(c, free, from);
                bank += free;
                c += free;
                left -= free;
                if left == 0 {
                    return Placed {
                        first: first.unwrap_or(c - n),
                        last: c - 1,
                        stall,
                        at_or_after,
                    };
                }
            }
            if busy != 0 {
                // The next word's bank is taken at `c`: its first free cycle after that.
                let x = self.first_free(bank, c + 1, now);
                stall += x - c;
                c = x;
            }
        }
    }

    /// Places one word on `bank` at the first cycle at or after `c` (`c ≥ now`) at which
    /// the bank is free, and returns that cycle: [`BankSlots::reserve_run`] of one word
    /// (its stall is the result − `c`) without a run's bookkeeping, for a line segment's
    /// first word after [`BankSlots::try_run`] found a conflict.
    #[inline]
    pub fn reserve_word(&mut self, bank: u64, c: Slot, now: Slot) -> Slot {
        let x = self.first_free(bank, c, now);
        let d = (bank.wrapping_sub(x) & self.bank_mask) as usize;
        self.take(d, x, 1);
        x
    }

    /// The first cycle at or after `c` at which `bank` is free.
    fn first_free(&mut self, bank: u64, c: Slot, now: Slot) -> Slot {
        let mut x = c;
        loop {
            self.cover(x, now);
            let d = (bank.wrapping_sub(x) & self.bank_mask) as usize;
            if self.taken(d, x, 1) == 0 {
                return x;
            }
            x += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::slots::{Slots, SparseSlots};
    use dualsplit_geometry::Pcg32;
    use std::collections::BTreeSet;

    /// One bank's reservations, all remembered: the first free cycle at or after a request.
    #[derive(Clone, Default)]
    struct Ideal(BTreeSet<Slot>);
    impl Ideal {
        fn reserve(&mut self, c: Slot) -> Slot {
            let mut x = c;
            while self.0.contains(&x) {
                x += 1;
            }
            self.0.insert(x);
            x
        }
    }

    /// Places `n` words one by one on per-bank tables: (slots, stall).
    fn word_by_word(
        banks: &mut [impl FnMut(Slot) -> Slot],
        bank: u64,
        c: Slot,
        n: u64,
    ) -> (Vec<Slot>, u64) {
        let mut x = c;
        let mut stall = 0;
        let mut slots = Vec::new();
        for i in 0..n {
            let s = banks[((bank + i) % banks.len() as u64) as usize](x);
            stall += s - x;
            slots.push(s);
            x = s + 1;
        }
        (slots, stall)
    }

    fn check(p: Placed, slots: &[Slot], stall: u64, from: Slot, what: &str) {
        assert_eq!(p.first, slots[0], "{what}");
        assert_eq!(p.last, *slots.last().unwrap(), "{what}");
        assert_eq!(p.stall, stall, "{what}");
        let after = slots.iter().filter(|&&s| s >= from).count() as u64;
        assert_eq!(p.at_or_after, after, "{what}");
    }

    /// Runs of words placed along diagonals land exactly where word-by-word placement with
    /// every reservation remembered puts them, under heavy contention and with runs longer
    /// than the ring (which then grows), for 16 and 4 banks.
    #[test]
    fn bank_runs_match_word_by_word_placement() {
        for (seed, banks) in (0..100).flat_map(|s| [(s, 16u32), (s, 4)]) {
            let mut rng = Pcg32::new(seed, 3);
            let mut ideal = vec![Ideal::default(); banks as usize];
            let mut diag = BankSlots::new(banks);
            let mut now = 0;
            for _ in 0..2000 {
                now += (rng.below(6) == 0) as u64 * rng.below(200) as u64;
                let c = now + rng.below(8) as u64;
                let bank = rng.below(banks) as u64;
                let n = 1 + rng.below(64) as u64;
                let from = c + rng.below(80) as u64;
                let mut fs: Vec<_> = ideal.iter_mut().map(|b| move |c| b.reserve(c)).collect();
                let (slots, stall) = word_by_word(&mut fs, bank, c, n);
                let p = diag.reserve_run(bank, c, n, now, from);
                check(
                    p,
                    &slots,
                    stall,
                    from,
                    &format!("seed {seed}, {banks} banks"),
                );
            }
        }
    }

    /// `try_run` takes a run exactly when `reserve_run` would place it without a stall
    /// (the same cycles), and leaves the table untouched otherwise: two tables fed the same
    /// random requests, one through `try_run` first, place every run alike.
    #[test]
    fn try_run_is_the_stall_free_reserve_run() {
        for seed in 0..50 {
            let mut rng = Pcg32::new(seed, 9);
            let (mut plain, mut tried) = (BankSlots::new(16), BankSlots::new(16));
            let (mut now, mut taken) = (0, 0);
            for i in 0..3000 {
                now += (rng.below(4) == 0) as u64 * rng.below(40) as u64;
                let c = now + rng.below(8) as u64;
                let bank = rng.below(16) as u64;
                let n = 1 + rng.below(20) as u64;
                let p = plain.reserve_run(bank, c, n, now, 0);
                let what = format!("seed {seed}, step {i}");
                if tried.try_run(bank, c, n) {
                    taken += 1;
                    assert_eq!((p.first, p.last, p.stall), (c, c + n - 1, 0), "{what}");
                } else {
                    assert_eq!(tried.reserve_run(bank, c, n, now, 0), p, "{what}");
                }
            }
            assert!(taken > 300, "seed {seed}: {taken}");
        }
    }

    /// `reserve_word` places a word where a one-word `reserve_run` does: two tables fed
    /// the same random requests (words and longer runs, some far ahead so the ring grows)
    /// agree on every placement.
    #[test]
    fn reserve_word_is_a_one_word_run() {
        for seed in 0..50 {
            let mut rng = Pcg32::new(seed, 13);
            let (mut runs, mut words) = (BankSlots::new(16), BankSlots::new(16));
            let (mut now, mut stalled) = (0, 0);
            for i in 0..3000 {
                now += (rng.below(4) == 0) as u64 * rng.below(40) as u64;
                let c = now + rng.below(8) as u64 + (rng.below(50) == 0) as u64 * 700;
                let bank = rng.below(16) as u64;
                let what = format!("seed {seed}, step {i}");
                if rng.below(2) == 0 {
                    let p = runs.reserve_run(bank, c, 1, now, 0);
                    let x = words.reserve_word(bank, c, now);
                    assert_eq!((p.first, p.stall), (x, x - c), "{what}");
                    stalled += (x > c) as u32;
                } else {
                    let n = 1 + rng.below(20) as u64;
                    let p = runs.reserve_run(bank, c, n, now, 0);
                    assert_eq!(words.reserve_run(bank, c, n, now, 0), p, "{what}");
                }
            }
            assert!(stalled > 100, "seed {seed}: {stalled}");
        }
    }

    /// Under light contention (no request far behind an earlier one on its bank) the
    /// result is also that of one 128-cycle-window [`Slots`](super::Slots) per bank.
    #[test]
    fn bank_runs_match_per_bank_windows_under_light_load() {
        for seed in 0..100 {
            let mut rng = Pcg32::new(seed, 5);
            let mut windows = vec![Slots::default(); 16];
            let mut diag = BankSlots::new(16);
            let mut now = 0;
            for _ in 0..2000 {
                now += rng.below(3) as u64;
                let c = now + rng.below(8) as u64;
                let bank = rng.below(16) as u64;
                let n = 1 + rng.below(20) as u64;
                let from = c + rng.below(30) as u64;
                let mut fs: Vec<_> = windows.iter_mut().map(|b| move |c| b.reserve(c)).collect();
                let (slots, stall) = word_by_word(&mut fs, bank, c, n);
                let p = diag.reserve_run(bank, c, n, now, from);
                check(p, &slots, stall, from, &format!("seed {seed}"));
            }
        }
    }

    /// A backlog far beyond the ring's initial 512 cycles: the ring grows and keeps every
    /// reservation; afterwards `now` moves on and old cycles are recycled.
    #[test]
    fn ring_grows_under_a_long_backlog_and_recycles() {
        let mut ideal = vec![Ideal::default(); 16];
        let mut diag = BankSlots::new(16);
        for round in 0..3u64 {
            let now = round * 5000;
            for i in 0..300 {
                let mut fs: Vec<_> = ideal.iter_mut().map(|b| move |c| b.reserve(c)).collect();
                let (slots, stall) = word_by_word(&mut fs, i % 16, now, 64);
                let p = diag.reserve_run(i % 16, now, 64, now, now + 100);
                check(
                    p,
                    &slots,
                    stall,
                    now + 100,
                    &format!("round {round}, load {i}"),
                );
            }
            assert!(diag.span() >= 1200, "{}", diag.span());
        }
    }

    /// The pending plane against a min-heap of the pending cycles (the plain form of a
    /// DRAM read queue): cycles reserved in a jittered order ahead of a rising floor, some far
    /// ahead, retired in bulk below a limit that moves back and forth (never below the
    /// floor) and one at a time from the earliest, as a full read queue does.
    #[test]
    fn pending_plane_matches_a_heap() {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        for seed in 0..20 {
            let mut rng = Pcg32::new(seed, 11);
            let mut heap = BinaryHeap::new();
            let mut slots = SparseSlots::<2>::default();
            let mut floor = 0;
            let cap = [1, 4, 64][seed as usize % 3];
            for i in 0..3000 {
                floor += rng.below(6) as u64 * (rng.below(4) == 0) as u64;
                let limit = floor + rng.below(40) as u64;
                while heap.peek().is_some_and(|&Reverse(d)| d < limit) {
                    heap.pop();
                }
                slots.retire_before(limit);
                slots.forget_before(floor);
                let what = format!("seed {seed}, request {i}");
                assert_eq!(slots.pending() as usize, heap.len(), "{what}");
                if heap.len() >= cap {
                    let first = heap.pop().map(|Reverse(d)| d);
                    assert_eq!(slots.retire_first(), first, "{what}");
                }
                let far = if rng.below(100) == 0 { 3000 } else { 0 };
                let s = slots.reserve_pending(floor + far + rng.below(200) as u64);
                heap.push(Reverse(s));
            }
            while let Some(Reverse(d)) = heap.pop() {
                assert_eq!(slots.retire_first(), Some(d), "seed {seed}: draining");
            }
            assert_eq!(slots.retire_first(), None);
        }
    }

    /// `SparseSlots` against a plain set of taken cycles: spans of 1..=20 cycles requested
    /// in a jittered order ahead of a rising floor, some far ahead (the ring grows), with
    /// `peek` checked before each reservation; spans of two lengths alternating, or of one
    /// length in a dense backlog.
    #[test]
    fn sparse_slots_match_a_set_of_taken_cycles() {
        for seed in 0..16 {
            let mut rng = Pcg32::new(seed, 9);
            let mut set = BTreeSet::new();
            let mut slots = SparseSlots::<1>::default();
            let mut floor = 0;
            let len = 1 + rng.below(20) as u64;
            // Seeds 8.. keep one span length and request densely (a saturated backlog:
            // the known range of non-fitting starts is used and extended).
            let (mixed, spread) = if seed < 8 { (true, 300) } else { (false, 60) };
            for i in 0..2000 {
                floor += rng.below(14) as u64;
                slots.forget_before(floor);
                let far = if rng.below(50) == 0 { 5000 } else { 0 };
                let c = floor + far + rng.below(spread) as u64;
                let free =
                    |set: &BTreeSet<Slot>, s: Slot, l: u64| (s..s + l).all(|x| !set.contains(&x));
                let mut p = c;
                while !free(&set, p, 1) {
                    p += 1;
                }
                assert_eq!(slots.peek(c), p, "seed {seed}, request {i}: peek");
                let l = if mixed && i % 2 == 1 { 1 } else { len };
                let mut s = c;
                while !free(&set, s, l) {
                    s += 1;
                }
                assert_eq!(slots.reserve_span(c, l), s, "seed {seed}, request {i}");
                set.extend(s..s + l);
            }
        }
    }
}
