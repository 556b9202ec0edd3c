//! The `fast` model's measured per-event costs: the committed calibration
//! (`crates/sim/calibration.toml`) and its format.

use crate::accel::SimAccel;
use crate::model::fast::event::{EVENTS, Event};
use crate::model::rv32::{ElfError, RunError};
use dualsplit_render::Workload;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::sync::OnceLock;

/// Fractional bits of the stored costs.
pub const FRAC_BITS: u32 = 8;
/// Measured quantities per event: the six instruction classes of [`crate::Mix`], the
/// dependency and pipeline-latency stall cycles, then the L1 words read beyond the
/// traversal's fetches.
pub const TARGETS: usize = 9;
/// The quantities' names, in order.
pub const TARGET_NAMES: [&str; TARGETS] = [
    "int",
    "fpadd",
    "fpmul",
    "fpcmp",
    "fpinv",
    "local",
    "dependency",
    "pipeline",
    "l1_words",
];
/// Index of the dependency stall cycles.
pub const DEPENDENCY: usize = 6;
/// Index of the pipeline-latency stall cycles.
pub const PIPELINE: usize = 7;
/// Index of the L1 words read beyond the traversal's fetches.
pub const L1_WORDS: usize = 8;
/// Index of the reciprocal ops.
const FPINV: usize = 4;

/// Measured per-event costs of one configuration and workload.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Costs {
    /// Per event ([`Event::index`]), per quantity ([`TARGET_NAMES`]), in 2^-FRAC_BITS units.
    per_event: [[u32; TARGETS]; EVENTS],
}

impl Costs {
    /// Costs from fixed-point values.
    pub fn from_fixed(per_event: [[u32; TARGETS]; EVENTS]) -> Self {
        Self { per_event }
    }

    /// Free events (for counting events only).
    pub const ZERO: Costs = Costs {
        per_event: [[0; TARGETS]; EVENTS],
    };

    /// Issue cycles of event `e` (instructions, dependency and pipeline-latency stalls),
    /// fixed point.
    pub fn cycles(&self, e: usize) -> u64 {
        self.per_event[e][..L1_WORDS]
            .iter()
            .map(|&x| x as u64)
            .sum()
    }

    /// L1 words event `e` reads beyond the traversal's fetches, fixed point.
    pub fn l1_words(&self, e: usize) -> u64 {
        self.per_event[e][L1_WORDS] as u64
    }

    /// Reciprocal ops of event `e`, fixed point.
    pub fn fpinv(&self, e: usize) -> u64 {
        self.per_event[e][FPINV] as u64
    }

    /// The quantities of `events` (counts by index), each rounded to a whole number.
    pub fn totals(&self, events: &[u64; EVENTS]) -> [u64; TARGETS] {
        let mut t = [0u64; TARGETS];
        for (k, out) in t.iter_mut().enumerate() {
            let fixed: u128 = events
                .iter()
                .zip(&self.per_event)
                .map(|(&n, c)| n as u128 * c[k] as u128)
                .sum();
            let half = 1u128 << (FRAC_BITS - 1);
            *out = ((fixed + half) >> FRAC_BITS).min(u64::MAX as u128) as u64;
        }
        t
    }
}

/// The calibration file: what was measured, on what, and the costs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// Fractional bits of the costs.
    pub frac_bits: u32,
    /// The unit latencies the dependency stalls were measured with (the config's name).
    pub config: String,
    /// The calibration frames (`scene`, width, height).
    pub frames: Vec<(String, u32, u32)>,
    /// One table per configuration and workload.
    pub tables: Vec<Table>,
}

