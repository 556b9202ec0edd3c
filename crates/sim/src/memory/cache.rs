//! A set-associative cache of 64-byte lines with fill times in the tags (LRU replacement;
//! associativity 1 is SimTRaX's direct-mapped cache, notes §1.4), plus the list of lines in
//! flight (the MSHRs).
//!
//! A miss is *reserved* when it is made (it learns its fill cycle at once, notes §5.2), but
//! the line it brings is only *installed* when that fill arrives, as in SimTRaX ("lines are
//! installed in L2 and L1 at their arrival cycle", notes §1.4) and in any cache with miss
//! status holding registers (Kroft 1981):
//!
//! * the line a miss replaces stays readable until the new line's fill arrives (`prev`), so a
//!   hot line (the top of a tree) is not lost for the whole miss latency of a conflicting
//!   line;
//! * a line still in flight is found by every later miss to it, even after another miss to
//!   the same set has taken its tag (`inflight`, SimTRaX's per-L1 list of in-flight lines
//!   and L2's pending list), so it is never requested twice.
//!
//! (Model versions ≤ 3 wrote the new tag at request time: the replaced line vanished
//! for the whole miss latency and an in-flight line whose tag was taken by a later conflicting
//! miss was requested again. Under load the two fed each other — longer latencies, more
//! re-requests of the top-of-tree lines, hotter L2 banks — which is why TM scaling broke
//! down at 128 TMs; see `docs/simulator.md`, "TM scaling".)

use crate::Cycle;
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

/// One way's tag: the line it holds and the cycle its fill arrives (16 bytes, so a
/// direct-mapped lookup touches one host cache line).
/// One way's tag: the line it holds once its fill arrives, and the line it replaced, still
/// readable until then (32 bytes: a direct-mapped lookup touches one host cache line).
#[derive(Clone, Copy, Debug)]
struct Way {
    /// The line this way holds once `fill` has arrived.
    line: u64,
    fill: Cycle,
    /// The line replaced by `line`, still readable before `fill` (its own fill cycle).
    prev: u64,
    prev_fill: Cycle,
}

const INVALID: u64 = u64::MAX;

/// In-flight entries are pruned once the table has grown past this many (amortised).
const INFLIGHT_PRUNE: usize = 64;

/// Tags of a set-associative cache, with the in-flight (MSHR) list.
#[derive(Clone, Debug)]
pub struct Cache {
    ways: Vec<Way>,
    /// LRU stamps, parallel to `ways` (empty when direct-mapped: nothing to choose).
    used: Vec<u64>,
    assoc: usize,
    set_mask: u64,
    stamp: u64,
    /// Lines in flight whose way has since been taken by a later miss: line → fill cycle.
    /// (Fx hashing: the list is probed on every miss that the set does not answer, and
    /// SipHash's resistance to chosen keys buys nothing for line numbers.)
    inflight: FxHashMap<u64, Cycle>,
    prune_at: usize,
    /// A one-hash Bloom filter over the in-flight list's lines (bit set ⇒ the line may be
    /// on it; clear ⇒ it is not), rebuilt when the list is pruned, and the latest fill on
    /// the list: most misses are answered by one bit test instead of a hash-table probe
    /// (host speed only; the answer is the list's).
    filter: Vec<u64>,
    /// log2 of the filter's bit count (the hash keeps this many top bits).
    filter_bits: u32,
    inflight_until: Cycle,
}

impl Cache {
    /// A cache of `size_bytes` with 64-byte lines and `associativity` ways (power-of-two sets).
    pub fn new(size_bytes: u64, line_bytes: u64, associativity: u32) -> Self {
        let assoc = associativity.max(1) as usize;
        let sets = (size_bytes / line_bytes / assoc as u64).max(1);
        let n = sets as usize * assoc;
        // One filter bit per set, 4096 to 65 536 bits.
        let filter_bits = sets.next_power_of_two().trailing_zeros().clamp(12, 16);
        Self {
            ways: vec![
                Way {
                    line: INVALID,
                    fill: 0,
                    prev: INVALID,
                    prev_fill: 0,
                };
                n
            ],
            used: if assoc > 1 { vec![0; n] } else { Vec::new() },
            assoc,
            set_mask: sets - 1,
            stamp: 0,
            inflight: FxHashMap::default(),
            prune_at: INFLIGHT_PRUNE,
            filter: vec![0; 1 << (filter_bits - 6)],
            filter_bits,
            inflight_until: 0,
        }
    }

