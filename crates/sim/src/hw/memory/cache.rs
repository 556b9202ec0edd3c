//! A set-associative cache of 64-byte lines with fill times in the tags (LRU replacement;
//! associativity 1 is SimTRaX's direct-mapped cache, `L1Cache.cc`/`L2Cache.cc`), plus the list of lines in
//! flight (the MSHRs).
//!
//! A miss is *reserved* when it is made (it learns its fill cycle at once: the reservation model), but
//! the line it brings is only *installed* when that fill arrives, as in SimTRaX
//! (`L1Cache.cc`/`L2Cache.cc`: `UpdateCache` queues the tag update, `ClockFall` applies it
//! at the fill cycle) and in any cache with miss
//! status holding registers (Kroft 1981):
//!
//! * the line a miss replaces stays readable until the new line's fill arrives (`prev`), so a
//!   hot line (the top of a tree) is not lost for the whole miss latency of a conflicting
//!   line;
//! * a line still in flight is found by every later miss to it, even after another miss to
//!   the same set has taken its tag (`inflight`, SimTRaX's per-L1 list of in-flight lines
//!   and L2's pending list), so it is never requested twice.
//!
//! Writing the tag at request time instead would make the replaced line vanish for the
//! whole miss latency and request an in-flight line again once a conflicting miss took its
//! tag; under load the two feed each other (longer latencies, more re-requests of the
//! top-of-tree lines, hotter L2 banks) and TM scaling breaks down at 128 TMs (an analysis
//! of model 4, in the git history only).

use crate::hw::Cycle;
use crate::hw::addr::LineAddr;
use rustc_hash::FxHashMap;

/// The result of a tag lookup.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lookup {
    /// The line is present or in flight; its data is (or will be) there at `fill`.
    Present {
        /// Cycle the line's fill arrives (≤ now for a plain hit).
        fill: Cycle,
    },
    /// The line is absent and not in flight.
    Absent,
}

/// One way's tag: the line it holds once its fill arrives, and the line it replaced, still
/// readable until then. Stored as 32-bit words (16 bytes a way) while every line number and
/// fill cycle fits, as 64-bit words (32 bytes) from the first one that does not ([`Ways`]).
#[derive(Clone, Copy, Debug)]
struct Way<W> {
    /// The line this way holds once `fill` has arrived.
    line: W,
    fill: W,
    /// The line replaced by `line`, still readable before `fill` (its own fill cycle).
    prev: W,
    prev_fill: W,
}

/// A tag word: a line number or a cycle.
trait Word: Copy + Eq {
    /// No line.
    const INVALID: Self;
    const ZERO: Self;
    /// `x` as a word, if it fits and is not `INVALID`.
    fn fit(x: u64) -> Option<Self>;
    fn get(self) -> u64;
}

impl Word for u32 {
    const INVALID: u32 = u32::MAX;
    const ZERO: u32 = 0;
    #[inline]
    fn fit(x: u64) -> Option<u32> {
        u32::try_from(x).ok().filter(|&v| v != u32::MAX)
    }
    #[inline]
    fn get(self) -> u64 {
        u64::from(self)
    }
}

impl Word for u64 {
    const INVALID: u64 = u64::MAX;
    const ZERO: u64 = 0;
    #[inline]
    fn fit(x: u64) -> Option<u64> {
        Some(x)
    }
    #[inline]
    fn get(self) -> u64 {
        self
    }
}

impl<W: Word> Way<W> {
    const EMPTY: Self = Way {
        line: W::INVALID,
        fill: W::ZERO,
        prev: W::INVALID,
        prev_fill: W::ZERO,
    };
}

/// The tag array: 16-byte ways halve the host memory a lookup streams through (64 L1 tag
/// arrays and the L2's, several MB, far beyond the host's L2 cache), and every frame so
/// far fits them (line numbers and cycles below 2^32 − 1); the first install that does not
/// fit converts the array to 64-bit words, so results never depend on the width.
#[derive(Clone, Debug)]
enum Ways {
    Narrow(Vec<Way<u32>>),
    Wide(Vec<Way<u64>>),
}

