//! A TRaX-style many-core simulator with the dual-split pipeline (Lin et al. 2020, §2.3, §4).
//!
//! ```text
//!  PixelJob (renderer)        Structures::closest_hit / any_hit  (the real traversal)
//!       │ rays                     │ Observer events: fetch, step, triangle_test, push, pop
//!       ▼                          ▼
//!  workload.rs ── per pixel ──▶ kernel::Recorder ──▶ Vec<Op>  (macro-ops, functional first)
//!                                                        │
//!                                                        ▼  timing second
//!  chip.rs: the event loop; scheduler.rs: timing wheel of thread wake-ups
//!      ├─ thread.rs: thread processors replaying the ops (single issue, in order)
//!      ├─ tm.rs (per TM): L1 (banks, tags with fill times), ray-box / ray-triangle /
//!      │          dual-split pipelines, shared reciprocal unit
//!      ├─ atomic.rs: the global atomic unit (pixel hand-out)
//!      └─ memory/: l2.rs (banks, tags), dram.rs (GDDR5 row buffers, buses, read queues)
//!                                                        │
//!                                                        ▼
//!  energy.rs: counts × per-event energy, split like Table 6 ──▶ SimResult
//! ```
//!
//! Ray paths do not depend on timing, so a pixel's rays are traced functionally, one ray at
//! a time, by the simulated thread that took the pixel from the global counter (the next
//! ray when the previous ray's ops have issued), and the recorded macro-ops are then
//! replayed by the timing model. Simulated hits are the renderer's hits by
//! construction ([`SimResult::radiance`] is the renderer's per-pixel value).
//!
//! ```no_run
//! use dualsplit_sim::{SimAccel, SimConfig, simulate};
//! use dualsplit_render::{RenderSettings, Workload};
//! let scene = dualsplit_scene::load("builtin:hairball").unwrap();
//! let structures = dualsplit_accel::Structures::build(&scene.triangles, &Default::default());
//! let settings = RenderSettings::new(64, 64, Workload::Cast);
//! let r = simulate(&scene, &structures, SimAccel::Dst, &settings, &SimConfig::lin2020(),
//!                  &|_, _| {}).unwrap();
//! println!("{} cycles, {:.3} ms", r.cycles, r.frame_ms);
//! ```

pub mod atomic;
pub mod calibrate;
pub mod chip;
mod compiled;
pub mod config;
mod cycle;
pub mod energy;
pub mod footprint;
pub mod fu;
pub mod kernel;
pub mod kernels;
pub mod memory;
pub mod ranges;
pub mod rv32;
mod scheduler;
mod shares;
pub mod slots;
pub mod thread;
pub mod tm;
pub mod tp;
mod workload;

/// Version of the timing and energy model. Bump it whenever a change alters simulated results
/// for the same inputs; the report's result cache includes it in every key, so stale cached
/// frames are recomputed.
pub const MODEL_VERSION: u32 = 7;

pub use chip::{Chip, ChipStats, WorkSource, run_chip};
pub use config::{CacheConfig, ConfigError, DramConfig, EnergyConfig, SimConfig, UnitConfig};
pub use cycle::{Cycle, Tick};
pub use kernel::{InstrCounts, Mix};
pub use memory::{CacheStats, DramStats};
pub use shares::StallShares;
pub use thread::{Stalls, Thread};
pub use tm::{Issued, Tm, UnitStats, WordAddr};

use dualsplit_accel::{AccelKind, TraversalSet};
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
    /// The traversal this configuration runs.
    pub fn kind(self) -> AccelKind {
        match self {
            SimAccel::Bvh2 | SimAccel::Bvh2Plus => AccelKind::Bvh2,
            SimAccel::Bvh4 | SimAccel::Bvh4Plus => AccelKind::Bvh4,
            SimAccel::Bvh8 | SimAccel::Bvh8Plus => AccelKind::Bvh8,
            SimAccel::DstSw => AccelKind::DstSw,
            SimAccel::Dst => AccelKind::Dst,
        }
    }
    /// The "+" configurations: all child boxes of a node tested in one issue slot, on as
    /// many ray-box pipelines (§4).
    pub fn parallel_boxes(self) -> bool {
        matches!(
            self,
            SimAccel::Bvh2Plus | SimAccel::Bvh4Plus | SimAccel::Bvh8Plus
        )
    }
    /// DST and DST\*: the traversal of the dual-split tree (stack entries carry
    /// `[t_min, t_max]`).
    pub fn is_dst(self) -> bool {
        matches!(self, SimAccel::Dst | SimAccel::DstSw)
    }
    /// Ray-box pipelines per TM: the node arity for the "+" configurations (§4).
    pub fn box_pipes(self, cfg: &SimConfig) -> u32 {
        match self {
            SimAccel::Bvh2Plus => 2,
            SimAccel::Bvh4Plus => 4,
            SimAccel::Bvh8Plus => 8,
            _ => cfg.units.box_pipes,
        }
    }
}