    /// Word and bit of `line` in the in-flight filter (Fibonacci hashing: lines of one set
    /// share their low bits, so those cannot be used directly).
    #[inline]
    fn filter_bit(&self, line: u64) -> (usize, u64) {
        let h = line.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - self.filter_bits);
        ((h >> 6) as usize, 1 << (h & 63))
    }

    #[inline]
    fn set(&self, line: u64) -> usize {
        (line & self.set_mask) as usize * self.assoc
    }

    /// Looks up `line` (a line number: byte address / 64) at cycle `now`, updating LRU state
    /// on a hit. A line replaced by a miss still in flight is a hit until that fill arrives;
    /// a line in flight is `Present` with its future fill cycle (the caller merges).
    #[inline]
    pub fn lookup(&mut self, line: u64, now: Cycle) -> Lookup {
        let s = self.set(line);
        if self.assoc == 1 {
            let w = self.ways[s];
            if w.line == line {
                return Lookup::Present { fill: w.fill };
            }
            if w.prev == line && now < w.fill {
                return Lookup::Present { fill: w.prev_fill };
            }
        } else {
            self.stamp += 1;
            for i in s..s + self.assoc {
                if self.ways[i].line == line {
                    self.used[i] = self.stamp;
                    return Lookup::Present {
                        fill: self.ways[i].fill,
                    };
                }
            }
            for w in &self.ways[s..s + self.assoc] {
                if w.prev == line && now < w.fill {
                    return Lookup::Present { fill: w.prev_fill };
                }
            }
        }
        if now < self.inflight_until
            && let (i, bit) = self.filter_bit(line)
            && self.filter[i] & bit != 0
            && let Some(&fill) = self.inflight.get(&line)
            && fill > now
        {
            return Lookup::Present { fill };
        }
        Lookup::Absent
    }

    /// The tag word of `line`'s first way, read without effect (see `Thread::touch`).
    #[inline]
    pub fn peek(&self, line: u64) -> u64 {
        self.ways[self.set(line)].line
    }

    /// Reserves the least recently used way of `line`'s set for a miss made at cycle `now`
    /// whose fill arrives at `fill`. The line it replaces stays readable until then; if that
    /// line is itself still in flight, it moves to the in-flight list.
    #[inline]
    pub fn install(&mut self, line: u64, fill: Cycle, now: Cycle) {
        let s = self.set(line);
        let victim = if self.assoc == 1 {
            s
        } else {
            self.stamp += 1;
            let v = (s..s + self.assoc)
                .min_by_key(|&i| {
                    if self.ways[i].line == INVALID {
                        0
                    } else {
                        self.used[i] + 1
                    }
                })
                .expect("at least one way");
            self.used[v] = self.stamp;
            v
        };
        let w = &mut self.ways[victim];
        let mut moved = None;
        if w.line != INVALID {
            if w.fill <= now {
                w.prev = w.line;
                w.prev_fill = w.fill;
            } else {
                // Still in flight: the older resident (`prev`) stays readable, the in-flight
                // line keeps its MSHR entry.
                moved = Some((w.line, w.fill));
            }
        }
        w.line = line;
        w.fill = fill;
        if let Some((l, f)) = moved {
            self.inflight.insert(l, f);
            let (i, bit) = self.filter_bit(l);
            self.filter[i] |= bit;
            self.inflight_until = self.inflight_until.max(f);
            if self.inflight.len() >= self.prune_at {
                self.inflight.retain(|_, f| *f > now);
                self.prune_at = (2 * self.inflight.len()).max(INFLIGHT_PRUNE);
                self.filter.fill(0);
                self.inflight_until = 0;
                for (&l, &f) in &self.inflight {
                    let (i, bit) = self.filter_bit(l);
                    self.filter[i] |= bit;
                    self.inflight_until = self.inflight_until.max(f);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direct_mapped_conflict_evicts_when_the_new_line_arrives() {
        let mut c = Cache::new(1024, 64, 1); // 16 sets
        c.install(3, 10, 0);
        assert_eq!(c.lookup(3, 10), Lookup::Present { fill: 10 });
        // A conflicting miss at cycle 12, filled at 20: line 3 is still there until 20.
        c.install(3 + 16, 20, 12);
        assert_eq!(c.lookup(3, 19), Lookup::Present { fill: 10 });
        assert_eq!(c.lookup(3, 20), Lookup::Absent);
        assert_eq!(c.lookup(19, 15), Lookup::Present { fill: 20 });
        assert_eq!(c.lookup(19, 20), Lookup::Present { fill: 20 });
    }

    #[test]
    fn a_line_in_flight_is_found_after_its_tag_is_taken() {
        let mut c = Cache::new(1024, 64, 1);
        c.install(3, 10, 0);
        // Line 19 in flight until 100; line 35 (same set) missed at 20, in flight until 50.
        c.install(19, 100, 11);
        c.install(35, 50, 20);
        // 19 is still pending: merged, not requested again.
        assert_eq!(c.lookup(19, 30), Lookup::Present { fill: 100 });
        assert_eq!(c.lookup(35, 30), Lookup::Present { fill: 50 });
        // Line 3 stays readable until the way's latest fill (35 at 50).
        assert_eq!(c.lookup(3, 30), Lookup::Present { fill: 10 });
        assert_eq!(c.lookup(3, 50), Lookup::Absent);
        // After its fill, 19 (displaced) is gone.
        assert_eq!(c.lookup(19, 100), Lookup::Absent);
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
                let in_set = c.ways[set..set + c.assoc]
                    .iter()
                    .any(|w| w.line == line || (w.prev == line && now < w.fill));
                let listed = c.inflight.get(&line).copied().filter(|&f| f > now);
                let got = c.lookup(line, now);
                if !in_set {
                    let want = listed.map_or(Lookup::Absent, |fill| Lookup::Present { fill });
                    assert_eq!(got, want, "assoc {assoc}, step {i}, line {line}");
                    found += u64::from(listed.is_some());
                }
                if got == Lookup::Absent {
                    c.install(line, now + 1 + rng.below(500) as u64, now);
                }
            }
            assert!(
                found > 100,
                "assoc {assoc}: only {found} lines found on the list"
            );
        }
    }

    #[test]
    fn two_way_keeps_both_and_evicts_lru() {
        let mut c = Cache::new(1024, 64, 2); // 8 sets
        c.install(1, 0, 0);
        c.install(9, 0, 0);
        assert!(matches!(c.lookup(1, 1), Lookup::Present { .. }));
        c.install(17, 5, 1); // replaces 9, the least recently used, at cycle 5
        assert!(matches!(c.lookup(1, 6), Lookup::Present { .. }));
        assert_eq!(c.lookup(9, 6), Lookup::Absent);
        assert!(matches!(c.lookup(17, 6), Lookup::Present { .. }));
    }
}
