//! The TM's fixed-function pipelines (Lin et al. 2020, §2.3, §3, Table 2).

use crate::config::UnitConfig;
use crate::hw::Cycle;
use crate::hw::counts::UnitStats;
use crate::hw::issued::Issued;
use crate::hw::slots::{Slots, earliest};
use serde::{Deserialize, Serialize};

/// A fixed-function pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Pipe {
    /// Ray-box (Kopta et al. 2013; Lin et al. 2020, Table 2).
    Box,
    /// Ray-triangle.
    Triangle,
    /// Dual-split (Lin et al. 2020, §3, Table 2).
    DualSplit,
}

/// The pipelines a configuration gives each TM beyond `units`: how many ray-box pipes, and
/// whether the ray-box and dual-split pipelines are the quantized ones (a dequantization
/// stage in front: `qbox_latency`, `qdst_latency`, and their energies). A plain count
/// converts into plain pipelines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TmPipes {
    /// Ray-box pipelines.
    pub box_pipes: u32,
    /// The ray-box pipelines dequantize CWBVH child boxes.
    pub quantized_boxes: bool,
    /// The dual-split pipeline dequantizes DST-Q planes.
    pub quantized_dst: bool,
}

impl From<u32> for TmPipes {
    fn from(box_pipes: u32) -> Self {
        TmPipes {
            box_pipes,
            quantized_boxes: false,
            quantized_dst: false,
        }
    }
}

/// A TM's ray-box, ray-triangle and dual-split pipelines (§2.3, §3): fully pipelined, one
/// op per pipe per cycle, results after `box_latency`, `tri_latency`, `dst_latency`; the
/// "+" configurations have one ray-box pipe per child (§4) and test all children of a node
/// in one issue slot. Quantized pipelines ([`TmPipes`]) take `qbox_latency` and
/// `qdst_latency` and count their ops apart.
pub struct Pipelines {
    /// Indexed by [`Pipe`] (`pipe as usize`).
    pipes: [Vec<Slots>; 3],
    latency: [u64; 3],
    /// Whether the ray-box and dual-split pipelines are quantized ones.
    quantized: [bool; 3],
}

impl Pipelines {
    /// Idle pipelines of `units`, with the ray-box pipes of `tm`.
    pub fn new(units: &UnitConfig, tm: TmPipes) -> Self {
        Self {
            pipes: [
                vec![Slots::default(); tm.box_pipes.max(1) as usize],
                vec![Slots::default(); units.tri_pipes as usize],
                vec![Slots::default(); units.dst_pipes as usize],
            ],
            latency: [
                if tm.quantized_boxes {
                    units.qbox_latency
                } else {
                    units.box_latency
                },
                units.tri_latency,
                if tm.quantized_dst {
                    units.qdst_latency
                } else {
                    units.dst_latency
                },
            ],
            quantized: [tm.quantized_boxes, false, tm.quantized_dst],
        }
    }

    /// `n` ops on the pipelines of kind `pipe` from cycle `at`: with `parallel` and
    /// pipes enough, all `n` in one issue slot (the first cycle from `at` at which `n` pipes
    /// are free); otherwise one after another, each on the pipe free first. `ready` is the
    /// last op's result, `busy` the cycles waited for a free pipe.
    #[inline(always)]
    pub fn issue(
        &mut self,
        pipe: Pipe,
        n: u8,
        parallel: bool,
        at: Cycle,
        units: &mut UnitStats,
    ) -> Issued {
        match (pipe, self.quantized[pipe as usize]) {
            (Pipe::Box, false) => units.box_ops += n as u64,
            (Pipe::Box, true) => units.qbox_ops += n as u64,
            (Pipe::Triangle, _) => units.tri_ops += n as u64,
            (Pipe::DualSplit, false) => units.dst_ops += n as u64,
            (Pipe::DualSplit, true) => units.qdst_ops += n as u64,
        }
        let lat = self.latency[pipe as usize];
        let pipes = &mut self.pipes[pipe as usize];
        let (last, next, busy) = if let [only] = &mut pipes[..] {
            // One pipe: a parallel op of n > 1 serialises, n = 1 is the same either way.
            let (mut c, mut last, mut busy) = (at, at, 0);
            for _ in 0..n {
                let s = Cycle(only.reserve(c.get()));
                busy += s - c;
                last = s;
                c = s + 1;
            }
            (last, c, busy)
        } else {
            pipe_general(pipes, n, parallel, at)
        };
        Issued {
            next_issue: next,
            ready: last + lat,
            busy,
        }
    }
}

/// `n` ops from cycle `at` on several pipes of one kind (the "+" configurations' box
/// pipes): in parallel when asked and there are pipes enough (all n start together in one
/// issue slot, at the first cycle from `at` at which n pipes are free), else one after
/// another, each on the pipe free first. Returns the last op's issue cycle, the cycle after
/// it, and the cycles waited.
#[inline(never)]
fn pipe_general(pipes: &mut [Slots], n: u8, parallel: bool, at: Cycle) -> (Cycle, Cycle, u64) {
    let mut c = at;
    let mut last = c;
    let mut busy = 0;
    if parallel && pipes.len() >= n as usize {
        let mut s = c;
        loop {
            let free = pipes.iter().filter(|p| p.peek(s.get()) == s.get()).count();
            if free >= n as usize {
                break;
            }
            s += 1;
        }
        busy += s - c;
        let mut taken = 0;
        for p in pipes.iter_mut() {
            if taken < n && p.peek(s.get()) == s.get() {
                p.reserve(s.get());
                taken += 1;
            }
        }
        last = s;
        c = s + 1;
    } else {
        for _ in 0..n {
            let s = earliest(pipes, c);
            busy += s - c;
            last = s;
            c = s + 1;
        }
    }
    (last, c, busy)
}
