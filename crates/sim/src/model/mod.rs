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
