//! What the recorders of one frame count: events, loads, atomics, and the first step that
//! did not fit an [`Op`](crate::model::fast::op::Op).

use crate::accel::{NodeUnit, SimAccel};
use crate::hw::counts::{InstrCounts, Mix};
use crate::model::fast::costs::{Costs, DEPENDENCY, PIPELINE};
use crate::model::fast::event::{DST_KINDS, EVENTS, Event};
use crate::model::fast::op::OpRangeError;
use dualsplit_accel::{DstNodeKind, StepOutcome};

/// What the recorders of one frame count, summed over every ray: events, loads and atomics,
/// and the first step that did not fit an [`Op`](crate::model::fast::op::Op).
#[derive(Clone, Debug)]
pub struct Tally {
    pub(super) accel: SimAccel,
    pub(super) costs: &'static Costs,
    /// Per event: issue cycles (instructions and dependency stalls) and reciprocal ops, in
    /// units of 2^-[`FRAC_BITS`](FRAC_BITS).
    pub(super) cycles: [u64; EVENTS],
    pub(super) fpinv: [u64; EVENTS],
    /// Per event: L1 words read beyond the traversal's fetches, same units.
    pub(super) words: [u64; EVENTS],
    pub(super) events: [u64; EVENTS],
    /// BVH nodes with at least one valid child (one box issue each on parallel pipes).
    pub(super) boxed_nodes: u64,
    /// Loads and atomics.
    pub(super) counts: InstrCounts,
    pub(super) error: Option<OpRangeError>,
    /// Physical address of the memory image's byte 0 (`memory::Placement::image_base`):
    /// the recorders' loads are placed there.
    pub(super) image_base: u64,
    /// What a recorder re-reads before its first fetch: the parameter block's first words
    /// (physical word address, words).
    pub(super) params: (u32, u16),
}

impl Tally {
    /// Nothing counted yet, for configuration `accel` with event costs `costs`.
    pub fn new(accel: SimAccel, costs: &'static Costs) -> Self {
        let mut cycles = [0; EVENTS];
        let mut fpinv = [0; EVENTS];
        let mut words = [0; EVENTS];
        for e in 0..EVENTS {
            cycles[e] = costs.cycles(e);
            fpinv[e] = costs.fpinv(e);
            words[e] = costs.l1_words(e);
        }
        Self {
            accel,
            costs,
            cycles,
            fpinv,
            words,
            events: [0; EVENTS],
            boxed_nodes: 0,
            counts: InstrCounts::default(),
            error: None,
            image_base: 0,
            params: (0, 1),
        }
    }

    /// The same tally with the recorders' loads placed at physical address `image_base` for
    /// the image's byte 0, and the parameter block's `params_words` words at physical 0.
    pub fn placed_at(mut self, image_base: u64, params_words: u16) -> Self {
        self.image_base = image_base;
        self.params = (0, params_words.max(1));
        self
    }

    /// Events counted so far, by [`Event::index`].
    pub fn events(&self) -> &[u64; EVENTS] {
        &self.events
    }

    /// The counts so far: each event's measured instruction mix times its count (rounded
    /// once, on the frame's totals), the loads, pipeline ops and atomics.
    pub fn counts(&self) -> InstrCounts {
        let e = &self.events;
        let mut c = self.counts;
        let [int, fpadd, fpmul, fpcmp, fpinv, local, ..] = self.costs.totals(e);
        c.mix = Mix {
            int,
            fpadd,
            fpmul,
            fpcmp,
            fpinv,
            local,
        };
        // Pipeline ops and node steps: one box op per valid child (one issue slot per node
        // on parallel pipes), one triangle op per test, one dual-split op per DST step on
        // the pipeline; node steps are BVH nodes and DST steps other than leaf words.
        c.box_ops = e[Event::BvhChild.index()];
        c.box_issues = if self.accel.parallel_boxes() {
            self.boxed_nodes
        } else {
            c.box_ops
        };
        if self.accel.node_unit() == NodeUnit::QuantizedBoxPipe {
            // rt.qboxn: one issue and 8 quantized box ops per node, every slot tested.
            c.box_ops = 0;
            c.qbox_ops = 8 * self.boxed_nodes;
            c.box_issues = self.boxed_nodes;
        }
        c.tri_ops = e[Event::TriTest.index()];
        let dst = &e[Event::Dst(DST_KINDS[0], StepOutcome::ALL[0]).index()..];
        let dst_leaf = &dst[4 * DstNodeKind::Leaf as usize..];
        match self.accel.node_unit() {
            NodeUnit::DualSplitPipe => c.dst_ops = dst.iter().sum(),
            NodeUnit::QuantizedDualSplitPipe => c.qdst_ops = dst.iter().sum(),
            _ => {}
        }
        c.node_steps =
            e[Event::BvhNode.index()] + dst.iter().sum::<u64>() - dst_leaf.iter().sum::<u64>();
        c
    }

    /// Dependency stall cycles the measured events carry (part of their issue runs).
    pub fn dependency_cycles(&self) -> u64 {
        self.costs.totals(&self.events)[DEPENDENCY]
    }

    /// Pipeline-latency stall cycles the measured events carry (part of their issue runs).
    pub fn pipeline_cycles(&self) -> u64 {
        self.costs.totals(&self.events)[PIPELINE]
    }

    /// The first step that did not fit an [`Op`](crate::model::fast::op::Op) (a program is then incomplete).
    pub fn error(&self) -> Option<OpRangeError> {
        self.error
    }

    /// Counts the global atomic increment that hands a pixel to a thread.
    pub fn atomic(&mut self) {
        self.counts.atomics += 1;
    }

    /// Keeps the first range error.
    #[cold]
    pub(super) fn fail(&mut self, e: OpRangeError) {
        self.error.get_or_insert(e);
    }
}
