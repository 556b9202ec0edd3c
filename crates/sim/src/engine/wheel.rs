//! The scheduler: a timing wheel of thread wake-up cycles.
//!
//! It orders the simulation, it is no hardware unit: every thread sleeps until the cycle
//! at which its next op can start, and the wheel hands out the threads of one cycle after
//! another, in the order they were scheduled within a cycle, so runs are deterministic. One
//! bucket per cycle for the next `WHEEL` cycles, an overflow heap beyond.
//!
//! A thread whose coming wake-ups would only move it to a later cycle (waiting for operands,
//! or a run of plain instructions that reserves nothing) is scheduled as a *forward entry*
//! ([`Wheel::push_forward`]): at each such cycle the wheel moves it on in the same place in
//! the bucket, without running it, exactly where the woken thread would have put itself.

use crate::hw::Cycle;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// A timing wheel of thread wake-ups: one bucket per cycle for the next
/// `WHEEL` cycles, an overflow heap beyond. Within a cycle, threads run in the order they
/// were scheduled (deterministic).
///
/// A bucket is an intrusive FIFO list through each thread's [`Link`] (a thread is in the
/// wheel at most once), so scheduling a wake-up writes two small arrays that stay in the
/// host's cache (56 KB for 2048 threads) instead of one of 4096 separately allocated
/// vectors.
pub(crate) struct Wheel {
    /// Per bucket: (first, last) thread of its list, `NONE` when empty.
    ends: Vec<(u32, u32)>,
    /// Per thread: its link and forward hops (12 bytes, one host cache line access for
    /// both).
    links: Vec<Link>,
    now: Cycle,
    in_wheel: usize,
    overflow: BinaryHeap<Reverse<(Cycle, u32)>>,
}

/// A thread's place in the wheel.
#[derive(Clone, Copy, Debug)]
struct Link {
    /// The thread after it in its bucket, `NONE` at the end.
    next: u32,
    /// Where its entry forwards it, as delays hop after hop (see [`Wheel::push_forward`]),
    /// `[0, ..]` for a wake-up.
    hops: [u32; HOPS],
}

const WHEEL: u64 = 4096;
pub(crate) const NONE: u32 = u32::MAX;
/// Most wake-ups one forward entry skips (`Thread::skip_ahead`): a wait for operands,
/// then an instruction run. Nothing skippable follows such a run: it needed its operands
/// and produces none, and consecutive runs are merged into one `Issue` by the recorder.
pub const HOPS: usize = 2;

impl Wheel {
    pub(crate) fn new(threads: usize) -> Self {
        Self {
            ends: vec![(NONE, NONE); WHEEL as usize],
            links: vec![
                Link {
                    next: NONE,
                    hops: [0; HOPS]
                };
                threads
            ],
            now: Cycle::ZERO,
            in_wheel: 0,
            overflow: BinaryHeap::new(),
        }
    }

    #[inline(always)]
    pub(crate) fn push(&mut self, t: Cycle, id: u32) {
        debug_assert!(t >= self.now);
        if t - self.now < WHEEL {
            self.append((t.get() % WHEEL) as usize, id);
        } else {
            self.push_overflow(t, id);
        }
    }

    /// A wake-up beyond the wheel, into the overflow heap (rare).
    #[inline(never)]
    fn push_overflow(&mut self, t: Cycle, id: u32) {
        self.overflow.push(Reverse((t, id)));
    }

    /// A forward entry: thread `id` has nothing to do at `t` but move on `hops[0]` cycles
    /// later, then (if not 0) `hops[1]` cycles later, and so on. When a
    /// bucket holding a forward entry is handed out, its holder calls
    /// [`Wheel::take_forward`] and pushes the thread to the next hop at its place in the
    /// bucket, exactly where the thread would have pushed itself had it been woken and run;
    /// it is neither touched nor run. Plain [`Wheel::push`] when `hops[0]` is 0.
    pub(crate) fn push_forward(&mut self, t: Cycle, hops: [u32; HOPS], id: u32) {
        self.links[id as usize].hops = hops;
        self.push(t, id);
    }

    /// True when thread `id`'s entry just handed out is a forward.
    #[inline]
    pub(crate) fn is_forward(&self, id: u32) -> bool {
        self.links[id as usize].hops[0] != 0
    }

