//! What a frame to simulate is: the [`FrameRequest`] and the [`ThreadModel`] that executes
//! it. Below both the entry point (`frame.rs`) and the thread models' frames, which take the
//! request.

use crate::accel::SimAccel;
use crate::config::SimConfig;
use dualsplit_accel::TraversalSet;
use dualsplit_render::RenderSettings;
use dualsplit_scene::Scene;
use serde::{Deserialize, Serialize};

/// One frame to simulate: the scene and its structures, the configuration simulated, the
/// frame's workload and size, the chip, and how its threads execute their kernel.
#[derive(Clone, Copy)]
pub struct FrameRequest<'a, S> {
    /// The scene.
    pub scene: &'a Scene,
    /// Its structures (a [`dualsplit_accel::Structures`] or one saved tree).
    pub structures: &'a S,
    /// The configuration simulated.
    pub accel: SimAccel,
    /// Workload, resolution, samples, camera and light.
    pub settings: &'a RenderSettings,
    /// The chip.
    pub cfg: &'a SimConfig,
    /// How the threads execute their kernel.
    pub model: ThreadModel,
    /// Host threads the frame runs on (TMs split among them; the result is the same for
    /// any number, `engine::run`).
    pub threads: usize,
}

impl<'a, S: TraversalSet> FrameRequest<'a, S> {
    /// A request for `accel` on the reference thread model ([`ThreadModel::Rv32`]).
    pub fn new(
        scene: &'a Scene,
        structures: &'a S,
        accel: SimAccel,
        settings: &'a RenderSettings,
        cfg: &'a SimConfig,
    ) -> Self {
        Self {
            scene,
            structures,
            accel,
            settings,
            cfg,
            model: ThreadModel::Rv32,
            threads: 1,
        }
    }

    /// The same request on `threads` host threads (at least one).
    pub fn with_threads(self, threads: usize) -> Self {
        Self {
            threads: threads.max(1),
            ..self
        }
    }

    /// The same request with thread model `model`.
    pub fn with_model(self, model: ThreadModel) -> Self {
        Self { model, ..self }
    }

    /// Pixels in the frame.
    pub fn pixels(&self) -> u64 {
        self.settings.width as u64 * self.settings.height as u64
    }
}

/// How the simulated threads execute their kernel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ThreadModel {
    /// Compiled RV32IMF kernels (`kernels/`) executed instruction by instruction on
    /// thread processors with a register scoreboard ([`crate::model::rv32::tp`]): the reference model.
    #[default]
    Rv32,
    /// The traversal replayed as macro-ops with per-event costs measured from the compiled
    /// kernels ([`crate::model::fast`]): faster, an approximation of
    /// [`ThreadModel::Rv32`].
    Fast,
    /// An RTX-style SIMT GPU with an RT unit per SM, as Vulkan-Sim models it
    /// ([`crate::model::simt`]): needs a `[simt]` chip (`configs/rtx2060.toml`).
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
