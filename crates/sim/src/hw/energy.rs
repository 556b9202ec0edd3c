//! Energy: event counts × per-event energies, as SimTRaX counts them (`main.cc`,
//! `ReadConfig.cc`: one L1 access per load word, one L2 access per L1 miss that reaches it,
//! one icache fetch and 3 register-file accesses per instruction; per-event energies from
//! the SimTRaX 65 nm configs and the paper's Table 2), split like the paper's
//! Table 6 into DRAM, caches (L1, L2, instruction caches, register files, local stores) and
//! compute (functional units and pipelines). No on-chip leakage, as in SimTRaX.

use crate::config::SimConfig;
use crate::hw::counts::InstrCounts;
use crate::hw::memory::CacheStats;
use crate::hw::memory::DramStats;
use serde::{Deserialize, Serialize};

/// Energy split like the paper's Table 6, in joules.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EnergySplit {
    /// DRAM (background, activations, reads).
    pub dram_j: f64,
    /// L1 + L2 + instruction caches + register files + local stores.
    pub caches_j: f64,
    /// Functional units and pipelines.
    pub compute_j: f64,
}

impl EnergySplit {
    /// Total energy.
    pub fn total(&self) -> f64 {
        self.dram_j + self.caches_j + self.compute_j
    }
}

/// The energy of a frame from its counts and frame time (ms).
pub fn split(
    cfg: &SimConfig,
    counts: &InstrCounts,
    caches: &CacheStats,
    dram: &DramStats,
    frame_ms: f64,
) -> EnergySplit {
    let e = &cfg.energy;
    let nj = 1e-9;
    let instrs = counts.total() as f64;
    let m = &counts.mix;
    let caches_j = (caches.l1_accesses as f64 * e.l1_nj
        + caches.l2_accesses as f64 * e.l2_nj
        + instrs * e.icache_nj
        + instrs * 3.0 * e.rf_access_nj
        + m.local as f64 * e.local_store_nj)
        * nj;
    // Loads, pipeline issues and atomics use the integer unit for address arithmetic.
    let int_ops = m.int + counts.loads + counts.atomics;
    let compute_j = (int_ops as f64 * e.int_nj
        + m.fpadd as f64 * e.fpadd_nj
        + m.fpmul as f64 * e.fpmul_nj
        + m.fpcmp as f64 * e.fpcmp_nj
        + m.fpinv as f64 * e.fpinv_nj
        + counts.box_ops as f64 * e.box_pipe_nj
        + counts.tri_ops as f64 * e.tri_pipe_nj
        + counts.dst_ops as f64 * e.dst_pipe_nj
        + counts.qbox_ops as f64 * e.qbox_pipe_nj
        + counts.qdst_ops as f64 * e.qdst_pipe_nj)
        * nj;
    let d = &cfg.dram;
    // A write burst costs a read's energy: USIMM prices it with IDD4W as a read with IDD4R
    // (`sim/memory_controller.cc:2236`), and `1Gb_x16_amd2GHz.vi` has IDD4W = IDD4R.
    let bursts = (dram.reads + dram.writes) as f64;
    let dram_j = (bursts * d.e_read_nj + dram.activations as f64 * d.e_activate_nj) * nj
        + d.background_w * frame_ms * 1e-3;
    EnergySplit {
        dram_j,
        caches_j,
        compute_j,
    }
}
