//! The event loop: one loop for both thread models, on one host thread or several.
//!
//! The timing wheel (`wheel.rs`) hands out the threads whose next step can start at the next
//! cycle with events. Each cycle runs in two phases:
//!
//! 1. **Local phase.** Each thread of the cycle is stepped by its thread model
//!    ([`Lane::step`]) against its own TM's units (L1 hits, pipelines, pools, reciprocal
//!    unit, instruction cache) while it can start in that cycle, and goes back to sleep until
//!    the cycle it can continue ([`Wake`]). A step that needs something outside its TM (an L1
//!    miss to the L2, the atomic unit, the frame buffer) stops before it and asks for the
//!    commit phase ([`Wake::Commit`]).
//! 2. **Commit phase.** Those threads are stepped again ([`Lane::commit`]) with the chip's
//!    shared units, in a fixed order: by TM, then in the order their TM's threads asked. As
//!    in hardware whose crossbar grants the L2 by a fixed priority, the requests of one cycle
//!    reach the L2 in TM order.
//!
//! TMs are split into contiguous groups, one per host thread ([`Lane`]). A TM's local phase
//! touches only that TM, and its threads' order within a cycle depends only on that TM's
//! history, so each group runs its local phases on its own, as far ahead of the others as
//! it gets. Commit phases are taken in (cycle, group) order: a group that has something to
//! commit at cycle `c` waits until every lower group has passed `c` and every higher group
//! has reached it (`sync::Frontiers`, conservative parallel discrete-event simulation);
//! groups never meet otherwise. The L2 and the atomic unit therefore see the same requests
//! in the same order as on one host thread, and the result is bit-identical for any number
//! of host threads. The frame ends when the last result of the last thread has arrived.
//!
//! ```text
//!   engine::run ──▶ per group: a wheel of its threads' wake-ups, and its frontier (the
//!        │          cycle it works on) published to the others (sync::Frontiers)
//!        ▼ Lane::step(id, TM, now) -> Wake::{At, Forward, Done, Commit}   (in parallel)
//!        ▼ Lane::commit(id, TM, L2, atomic unit, now)          (in (cycle, TM) order)
//!   model::rv32 (thread processors executing the compiled kernels)
//!   model::fast (threads replaying recorded macro-ops)
//!        │
//!        ▼ requests at a cycle, answers with the cycle their result is ready
//!   hw::Chip: TMs (L1, pipelines, reciprocal unit, pools), L2, DRAM, atomic unit
//! ```
//!
//! Anchors: Arches-v2 (`src/arches-v2/simulator/simulator.cpp`) runs every cycle as two
//! phases over unit groups with latched ports, deterministic; Accel-Sim's OpenMP version
//! runs SMs in parallel with per-SM statistics; SimTRaX's `--simulation-threads` takes L2
//! requests under a mutex in host-thread order, so its results can depend on the
//! interleaving, which the fixed commit order here rules out.

pub(crate) mod sync;
pub(crate) mod wheel;

use crate::hw::atomic::AtomicUnit;
use crate::hw::memory::L2;
use crate::hw::tm::Tm;
use crate::hw::{Chip, Cycle, Stall, Stalls};
use std::ops::Range;
use std::sync::{Mutex, PoisonError};
use sync::Frontiers;
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
    /// In this cycle's commit phase ([`Lane::commit`]): its next request needs a unit
    /// outside its TM. Only [`Lane::step`] returns it, before making that request.
    Commit,
}

/// What the commit phase reaches besides a thread's TM: the chip's shared units and the
/// thread model's shared state.
pub struct Commit<'c, S> {
    /// The L2 (and the DRAM behind it).
    pub l2: &'c mut L2,
    /// The global atomic unit.
    pub atomic: &'c mut AtomicUnit,
    /// The thread model's shared state (the frame buffer, the work source).
    pub model: &'c mut S,
}

