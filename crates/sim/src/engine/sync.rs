//! How the host threads of a parallel frame keep the commit phases in order without
//! meeting every cycle.
//!
//! Commits are ordered by (cycle, party): party `p`'s commit phase of cycle `c` comes after
//! every commit of an earlier cycle and after those of the lower parties in cycle `c`. Each
//! party publishes its **frontier**, the earliest cycle it may still commit at (the cycle
//! it is working on; `u64::MAX` once it is done), and before committing at `c` waits until
//! every lower party's frontier is past `c` and every higher party's has reached it
//! ([`Frontiers::wait_turn`]). Local phases touch only the party's own TMs, so a party runs
//! them as far ahead as it likes: it waits only when it has something to commit and another
//! party may still commit before it. No party waits for another while that one waits for
//! it: a party waiting at `c` holds its frontier at `c`, which lets every party whose
//! turn comes before `(c, p)` go on.
//!
//! This is conservative parallel discrete-event simulation (Chandy and Misra 1979) with
//! the frontiers as the null messages. A waiting thread spins for a while (a cycle's work
//! on a dedicated core), then parks until a frontier it waits on moves, so that more host
//! threads than cores (a test run beside others) do not take each other's time slices.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::Thread;

/// Spins before parking when every party has a core of its own: about a millisecond (a
/// `pause` takes about 40 ns on recent x86), longer than a cycle's work, so parties pass
/// the turn without a system call. Source: on a 2-core host, 128² Dragon Box BVH2 path
/// frame on two host threads, a per-cycle barrier with this spin limit gave 1.74× one
/// thread's speed, and 0.38× with 128 spins (a futex wake-up every cycle).
const SPINS_OWN_CORE: u32 = 16384;
/// Spins before parking when there are more parties than cores: a waiting party gives its
/// core to the one it waits for almost at once.
const SPINS_SHARED_CORE: u32 = 128;

/// A value alone on its host cache lines (128 bytes: two lines, for the adjacent-line
/// prefetcher), so that one party publishing does not slow another's reads.
#[repr(align(128))]
struct Padded<T>(T);

/// The parties' frontiers, the first cycle any party failed at, and what parks and wakes
/// them.
pub(crate) struct Frontiers {
    /// Per party, the earliest cycle it may still commit at.
    at: Vec<Padded<AtomicU64>>,
    /// Per party, whether it is about to park or parked (set before its last check).
    sleeping: Vec<Padded<AtomicBool>>,
    /// Each party's host thread, to wake it ([`Frontiers::join`]).
    threads: Vec<OnceLock<Thread>>,
    /// The earliest cycle a party's step failed at (`u64::MAX`: none).
    failed: AtomicU64,
    /// A party panicked ([`Frontiers::poison`]).
    poisoned: AtomicBool,
    /// Spins before parking.
    spins: u32,
}

impl Frontiers {
    /// `parties` parties, every frontier at cycle 0.
    pub(crate) fn new(parties: usize) -> Self {
        Self {
            at: (0..parties).map(|_| Padded(AtomicU64::new(0))).collect(),
            sleeping: (0..parties)
                .map(|_| Padded(AtomicBool::new(false)))
                .collect(),
            threads: (0..parties).map(|_| OnceLock::new()).collect(),
            failed: AtomicU64::new(u64::MAX),
            poisoned: AtomicBool::new(false),
            spins: if parties <= std::thread::available_parallelism().map_or(1, usize::from) {
                SPINS_OWN_CORE
            } else {
                SPINS_SHARED_CORE
            },
        }
    }

    /// Registers the calling host thread as party `p`'s; every party does so before it
    /// first publishes or waits.
    pub(crate) fn join(&self, p: usize) {
        let _ = self.threads[p].set(std::thread::current());
    }

    /// Party `p` will not commit before cycle `c` (`u64::MAX`: never again); wakes the
    /// parties parked on it.
    #[inline]
    pub(crate) fn publish(&self, p: usize, c: u64) {
        self.at[p].0.store(c, Ordering::SeqCst);
        self.wake_others(p);
    }

    /// Wakes every party but `p` that is parked or about to park.
    #[inline]
    fn wake_others(&self, p: usize) {
        for (q, s) in self.sleeping.iter().enumerate() {
            if q != p
                && s.0.load(Ordering::SeqCst)
                && let Some(t) = self.threads[q].get()
            {
                t.unpark();
            }
        }
    }

