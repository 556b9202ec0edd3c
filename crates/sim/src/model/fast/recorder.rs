//! The `fast` thread model's kernel costs: what each traversal event costs in the compiled
//! kernels, measured by `model/fast/calibrate.rs`, and the recording observer that turns a traversal's
//! events into macro-operations.
//!
//! The traversal code is the real one (`dualsplit_accel::Structures`); this module only
//! translates what it reports: every `fetch` becomes word loads at the image's byte
//! addresses, every node step a pipeline op (where the configuration has one) plus the
//! instructions around it, every triangle test a ray-triangle pipeline op. The instructions
//! around them are not counted by hand: each [`Event`] carries the instructions per
//! functional-unit class and the dependency stall cycles that the configuration's compiled
//! kernel spends on it, fitted to the kernels' own execution ([`crate::model::fast::calibrate`]).

use crate::accel::{NodeUnit, SimAccel};
use crate::hw::pipe::Pipe;
use crate::model::fast::costs::FRAC_BITS;
use crate::model::fast::event::{Event, bvh_pairs};
use crate::model::fast::op::{Op, OpRangeError};
use crate::model::fast::tally::Tally;
use dualsplit_accel::{ByteAddr, NodeStep, Observer, TraversalSet};
use dualsplit_geometry::PrimId;
use dualsplit_render::{RayKind, TraceResult};

/// The observer the simulator passes to the traversal: appends macro-ops to a thread's
/// program and counts events into a [`Tally`].
///
/// Consecutive events' instructions merge into one [`Op::Issue`] run, kept in the recorder
/// and written out when a load or pipeline op follows or the recording ends
/// ([`Recorder::finish`], [`Recorder::finish_open`]). Costs are fractional (measured
/// averages): the run sums them in units of 2^-[`FRAC_BITS`]
/// and writes whole cycles, carrying the fraction into the next run, so a thread's issue
/// cycles are its events' summed costs to within one cycle.
pub struct Recorder<'a> {
    ops: &'a mut Vec<Op>,
    tally: &'a mut Tally,
    /// Whether a run is open (the last op recorded is the unwritten run).
    open: bool,
    /// The run's issue cycles and reciprocal ops, fixed point (with the carried fraction).
    run: Run,
    /// DST or DST-Q on a dual-split pipeline (not decoded in software).
    dst_hw: bool,
    /// CWBVH: one wide quantized box op of all 8 slots per node (`rt.qboxn`).
    quantized_boxes: bool,
    /// The "+" configurations: all child boxes in one issue slot.
    parallel_boxes: bool,
    /// The last fetch (physical word address, words): the measured extra L1 words are
    /// re-reads of it.
    last: (u32, u16),
    /// Boxes fetched since the last other fetch (a BVH node's header).
    boxes: u8,
}

/// An instruction run being merged, fixed point (see [`Recorder`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Run {
    /// Issue cycles (instructions and dependency stalls), in 2^-FRAC_BITS units.
    pub cycles: u64,
    /// Of which reciprocal / inverse-square-root ops, in the same units.
    pub fpinv: u64,
    /// L1 words to re-read (the events' measured extra words not yet written as loads),
    /// same units.
    pub words: u64,
}

impl Run {
    /// The run's whole cycles as an op (the fraction is dropped); `None` when it is under one
    /// cycle.
    pub fn op(self) -> Option<Op> {
        let (n, fpinv) = self.whole();
        (n > 0).then_some(Op::Issue {
            n: n.min(u32::MAX as u64) as u32,
            fpinv: fpinv.min(u16::MAX as u64) as u16,
        })
    }

    /// Whole cycles and reciprocal ops (at most the cycles).
    fn whole(self) -> (u64, u64) {
        let n = self.cycles >> FRAC_BITS;
        (n, (self.fpinv >> FRAC_BITS).min(n))
    }
}

impl<'a> Recorder<'a> {
    /// Records into `ops`, counting into `tally`.
    pub fn new(tally: &'a mut Tally, ops: &'a mut Vec<Op>) -> Self {
        Self::resume(tally, ops, None)
    }

