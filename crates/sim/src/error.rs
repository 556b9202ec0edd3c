//! Errors of the simulator.

use crate::config::ConfigError;
use crate::footprint;
use crate::model::fast::costs::CalibrationError;
use crate::model::fast::op::OpRangeError;
use crate::model::rv32::{ElfError, ExecError};

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
    Op(#[from] OpRangeError),
    /// A committed kernel did not load.
    #[error("kernel: {0}")]
    Kernel(#[from] ElfError),
    /// A tree its configuration's hardware unit cannot run: an encoding the unit does not
    /// decode, or a node region its addresses do not reach
    /// ([`dualsplit_accel::Structure::fits_unit`]).
    #[error(transparent)]
    Unit(#[from] dualsplit_accel::UnitMismatch),
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
    Exec(#[from] ExecError),
    /// The simulation would take more host memory than [`footprint::MAX_SIM_BYTES`].
    #[error(transparent)]
    Memory(#[from] footprint::TooLarge),
    /// The structures given have no traversal for this configuration (one saved tree holds
    /// one structure).
    #[error("no {accel} traversal here: the structures given have {available}")]
    Unsupported {
        /// The configuration asked for.
        accel: &'static str,
        /// The traversals there are, comma-separated.
        available: String,
    },
    /// The `fast` model replays costs measured on the default kernels only.
    #[error(
        "the fast model is calibrated on the default kernels ([kernels] parity = true, node_fetch = \"loads\", child_order = \"hits\"); kernels with {variant} need --model rv32"
    )]
    FastKernelVariant {
        /// The variant asked for, as its `[kernels]` keys.
        variant: String,
    },
    /// `--model simt` on a configuration without a `[simt]` chip.
    #[error(
        "the simt model needs a GPU chip: a [simt] table in the configuration (configs/rtx2060.toml)"
    )]
    NoSimtChip,
    /// The `simt` model stopped with warps unfinished (a bug in the model).
    #[error("simt model: warps left unfinished at cycle {cycle}")]
    SimtStuck {
        /// The last cycle simulated.
        cycle: u64,
    },
    /// The `fast` model's measured costs are missing or unreadable.
    #[error("fast model: {0}")]
    Calibration(#[from] CalibrationError),
}