/// A group of threads, on the contiguous TMs [`Lane::tms`], as one host thread steps
/// them. Thread ids are the lane's own, `0..count`.
pub trait Lane: Send {
    /// What a step can fail with.
    type Error: Send;
    /// The thread model's state that only the commit phase touches.
    type Shared: Send;
    /// Whether [`Lane::touch`] is worth a pass over each cycle's threads.
    const TOUCH: bool = false;
    /// The number of threads.
    fn count(&self) -> usize;
    /// The chip's TMs this lane's threads run on.
    fn tms(&self) -> Range<usize>;
    /// The TM of thread `id`, counted from the lane's first.
    fn tm_of(&self, id: usize) -> usize;
    /// Reads (without effect) the host memory thread `id`'s next step will touch first, so
    /// that the host cache misses of a cycle's threads overlap; returns a value to keep the
    /// reads. Changes nothing simulated.
    #[inline]
    fn touch(&self, _id: usize, _tm: &Tm) -> u64 {
        0
    }
    /// Runs thread `id` while it can start at cycle `now` on its TM `tm` alone; returns
    /// [`Wake::Commit`] before a request that needs anything else.
    fn step(
        &mut self,
        id: usize,
        tm: &mut Tm,
        stalls: &mut Stalls,
        now: Cycle,
    ) -> Result<Wake, Self::Error>;
    /// Runs thread `id`, which asked for the commit phase at cycle `now`, with the chip's
    /// shared units; never returns [`Wake::Commit`].
    fn commit(
        &mut self,
        id: usize,
        tm: &mut Tm,
        stalls: &mut Stalls,
        shared: Commit<'_, Self::Shared>,
        now: Cycle,
    ) -> Result<Wake, Self::Error>;
    /// Called after each commit phase of a group, with the shared state (progress reports).
    #[inline]
    fn after_cycle(_shared: &mut Self::Shared) {}
}

/// The TMs of each of at most `threads` host threads: `tms` split into contiguous groups
/// of sizes differing by at most one, in order (at least one group).
pub fn groups(tms: usize, threads: usize) -> Vec<Range<usize>> {
    let n = threads.clamp(1, tms.max(1));
    (0..n).map(|k| k * tms / n..(k + 1) * tms / n).collect()
}

/// How to share `threads` host threads among `frames` frames: (frames run side by side,
/// host threads per frame). Side by side first (frames scale perfectly; one frame's
/// threads meet every cycle), so each frame gets more than one thread only when there are
/// fewer frames than threads.
pub fn share_threads(frames: usize, threads: usize) -> (usize, usize) {
    let threads = threads.max(1);
    let side = frames.clamp(1, threads);
    (side, threads / side)
}

/// The chip's shared units and the model's shared state, behind the lock that separates
/// the phases.
struct Common<'a, S> {
    l2: &'a mut L2,
    atomic: &'a mut AtomicUnit,
    model: &'a mut S,
}

/// What one lane leaves: its threads' finish cycles, its stall counts, and its first
/// error with the cycle and the chip TM it came from.
struct Left<E> {
    finish: Vec<Cycle>,
    stalls: Stalls,
    error: Option<(Cycle, usize, E)>,
}

/// Runs every thread of `lanes` to completion on `chip`, one host thread per lane (the
/// lanes' TMs must cover the chip's in order); returns the cycle the last result arrived,
/// and adds the threads' stall counts and the idle-at-end count to the chip's. When steps
/// fail, the error of the lowest TM in the first cycle with errors is returned.
pub fn run<L: Lane>(
    chip: &mut Chip,
    lanes: &mut [L],
    shared: &mut L::Shared,
) -> Result<Cycle, L::Error> {
    let (tms, l2, atomic, chip_stalls) = chip.parts();
    let mut rest = tms;
    let mut parts = Vec::with_capacity(lanes.len());
    let mut at = 0;
    for lane in lanes.iter() {
        let r = lane.tms();
        assert_eq!(r.start, at, "lanes must cover the TMs in order");
        let (mine, others) = std::mem::take(&mut rest).split_at_mut(r.len());
        parts.push(mine);
        rest = others;
        at = r.end;
    }
    assert!(rest.is_empty(), "lanes must cover every TM");
    let common = Mutex::new(Common {
        l2,
        atomic,
        model: shared,
    });
    let parties = lanes.len();
    let left: Vec<Left<L::Error>> = if parties == 1 {
        lanes
            .iter_mut()
            .zip(parts)
            .map(|(lane, tms)| drive(lane, tms, &common, None))
            .collect()
    } else {
        let frontiers = Frontiers::new(parties);
        let (frontiers, common) = (&frontiers, &common);
        std::thread::scope(|s| {
            let handles: Vec<_> = lanes
                .iter_mut()
                .zip(parts)
                .enumerate()
                .map(|(p, (lane, tms))| {
                    s.spawn(move || drive(lane, tms, common, Some((p, frontiers))))
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
                .collect()
        })
    };
    let end = left
        .iter()
        .flat_map(|l| l.finish.iter().copied())
        .max()
        .unwrap_or(Cycle::ZERO);
    let mut error: Option<(Cycle, usize, L::Error)> = None;
    for l in left {
        chip_stalls.add(&l.stalls);
        chip_stalls.count(Stall::Idle, l.finish.iter().map(|&f| end - f).sum::<u64>());
        if let Some((c, tm, e)) = l.error
            && error
                .as_ref()
                .is_none_or(|(c0, t0, _)| (c, tm) < (*c0, *t0))
        {
            error = Some((c, tm, e));
        }
    }
    match error {
        Some((_, _, e)) => Err(e),
        None => Ok(end),
    }
}

/// Publishes that its lane will never commit again when it ends, however it ends, and
/// poisons the frontiers if it panics, so that the other lanes stop waiting for it.
struct Leave<'f>(Option<(usize, &'f Frontiers)>);