/// Finds `line` in set `s` (see [`Cache::lookup`]): the fill cycle of a present line or of
/// a replaced line still readable at `now`.
#[inline]
fn find<W: Word>(
    ways: &[Way<W>],
    used: &mut [u64],
    stamp: u64,
    s: usize,
    assoc: usize,
    line: u64,
    now: u64,
) -> Option<u64> {
    // A line that does not fit was never installed in a narrow array.
    let line = W::fit(line)?;
    if assoc == 1 {
        let w = ways[s];
        if w.line == line {
            return Some(w.fill.get());
        }
        if w.prev == line && now < w.fill.get() {
            return Some(w.prev_fill.get());
        }
        return None;
    }
    for i in s..s + assoc {
        if ways[i].line == line {
            used[i] = stamp;
            return Some(ways[i].fill.get());
        }
    }
    ways[s..s + assoc]
        .iter()
        .find(|w| w.prev == line && now < w.fill.get())
        .map(|w| w.prev_fill.get())
}

/// Puts `line` (filled at `fill`, missed at `now`) into the least recently used way of set
/// `s` (see [`Cache::install`]); returns the replaced line and its fill if it was still in
/// flight.
#[allow(clippy::too_many_arguments)]
#[inline]
fn replace<W: Word>(
    ways: &mut [Way<W>],
    used: &mut [u64],
    stamp: u64,
    s: usize,
    assoc: usize,
    line: W,
    fill: W,
    now: u64,
) -> Option<(u64, u64)> {
    let victim = if assoc == 1 {
        s
    } else {
        let v = (s..s + assoc)
            .min_by_key(|&i| {
                if ways[i].line == W::INVALID {
                    0
                } else {
                    used[i] + 1
                }
            })
            .expect("at least one way");
        used[v] = stamp;
        v
    };
    let w = &mut ways[victim];
    let mut moved = None;
    if w.line != W::INVALID {
        if w.fill.get() <= now {
            w.prev = w.line;
            w.prev_fill = w.fill;
        } else {
            // Still in flight: the older resident (`prev`) stays readable, the in-flight
            // line keeps its MSHR entry.
            moved = Some((w.line.get(), w.fill.get()));
        }
    }
    w.line = line;
    w.fill = fill;
    moved
}

/// In-flight entries are pruned once the table has grown past this many (amortised).
const INFLIGHT_PRUNE: usize = 64;

/// Tags of a set-associative cache, with the in-flight (MSHR) list.
#[derive(Clone, Debug)]
pub struct Cache {
    ways: Ways,
    /// LRU stamps, parallel to `ways` (empty when direct-mapped: nothing to choose).
    used: Vec<u64>,
    assoc: usize,
    set_mask: u64,
    stamp: u64,
    /// Lines in flight whose way has since been taken by a later miss: line → fill cycle.
    /// (Fx hashing: the list is probed on every miss that the set does not answer, and
    /// SipHash's resistance to chosen keys buys nothing for line numbers.)
    inflight: FxHashMap<u64, u64>,
    prune_at: usize,
    /// What may be on `inflight` (host speed only; the answer is the list's).
    filter: InflightFilter,
}

/// A one-hash Bloom filter over the in-flight list's lines (bit set ⇒ the line may be on
/// it; clear ⇒ it is not), rebuilt when the list is pruned, and the latest fill on the
/// list: most misses are answered by one bit test instead of a hash-table probe.
#[derive(Clone, Debug)]
struct InflightFilter {
    bits: Vec<u64>,
    /// log2 of the bit count (the hash keeps this many top bits).
    log2: u32,
    /// The latest fill of a listed line: nothing is in flight from then on.
    until: u64,
}

impl InflightFilter {
    /// One bit per set, 4096 to 65 536 bits.
    fn new(sets: u64) -> Self {
        let log2 = sets.next_power_of_two().trailing_zeros().clamp(12, 16);
        InflightFilter {
            bits: vec![0; 1 << (log2 - 6)],
            log2,
            until: 0,
        }
    }