    /// The next hop of thread `id`'s forward entry just handed out (the entry is then one
    /// hop shorter), or `None` when the entry is a wake-up.
    #[inline]
    pub(crate) fn take_forward(&mut self, id: u32) -> Option<Cycle> {
        let h = &mut self.links[id as usize].hops;
        let d = h[0];
        if d == 0 {
            // A wake-up: no hops (they are filled from the first), nothing to write.
            return None;
        }
        h.copy_within(1.., 0);
        h[HOPS - 1] = 0;
        Some(self.now + d as u64)
    }

    /// Appends thread `id` to bucket `b`'s list.
    #[inline]
    fn append(&mut self, b: usize, id: u32) {
        self.links[id as usize].next = NONE;
        let (first, last) = &mut self.ends[b];
        if *first == NONE {
            *first = id;
        } else {
            self.links[*last as usize].next = id;
        }
        *last = id;
        self.in_wheel += 1;
    }

    /// Detaches the list of the next cycle with events and returns that cycle and the
    /// list's first thread; the list is walked in place with [`Wheel::after`] (in the order
    /// the threads were scheduled), and [`Wheel::taken`] is called once for each of its
    /// threads before the next call. Walking the links instead of copying them into a
    /// vector saves a store, a capacity test and a reload per entry.
    pub(crate) fn next_bucket(&mut self) -> Option<(Cycle, u32)> {
        if self.in_wheel == 0 {
            let &Reverse((t, _)) = self.overflow.peek()?;
            self.now = t;
        }
        loop {
            while let Some(&Reverse((t, id))) = self.overflow.peek() {
                if t - self.now < WHEEL {
                    self.overflow.pop();
                    self.append((t.get() % WHEEL) as usize, id);
                } else {
                    break;
                }
            }
            let b = (self.now.get() % WHEEL) as usize;
            let (first, _) = self.ends[b];
            if first != NONE {
                self.ends[b] = (NONE, NONE);
                return Some((self.now, first));
            }
            self.now += 1;
        }
    }

    /// The thread after `id` in a detached list (`NONE` at its end). Valid until `id` is
    /// pushed again, so it is read before `id` is run. A push never lands in the detached
    /// list: it is for a later cycle, and a thread is in the wheel at most once.
    #[inline]
    pub(crate) fn after(&self, id: u32) -> u32 {
        self.links[id as usize].next
    }

