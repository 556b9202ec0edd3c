//! A set-associative cache of 64-byte lines with fill times in the tags (LRU replacement;
//! associativity 1 is SimTRaX's direct-mapped cache, notes §1.4).

use crate::Cycle;

/// The result of a tag lookup.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lookup {
    /// The line is present; its data is (or will be) there at `fill`.
    Present {
        /// Cycle the line's fill arrives (≤ now for a plain hit).
        fill: Cycle,
    },
    /// The line is absent.
    Absent,
}

/// One way's tag: the line it holds and the cycle its fill arrives (16 bytes, so a
/// direct-mapped lookup touches one host cache line).
#[derive(Clone, Copy, Debug)]
struct Way {
    line: u64,
    fill: Cycle,
}

const INVALID: u64 = u64::MAX;

/// Tags of a set-associative cache.
#[derive(Clone, Debug)]
pub struct Cache {
    ways: Vec<Way>,
    /// LRU stamps, parallel to `ways` (empty when direct-mapped: nothing to choose).
    used: Vec<u64>,
    assoc: usize,
    set_mask: u64,
    stamp: u64,
}

impl Cache {
    /// A cache of `size_bytes` with 64-byte lines and `associativity` ways (power-of-two sets).
    pub fn new(size_bytes: u64, line_bytes: u64, associativity: u32) -> Self {
        let assoc = associativity.max(1) as usize;
        let sets = (size_bytes / line_bytes / assoc as u64).max(1);
        let n = sets as usize * assoc;
        Self {
            ways: vec![
                Way {
                    line: INVALID,
                    fill: 0
                };
                n
            ],
            used: if assoc > 1 { vec![0; n] } else { Vec::new() },
            assoc,
            set_mask: sets - 1,
            stamp: 0,
        }
    }

    #[inline]
    fn set(&self, line: u64) -> usize {
        (line & self.set_mask) as usize * self.assoc
    }

    /// Looks up `line` (a line number: byte address / 64), updating LRU state on a hit.
    #[inline]
    pub fn lookup(&mut self, line: u64) -> Lookup {
        let s = self.set(line);
        if self.assoc == 1 {
            let w = self.ways[s];
            return if w.line == line {
                Lookup::Present { fill: w.fill }
            } else {
                Lookup::Absent
            };
        }
        self.stamp += 1;
        for (i, w) in self.ways[s..s + self.assoc].iter().enumerate() {
            if w.line == line {
                self.used[s + i] = self.stamp;
                return Lookup::Present { fill: w.fill };
            }
        }
        Lookup::Absent
    }

    /// The tag word of `line`'s first way, read without effect (see `Thread::touch`).
    #[inline]
    pub fn peek(&self, line: u64) -> u64 {
        self.ways[self.set(line)].line
    }

    /// Installs `line` with its fill cycle, evicting the least recently used way.
    #[inline]
    pub fn install(&mut self, line: u64, fill: Cycle) {
        let s = self.set(line);
        let new = Way { line, fill };
        if self.assoc == 1 {
            self.ways[s] = new;
            return;
        }
        self.stamp += 1;
        let victim = (s..s + self.assoc)
            .min_by_key(|&i| {
                if self.ways[i].line == INVALID {
                    0
                } else {
                    self.used[i] + 1
                }
            })
            .expect("at least one way");
        self.ways[victim] = new;
        self.used[victim] = self.stamp;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direct_mapped_conflict_evicts() {
        let mut c = Cache::new(1024, 64, 1); // 16 sets
        c.install(3, 10);
        assert_eq!(c.lookup(3), Lookup::Present { fill: 10 });
        c.install(3 + 16, 20);
        assert_eq!(c.lookup(3), Lookup::Absent);
        assert_eq!(c.lookup(19), Lookup::Present { fill: 20 });
    }

    #[test]
    fn two_way_keeps_both_and_evicts_lru() {
        let mut c = Cache::new(1024, 64, 2); // 8 sets
        c.install(1, 0);
        c.install(9, 0);
        assert!(matches!(c.lookup(1), Lookup::Present { .. }));
        c.install(17, 0); // evicts 9, the least recently used
        assert!(matches!(c.lookup(1), Lookup::Present { .. }));
        assert_eq!(c.lookup(9), Lookup::Absent);
        assert!(matches!(c.lookup(17), Lookup::Present { .. }));
    }
}