    /// Word and bit of `line` (Fibonacci hashing: lines of one set share their low bits,
    /// so those cannot be used directly).
    #[inline]
    fn bit(&self, line: u64) -> (usize, u64) {
        let h = line.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - self.log2);
        ((h >> 6) as usize, 1 << (h & 63))
    }

    /// Records `line`, in flight until `fill`.
    #[inline]
    fn note(&mut self, line: u64, fill: u64) {
        let (i, bit) = self.bit(line);
        self.bits[i] |= bit;
        self.until = self.until.max(fill);
    }

    /// Whether `line` may be on the list at `now`.
    #[inline]
    fn may_hold(&self, line: u64, now: u64) -> bool {
        now < self.until && {
            let (i, bit) = self.bit(line);
            self.bits[i] & bit != 0
        }
    }

    /// Forgets everything and records `list` again.
    fn rebuild(&mut self, list: &FxHashMap<u64, u64>) {
        self.bits.fill(0);
        self.until = 0;
        for (&l, &f) in list {
            self.note(l, f);
        }
    }
}

impl Cache {
    /// A cache of `size_bytes` with 64-byte lines and `associativity` ways (power-of-two sets).
    pub fn new(size_bytes: u64, line_bytes: u64, associativity: u32) -> Self {
        let assoc = associativity.max(1) as usize;
        let sets = (size_bytes / line_bytes / assoc as u64).max(1);
        let n = sets as usize * assoc;
        Self {
            ways: Ways::Narrow(vec![Way::EMPTY; n]),
            used: if assoc > 1 { vec![0; n] } else { Vec::new() },
            assoc,
            set_mask: sets - 1,
            stamp: 0,
            inflight: FxHashMap::default(),
            prune_at: INFLIGHT_PRUNE,
            filter: InflightFilter::new(sets),
        }
    }

    #[inline]
    fn set(&self, line: u64) -> usize {
        (line & self.set_mask) as usize * self.assoc
    }

    /// Looks up `line` (a line number: byte address / 64) at cycle `now`, updating LRU state
    /// on a hit. A line replaced by a miss still in flight is a hit until that fill arrives;
    /// a line in flight is `Present` with its future fill cycle (the caller merges).
    ///
    /// A line a direct-mapped cache holds in its way is answered inline
    /// (`Cache::find_direct`); the rest goes through `Cache::lookup_general`.
    #[inline]
    pub fn lookup(&mut self, line: LineAddr, now: Cycle) -> Lookup {
        let line = line.get();
        if let Some(fill) = self.find_direct(line) {
            return Lookup::Present { fill };
        }
        self.lookup_general(line, now.get())
    }

    /// [`Cache::lookup`] in general: any associativity or tag width, the replaced line
    /// still readable, and the in-flight list.
    #[inline(never)]
    fn lookup_general(&mut self, line: u64, now: u64) -> Lookup {
        let s = self.set(line);
        if self.assoc > 1 {
            self.stamp += 1;
        }
        let (assoc, stamp) = (self.assoc, self.stamp);
        let found = match &self.ways {
            Ways::Narrow(w) => find(w, &mut self.used, stamp, s, assoc, line, now),
            Ways::Wide(w) => find(w, &mut self.used, stamp, s, assoc, line, now),
        };
        if let Some(fill) = found {
            return Lookup::Present { fill: Cycle(fill) };
        }
        if self.filter.may_hold(line, now)
            && let Some(&fill) = self.inflight.get(&line)
            && fill > now
        {
            return Lookup::Present { fill: Cycle(fill) };
        }
        Lookup::Absent
    }

    /// The fill cycle of `line` when a direct-mapped cache holds it in its way (the first
    /// test of [`Cache::lookup`], which has no other effect there); `None` when the way
    /// holds another line, or the cache is set-associative or has 64-bit tags: then
    /// [`Cache::lookup`] answers. Small enough to inline into the load path, so an L1 hit
    /// costs no call.
    #[inline]
    fn find_direct(&self, line: u64) -> Option<Cycle> {
        match &self.ways {
            Ways::Narrow(w) if self.assoc == 1 => {
                let way = w[self.set(line)];
                // An empty way (`INVALID`) never matches, even line 2^32 − 1.
                (way.line != u32::INVALID && u64::from(way.line) == line)
                    .then_some(Cycle(u64::from(way.fill)))
            }
            _ => None,
        }
    }

