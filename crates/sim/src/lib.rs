//! A TRaX-style many-core simulator with the dual-split pipeline (Lin et al. 2020, §4).
//!
//! SKELETON: the public API below is the contract the report and the CLI code against.

use dualsplit_accel::Structures;
use dualsplit_render::RenderSettings;
use dualsplit_scene::Scene;
use serde::{Deserialize, Serialize};

/// The eight simulated configurations of the paper (§4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SimAccel {
    /// BVH2, child boxes tested one after another on the TM's ray-box pipeline.
    Bvh2,
    /// BVH2 with 2 ray-box pipelines (all child boxes in parallel).
    Bvh2Plus,
    /// BVH4, serial box tests.
    Bvh4,
    /// BVH4 with 4 ray-box pipelines.
    Bvh4Plus,
    /// BVH8, serial box tests.
    Bvh8,
    /// BVH8 with 8 ray-box pipelines.
    Bvh8Plus,
    /// DST decoded in software (DST*).
    DstSw,
    /// DST on the dual-split pipeline.
    Dst,
}

impl SimAccel {
    /// All eight, in the paper's table order.
    pub const ALL: [SimAccel; 8] = [
        SimAccel::Bvh2,
        SimAccel::Bvh2Plus,
        SimAccel::Bvh4,
        SimAccel::Bvh4Plus,
        SimAccel::Bvh8,
        SimAccel::Bvh8Plus,
        SimAccel::DstSw,
        SimAccel::Dst,
    ];
    /// Command-line name: `bvh2`, `bvh2+`, ..., `dst-sw`, `dst`.
    pub fn name(self) -> &'static str {
        match self {
            SimAccel::Bvh2 => "bvh2",
            SimAccel::Bvh2Plus => "bvh2+",
            SimAccel::Bvh4 => "bvh4",
            SimAccel::Bvh4Plus => "bvh4+",
            SimAccel::Bvh8 => "bvh8",
            SimAccel::Bvh8Plus => "bvh8+",
            SimAccel::DstSw => "dst-sw",
            SimAccel::Dst => "dst",
        }
    }
    /// The paper's label: `BVH2`, `BVH2+`, ..., `DST*`, `DST`.
    pub fn label(self) -> &'static str {
        match self {
            SimAccel::Bvh2 => "BVH2",
            SimAccel::Bvh2Plus => "BVH2+",
            SimAccel::Bvh4 => "BVH4",
            SimAccel::Bvh4Plus => "BVH4+",
            SimAccel::Bvh8 => "BVH8",
            SimAccel::Bvh8Plus => "BVH8+",
            SimAccel::DstSw => "DST*",
            SimAccel::Dst => "DST",
        }
    }
    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }
}

/// Hardware configuration (TOML, see `configs/lin2020.toml`).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SimConfig {
    /// Thread multiprocessors.
    pub tms: u32,
}

impl SimConfig {
    /// The paper's Table 1 configuration.
    pub fn lin2020() -> Self {
        Self { tms: 64 }
    }
}

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

/// What one simulated frame reports.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct SimResult {
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
    /// L1 hit rate.
    pub l1_hit_rate: f64,
    /// L2 hit rate.
    pub l2_hit_rate: f64,
    /// Rays traced.
    pub rays: u64,
}

/// Errors of the simulator.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// Not yet implemented.
    #[error("the simulator is not implemented yet")]
    Unimplemented,
}

/// Simulates one frame of `settings` on `scene` with configuration `accel`; `progress` is
/// called with (pixels done, pixels total).
pub fn simulate(
    _scene: &Scene,
    _structures: &Structures,
    _accel: SimAccel,
    _settings: &RenderSettings,
    _cfg: &SimConfig,
    _progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<SimResult, SimError> {
    Err(SimError::Unimplemented)
}