/// How the simulated threads execute their kernel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ThreadModel {
    /// Compiled RV32IMF kernels (`kernels/`) executed instruction by instruction on
    /// thread processors with a register scoreboard (`tp.rs`): the reference model.
    #[default]
    Rv32,
    /// The traversal replayed as macro-ops with per-event costs measured from the compiled
    /// kernels (`kernel.rs`, `calibrate.rs`, `thread.rs`): faster, an approximation of
    /// [`ThreadModel::Rv32`].
    Fast,
}

impl ThreadModel {
    /// Both, reference first.
    pub const ALL: [ThreadModel; 2] = [ThreadModel::Rv32, ThreadModel::Fast];
    /// Command-line name: `rv32` or `fast`.
    pub fn name(self) -> &'static str {
        match self {
            ThreadModel::Rv32 => "rv32",
            ThreadModel::Fast => "fast",
        }
    }
    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == s)
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

/// Errors of the simulator.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// The configuration is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The frame has no pixels.
    #[error("empty frame: {width}×{height} pixels")]
    EmptyFrame {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
    },
    /// A traversal step does not fit the replay's 8-byte ops (e.g. an image beyond 16 GiB).
    #[error(transparent)]
    Op(#[from] kernel::OpRangeError),
    /// A committed kernel did not load.
    #[error("kernel: {0}")]
    Kernel(#[from] rv32::ElfError),
    /// The frame does not fit the compiled kernels' 32-bit memory map (`docs/isa.md`).
    #[error("the {region} takes {bytes} bytes; the kernels' memory map holds at most {limit}")]
    MemoryMap {
        /// `memory image` or `frame buffer`.
        region: &'static str,
        /// Its size.
        bytes: u64,
        /// The room the map gives it.
        limit: u64,
    },
    /// A kernel instruction failed (an address outside the memory map, an illegal
    /// instruction).
    #[error("kernel: {0}")]
    Exec(#[from] rv32::ExecError),
    /// The simulation would take more host memory than [`footprint::MAX_SIM_BYTES`].
    #[error(
        "the simulation would need about {} MiB of memory (threads {} MiB, caches and units {} MiB, DRAM model {} MiB, frame {} MiB, fixed {} MiB); at most {} MiB: lower tms, tps_per_tm, units.local_store_bytes, the cache sizes or the resolution",
        mib(need.total()), mib(need.threads), mib(need.caches), mib(need.dram), mib(need.frame), mib(need.fixed), mib(*limit)
    )]
    Memory {
        /// The estimate, by term.
        need: footprint::Footprint,
        /// The limit.
        limit: u64,
    },
    /// The structures given have no traversal for this configuration (one saved tree holds
    /// one structure).
    #[error("no {accel} traversal here: the structures given have {available}")]
    Unsupported {
        /// The configuration asked for.
        accel: &'static str,
        /// The traversals there are, comma-separated.
        available: String,
    },
    /// The `fast` model's measured costs are missing or unreadable.
    #[error("fast model: {0}")]
    Calibration(#[from] calibrate::CalibrationError),
}

/// Bytes in MiB, rounded up.
fn mib(bytes: u64) -> u64 {
    bytes.div_ceil(1 << 20)
}

/// Simulates one frame of `settings` on `scene` with configuration `accel`, the threads
/// executing the compiled kernels ([`ThreadModel::Rv32`]); `progress` is called with
/// (pixels done, pixels total).
pub fn simulate<S: TraversalSet>(
    scene: &Scene,
    structures: &S,
    accel: SimAccel,
    settings: &RenderSettings,
    cfg: &SimConfig,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<SimResult, SimError> {
    simulate_model(
        ThreadModel::Rv32,
        scene,
        structures,
        accel,
        settings,
        cfg,
        progress,
    )
}

/// [`simulate`] with the threads' execution model `model`.
pub fn simulate_model<S: TraversalSet>(
    model: ThreadModel,
    scene: &Scene,
    structures: &S,
    accel: SimAccel,
    settings: &RenderSettings,
    cfg: &SimConfig,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<SimResult, SimError> {
    cfg.validate()?;
    if !structures.supports(accel.kind()) {
        return Err(SimError::Unsupported {
            accel: accel.label(),
            available: structures.kind_names(),
        });
    }
    if settings.width == 0 || settings.height == 0 {
        return Err(SimError::EmptyFrame {
            width: settings.width,
            height: settings.height,
        });
    }
    let pixels = settings.width as u64 * settings.height as u64;
    footprint::check(cfg, accel, model, pixels)?;
    match model {
        ThreadModel::Rv32 => compiled::run(scene, structures, accel, settings, cfg, progress),
        ThreadModel::Fast => workload::run(scene, structures, accel, settings, cfg, progress),
    }
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
