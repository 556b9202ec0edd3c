//! What one simulated frame reports.

use crate::accel::SimAccel;
use crate::config::SimConfig;
use crate::hw::counts::InstrCounts;
use crate::hw::counts::UnitStats;
use crate::hw::energy::{self, EnergySplit};
use crate::hw::memory::{CacheStats, DramStats};
use crate::hw::{ChipStats, Cycle, Stalls};
use crate::model::ThreadModel;
use serde::{Deserialize, Serialize};

/// Pipeline utilisation: ops / (cycles × pipes × TMs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Utilisation {
    /// Ray-box pipelines.
    pub box_pipe: f64,
    /// Ray-triangle pipelines.
    pub tri_pipe: f64,
    /// Dual-split pipelines.
    pub dst_pipe: f64,
    /// Issue slots used: instructions / (cycles × threads).
    pub issue: f64,
}

/// What one simulated frame reports.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SimResult {
    /// Configuration simulated.
    pub accel: Option<SimAccel>,
    /// How the threads executed the kernel.
    #[serde(default)]
    pub thread_model: ThreadModel,
    /// Thread multiprocessors simulated.
    pub tms: u32,
    /// Hardware threads (TMs × TPs per TM).
    pub threads: u32,
    /// Simulated cycles.
    pub cycles: u64,
    /// Frame time in milliseconds at the configured clock.
    pub frame_ms: f64,
    /// Energy by category.
    pub energy: EnergySplit,
    /// 64-byte DRAM lines read.
    pub dram_lines: u64,
    /// DRAM row activations.
    pub dram_activations: u64,
    /// Row-buffer hit rate of DRAM reads.
    pub row_hit_rate: f64,
    /// L1 hit rate (hits on filled lines / accesses; merged misses count as misses).
    pub l1_hit_rate: f64,
    /// L2 hit rate (hits on filled lines / accesses).
    pub l2_hit_rate: f64,
    /// Rays traced.
    pub rays: u64,
    /// Pixels simulated.
    pub pixels: u64,
    /// Instructions by class.
    pub instructions: InstrCounts,
    /// Cache counters.
    pub caches: CacheStats,
    /// DRAM counters.
    pub dram: DramStats,
    /// Pipeline and unit op counts.
    pub units: UnitStats,
    /// Pipeline and issue utilisation.
    pub utilisation: Utilisation,
    /// Stall breakdown in thread-cycles.
    pub stalls: Stalls,
    /// Per-pixel radiance in scanline order, as the renderer computes it from the same hits.
    #[serde(skip)]
    pub radiance: Vec<f32>,
}

impl SimResult {
    /// The result of a frame from the chip's counters after `cycles`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn assemble(
        accel: SimAccel,
        thread_model: ThreadModel,
        cfg: &SimConfig,
        cycles: Cycle,
        stats: ChipStats,
        instructions: InstrCounts,
        rays: u64,
        pixels: u64,
        radiance: Vec<f32>,
    ) -> SimResult {
        let dram = stats.dram;
        let c = &stats.caches;
        let ratio = |a: u64, b: u64| if b == 0 { 0.0 } else { a as f64 / b as f64 };
        let cycles = cycles.get();
        let frame_ms = cycles as f64 / (cfg.clock_ghz * 1e6);
        let cyc_units = cycles.max(1) as f64 * cfg.tms as f64;
        let utilisation = Utilisation {
            box_pipe: stats.units.box_ops as f64 / (cyc_units * accel.box_pipes(cfg) as f64),
            tri_pipe: stats.units.tri_ops as f64 / (cyc_units * cfg.units.tri_pipes as f64),
            dst_pipe: stats.units.dst_ops as f64 / (cyc_units * cfg.units.dst_pipes as f64),
            issue: instructions.total() as f64 / (cyc_units * cfg.tps_per_tm as f64),
        };
        SimResult {
            accel: Some(accel),
            thread_model,
            tms: cfg.tms,
            threads: cfg.tms * cfg.tps_per_tm,
            cycles,
            frame_ms,
            energy: energy::split(cfg, &instructions, &stats.caches, &dram, frame_ms),
            dram_lines: dram.reads,
            dram_activations: dram.activations,
            row_hit_rate: ratio(dram.row_hits, dram.reads),
            l1_hit_rate: ratio(c.l1_hits, c.l1_accesses),
            l2_hit_rate: ratio(c.l2_hits, c.l2_accesses),
            rays,
            pixels,
            instructions,
            caches: stats.caches,
            dram,
            units: stats.units,
            utilisation,
            stalls: stats.stalls,
            radiance,
        }
    }
}
