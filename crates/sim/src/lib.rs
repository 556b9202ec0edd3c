//! A TRaX-style many-core simulator with the dual-split pipeline (Lin et al. 2020, §2.3, §4).
//!
//! ```text
//!  FrameRequest (scene, structures, configuration, settings, chip, thread model)
//!       │ simulate()
//!       ├──────────────────────────────┬─────────────────────────────────────────────┐
//!       ▼ model::rv32 (the reference)  ▼ model::fast                                 │
//!  thread processors executing the     threads replaying the real traversal's       │
//!  compiled RV32IMF kernels            events (Structures::closest_hit / any_hit,   │
//!  (kernels/*.elf) instruction by      observed by a Recorder) as macro-ops, each   │
//!  instruction: decode, hart, tp       charged its measured kernel cost (calibrate) │
//!       │                                   │                                        │
//!       └──────── engine::run: one event loop, a timing wheel of thread wake-ups ────┘
//!                       │ Lane::step(id, &mut Tm, now) -> Wake; Lane::commit (L2, atomic)
//!                       ▼
//!  hw: Chip ── TMs (L1, ray-box / ray-triangle / dual-split pipelines, reciprocal unit,
//!              functional-unit pools) ── L2 ── GDDR5 DRAM; the global atomic unit
//!                       │ counters
//!                       ▼
//!  hw::energy: counts × per-event energy, split like Table 6 ──▶ SimResult
//! ```
//!
//! Ray paths do not depend on timing. Both thread models give the renderer's pixels bit for
//! bit ([`SimResult::radiance`] is the renderer's per-pixel value): the compiled kernels
//! compute them, the `fast` model traces each pixel's rays functionally with the renderer's
//! own traversal, then replays the recorded ops on the timing model.
//!
//! Layout: [`hw`] holds the hardware units and imports nothing from [`model`]; [`engine`]
//! drives any [`engine::Lane`]; [`model::rv32`] and [`model::fast`] are the two thread
//! models; [`accel`] registers the simulated configurations; [`config`] is the chip's
//! configuration (`configs/lin2020.toml`, every key with its source).
//!
//! ```no_run
//! use dualsplit_sim::{FrameRequest, SimAccel, SimConfig, simulate};
//! use dualsplit_render::{RenderSettings, Workload};
//! let scene = dualsplit_scene::load("builtin:hairball").unwrap();
//! let structures = dualsplit_accel::Structures::build(&scene.triangles, &Default::default());
//! let settings = RenderSettings::new(64, 64, Workload::Cast);
//! let cfg = SimConfig::lin2020();
//! let frame = FrameRequest::new(&scene, &structures, SimAccel::Dst, &settings, &cfg);
//! let r = simulate(&frame, &|_, _| {}).unwrap();
//! println!("{} cycles, {:.3} ms", r.cycles, r.frame_ms);
//! ```

pub mod accel;
pub mod config;
pub mod engine;
mod error;
pub mod footprint;
mod frame;
pub mod hw;
pub mod model;
pub mod ranges;
mod request;
mod result;
mod shares;

/// Version of the timing and energy model. Bump it whenever a change alters simulated results
/// for the same inputs; the report's result cache includes it in every key, so stale cached
/// frames are recomputed.
pub const MODEL_VERSION: u32 = 13;

pub use accel::{NodeUnit, SimAccel};
pub use config::{
    CacheConfig, ChildOrder, ConfigError, DramConfig, EnergyConfig, KernelsConfig, NodeFetch,
    SimConfig, UnitConfig,
};
pub use engine::share_threads;
pub use error::SimError;
pub use frame::{check_model, simulate};
pub use hw::counts::UnitStats;
pub use hw::counts::{InstrCounts, Mix};
pub use hw::energy::EnergySplit;
pub use hw::memory::{CacheStats, DramStats};
pub use hw::{ChipStats, Cycle, Stalls, Tick};
pub use request::{FrameRequest, ThreadModel};
pub use result::{MemoryFigures, SimResult, Utilisation};
pub use shares::StallShares;