    /// Whether a way of `line`'s set holds `line` as its tag, read without effect: then
    /// [`Cache::lookup`] finds it `Present` at every cycle (its fill may still be coming).
    /// False says nothing: a replaced line or one on the in-flight list may still answer.
    #[inline]
    pub fn holds(&self, line: LineAddr) -> bool {
        let line = line.get();
        // Most L1 accesses hit a direct-mapped cache: one compare.
        if self.find_direct(line).is_some() {
            return true;
        }
        let s = self.set(line);
        match &self.ways {
            Ways::Narrow(w) => {
                u32::fit(line).is_some_and(|l| w[s..s + self.assoc].iter().any(|way| way.line == l))
            }
            Ways::Wide(w) => w[s..s + self.assoc].iter().any(|way| way.line == line),
        }
    }

    /// The tag word of `line`'s first way, read without effect (see `Thread::touch`).
    #[inline]
    pub fn peek(&self, line: LineAddr) -> u64 {
        let line = line.get();
        let s = self.set(line);
        match &self.ways {
            Ways::Narrow(w) => w[s].line.get(),
            Ways::Wide(w) => w[s].line,
        }
    }

    /// Takes the tag array out as 64-bit words (exact: every narrow word widens to itself,
    /// `INVALID` to `INVALID`); the caller puts it back.
    fn take_wide(&mut self) -> Vec<Way<u64>> {
        match std::mem::replace(&mut self.ways, Ways::Wide(Vec::new())) {
            Ways::Wide(w) => w,
            Ways::Narrow(w) => {
                let wide = |x: u32| {
                    if x == u32::INVALID {
                        u64::INVALID
                    } else {
                        u64::from(x)
                    }
                };
                w.iter()
                    .map(|w| Way {
                        line: wide(w.line),
                        fill: u64::from(w.fill),
                        prev: wide(w.prev),
                        prev_fill: u64::from(w.prev_fill),
                    })
                    .collect()
            }
        }
    }

    /// Reserves the least recently used way of `line`'s set for a miss made at cycle `now`
    /// whose fill arrives at `fill`. The line it replaces stays readable until then; if that
    /// line is itself still in flight, it moves to the in-flight list.
    ///
    /// A direct-mapped cache with 32-bit tags whose way holds no line still in flight (most
    /// installs) is served inline; the rest goes through `Cache::install_general`.
    #[inline]
    pub fn install(&mut self, line: LineAddr, fill: Cycle, now: Cycle) {
        let line = line.get();
        let (fill, now) = (fill.get(), now.get());
        let s = self.set(line);
        if self.assoc == 1
            && let Ways::Narrow(ways) = &mut self.ways
            && let (Some(l), Some(f)) = (u32::fit(line), u32::fit(fill))
        {
            let w = &mut ways[s];
            if w.line == u32::INVALID {
                (w.line, w.fill) = (l, f);
                return;
            }
            if u64::from(w.fill) <= now {
                (w.prev, w.prev_fill, w.line, w.fill) = (w.line, w.fill, l, f);
                return;
            }
        }
        self.install_general(line, fill, now);
    }