    /// One thread of the detached list has been handed out.
    #[inline]
    pub(crate) fn taken(&mut self) {
        self.in_wheel -= 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Wheel {
        /// The next cycle's threads in order, as `run_chip` walks them.
        fn take_bucket(&mut self, ids: &mut Vec<u32>) -> Option<Cycle> {
            let (now, mut id) = self.next_bucket()?;
            while id != NONE {
                ids.push(id);
                id = self.after(id);
                self.taken();
            }
            Some(now)
        }
    }

    /// The plain wheel: one vector per bucket (the reference).
    struct VecWheel {
        buckets: Vec<Vec<u32>>,
        now: Cycle,
        in_wheel: usize,
        overflow: BinaryHeap<Reverse<(Cycle, u32)>>,
    }

    impl VecWheel {
        fn new() -> Self {
            Self {
                buckets: vec![Vec::new(); WHEEL as usize],
                now: Cycle::ZERO,
                in_wheel: 0,
                overflow: BinaryHeap::new(),
            }
        }

        fn push(&mut self, t: Cycle, id: u32) {
            if t - self.now < WHEEL {
                self.buckets[(t.get() % WHEEL) as usize].push(id);
                self.in_wheel += 1;
            } else {
                self.overflow.push(Reverse((t, id)));
            }
        }

        fn next_bucket(&mut self) -> Option<(Cycle, Vec<u32>)> {
            if self.in_wheel == 0 {
                let &Reverse((t, _)) = self.overflow.peek()?;
                self.now = t;
            }
            loop {
                while let Some(&Reverse((t, id))) = self.overflow.peek() {
                    if t - self.now < WHEEL {
                        self.overflow.pop();
                        self.buckets[(t.get() % WHEEL) as usize].push(id);
                        self.in_wheel += 1;
                    } else {
                        break;
                    }
                }
                let b = (self.now.get() % WHEEL) as usize;
                if !self.buckets[b].is_empty() {
                    let ids = std::mem::take(&mut self.buckets[b]);
                    self.in_wheel -= ids.len();
                    return Some((self.now, ids));
                }
                self.now += 1;
            }
        }
    }

    /// The list wheel hands out the same threads in the same order as the vector wheel:
    /// random wake-up delays, some beyond the wheel (overflow), so a cycle's bucket mixes
    /// direct and migrated entries.
    #[test]
    fn wheel_lists_keep_the_order_of_bucket_vectors() {
        for seed in 0..10 {
            let mut rng = dualsplit_geometry::Pcg32::new(seed, 7);
            let n = 300;
            let mut w = Wheel::new(n);
            let mut v = VecWheel::new();
            for id in 0..n as u32 {
                w.push(Cycle::ZERO, id);
                v.push(Cycle::ZERO, id);
            }
            let mut ids = Vec::new();
            let mut steps = 0;
            while let Some(now) = w.take_bucket(&mut ids) {
                let (vnow, vids) = v.next_bucket().expect("vector wheel ran dry first");
                assert_eq!((now, &ids), (vnow, &vids), "seed {seed}, step {steps}");
                steps += 1;
                if steps < 20_000 {
                    for &id in &ids {
                        let d = match rng.below(10) {
                            0 => WHEEL + rng.below(3 * WHEEL as u32) as u64,
                            1 => WHEEL - 1 - rng.below(4) as u64,
                            _ => 1 + rng.below(40) as u64,
                        };
                        w.push(now + d, id);
                        v.push(now + d, id);
                    }
                }
                ids.clear();
            }
            assert!(v.next_bucket().is_none(), "seed {seed}");
            assert!(steps > 20_000, "seed {seed}: {steps}");
        }
    }

    /// Forward entries hand out every wake-up in the same order as a wheel without them,
    /// where a thread with nothing to do is woken at each hop and pushes itself on: random
    /// delays (some beyond the wheel) and random chains of 0–2 hops, so buckets mix real
    /// wake-ups, forwards and their targets.
    #[test]
    fn forward_entries_keep_the_order_of_plain_wake_ups() {
        for seed in 0..10 {
            let mut rng = dualsplit_geometry::Pcg32::new(seed, 11);
            let n = 300;
            let mut w = Wheel::new(n);
            let mut v = VecWheel::new();
            // The reference's pending hops per thread (it wakes the thread at each).
            let mut plan: Vec<Vec<Cycle>> = vec![Vec::new(); n];
            for id in 0..n as u32 {
                w.push(Cycle::ZERO, id);
                v.push(Cycle::ZERO, id);
            }
            let delay = |rng: &mut dualsplit_geometry::Pcg32| match rng.below(10) {
                0 => WHEEL + rng.below(3 * WHEEL as u32) as u64,
                1 => WHEEL - 1 - rng.below(4) as u64,
                _ => 1 + rng.below(40) as u64,
            };
            let (mut ids, mut steps, mut real, mut forwards) = (Vec::new(), 0, 0, 0);
            while let Some(now) = w.take_bucket(&mut ids) {
                let (vnow, vids) = v.next_bucket().expect("reference wheel ran dry first");
                assert_eq!((now, &ids), (vnow, &vids), "seed {seed}, step {steps}");
                steps += 1;
                for &id in &ids {
                    let to = w.take_forward(id);
                    let p = &mut plan[id as usize];
                    assert_eq!(to, (!p.is_empty()).then(|| p[0]), "seed {seed}, {id}");
                    if let Some(to) = to {
                        p.remove(0);
                        w.push(to, id);
                        v.push(to, id);
                        forwards += 1;
                        continue;
                    }
                    real += 1;
                    if real < 20_000 {
                        let t = now + delay(&mut rng);
                        let mut hops = [0; HOPS];
                        let mut at = t;
                        for h in hops.iter_mut().take(rng.below(HOPS as u32 + 1) as usize) {
                            *h = delay(&mut rng) as u32;
                            at += *h as u64;
                            p.push(at);
                        }
                        w.push_forward(t, hops, id);
                        v.push(t, id);
                    }
                }
                ids.clear();
            }
            assert!(v.next_bucket().is_none(), "seed {seed}");
            assert!(
                real > 20_000 && forwards > 10_000,
                "seed {seed}: {real} {forwards}"
            );
        }
    }
}