    /// Records into `ops`, counting into `tally`, continuing the open run `run` (the trailing
    /// run of the previous recording, see [`Recorder::finish_open`]).
    #[inline]
    pub fn resume(tally: &'a mut Tally, ops: &'a mut Vec<Op>, run: Option<Run>) -> Self {
        let (accel, last) = (tally.accel, tally.params);
        Self {
            ops,
            tally,
            open: run.is_some(),
            run: run.unwrap_or_default(),
            dst_hw: accel.node_unit().is_dual_split_pipe(),
            quantized_boxes: accel.node_unit() == NodeUnit::QuantizedBoxPipe,
            parallel_boxes: accel.parallel_boxes(),
            last,
            boxes: 0,
        }
    }

    /// The tally counted into.
    pub fn tally(&self) -> &Tally {
        self.tally
    }

    /// Ends the recording with the open run written to the ops.
    pub fn finish(mut self) {
        self.close_run();
        self.reread();
    }

    /// Ends the recording leaving the open run out of the ops: it is returned, to be
    /// continued by the next recording ([`Recorder::resume`]) or written as the program's
    /// last op ([`Run::op`]); `None` when nothing is left, not even a fraction of a cycle.
    #[inline]
    pub fn finish_open(mut self) -> Option<Run> {
        // A closed run may still carry a fraction of a cycle.
        self.reread();
        if !self.open && self.run == Run::default() {
            return None;
        }
        self.check(self.run);
        Some(self.run)
    }

    /// Charges a workload event (a pixel, or a ray's set-up and finish by its outcome).
    #[inline]
    pub fn event(&mut self, e: Event) {
        self.charge(e.index(), 1);
    }

    /// Counts `k` events of index `e` and adds their costs to the open run.
    #[inline(always)]
    fn charge(&mut self, e: usize, k: u64) {
        let t = &mut *self.tally;
        t.events[e] += k;
        self.run.cycles += k * t.cycles[e];
        self.run.fpinv += k * t.fpinv[e];
        self.run.words += k * t.words[e];
        self.open = true;
    }

    /// Keeps an [`OpRangeError`] when `run`'s whole cycles or reciprocals do not fit an op.
    fn check(&mut self, run: Run) {
        let n = run.cycles >> FRAC_BITS;
        let fpinv = run.fpinv >> FRAC_BITS;
        if n > u32::MAX as u64 {
            self.tally.fail(OpRangeError::Issue { n });
        } else if fpinv > u16::MAX as u64 {
            self.tally.fail(OpRangeError::Fpinv { fpinv });
        }
    }

    /// Writes the open run's whole cycles (if any) as an `Issue` op; its fraction stays for
    /// the next run.
    #[inline(always)]
    fn close_run(&mut self) {
        if !self.open {
            return;
        }
        self.open = false;
        self.check(self.run);
        if let Some(op) = self.run.op() {
            self.ops.push(op);
        }
        let mask = (1 << FRAC_BITS) - 1;
        self.run.cycles &= mask;
        self.run.fpinv &= mask;
    }

    /// Writes the whole extra L1 words due so far as re-reads of the last fetch (its
    /// fraction stays).
    #[inline(always)]
    fn reread(&mut self) {
        let mut n = self.run.words >> FRAC_BITS;
        if n == 0 {
            return;
        }
        self.run.words &= (1 << FRAC_BITS) - 1;
        self.tally.counts.loads += n;
        let (word, len) = self.last;
        while n > 0 {
            let words = n.min(len as u64) as u16;
            self.ops.push(Op::Load { words, word });
            n -= words as u64;
        }
    }

    /// Appends a load or pipeline op after the open run and the extra words due.
    #[inline(always)]
    fn push_op(&mut self, op: Op) {
        self.close_run();
        self.reread();
        self.ops.push(op);
    }
    /// Appends the load of the words holding `bytes` bytes at image address `addr`.
    #[inline(always)]
    fn load(&mut self, ByteAddr(addr): ByteAddr, bytes: u32) {
        let addr = addr + self.tally.image_base;
        // Words from the one holding byte `addr` to the one holding byte `addr + bytes − 1`.
        let words = ((addr & 3) + bytes as u64).div_ceil(4);
        if words == 0 {
            return;
        }
        self.tally.counts.loads += words;
        match Op::load(addr & !3, words) {
            Ok(op) => {
                self.push_op(op);
                if let Op::Load { word, words } = op {
                    self.last = (word, words);
                }
            }
            Err(e) => self.tally.fail(e),
        }
    }

