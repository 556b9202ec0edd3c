//! Where a simulated frame's thread-cycles went, as shares of all of them.

use crate::result::SimResult;
use serde::Serialize;

/// Shares of all thread-cycles (cycles × threads) by what a thread waited for.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct StallShares {
    /// Waiting for load data.
    pub memory: f64,
    /// Waiting for a pipeline result.
    pub pipeline_latency: f64,
    /// Waiting for a free pipeline.
    pub pipeline_busy: f64,
    /// Waiting for a functional unit's result (compiled kernels).
    pub dependency: f64,
    /// Waiting for a free shared unit (compiled kernels).
    pub fu_busy: f64,
    /// Waiting for the reciprocal unit.
    pub fpinv: f64,
    /// L1 bank conflicts and refused L2 requests.
    pub l1_bank: f64,
    /// Instruction-cache bank conflicts (compiled kernels).
    pub icache: f64,
    /// Waiting for the global atomic unit.
    pub atomic: f64,
    /// Finished while other threads still ran (the frame's tail).
    pub idle_at_end: f64,
}

impl StallShares {
    /// The shares of `r`'s thread-cycles.
    pub fn of(r: &SimResult) -> Self {
        let total = r.cycles as f64 * f64::from(r.threads);
        let f = |x: u64| if total > 0.0 { x as f64 / total } else { 0.0 };
        let s = &r.stalls;
        Self {
            memory: f(s.memory),
            pipeline_latency: f(s.pipeline_latency),
            pipeline_busy: f(s.pipeline_busy),
            dependency: f(s.dependency),
            fu_busy: f(s.fu_busy),
            fpinv: f(s.fpinv),
            l1_bank: f(s.l1_bank),
            icache: f(s.icache),
            atomic: f(s.atomic),
            idle_at_end: f(s.idle),
        }
    }

    /// Stalls on units and pipelines: everything but memory and the idle tail.
    pub fn units(&self) -> f64 {
        self.pipeline_latency
            + self.pipeline_busy
            + self.dependency
            + self.fu_busy
            + self.fpinv
            + self.l1_bank
            + self.icache
            + self.atomic
    }
}

impl StallShares {
    /// The share spent issuing instructions: what no stall took.
    pub fn issuing(&self) -> f64 {
        1.0 - self.memory - self.units() - self.idle_at_end
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_add_up_to_one() {
        let mut r = SimResult {
            cycles: 100,
            threads: 2,
            ..Default::default()
        };
        r.stalls.memory = 50;
        r.stalls.pipeline_latency = 20;
        r.stalls.idle = 10;
        let s = StallShares::of(&r);
        assert_eq!((s.memory, s.idle_at_end), (0.25, 0.05));
        assert!((s.issuing() - 0.6).abs() < 1e-12);
    }
}
