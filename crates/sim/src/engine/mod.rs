//! The event loop: one loop for both thread models.
//!
//! The timing wheel (`wheel.rs`) hands out the threads whose next step can start at the next cycle
//! with events. Each is stepped by its thread model ([`Threads::step`]) against its TM's
//! units while it can start in that cycle, and goes back to sleep until the cycle it can
//! continue ([`Wake`]). The frame ends when the last result of the last thread has arrived.
//! Requests reserve their units at their own start cycle, never before the current event
//! time, and events are processed in time order, so reservations are made in (nearly)
//! causal order.
//!
//! ```text
//!   engine::run ──▶ wheel: next cycle's threads, in the order they were scheduled
//!        │
//!        ▼ Threads::step(id, &mut Chip, now) -> Wake::{At, Forward, Done}
//!   model::rv32 (thread processors executing the compiled kernels)
//!   model::fast (threads replaying recorded macro-ops)
//!        │
//!        ▼ requests at a cycle, answers with the cycle their result is ready
//!   hw::Chip: TMs (L1, pipelines, reciprocal unit, pools), L2, DRAM, atomic unit
//! ```

pub(crate) mod wheel;

use crate::hw::{Chip, Cycle};
use wheel::{NONE, Wheel};

pub use wheel::HOPS;

/// When a stepped thread runs next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wake {
    /// At this cycle.
    At(Cycle),
    /// At this cycle as a forward entry: at the first `k` cycles given by the delays (each
    /// after the previous), the wheel moves it on without stepping it, exactly where the
    /// woken thread would have put itself (`Wheel::push_forward`).
    Forward(Cycle, [u32; HOPS]),
    /// Never: it is done, and its last result arrives at this cycle.
    Done(Cycle),
}

/// A thread model: the threads of a frame, as the event loop steps them.
pub trait Threads {
    /// What a step can fail with.
    type Error;
    /// Whether [`Threads::touch`] is worth a pass over each cycle's threads.
    const TOUCH: bool = false;
    /// The number of threads (ids `0..count`).
    fn count(&self) -> usize;
    /// Reads (without effect) the host memory thread `id`'s next step will touch first, so
    /// that the host cache misses of a cycle's threads overlap; returns a value to keep the
    /// reads. Changes nothing simulated.
    #[inline]
    fn touch(&self, _id: usize, _chip: &Chip) -> u64 {
        0
    }
    /// Runs thread `id` while it can start at cycle `now`.
    fn step(&mut self, id: usize, chip: &mut Chip, now: Cycle) -> Result<Wake, Self::Error>;
    /// Called after every cycle with events (progress reports).
    #[inline]
    fn after_cycle(&mut self) {}
}

/// Runs every thread of `threads` to completion on `chip`; returns the cycle the last
/// result arrived, and sets the chip's idle-at-end stall count.
pub fn run<T: Threads>(chip: &mut Chip, threads: &mut T) -> Result<Cycle, T::Error> {
    let n = threads.count();
    let mut wheel = Wheel::new(n);
    for i in 0..n as u32 {
        wheel.push(Cycle::ZERO, i);
    }
    let mut finish = vec![Cycle::ZERO; n];
    while let Some((now, first)) = wheel.next_bucket() {
        if T::TOUCH {
            let mut touched = 0;
            let mut id = first;
            while id != NONE {
                if !wheel.is_forward(id) {
                    touched ^= threads.touch(id as usize, chip);
                }
                id = wheel.after(id);
            }
            std::hint::black_box(touched);
        }
        let mut id = first;
        while id != NONE {
            let next = wheel.after(id);
            wheel.taken();
            if let Some(to) = wheel.take_forward(id) {
                wheel.push(to, id);
                id = next;
                continue;
            }
            match threads.step(id as usize, chip, now)? {
                Wake::At(t) => wheel.push(t, id),
                Wake::Forward(t, hops) => wheel.push_forward(t, hops, id),
                Wake::Done(t) => finish[id as usize] = t,
            }
            id = next;
        }
        threads.after_cycle();
    }
    let end = finish.iter().copied().max().unwrap_or(Cycle::ZERO);
    chip.set_idle(finish.iter().map(|&f| end - f).sum());
    Ok(end)
}