    /// Widens the last op, a load, to cover the words holding `bytes` bytes at image address
    /// `addr` too; false (nothing changed) when the union does not fit one load op.
    #[inline(always)]
    fn join(&mut self, ByteAddr(addr): ByteAddr, bytes: u32) -> bool {
        let addr = addr + self.tally.image_base;
        let (word, end) = (addr / 4, (addr + bytes as u64).div_ceil(4));
        let Some(Op::Load {
            word: w0,
            words: n0,
        }) = self.ops.last_mut()
        else {
            return false;
        };
        let start = word.min(*w0 as u64);
        let stop = end.max(*w0 as u64 + *n0 as u64);
        let (Ok(start), Ok(n)) = (u32::try_from(start), u16::try_from(stop - start)) else {
            return false;
        };
        self.tally.counts.loads += n as u64 - *n0 as u64;
        (*w0, *n0) = (start, n);
        self.last = (start, n);
        true
    }
}

impl Observer for Recorder<'_> {
    #[inline(always)]
    fn fetch(&mut self, addr: ByteAddr, bytes: u32) {
        self.boxes = 0;
        self.load(addr, bytes);
    }

    /// The kernels read a BVH node's header and use it (the child slots' kinds and the
    /// children's offset) before they read a box: the first box waits for the header's
    /// words. A serial kernel then tests each box as it has read it, one after another; the
    /// "+" kernels' wide-box instruction reads the node's boxes together, so a box joins the
    /// previous box's load.
    #[inline(always)]
    fn fetch_box(&mut self, addr: ByteAddr, bytes: u32) {
        let loaded_last = !self.open
            && matches!(self.ops.last(), Some(&Op::Load { word, words }) if (word, words) == self.last);
        let first = self.boxes == 0;
        self.boxes = self.boxes.saturating_add(1);
        if first && loaded_last {
            // Waits for the header's words, issues nothing.
            self.ops.push(Op::Issue { n: 0, fpinv: 0 });
        } else if self.parallel_boxes && loaded_last && self.join(addr, bytes) {
            return;
        }
        self.load(addr, bytes);
        if !self.parallel_boxes {
            self.push_op(Op::Pipe {
                pipe: Pipe::Box,
                n: 1,
                parallel: false,
            });
        }
    }

    #[inline(always)]
    fn step(&mut self, step: NodeStep) {
        match step {
            NodeStep::Bvh { valid, hits, .. } => {
                // Serial box tests were recorded with their boxes' fetches; a compressed
                // node's 8 slots are tested by one instruction, on one pipe or eight.
                if self.quantized_boxes {
                    self.push_op(Op::Pipe {
                        pipe: Pipe::Box,
                        n: 8,
                        parallel: self.parallel_boxes,
                    });
                    self.tally.boxed_nodes += 1;
                } else if valid != 0 && self.parallel_boxes {
                    self.push_op(Op::Pipe {
                        pipe: Pipe::Box,
                        n: valid,
                        parallel: true,
                    });
                    self.tally.boxed_nodes += 1;
                }
                let (valid, hits) = (valid as u64, hits as u64);
                self.charge(Event::BvhNode.index(), 1);
                self.charge(Event::BvhChild.index(), valid);
                self.charge(Event::BvhHit.index(), hits);
                self.charge(Event::BvhSortPair.index(), bvh_pairs(hits));
            }
            NodeStep::Dst { kind, outcome, .. } => {
                if self.dst_hw {
                    self.push_op(Op::Pipe {
                        pipe: Pipe::DualSplit,
                        n: 1,
                        parallel: false,
                    });
                }
                self.charge(Event::Dst(kind, outcome).index(), 1);
            }
            NodeStep::Leaf { .. } => self.charge(Event::Leaf.index(), 1),
        }
    }

    #[inline(always)]
    fn triangle_test(&mut self, _prim: PrimId, hit: bool) {
        self.push_op(Op::Pipe {
            pipe: Pipe::Triangle,
            n: 1,
            parallel: false,
        });
        self.charge(Event::TriTest.index(), 1);
        if hit {
            self.charge(Event::TriAccept.index(), 1);
        }
    }

    #[inline(always)]
    fn push(&mut self) {
        self.charge(Event::Push.index(), 1);
    }

    #[inline(always)]
    fn pop(&mut self) {
        self.charge(Event::Pop.index(), 1);
    }
}

