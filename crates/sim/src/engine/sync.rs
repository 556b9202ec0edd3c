//! How the host threads of a parallel frame meet: once per simulated cycle with events, to
//! agree on that cycle ([`Meeting`]), and once to take their turns at the commit phase
//! ([`Turns`]). A waiting thread spins for a few microseconds (a cycle's work on a
//! dedicated core), then parks until the thread it waits for wakes it, so that more host
//! threads than cores (a test run beside others) do not take each other's time slices.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::thread::Thread;

/// Spins before parking when every party has a core of its own: about a millisecond (a
/// `pause` takes about 40 ns on recent x86), longer than a cycle's work, so the parties
/// meet without a system call. Measured on a 2-core host, 128² Dragon Box BVH2 path frame,
/// two host threads: 1.74× one thread's speed; with 128 spins, 0.38× (a futex wake-up
/// every cycle).
const SPINS_OWN_CORE: u32 = 16384;
/// Spins before parking when there are more parties than cores: a waiting party gives its
/// core to the one it waits for almost at once.
const SPINS_SHARED_CORE: u32 = 128;

/// Waits until `done` holds: spins, then parks (woken by `Meeting::wake`; a wake-up may
/// be spurious, so `done` is tested again). Panics when `poisoned` is raised (a party
/// panicked and will never arrive).
#[inline]
fn wait_until(poisoned: &AtomicBool, limit: u32, mut done: impl FnMut() -> bool) {
    let mut spins = 0u32;
    while !done() {
        if poisoned.load(Ordering::Acquire) {
            panic!("another host thread of the simulated frame panicked");
        }
        if spins < limit {
            spins += 1;
            std::hint::spin_loop();
        } else {
            std::thread::park();
        }
    }
}

/// A barrier that also takes the minimum of the values its parties bring, and an abort
/// flag any party may raise.
pub(crate) struct Meeting {
    parties: usize,
    arrived: AtomicUsize,
    /// Meetings completed.
    generation: AtomicUsize,
    /// The minimum and the abort flag of the current meeting (even generations) and of the
    /// next (odd): a party that has left a meeting may already bring the next one's.
    min: [AtomicU64; 2],
    abort: [AtomicBool; 2],
    /// A party panicked ([`Meeting::poison`]).
    poisoned: AtomicBool,
    /// Each party's host thread, to wake it ([`Meeting::join`]).
    threads: Vec<OnceLock<Thread>>,
    /// Spins before parking.
    spins: u32,
}

impl Meeting {
    pub(crate) fn new(parties: usize) -> Self {
        Self {
            parties,
            arrived: AtomicUsize::new(0),
            generation: AtomicUsize::new(0),
            min: [AtomicU64::new(u64::MAX), AtomicU64::new(u64::MAX)],
            abort: [AtomicBool::new(false), AtomicBool::new(false)],
            poisoned: AtomicBool::new(false),
            threads: (0..parties).map(|_| OnceLock::new()).collect(),
            spins: if parties <= std::thread::available_parallelism().map_or(1, usize::from) {
                SPINS_OWN_CORE
            } else {
                SPINS_SHARED_CORE
            },
        }
    }

    /// Registers the calling host thread as party `p`'s; every party does so before its
    /// first meeting.
    pub(crate) fn join(&self, p: usize) {
        let _ = self.threads[p].set(std::thread::current());
    }

    /// Wakes party `p` if it is parked (and makes its next park return at once if not).
    #[inline]
    fn wake(&self, p: usize) {
        if let Some(t) = self.threads[p].get() {
            t.unpark();
        }
    }

    /// The number of parties.
    pub(crate) fn parties(&self) -> usize {
        self.parties
    }

    /// Raised by a party that panics, so that the others panic instead of waiting for it
    /// (at this meeting or at a turn).
    pub(crate) fn poison(&self) {
        self.poisoned.store(true, Ordering::Release);
        for p in 0..self.parties {
            self.wake(p);
        }
    }