/// The costs of one configuration and workload, with the fit's record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Table {
    /// Configuration.
    pub accel: SimAccel,
    /// `cast` or `path`.
    pub workload: String,
    /// Segments fitted (pixels and rays of the calibration frames).
    pub segments: u64,
    /// Instructions of the calibration frames in the six classes of [`crate::Mix`] (loads,
    /// stores, pipeline ops and atomics are timed and priced as such, not fitted).
    pub instructions: u64,
    /// Per quantity: the fitted costs' total over the calibration frames relative to the
    /// measured total, minus one.
    pub total_error: [f64; TARGETS],
    /// Per quantity: the coefficient of determination of the per-segment fit.
    pub r2: [f64; TARGETS],
    /// Events of the configuration's structure (BVH or DST) that never occurred on the
    /// calibration frames (their cost is 0; the DST's are node kinds that cannot return
    /// that code).
    pub unseen: Vec<String>,
    /// Per event name: the quantities of [`TARGET_NAMES`] in 2^-`frac_bits` units.
    pub cost: BTreeMap<String, [u32; TARGETS]>,
}

impl Table {
    fn costs(&self) -> Result<Costs, CalibrationError> {
        let mut per_event = [[0; TARGETS]; EVENTS];
        for (name, c) in &self.cost {
            let e = Event::all()
                .into_iter()
                .find(|e| e.name() == *name)
                .ok_or_else(|| CalibrationError::Format(format!("unknown event {name:?}")))?;
            per_event[e.index()] = *c;
        }
        Ok(Costs { per_event })
    }
}

/// Why a calibration could not be measured or read.
#[derive(Debug, thiserror::Error)]
pub enum CalibrationError {
    /// A kernel stopped with an error.
    #[error("kernel {accel} ({workload}) on {scene}: {source}")]
    Run {
        /// Configuration.
        accel: &'static str,
        /// Workload.
        workload: &'static str,
        /// Scene.
        scene: String,
        /// The error.
        source: RunError,
    },
    /// The kernel's pixels and rays did not follow the Rust traversal's.
    #[error(
        "kernel {accel} ({workload}) on {scene}: its pixel and ray segments ({kernel}) do not \
         match the traversal's ({traversal})"
    )]
    Segments {
        /// Configuration.
        accel: &'static str,
        /// Workload.
        workload: &'static str,
        /// Scene.
        scene: String,
        /// Segments of the kernel.
        kernel: usize,
        /// Segments of the traversal.
        traversal: usize,
    },
    /// The calibration file is malformed or lacks a table.
    #[error("calibration file: {0}")]
    Format(String),
    /// A kernel ELF could not be loaded.
    #[error(transparent)]
    Elf(#[from] ElfError),
}

/// The committed calibration (`crates/sim/calibration.toml`).
pub const CALIBRATION_TOML: &str = include_str!("../../../calibration.toml");

/// The committed costs of `accel` for `workload`, parsed once.
pub fn costs(accel: SimAccel, workload: Workload) -> Result<&'static Costs, CalibrationError> {
    type Tables = Result<Vec<(SimAccel, String, Costs)>, String>;
    static TABLES: OnceLock<Tables> = OnceLock::new();
    let tables = TABLES
        .get_or_init(|| {
            let c: Calibration = toml::from_str(CALIBRATION_TOML).map_err(|e| e.to_string())?;
            if c.frac_bits != FRAC_BITS {
                return Err(format!("frac_bits {} (expected {FRAC_BITS})", c.frac_bits));
            }
            c.tables
                .iter()
                .map(|t| {
                    Ok((
                        t.accel,
                        t.workload.clone(),
                        t.costs().map_err(|e| e.to_string())?,
                    ))
                })
                .collect()
        })
        .as_ref()
        .map_err(|e| CalibrationError::Format(e.clone()))?;
    let name = workload_name(workload);
    tables
        .iter()
        .find(|(a, w, _)| *a == accel && w == name)
        .map(|(_, _, c)| c)
        .ok_or_else(|| CalibrationError::Format(format!("no table for {} ({name})", accel.name())))
}

pub(crate) fn workload_name(w: Workload) -> &'static str {
    match w {
        Workload::Cast => "cast",
        Workload::Path => "path",
    }
}