    /// Whether party `p` may commit at cycle `c`: every lower party is past `c`, every
    /// higher one has reached it.
    #[inline]
    fn my_turn(&self, p: usize, c: u64) -> bool {
        self.at.iter().enumerate().all(|(q, f)| {
            let f = f.0.load(Ordering::SeqCst);
            if q < p { f > c } else { q == p || f >= c }
        })
    }

    /// Waits until party `p` may commit at cycle `c` (its own frontier is at `c`). Spins,
    /// then parks; panics when a party has panicked (it will never publish again).
    pub(crate) fn wait_turn(&self, p: usize, c: u64) {
        let mut spins = 0u32;
        while !self.my_turn(p, c) {
            if self.poisoned.load(Ordering::Acquire) {
                panic!("another host thread of the simulated frame panicked");
            }
            if spins < self.spins {
                spins += 1;
                std::hint::spin_loop();
                continue;
            }
            // Publish the intent to park, then look again: a frontier moved after this
            // store sees the flag and unparks (SeqCst on both sides), and an unpark before
            // the park makes it return at once.
            self.sleeping[p].0.store(true, Ordering::SeqCst);
            if !self.my_turn(p, c) && !self.poisoned.load(Ordering::Acquire) {
                std::thread::park();
            }
            self.sleeping[p].0.store(false, Ordering::SeqCst);
        }
    }

    /// A step failed at cycle `c`: no party goes on past the earliest such cycle.
    pub(crate) fn fail(&self, c: u64) {
        self.failed.fetch_min(c, Ordering::SeqCst);
    }

    /// The earliest cycle a step failed at (`u64::MAX`: none so far).
    #[inline]
    pub(crate) fn failed(&self) -> u64 {
        self.failed.load(Ordering::SeqCst)
    }

    /// Raised by a party that panics, so that the others panic instead of waiting for it.
    pub(crate) fn poison(&self) {
        self.poisoned.store(true, Ordering::SeqCst);
        for t in self.threads.iter().filter_map(OnceLock::get) {
            t.unpark();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Commits come in (cycle, party) order for parties with different, sparse commit
    /// cycles, whatever the interleaving of their host threads.
    #[test]
    fn commits_come_in_cycle_then_party_order() {
        for parties in [1, 2, 3, 5] {
            let f = Frontiers::new(parties);
            let order = std::sync::Mutex::new(Vec::new());
            std::thread::scope(|s| {
                for p in 0..parties {
                    let (f, order) = (&f, &order);
                    s.spawn(move || {
                        f.join(p);
                        // Party p works at the cycles ≡ 0 mod p + 1 and commits at every
                        // second of them.
                        let step = p as u64 + 1;
                        for (k, c) in (0..400).step_by(step as usize).enumerate() {
                            f.publish(p, c);
                            if k % 2 == 0 {
                                f.wait_turn(p, c);
                                order.lock().unwrap().push((c, p));
                            }
                        }
                        f.publish(p, u64::MAX);
                    });
                }
            });
            let order = order.into_inner().unwrap();
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(order, sorted, "{parties} parties");
            let want: usize = (0..parties)
                .map(|p| (0..400).step_by(p + 1).count().div_ceil(2))
                .sum();
            assert_eq!(order.len(), want, "{parties} parties");
        }
    }

    /// A panicking party's poison reaches a party parked waiting for it.
    #[test]
    fn poison_wakes_a_waiting_party() {
        let f = Frontiers::new(2);
        let r = std::thread::scope(|s| {
            let h = s.spawn(|| {
                f.join(1);
                f.publish(1, 5);
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f.wait_turn(1, 5)))
            });
            f.join(0);
            std::thread::sleep(std::time::Duration::from_millis(20));
            f.poison();
            h.join().unwrap()
        });
        assert!(r.is_err());
    }

    /// The earliest failure wins.
    #[test]
    fn the_earliest_failure_is_kept() {
        let f = Frontiers::new(3);
        assert_eq!(f.failed(), u64::MAX);
        f.fail(9);
        f.fail(4);
        f.fail(7);
        assert_eq!(f.failed(), 4);
    }
}