    /// Meeting number `g` (each party counts its own, from 0): brings `value`, waits for
    /// every party, and returns the least value brought and whether any party aborted.
    pub(crate) fn meet(&self, g: usize, value: u64, abort: bool) -> (u64, bool) {
        if abort {
            self.abort[g & 1].store(true, Ordering::Relaxed);
        }
        let slot = &self.min[g & 1];
        slot.fetch_min(value, Ordering::AcqRel);
        if self.arrived.fetch_add(1, Ordering::AcqRel) + 1 == self.parties {
            self.arrived.store(0, Ordering::Relaxed);
            // The next meeting's slot is fresh before anyone can reach it; this one's
            // stays readable until every party has left it (it is reset two meetings on).
            self.min[(g + 1) & 1].store(u64::MAX, Ordering::Relaxed);
            self.abort[(g + 1) & 1].store(false, Ordering::Relaxed);
            self.generation.store(g + 1, Ordering::Release);
            for p in 0..self.parties {
                self.wake(p);
            }
        } else {
            wait_until(&self.poisoned, self.spins, || {
                self.generation.load(Ordering::Acquire) > g
            });
        }
        (
            slot.load(Ordering::Acquire),
            self.abort[g & 1].load(Ordering::Relaxed),
        )
    }
}

/// Turns in a fixed order: party `p` of `parties` takes round `r`'s turn after party
/// `p − 1`, and party 0 after party `parties − 1` of round `r − 1`.
pub(crate) struct Turns {
    parties: usize,
    next: AtomicUsize,
}

impl Turns {
    pub(crate) fn new(parties: usize) -> Self {
        Self {
            parties,
            next: AtomicUsize::new(0),
        }
    }

    /// Waits for party `p`'s turn of round `r` (panics when `m` is poisoned).
    pub(crate) fn wait(&self, r: usize, p: usize, m: &Meeting) {
        let me = r * self.parties + p;
        wait_until(&m.poisoned, m.spins, || {
            self.next.load(Ordering::Acquire) == me
        });
    }

    /// Ends party `p`'s turn of round `r` and wakes the next party.
    pub(crate) fn pass(&self, r: usize, p: usize, m: &Meeting) {
        self.next.store(r * self.parties + p + 1, Ordering::Release);
        m.wake((p + 1) % self.parties);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every party learns the least value of each meeting, over many meetings with
    /// values that change, and turns come in party order.
    #[test]
    fn meetings_agree_on_the_minimum_and_turns_keep_their_order() {
        for parties in [1, 2, 3, 5] {
            let meeting = Meeting::new(parties);
            let turns = Turns::new(parties);
            let order = std::sync::Mutex::new(Vec::new());
            let seen: Vec<Vec<u64>> = std::thread::scope(|s| {
                let hs: Vec<_> = (0..parties)
                    .map(|p| {
                        let (meeting, turns, order) = (&meeting, &turns, &order);
                        s.spawn(move || {
                            let mut seen = Vec::new();
                            for g in 0..500 {
                                let v = ((g * 7 + p * 13) % 11) as u64;
                                if g == 0 {
                                    meeting.join(p);
                                }
                                let (m, abort) = meeting.meet(g, v, false);
                                assert!(!abort);
                                seen.push(m);
                                turns.wait(g, p, meeting);
                                order.lock().unwrap().push((g, p));
                                turns.pass(g, p, meeting);
                            }
                            seen
                        })
                    })
                    .collect();
                hs.into_iter().map(|h| h.join().unwrap()).collect()
            });
            let want: Vec<u64> = (0..500)
                .map(|g| {
                    (0..parties)
                        .map(|p| ((g * 7 + p * 13) % 11) as u64)
                        .min()
                        .unwrap()
                })
                .collect();
            for s in &seen {
                assert_eq!(s, &want, "{parties} parties");
            }
            let order = order.into_inner().unwrap();
            let expected: Vec<_> = (0..500)
                .flat_map(|g| (0..parties).map(move |p| (g, p)))
                .collect();
            assert_eq!(order, expected);
        }
    }

    #[test]
    fn an_abort_reaches_every_party() {
        let meeting = Meeting::new(3);
        let aborts: Vec<bool> = std::thread::scope(|s| {
            let hs: Vec<_> = (0..3)
                .map(|p| {
                    let meeting = &meeting;
                    s.spawn(move || {
                        meeting.join(p);
                        let (_, a0) = meeting.meet(0, 1, false);
                        assert!(!a0);
                        meeting.meet(1, 1, p == 2).1
                    })
                })
                .collect();
            hs.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert_eq!(aborts, vec![true; 3]);
    }
}
