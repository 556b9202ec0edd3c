//! The `fast` model as the event loop steps it: threads replaying their macro-ops, taking
//! more work from a [`WorkSource`] when a program is done.

use crate::engine::{self, Threads, Wake};
use crate::hw::{Chip, Cycle, Stalls};
use crate::model::fast::op::Op;
use crate::model::fast::thread::Thread;
use std::convert::Infallible;

/// Supplies threads with work: called when a thread's program is done; returns the next
/// program or `None` when there is no work left.
pub trait WorkSource {
    /// The next program for thread `id` (its index in the thread slice), whose previous
    /// program is done.
    fn next(&mut self, id: usize, thread: &mut Thread, chip: &mut Chip) -> Option<Vec<Op>>;
}

/// Replaying threads and their work.
pub struct Replay<'t, 'w> {
    threads: &'t mut [Thread],
    work: &'w mut dyn WorkSource,
    /// Whether a sleeping thread's wake-ups that would do nothing are played ahead
    /// ([`Thread::skip_ahead`]); the tests compare both.
    forwards: bool,
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

impl Threads for Replay<'_, '_> {
    type Error = Infallible;
    const TOUCH: bool = true;

    fn count(&self) -> usize {
        self.threads.len()
    }

    #[inline]
    fn touch(&self, id: usize, chip: &Chip) -> u64 {
        let th = &self.threads[id];
        let (tm, l2) = chip.tm(th.tm());
        th.touch(tm, l2)
    }

    /// A thread whose wake-ups would only move it to a later cycle often has nothing to do
    /// but go back to sleep: its next op is not a load and waits for a result due later, or
    /// it is a run of plain instructions that reserves nothing. Such wake-ups are played
    /// ahead when the thread goes to sleep ([`Thread::skip_ahead`]), and the thread is
    /// scheduled as a forward entry ([`Wake::Forward`]), so every bucket's order, hence every
    /// result, stays exact.
    #[inline]
    fn step(&mut self, id: usize, chip: &mut Chip, now: Cycle) -> Result<Wake, Infallible> {
        let th = &mut self.threads[id];
        loop {
            let u = chip.units(th.tm());
            if th.run(u.tm, u.l2, u.stalls, now) {
                return Ok(sleep(th, u.stalls, self.forwards));
            }
            // Program finished: the thread takes more work at its next issue slot, not
            // before, so that the chip's requests (the atomic unit's pixel hand-out) are
            // made in time order; or it retires once its results are in.
            if th.next_issue() > now {
                return Ok(sleep(th, u.stalls, self.forwards));
            }
            match self.work.next(id, th, chip) {
                Some(ops) => {
                    th.load_program(ops);
                    if th.next_issue() > now {
                        let u = chip.units(th.tm());
                        return Ok(sleep(th, u.stalls, self.forwards));
                    }
                }
                None => return Ok(Wake::Done(th.results_ready())),
            }
        }
    }
}

/// Runs every thread to completion, taking work from `work`; returns the cycle the last
/// result arrived.
pub fn run(chip: &mut Chip, threads: &mut [Thread], work: &mut dyn WorkSource) -> Cycle {
    run_with(chip, threads, work, true)
}

/// [`run`], with forward wake-ups (`forwards`) or without.
pub(crate) fn run_with(
    chip: &mut Chip,
    threads: &mut [Thread],
    work: &mut dyn WorkSource,
    forwards: bool,
) -> Cycle {
    let mut replay = Replay {
        threads,
        work,
        forwards,
    };
    match engine::run(chip, &mut replay) {
        Ok(end) => end,
        Err(never) => match never {},
    }
}
