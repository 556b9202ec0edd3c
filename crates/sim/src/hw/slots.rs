//! Reservation tables. [`Slots`]: one resource that accepts one operation per cycle, a
//! 128-cycle bitmap window, so a request can take a free cycle *before* a later reservation
//! (a plain next-free counter cannot fill such holes, which serialises threads whose issue
//! cycles are slightly out of order: Sniper's "fluffy time", snipersim.org/w/Causality). [`BankSlots`]: the 16 word
//! banks of one TM's L1, one bitmap per bank/cycle diagonal, so the words of a line segment
//! are placed with one test. [`SparseSlots`]: DRAM buses and activation spacing, whose
//! reservations can lie far ahead, in a growing bitmap ring.

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

/// The word banks of one TM's L1 (one access per bank per cycle), stored along
/// *diagonals*: word `w` of a load issued at cycle `x` uses bank `w mod banks`, and a load
/// issues one word per cycle, so the consecutive words of a line segment that meet no
/// conflict lie on one diagonal `d = (bank − cycle) mod banks`. Each diagonal is a bitmap
/// over cycles, so a whole segment's bank-conflict check is one masked word test instead of
/// one test per word.
///
/// Semantics: a word takes the first cycle at or after its request at which its bank is
/// free, exactly as one [`Slots`] per bank, but without a per-bank window: every
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

/// A reservation table for resources whose reservations can lie far in the future (DRAM
/// channel buses and activation spacing: a backed-up bank schedules its reads hundreds of
/// nanoseconds ahead). Unlike [`Slots`], a far-future reservation never moves a window past
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

#[cfg(test)]
mod bank_tests {
    use super::*;
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
    /// result is also that of one 128-cycle-window [`Slots`] per bank.
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
