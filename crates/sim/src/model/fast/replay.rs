//! The `fast` model as the event loop steps it: threads replaying their macro-ops, taking
//! more work from a [`WorkSource`] when a program is done.

use crate::engine::{self, Commit, Lane, Wake};
use crate::hw::atomic::AtomicUnit;
use crate::hw::tm::Tm;
use crate::hw::{Chip, Cycle, Stalls};
use crate::model::fast::op::Op;
use crate::model::fast::thread::{Ran, Thread};
use std::convert::Infallible;
use std::marker::PhantomData;
use std::ops::Range;

/// Supplies threads with work: called (in the event loop's commit phase) when a thread's
/// program is done; returns the next program or `None` when there is no work left.
pub trait WorkSource: Send {
    /// The next program for thread `id` (its index in the frame's thread slice), whose
    /// previous program is done; `atomic` is the chip's atomic unit, for the pixel
    /// hand-out, and `stalls` the thread's stall counters.
    fn next(
        &mut self,
        id: usize,
        thread: &mut Thread,
        atomic: &mut AtomicUnit,
        stalls: &mut Stalls,
    ) -> Option<Vec<Op>>;
}

/// The replaying threads of a group of TMs.
struct Replay<'t, 'w> {
    threads: &'t mut [Thread],
    /// The frame's index of `threads[0]`.
    base: usize,
    tms: Range<usize>,
    /// Whether a sleeping thread's wake-ups that would do nothing are played ahead
    /// ([`Thread::skip_ahead`]); the tests compare both.
    forwards: bool,
    work: PhantomData<&'w mut ()>,
}

/// Puts a thread to sleep until its next issue slot, as a forward entry when `forwards`.
#[inline(always)]
fn sleep(th: &mut Thread, stalls: &mut Stalls, forwards: bool) -> Wake {
    let t = th.next_issue();
    if forwards {
        Wake::Forward(t, th.skip_ahead(stalls))
    } else {
        th.forget_next();
        Wake::At(t)
    }
}

impl<'t, 'w> Lane for Replay<'t, 'w> {
    type Error = Infallible;
    type Shared = &'w mut dyn WorkSource;
    const TOUCH: bool = true;

    fn count(&self) -> usize {
        self.threads.len()
    }

    fn tms(&self) -> Range<usize> {
        self.tms.clone()
    }

    #[inline]
    fn tm_of(&self, id: usize) -> usize {
        self.threads[id].tm() - self.tms.start
    }

    #[inline]
    fn touch(&self, id: usize, tm: &Tm) -> u64 {
        self.threads[id].touch(tm)
    }

    /// A thread whose wake-ups would only move it to a later cycle often has nothing to do
    /// but go back to sleep: its next op is not a load and waits for a result due later, or
    /// it is a run of plain instructions that reserves nothing. Such wake-ups are played
    /// ahead when the thread goes to sleep ([`Thread::skip_ahead`]), and the thread is
    /// scheduled as a forward entry ([`Wake::Forward`]), so every bucket's order, hence every
    /// result, stays exact. A load that misses the L1 and a finished program (its next work
    /// comes from the shared work source) go to the commit phase.
    #[inline]
    fn step(
        &mut self,
        id: usize,
        tm: &mut Tm,
        stalls: &mut Stalls,
        now: Cycle,
    ) -> Result<Wake, Infallible> {
        let th = &mut self.threads[id];
        Ok(match th.run(tm, None, stalls, now) {
            Ran::Asleep => sleep(th, stalls, self.forwards),
            Ran::Commit => Wake::Commit,
            // Program finished: the thread takes more work at its next issue slot, not
            // before, so that the chip's requests (the atomic unit's pixel hand-out) are
            // made in time order.
            Ran::Finished if th.next_issue() > now => sleep(th, stalls, self.forwards),
            Ran::Finished => Wake::Commit,
        })
    }

    fn commit(
        &mut self,
        id: usize,
        tm: &mut Tm,
        stalls: &mut Stalls,
        shared: Commit<'_, Self::Shared>,
        now: Cycle,
    ) -> Result<Wake, Infallible> {
        let th = &mut self.threads[id];
        loop {
            match th.run(tm, Some(&mut *shared.l2), stalls, now) {
                Ran::Asleep => return Ok(sleep(th, stalls, self.forwards)),
                Ran::Commit => unreachable!("a run with the L2 made its load"),
                Ran::Finished if th.next_issue() > now => {
                    return Ok(sleep(th, stalls, self.forwards));
                }
                Ran::Finished => {}
            }
            // Take more work, or retire once the results are in.
            match shared.model.next(self.base + id, th, shared.atomic, stalls) {
                Some(ops) => {
                    th.load_program(ops);
                    if th.next_issue() > now {
                        return Ok(sleep(th, stalls, self.forwards));
                    }
                }
                None => return Ok(Wake::Done(th.results_ready())),
            }
        }
    }
}

/// Runs every thread to completion on one host thread, taking work from `work`; returns
/// the cycle the last result arrived.
pub fn run(chip: &mut Chip, threads: &mut [Thread], work: &mut dyn WorkSource) -> Cycle {
    run_with(chip, threads, work, true, 1)
}

/// [`run`] on `host_threads` host threads, with forward wake-ups (`forwards`) or without.
/// `threads` are in TM order.
pub(crate) fn run_with(
    chip: &mut Chip,
    threads: &mut [Thread],
    mut work: &mut dyn WorkSource,
    forwards: bool,
    host_threads: usize,
) -> Cycle {
    assert!(
        threads.is_sorted_by_key(Thread::tm),
        "threads must be in TM order"
    );
    let mut rest: &mut [Thread] = threads;
    let mut base = 0;
    let mut lanes = Vec::new();
    for tms in engine::groups(chip.tm_count(), host_threads) {
        let n = rest.partition_point(|t| t.tm() < tms.end);
        let (mine, others) = std::mem::take(&mut rest).split_at_mut(n);
        rest = others;
        lanes.push(Replay {
            threads: mine,
            base,
            tms,
            forwards,
            work: PhantomData,
        });
        base += n;
    }
    match engine::run(chip, &mut lanes, &mut work) {
        Ok(end) => end,
        Err(never) => match never {},
    }
}