/// Traces one ray of a pixel with `rec` as the observer, then charges the ray's event by
/// its outcome.
pub(crate) fn trace_ray<S: TraversalSet>(
    structures: &S,
    accel: SimAccel,
    kind: RayKind,
    ray: &dualsplit_geometry::Ray,
    rec: &mut Recorder<'_>,
) -> TraceResult {
    let k = accel.kind();
    match kind {
        RayKind::Shadow => {
            let blocked = structures.any_hit(k, ray, rec);
            rec.event(if blocked {
                Event::ShadowBlocked
            } else {
                Event::ShadowLit
            });
            TraceResult::Occluded(blocked)
        }
        RayKind::Primary | RayKind::Diffuse => {
            let hit = structures.closest_hit(k, ray, rec);
            rec.event(if hit.is_some() {
                Event::ClosestHit
            } else {
                Event::ClosestMiss
            });
            TraceResult::Closest(hit)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hw::counts::{InstrCounts, Mix};
    use crate::model::fast::costs::{Costs, L1_WORDS, TARGETS};
    use crate::model::fast::event::{DST_KINDS, EVENTS};
    use dualsplit_accel::{DstNodeKind, StepOutcome};
    use dualsplit_geometry::Pcg32;

    /// Costs with random fractional instruction counts per event (leaked: tallies take
    /// `'static` costs).
    fn random_costs(seed: u64) -> &'static Costs {
        Box::leak(Box::new(Costs::from_fixed(random_fixed(seed))))
    }

    fn random_fixed(seed: u64) -> [[u32; TARGETS]; EVENTS] {
        let mut rng = Pcg32::new(seed, 9);
        let mut per_event = [[0u32; TARGETS]; EVENTS];
        for row in &mut per_event {
            for x in row.iter_mut() {
                *x = rng.below(12 << FRAC_BITS);
            }
        }
        per_event
    }

    /// A random stream of events of `seed` recorded for `accel` with `costs`, cut into
    /// recordings at random points (as a pixel's rays are), each continuing the previous
    /// one's open run: the ops, the tally and the last open run.
    fn random_stream(
        seed: u64,
        accel: SimAccel,
        costs: &'static Costs,
    ) -> (Vec<Op>, Tally, Option<Run>) {
        let (mut ops, mut run) = (Vec::new(), None);
        let mut tally = Tally::new(accel, costs);
        let (mut rng, mut cuts) = (Pcg32::new(seed, 1), Pcg32::new(seed, 2));
        let mut left = 1 + Pcg32::new(seed, 7).below(300);
        while left > 0 {
            let n = (1 + cuts.below(40)).min(left);
            left -= n;
            let mut r = Recorder::resume(&mut tally, &mut ops, run);
            for _ in 0..n {
                random_event(&mut rng, &mut r);
            }
            run = r.finish_open();
        }
        (ops, tally, run)
    }

    /// One random traversal or workload event.
    fn random_event(rng: &mut Pcg32, r: &mut Recorder) {
        match rng.below(9) {
            0 => r.fetch(ByteAddr(rng.below(1 << 20) as u64), rng.below(220)),
            8 => r.fetch_box(ByteAddr(4 * rng.below(1 << 18) as u64), 24),
            1 => {
                let arity = [2u8, 4, 8][rng.below(3) as usize];
                let valid = rng.below(arity as u32 + 1) as u8;
                let hits = rng.below(valid as u32 + 1) as u8;
                r.step(NodeStep::Bvh { arity, valid, hits });
            }
            2 => r.step(NodeStep::Dst {
                kind: DST_KINDS[rng.below(4) as usize],
                outcome: StepOutcome::ALL[rng.below(4) as usize],
                carving_leaf: rng.below(2) == 1,
            }),
            3 => r.step(NodeStep::Leaf {
                count: rng.below(8),
            }),
            4 => r.triangle_test(PrimId(rng.below(1000)), rng.below(2) == 1),
            5 => r.push(),
            6 => r.pop(),
            _ => r.event(Event::all()[rng.below(5) as usize]),
        }
    }

    #[test]
    fn event_indices_and_names_are_distinct() {
        let all = Event::all();
        let names: std::collections::BTreeSet<String> = all.iter().map(|e| e.name()).collect();
        assert_eq!(names.len(), EVENTS);
        for (i, e) in all.into_iter().enumerate() {
            assert_eq!(e.index(), i, "{e:?}");
        }
    }

    #[test]
    fn issue_cycles_are_the_summed_costs_to_within_a_cycle() {
        for seed in 0..40u64 {
            for accel in SimAccel::ALL {
                let costs = random_costs(seed);
                let (mut ops, tally, run) = random_stream(seed, accel, costs);
                ops.extend(run.and_then(Run::op));
                assert_eq!(tally.error(), None);
                let fixed: u64 = (0..EVENTS)
                    .map(|e| tally.events()[e] * costs.cycles(e))
                    .sum();
                let issued: u64 = ops
                    .iter()
                    .map(|op| match op {
                        Op::Issue { n, .. } => *n as u64,
                        _ => 0,
                    })
                    .sum();
                assert_eq!(issued, fixed >> FRAC_BITS, "seed {seed}, {accel:?}");
                // The frame's instruction classes are the rounded products.
                let c = tally.counts();
                let mix = costs.totals(tally.events());
                assert_eq!(c.mix.int, mix[0]);
                assert_eq!(c.mix.local, mix[5]);
                assert_eq!(
                    c.tri_ops,
                    ops.iter()
                        .filter(|o| matches!(
                            o,
                            Op::Pipe {
                                pipe: Pipe::Triangle,
                                ..
                            }
                        ))
                        .count() as u64
                );
            }
        }
    }

    /// The measured extra L1 words are re-read as loads: the words loaded beyond the
    /// fetches are the events' summed extra words (whole words; the fraction is carried
    /// from ray to ray), and each re-read lies within the last fetch.
    #[test]
    fn extra_l1_words_are_rereads_of_the_last_fetch() {
        for seed in 0..40u64 {
            let accel = SimAccel::ALL[seed as usize % SimAccel::ALL.len()];
            let costs = random_costs(seed);
            let mut fixed = random_fixed(seed);
            for row in &mut fixed {
                row[L1_WORDS] = 0;
            }
            let no_extra: &'static Costs = Box::leak(Box::new(Costs::from_fixed(fixed)));
            let record = |costs: &'static Costs| {
                let (ops, tally, _) = random_stream(seed, accel, costs);
                let loaded: u64 = ops
                    .iter()
                    .map(|op| match op {
                        Op::Load { words, .. } => *words as u64,
                        _ => 0,
                    })
                    .sum();
                assert_eq!(loaded, tally.counts().loads, "seed {seed}");
                (ops, tally)
            };
            let (ops, tally) = record(costs);
            let (plain, _) = record(no_extra);
            let extra: u64 = (0..EVENTS)
                .map(|e| tally.events()[e] * costs.l1_words(e))
                .sum::<u64>()
                >> FRAC_BITS;
            let loads = |ops: &[Op]| -> Vec<(u32, u16)> {
                ops.iter()
                    .filter_map(|op| match *op {
                        Op::Load { word, words } => Some((word, words)),
                        _ => None,
                    })
                    .collect()
            };
            let (with, without) = (loads(&ops), loads(&plain));
            let sum = |v: &[(u32, u16)]| v.iter().map(|l| l.1 as u64).sum::<u64>();
            assert_eq!(sum(&with) - sum(&without), extra, "seed {seed}");
            // Every load of the plain recording is a fetch; the others re-read within the
            // fetch before them, or (a recording's first re-reads, before its first fetch)
            // the parameter block's first word, as the tally's default placement has it.
            let mut last = (0u32, 1u16);
            let mut fetches = without.iter().peekable();
            for l in with {
                if fetches.peek() == Some(&&l) {
                    fetches.next();
                    last = l;
                } else {
                    let params = l.0 == 0 && l.1 == 1;
                    assert!(
                        params || (l.0 == last.0 && l.1 <= last.1),
                        "seed {seed}: {l:?} after {last:?}"
                    );
                }
            }
            assert!(fetches.next().is_none());
        }
    }

    #[test]
    fn fetch_covers_every_touched_word() {
        let mut ops = Vec::new();
        let mut tally = Tally::new(SimAccel::Bvh2, random_costs(1));
        let mut r = Recorder::new(&mut tally, &mut ops);
        r.fetch(ByteAddr(52), 52);
        r.fetch(ByteAddr(6), 4); // straddles two words
        assert_eq!(r.tally().counts().loads, 15);
        assert_eq!(
            ops,
            vec![
                Op::Load {
                    word: 13,
                    words: 13
                },
                Op::Load { word: 1, words: 2 }
            ]
        );
    }

    #[test]
    fn ops_are_8_bytes_and_out_of_range_values_are_errors() {
        assert_eq!(std::mem::size_of::<Op>(), 8);
        let top = 4 * u32::MAX as u64;
        assert_eq!(
            Op::load(top, 65_535),
            Ok(Op::Load {
                word: u32::MAX,
                words: 65_535
            })
        );
        assert_eq!(
            Op::load(top + 4, 1),
            Err(OpRangeError::Address { addr: top + 4 })
        );
        assert_eq!(
            Op::load(0, 65_536),
            Err(OpRangeError::Words { words: 65_536 })
        );
        // The recorder keeps the first error instead of wrapping.
        let mut ops = Vec::new();
        let mut tally = Tally::new(SimAccel::Bvh2, random_costs(2));
        let mut r = Recorder::new(&mut tally, &mut ops);
        r.fetch(ByteAddr(8), 4);
        assert_eq!(r.tally().error(), None);
        r.fetch(ByteAddr(top + 8), 4);
        r.fetch(ByteAddr(0), 4 * 70_000);
        assert_eq!(
            r.tally().error(),
            Some(OpRangeError::Address { addr: top + 8 })
        );
        // A run of more reciprocals than an op holds, then one of more cycles.
        let mut per_event = [[0u32; TARGETS]; EVENTS];
        per_event[Event::Push.index()][4] = 40_000 << FRAC_BITS;
        per_event[Event::Pop.index()][0] = 3_000_000 << FRAC_BITS;
        let costs: &'static Costs = Box::leak(Box::new(Costs::from_fixed(per_event)));
        let mut ops = Vec::new();
        let mut tally = Tally::new(SimAccel::Bvh2, costs);
        let mut r = Recorder::new(&mut tally, &mut ops);
        r.push();
        r.push();
        r.fetch(ByteAddr(0), 4);
        assert_eq!(
            r.tally().error(),
            Some(OpRangeError::Fpinv { fpinv: 80_000 })
        );
        let mut tally = Tally::new(SimAccel::Bvh2, costs);
        let mut r = Recorder::new(&mut tally, &mut ops);
        for _ in 0..1500 {
            r.pop();
        }
        r.finish();
        assert_eq!(
            tally.error(),
            Some(OpRangeError::Issue { n: 4_500_000_000 })
        );
    }

    #[test]
    fn serial_and_parallel_box_issue() {
        for (accel, issues) in [(SimAccel::Bvh4, 3), (SimAccel::Bvh4Plus, 1)] {
            let mut ops = Vec::new();
            let mut tally = Tally::new(accel, random_costs(3));
            let mut r = Recorder::new(&mut tally, &mut ops);
            r.step(NodeStep::Bvh {
                arity: 4,
                valid: 3,
                hits: 2,
            });
            let c = r.tally().counts();
            assert_eq!(c.box_ops, 3);
            assert_eq!(c.box_issues, issues);
            assert_eq!(c.node_steps, 1);
            let e = r.tally().events();
            assert_eq!(
                [e[10], e[11], e[12], e[13]],
                [1, 3, 2, 1],
                "node, children, hits, sort pairs"
            );
        }
    }

    #[test]
    fn frame_totals_do_not_wrap_at_2_pow_32() {
        // A 512×512 DST* path-traced frame issues ~6·10^9 instructions: u32 counters would
        // wrap (energy and issue utilisation would come out too low).
        let mut c = InstrCounts::default();
        let big = InstrCounts {
            mix: Mix {
                int: 3_000_000_000,
                local: 2_000_000_000,
                ..Default::default()
            },
            ..Default::default()
        };
        c.add(&big);
        c.add(&big);
        assert_eq!(c.mix.int, 6_000_000_000);
        assert_eq!(c.total(), 10_000_000_000);
    }

    #[test]
    fn dst_on_the_pipeline_is_one_pipeline_op_per_step() {
        let step = NodeStep::Dst {
            kind: DstNodeKind::Split,
            outcome: StepOutcome::BothChildren,
            carving_leaf: false,
        };
        for (accel, pipe_ops) in [(SimAccel::Dst, 1), (SimAccel::DstSw, 0)] {
            let mut ops = Vec::new();
            let mut tally = Tally::new(accel, random_costs(4));
            let mut r = Recorder::new(&mut tally, &mut ops);
            r.step(step);
            assert_eq!(r.tally().counts().dst_ops, pipe_ops);
            assert_eq!(r.tally().counts().node_steps, 1);
            let e = Event::Dst(DstNodeKind::Split, StepOutcome::BothChildren);
            assert_eq!(r.tally().events()[e.index()], 1);
        }
    }
}
