//! The two thread models: how the simulated threads execute their kernel.
//!
//! * [`rv32`]: thread processors executing the compiled RV32IMF kernels instruction by
//!   instruction (the reference);
//! * [`fast`]: threads replaying the real traversal's events as macro-ops, each charged the
//!   instructions the compiled kernel spends on it, as measured by [`fast::calibrate`].
//!
//! Both implement [`crate::engine::Lane`] and drive the same [`crate::hw`] units.

pub mod fast;
pub mod rv32;
pub mod simt;

use serde::{Deserialize, Serialize};

/// How the simulated threads execute their kernel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ThreadModel {
    /// Compiled RV32IMF kernels (`kernels/`) executed instruction by instruction on
    /// thread processors with a register scoreboard ([`rv32::tp`]): the reference model.
    #[default]
    Rv32,
    /// The traversal replayed as macro-ops with per-event costs measured from the compiled
    /// kernels ([`fast`]): faster, an approximation of
    /// [`ThreadModel::Rv32`].
    Fast,
    /// An RTX-style SIMT GPU with an RT unit per SM, as Vulkan-Sim models it ([`simt`]):
    /// needs a `[simt]` chip (`configs/rtx2060.toml`).
    Simt,
}

impl ThreadModel {
    /// The TRaX chip's two, reference first (the `simt` model runs a GPU chip instead).
    pub const ALL: [ThreadModel; 2] = [ThreadModel::Rv32, ThreadModel::Fast];
    /// Every model, as [`ThreadModel::parse`] knows them.
    pub const NAMED: [ThreadModel; 3] = [ThreadModel::Rv32, ThreadModel::Fast, ThreadModel::Simt];
    /// Command-line name: `rv32`, `fast` or `simt`.
    pub fn name(self) -> &'static str {
        match self {
            ThreadModel::Rv32 => "rv32",
            ThreadModel::Fast => "fast",
            ThreadModel::Simt => "simt",
        }
    }
    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Self> {
        Self::NAMED.into_iter().find(|m| m.name() == s)
    }
}
