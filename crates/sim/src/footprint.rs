//! How much host memory a simulation takes, estimated from the configuration and the frame
//! before anything is allocated, so that a configuration that would not fit is refused with
//! a message instead of aborting the process ("memory allocation of N bytes failed").
//!
//! The estimate is an upper bound of what [`crate::simulate`] allocates itself (the
//! scene and the structures are the caller's), term by term from the units' allocations:
//!
//! | term | bytes |
//! |---|---|
//! | threads | threads × ([`THREAD_BYTES`] + the local store with `rv32`) |
//! | caches | (TMs × L1 lines + L2 lines) × [`LINE_BYTES`], plus the banks' and units' schedules ([`TM_BYTES`], [`BANK_BYTES`]) |
//! | DRAM model | channels × banks × [`DRAM_BANK_BYTES`] + channels × read-queue entries × [`QUEUE_ENTRY_BYTES`] |
//! | frame | pixels × 4 (radiance), plus 12 per pixel with `rv32` (the kernel's frame buffer) |
//! | fixed | [`FIXED_BYTES`]: program, calibration, parameters, counters |
//!
//! `crates/sim/tests/footprint.rs` runs simulations under an allocator capped at this
//! estimate (so a single byte beyond it fails the test) and prints how much of it they used.

use crate::accel::SimAccel;
use crate::config::SimConfig;
use crate::model::rv32::kernels::FRAME_FLOATS_PER_PIXEL;
use crate::request::ThreadModel;

/// Per thread, besides its local store: the `rv32` hart and scoreboard or the fast model's
/// thread and pixel state.
pub const THREAD_BYTES: u64 = 4096;
/// Per cache line of the L1s and the L2: a way (line, fill cycle, replaced line and its fill
/// cycle, 32 bytes at most) and its replacement stamp.
pub const LINE_BYTES: u64 = 40;
/// Per TM besides its L1's lines: the five shared unit pools' 1024-cycle rings (16 bytes an
/// entry), the pipelines' schedules and the L1's in-flight filter.
pub const TM_BYTES: u64 = 5 * 1024 * 16 + 64 * 1024;
/// Per L1 or L2 bank: its reservation window.
pub const BANK_BYTES: u64 = 1024;
/// Per DRAM bank: its state and its row epochs.
pub const DRAM_BANK_BYTES: u64 = 1024;
/// Per DRAM read-queue entry of each channel.
pub const QUEUE_ENTRY_BYTES: u64 = 64;
/// The program, the measured costs, the parameter block and the counters.
pub const FIXED_BYTES: u64 = 64 << 20;
/// The most memory a simulation may take: 8 GiB, a third of the 24 GiB machines this
/// project runs on, leaving the rest to the scene and its structures.
pub const MAX_SIM_BYTES: u64 = 8 << 30;

/// The estimate, by term.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Footprint {
    /// Thread state and local stores.
    pub threads: u64,
    /// L1s, L2, their banks and the TMs' units.
    pub caches: u64,
    /// The DRAM model.
    pub dram: u64,
    /// The frame's per-pixel buffers.
    pub frame: u64,
    /// Everything else.
    pub fixed: u64,
}

impl Footprint {
    /// The estimate for simulating a frame of `pixels` with `cfg` (validated), `model`.
    pub fn estimate(cfg: &SimConfig, accel: SimAccel, model: ThreadModel, pixels: u64) -> Self {
        let tms = cfg.tms as u64;
        let threads = tms * cfg.tps_per_tm as u64;
        let local = match model {
            ThreadModel::Rv32 => cfg.units.local_store_bytes as u64,
            ThreadModel::Fast | ThreadModel::Simt => 0,
        };
        let lines = |c: &crate::CacheConfig| c.size_bytes / c.line_bytes;
        let pipes = (accel.box_pipes(cfg) + cfg.units.tri_pipes + cfg.units.dst_pipes) as u64
            + cfg.units.fpinv_units as u64;
        let caches = tms * (lines(&cfg.l1) * LINE_BYTES + cfg.l1.banks as u64 * BANK_BYTES)
            + tms * (TM_BYTES + pipes * BANK_BYTES)
            + lines(&cfg.l2) * LINE_BYTES
            + cfg.l2.banks as u64 * BANK_BYTES;
        let d = &cfg.dram;
        let dram = d.channels as u64
            * (d.banks_per_channel as u64 * DRAM_BANK_BYTES
                + d.read_queue as u64 * QUEUE_ENTRY_BYTES);
        let per_pixel = 4 + match model {
            ThreadModel::Rv32 => 4 * FRAME_FLOATS_PER_PIXEL as u64,
            ThreadModel::Fast | ThreadModel::Simt => 0,
        };
        Self {
            threads: threads * (THREAD_BYTES + local),
            caches,
            dram,
            frame: pixels.saturating_mul(per_pixel),
            fixed: FIXED_BYTES,
        }
    }

    /// The whole estimate.
    pub fn total(&self) -> u64 {
        [self.threads, self.caches, self.dram, self.frame, self.fixed]
            .iter()
            .fold(0u64, |a, &b| a.saturating_add(b))
    }
}

/// Refuses a simulation whose [`Footprint::estimate`] exceeds [`MAX_SIM_BYTES`]; callers
/// may check before they load the scene, [`crate::simulate`] checks again.
pub fn check(
    cfg: &SimConfig,
    accel: SimAccel,
    model: ThreadModel,
    pixels: u64,
) -> Result<(), TooLarge> {
    let need = Footprint::estimate(cfg, accel, model, pixels);
    if need.total() > MAX_SIM_BYTES {
        return Err(TooLarge {
            need,
            limit: MAX_SIM_BYTES,
        });
    }
    Ok(())
}

/// A simulation that would take more host memory than [`MAX_SIM_BYTES`].
#[derive(Debug, thiserror::Error)]
#[error(
        "the simulation would need about {} MiB of memory (threads {} MiB, caches and units {} MiB, DRAM model {} MiB, frame {} MiB, fixed {} MiB); at most {} MiB: lower tms, tps_per_tm, units.local_store_bytes, the cache sizes or the resolution",
        mib(need.total()), mib(need.threads), mib(need.caches), mib(need.dram), mib(need.frame), mib(need.fixed), mib(*limit)
    )]
pub struct TooLarge {
    /// The estimate, by term.
    pub need: Footprint,
    /// The limit.
    pub limit: u64,
}

/// Bytes in MiB, rounded up.
fn mib(bytes: u64) -> u64 {
    bytes.div_ceil(1 << 20)
}