    /// [`Cache::install`] in general: any associativity or tag width, and a replaced line
    /// still in flight, which moves to the in-flight list.
    #[inline(never)]
    fn install_general(&mut self, line: u64, fill: u64, now: u64) {
        let s = self.set(line);
        if self.assoc > 1 {
            self.stamp += 1;
        }
        let (assoc, stamp) = (self.assoc, self.stamp);
        let moved = match (&mut self.ways, u32::fit(line), u32::fit(fill)) {
            (Ways::Narrow(w), Some(l), Some(f)) => {
                replace(w, &mut self.used, stamp, s, assoc, l, f, now)
            }
            (Ways::Wide(w), ..) => replace(w, &mut self.used, stamp, s, assoc, line, fill, now),
            (Ways::Narrow(_), ..) => {
                // The first line or cycle beyond 32 bits.
                let mut w = self.take_wide();
                let moved = replace(&mut w, &mut self.used, stamp, s, assoc, line, fill, now);
                self.ways = Ways::Wide(w);
                moved
            }
        };
        if let Some((l, f)) = moved {
            self.inflight.insert(l, f);
            self.filter.note(l, f);
            if self.inflight.len() >= self.prune_at {
                self.inflight.retain(|_, f| *f > now);
                self.prune_at = (2 * self.inflight.len()).max(INFLIGHT_PRUNE);
                self.filter.rebuild(&self.inflight);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Cache {
        /// [`Cache::lookup`] at cycle `now`.
        fn lk(&mut self, line: u64, now: u64) -> Lookup {
            self.lookup(LineAddr::new(line), Cycle(now))
        }

        /// [`Cache::install`] of a fill at cycle `fill` made at `now`.
        fn ins(&mut self, line: u64, fill: u64, now: u64) {
            self.install(LineAddr::new(line), Cycle(fill), Cycle(now))
        }

        /// A lookup at cycle 0 on a copy (no effect on `self`).
        fn lookup_copy(&self, line: u64) -> Lookup {
            self.clone().lk(line, 0)
        }
    }

    #[test]
    fn direct_mapped_conflict_evicts_when_the_new_line_arrives() {
        let mut c = Cache::new(1024, 64, 1); // 16 sets
        c.ins(3, 10, 0);
        assert_eq!(c.lk(3, 10), Lookup::Present { fill: Cycle(10) });
        // A conflicting miss at cycle 12, filled at 20: line 3 is still there until 20.
        c.ins(3 + 16, 20, 12);
        assert_eq!(c.lk(3, 19), Lookup::Present { fill: Cycle(10) });
        assert_eq!(c.lk(3, 20), Lookup::Absent);
        assert_eq!(c.lk(19, 15), Lookup::Present { fill: Cycle(20) });
        assert_eq!(c.lk(19, 20), Lookup::Present { fill: Cycle(20) });
    }

    #[test]
    fn a_line_in_flight_is_found_after_its_tag_is_taken() {
        let mut c = Cache::new(1024, 64, 1);
        c.ins(3, 10, 0);
        // Line 19 in flight until 100; line 35 (same set) missed at 20, in flight until 50.
        c.ins(19, 100, 11);
        c.ins(35, 50, 20);
        // 19 is still pending: merged, not requested again.
        assert_eq!(c.lk(19, 30), Lookup::Present { fill: Cycle(100) });
        assert_eq!(c.lk(35, 30), Lookup::Present { fill: Cycle(50) });
        // Line 3 stays readable until the way's latest fill (35 at 50).
        assert_eq!(c.lk(3, 30), Lookup::Present { fill: Cycle(10) });
        assert_eq!(c.lk(3, 50), Lookup::Absent);
        // After its fill, 19 (displaced) is gone.
        assert_eq!(c.lk(19, 100), Lookup::Absent);
    }

    /// The in-flight filter never hides a line on the list: random conflicting misses
    /// (many lines per set, fills far ahead so the list grows and is pruned) with lookups
    /// compared to a probe of the list itself.
    #[test]
    fn the_in_flight_filter_answers_as_the_list() {
        for assoc in [1, 2] {
            let mut rng = dualsplit_geometry::Pcg32::new(assoc as u64, 11);
            let mut c = Cache::new(64 * 64, 64, assoc); // 64 lines
            let mut now = 0;
            let mut found = 0;
            for i in 0..20_000 {
                now += rng.below(3) as u64;
                let line = rng.below(4096) as u64;
                let set = c.set(line);
                let Ways::Narrow(ways) = &c.ways else {
                    panic!("the test's lines and cycles fit 32 bits")
                };
                let in_set = ways[set..set + c.assoc]
                    .iter()
                    .any(|w| w.line.get() == line || (w.prev.get() == line && now < w.fill.get()));
                let listed = c.inflight.get(&line).copied().filter(|&f| f > now);
                let got = c.lk(line, now);
                if !in_set {
                    let want =
                        listed.map_or(Lookup::Absent, |fill| Lookup::Present { fill: Cycle(fill) });
                    assert_eq!(got, want, "assoc {assoc}, step {i}, line {line}");
                    found += u64::from(listed.is_some());
                }
                if got == Lookup::Absent {
                    c.ins(line, now + 1 + rng.below(500) as u64, now);
                }
            }
            assert!(
                found > 100,
                "assoc {assoc}: only {found} lines found on the list"
            );
        }
    }

    /// 16-byte (narrow) and 32-byte (wide) tag arrays answer alike, and an install beyond
    /// 32 bits (a line, then a fill cycle) converts a narrow array on the fly without
    /// changing an answer.
    #[test]
    fn narrow_and_wide_tags_answer_alike() {
        for (assoc, by_line) in [(1, true), (1, false), (2, true), (4, false)] {
            let mut rng = dualsplit_geometry::Pcg32::new(assoc as u64, 13);
            let mut narrow = Cache::new(64 * 64, 64, assoc);
            let mut wide = Cache::new(64 * 64, 64, assoc);
            wide.ways = Ways::Wide(wide.take_wide());
            let mut now = 0;
            for i in 0..30_000 {
                now += rng.below(3) as u64;
                let far = 1u64 << 33;
                let line = match (i, rng.below(8)) {
                    (20_000.., 0) if by_line => far + rng.below(64) as u64,
                    _ => rng.below(1024) as u64,
                };
                let at = |c: &mut Cache| c.lk(line, now);
                let got = at(&mut narrow);
                assert_eq!(got, at(&mut wide), "assoc {assoc}, step {i}, line {line}");
                if got == Lookup::Absent {
                    let mut fill = now + 1 + rng.below(300) as u64;
                    if i >= 25_000 && !by_line {
                        fill += far;
                    }
                    narrow.ins(line, fill, now);
                    wide.ins(line, fill, now);
                }
                let is_wide = matches!(narrow.ways, Ways::Wide(_));
                let from = if by_line { 20_000 } else { 25_000 };
                assert!(!is_wide || i >= from, "widened at step {i}");
            }
            assert!(matches!(narrow.ways, Ways::Wide(_)), "assoc {assoc}");
        }
    }

    /// The inline test `find_direct` answers as `lookup` whenever it answers (random
    /// conflicting lines, fills ahead, lines up to 2^32 − 1 so an empty way's `INVALID` is
    /// asked for), answers most hits of a direct-mapped narrow cache, and never a
    /// set-associative or wide one (nor this one once line 2^32 − 1 has widened it).
    #[test]
    fn find_direct_answers_as_lookup() {
        // An empty way is not line 2^32 − 1.
        let cold = Cache::new(64 * 64, 64, 1);
        assert_eq!(cold.find_direct(u64::from(u32::MAX)), None);
        assert_eq!(cold.lookup_copy(u64::from(u32::MAX)), Lookup::Absent);
        for (assoc, wide) in [(1, false), (2, false), (1, true)] {
            let mut rng = dualsplit_geometry::Pcg32::new(assoc as u64, 17);
            let mut c = Cache::new(64 * 64, 64, assoc);
            if wide {
                c.ways = Ways::Wide(c.take_wide());
            }
            let (mut now, mut answered) = (0, 0);
            for i in 0..20_000 {
                now += rng.below(3) as u64;
                // Line 2^32 − 1 widens the array when installed: asked for late.
                let line = match (i, rng.below(50)) {
                    (15_000.., 0) => u64::from(u32::MAX),
                    (_, 1) => u64::from(u32::MAX) - 64,
                    _ => rng.below(80) as u64,
                };
                let direct = c.find_direct(line);
                let got = c.lookup_general(line, now);
                if let Some(fill) = direct {
                    assert_eq!(got, Lookup::Present { fill }, "assoc {assoc}, step {i}");
                    answered += 1;
                }
                if got == Lookup::Absent {
                    c.ins(line, now + 1 + rng.below(300) as u64, now);
                }
            }
            if assoc == 1 && !wide {
                assert!(answered > 1000, "only {answered} answered");
            } else {
                assert_eq!(answered, 0, "assoc {assoc}, wide {wide}");
            }
        }
    }

    #[test]
    fn two_way_keeps_both_and_evicts_lru() {
        let mut c = Cache::new(1024, 64, 2); // 8 sets
        c.ins(1, 0, 0);
        c.ins(9, 0, 0);
        assert!(matches!(c.lk(1, 1), Lookup::Present { .. }));
        c.ins(17, 5, 1); // replaces 9, the least recently used, at cycle 5
        assert!(matches!(c.lk(1, 6), Lookup::Present { .. }));
        assert_eq!(c.lk(9, 6), Lookup::Absent);
        assert!(matches!(c.lk(17, 6), Lookup::Present { .. }));
    }
}
