//! What one simulated frame reports.

use crate::accel::SimAccel;
use crate::config::SimConfig;
use crate::hw::counts::InstrCounts;
use crate::hw::counts::UnitStats;
use crate::hw::energy::{self, EnergySplit};
use crate::hw::memory::{CacheStats, DramStats};
use crate::hw::{ChipStats, Cycle, Stalls};
use crate::request::ThreadModel;
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

/// The memory system's figures of a frame: what explains where a frame sits between the
/// compute and the bandwidth regime.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MemoryFigures {
    /// L1 hit rate (hits on filled lines / accesses).
    pub l1_hit_rate: f64,
    /// L2 hit rate (hits on filled lines / accesses).
    pub l2_hit_rate: f64,
    /// Cycles L2 requests waited for a busy L2 bank, summed over requests.
    pub l2_bank_conflict_cycles: u64,
    /// Row-buffer hit rate of DRAM reads.
    pub dram_row_hit_rate: f64,
    /// Mean DRAM read latency (arrival at the DRAM to data), core cycles.
    pub dram_latency_mean_cycles: f64,
    /// 95th percentile of the DRAM read latency, core cycles.
    pub dram_latency_p95_cycles: u64,
    /// DRAM bandwidth achieved over the frame: lines read × line size / frame time, GB/s
    /// (10^9 bytes per second).
    pub dram_gbps: f64,
    /// DRAM lines read per pixel.
    pub lines_per_pixel: f64,
    /// Rays traced per pixel.
    pub rays_per_pixel: f64,
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
    /// The memory system's figures.
    #[serde(default)]
    pub memory: MemoryFigures,
    /// The `simt` model's figures (RT units, SIMT efficiency, transactions).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simt: Option<crate::model::simt::SimtFigures>,
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
            box_pipe: (stats.units.box_ops + stats.units.qbox_ops) as f64
                / (cyc_units * accel.box_pipes(cfg) as f64),
            tri_pipe: stats.units.tri_ops as f64 / (cyc_units * cfg.units.tri_pipes as f64),
            dst_pipe: (stats.units.dst_ops + stats.units.qdst_ops) as f64
                / (cyc_units * cfg.units.dst_pipes as f64),
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
            memory: MemoryFigures {
                l1_hit_rate: ratio(c.l1_hits, c.l1_accesses),
                l2_hit_rate: ratio(c.l2_hits, c.l2_accesses),
                l2_bank_conflict_cycles: c.l2_bank_wait,
                dram_row_hit_rate: ratio(dram.row_hits, dram.reads),
                dram_latency_mean_cycles: ratio(dram.latency_cycles, dram.reads),
                dram_latency_p95_cycles: dram.latency_p95_cycles,
                dram_gbps: if frame_ms > 0.0 {
                    dram.reads as f64 * cfg.l2.line_bytes as f64 / (frame_ms * 1e-3) / 1e9
                } else {
                    0.0
                },
                lines_per_pixel: ratio(dram.reads, pixels),
                rays_per_pixel: ratio(rays, pixels),
            },
            simt: None,
            radiance,
        }
    }
}