impl Drop for Leave<'_> {
    fn drop(&mut self) {
        if let Some((p, f)) = self.0 {
            if std::thread::panicking() {
                f.poison();
            }
            f.publish(p, u64::MAX);
        }
    }
}

/// Keeps `e` (from chip TM `tm`, at cycle `now`) when it is the lane's first error or from
/// a lower TM in the same cycle.
fn note<E>(error: &mut Option<(Cycle, usize, E)>, now: Cycle, tm: usize, e: E) {
    if error.as_ref().is_none_or(|(c, t, _)| (now, tm) < (*c, *t)) {
        *error = Some((now, tm, e));
    }
}

/// Puts thread `id` back into `wheel` as `w` says.
#[inline(always)]
fn schedule(wheel: &mut Wheel, finish: &mut [Cycle], deferred: &mut Vec<u32>, id: u32, w: Wake) {
    match w {
        Wake::At(t) => wheel.push(t, id),
        Wake::Forward(t, hops) => wheel.push_forward(t, hops, id),
        Wake::Done(t) => finish[id as usize] = t,
        Wake::Commit => deferred.push(id),
    }
}

/// One lane's loop: its wheel, cycle after cycle with events, its local phase and, when
/// its threads asked for it, its turn of the commit phase; `sync` is its party number and
/// the lanes' frontiers when there is more than one lane. The lane publishes each cycle it
/// reaches as its frontier before working on it, and waits for its turn only to commit.
fn drive<L: Lane>(
    lane: &mut L,
    tms: &mut [Tm],
    common: &Mutex<Common<'_, L::Shared>>,
    sync: Option<(usize, &Frontiers)>,
) -> Left<L::Error> {
    let _leave = Leave(sync);
    if let Some((p, f)) = sync {
        f.join(p);
    }
    let n = lane.count();
    let tm0 = lane.tms().start;
    let mut wheel = Wheel::new(n);
    for i in 0..n as u32 {
        wheel.push(Cycle::ZERO, i);
    }
    let mut finish = vec![Cycle::ZERO; n];
    let mut stalls = Stalls::default();
    let mut error: Option<(Cycle, usize, L::Error)> = None;
    let mut deferred: Vec<u32> = Vec::new();
    while let Some((now, first)) = wheel.next_bucket() {
        if let Some((p, f)) = sync {
            // No lane goes on past the first cycle with a failed step.
            if now.get() > f.failed() {
                break;
            }
            f.publish(p, now.get());
        }
        if L::TOUCH {
            let mut touched = 0;
            let mut id = first;
            while id != NONE {
                if !wheel.is_forward(id) {
                    touched ^= lane.touch(id as usize, &tms[lane.tm_of(id as usize)]);
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
            let tm = lane.tm_of(id as usize);
            match lane.step(id as usize, &mut tms[tm], &mut stalls, now) {
                Ok(w) => schedule(&mut wheel, &mut finish, &mut deferred, id, w),
                Err(e) => note(&mut error, now, tm0 + tm, e),
            }
            id = next;
        }
        if !deferred.is_empty() {
            if let Some((p, f)) = sync {
                f.wait_turn(p, now.get());
                if now.get() > f.failed() {
                    break;
                }
            }
            let mut guard = common.lock().unwrap_or_else(PoisonError::into_inner);
            let g = &mut *guard;
            // By TM, then in the order the TM's threads asked (a stable sort).
            deferred.sort_by_key(|&id| lane.tm_of(id as usize));
            for &id in &deferred {
                let tm = lane.tm_of(id as usize);
                let shared = Commit {
                    l2: &mut *g.l2,
                    atomic: &mut *g.atomic,
                    model: &mut *g.model,
                };
                match lane.commit(id as usize, &mut tms[tm], &mut stalls, shared, now) {
                    Ok(Wake::Commit) => unreachable!("a commit step asked for the commit phase"),
                    Ok(w) => schedule(&mut wheel, &mut finish, &mut Vec::new(), id, w),
                    Err(e) => note(&mut error, now, tm0 + tm, e),
                }
            }
            deferred.clear();
            L::after_cycle(g.model);
        }
        if error.is_some() {
            if let Some((_, f)) = sync {
                f.fail(now.get());
            }
            break;
        }
    }
    Left {
        finish,
        stalls,
        error,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;

    /// A toy thread model: each thread steps once a cycle until cycle 200, asks for the
    /// commit phase every third cycle, and the threads of `fails` fail at their cycle (in
    /// the local phase for even TMs, in the commit phase for odd ones), naming their TM.
    struct Toy {
        tms: Range<usize>,
        per_tm: usize,
        fails: Vec<(usize, u64)>,
    }

    impl Toy {
        fn fails_now(&self, id: usize, now: Cycle, commit: bool) -> Option<usize> {
            let tm = self.tms.start + id / self.per_tm;
            let at = self.fails.iter().find(|&&(t, _)| t == tm)?.1;
            (at == now.get() && (tm % 2 == 1) == commit).then_some(tm)
        }
    }

    impl Lane for Toy {
        type Error = (u64, usize);
        type Shared = Vec<(u64, usize)>;

        fn count(&self) -> usize {
            self.tms.len() * self.per_tm
        }

        fn tms(&self) -> Range<usize> {
            self.tms.clone()
        }

        fn tm_of(&self, id: usize) -> usize {
            id / self.per_tm
        }

        fn step(
            &mut self,
            id: usize,
            _: &mut Tm,
            _: &mut Stalls,
            now: Cycle,
        ) -> Result<Wake, (u64, usize)> {
            if let Some(tm) = self.fails_now(id, now, false) {
                return Err((now.get(), tm));
            }
            Ok(match now.get() {
                200.. => Wake::Done(now),
                c if c % 3 == 0 => Wake::Commit,
                _ => Wake::At(now + 1),
            })
        }

        fn commit(
            &mut self,
            id: usize,
            _: &mut Tm,
            _: &mut Stalls,
            shared: Commit<'_, Self::Shared>,
            now: Cycle,
        ) -> Result<Wake, (u64, usize)> {
            let tm = self.tms.start + id / self.per_tm;
            shared.model.push((now.get(), tm));
            if let Some(tm) = self.fails_now(id, now, true) {
                return Err((now.get(), tm));
            }
            Ok(Wake::At(now + 1))
        }
    }

    /// A toy run's result, and the (cycle, TM) of each commit in the order the shared state
    /// saw them.
    type ToyRun = (Result<Cycle, (u64, usize)>, Vec<(u64, usize)>);

    /// Runs the toy on `lanes` host threads.
    fn toy(lanes: usize, fails: &[(usize, u64)]) -> ToyRun {
        let mut cfg = SimConfig::lin2020();
        cfg.tms = 8;
        let mut chip = Chip::new(&cfg, 1);
        let mut toys: Vec<Toy> = groups(8, lanes)
            .into_iter()
            .map(|tms| Toy {
                tms,
                per_tm: 3,
                fails: fails.to_vec(),
            })
            .collect();
        let mut seen = Vec::new();
        let r = run(&mut chip, &mut toys, &mut seen);
        (r, seen)
    }

    /// Commits reach the shared state in (cycle, TM) order, and a run ends with the same
    /// result, on any number of host threads.
    #[test]
    fn commits_are_ordered_and_results_equal_on_any_thread_count() {
        let (one, seen) = toy(1, &[]);
        assert_eq!(one, Ok(Cycle(200)));
        let mut sorted = seen.clone();
        sorted.sort();
        assert_eq!(seen, sorted);
        for lanes in [2, 3, 8] {
            assert_eq!(toy(lanes, &[]), (one, seen.clone()), "{lanes} lanes");
        }
    }

    /// The error of the lowest TM in the first cycle with errors is returned, whichever
    /// lane it is in and whichever phase it comes from, on any number of host threads.
    #[test]
    fn the_first_cycles_lowest_tm_error_wins_on_any_thread_count() {
        for (fails, want) in [
            (vec![(6, 40), (2, 40), (7, 90)], (40, 2)),
            (vec![(1, 61), (6, 60), (4, 60)], (60, 4)),
            (vec![(7, 30), (5, 33), (0, 120)], (30, 7)),
            (vec![(3, 150), (5, 150)], (150, 3)),
        ] {
            for lanes in [1, 2, 3, 8] {
                let (r, _) = toy(lanes, &fails);
                assert_eq!(r, Err(want), "{fails:?} on {lanes} lanes");
            }
        }
    }
}
