//! One simulated frame: the request and the entry point.

use crate::accel::SimAccel;
use crate::config::{KernelsConfig, SimConfig};
use crate::error::SimError;
use crate::footprint;
use crate::model::{ThreadModel, fast, rv32};
use crate::result::SimResult;
use dualsplit_accel::TraversalSet;
use dualsplit_render::RenderSettings;
use dualsplit_scene::Scene;

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

/// Whether `model` runs `cfg`'s kernel variant (`[kernels]`): the `fast` model replays costs
/// measured on the default kernels only ([`SimError::FastKernelVariant`] otherwise).
pub fn check_model(cfg: &SimConfig, model: ThreadModel) -> Result<(), SimError> {
    // Shadow rays or none is not a kernel variant: the fast model follows the renderer.
    let variant = KernelsConfig {
        shadows: true,
        ..cfg.kernels
    };
    if model == ThreadModel::Fast && variant != KernelsConfig::default() {
        return Err(SimError::FastKernelVariant {
            variant: format!(
                "parity = {}, node_fetch = \"{}\", child_order = \"{}\"",
                cfg.kernels.parity,
                cfg.kernels.node_fetch.name(),
                cfg.kernels.child_order.name()
            ),
        });
    }
    Ok(())
}

/// Simulates one frame; `progress` is called with (pixels done, pixels total).
pub fn simulate<S: TraversalSet>(
    frame: &FrameRequest<'_, S>,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<SimResult, SimError> {
    let FrameRequest {
        structures,
        accel,
        settings,
        cfg,
        model,
        ..
    } = *frame;
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
    footprint::check(cfg, accel, model, frame.pixels())?;
    check_model(cfg, model)?;
    structures.fits_unit(accel.kind())?;
    // `kernels.shadows = false` turns the frame's shadow rays off.
    let shadowless = RenderSettings {
        shadows: false,
        ..*settings
    };
    let shadowless = FrameRequest {
        settings: &shadowless,
        ..*frame
    };
    let frame = if settings.shadows && !cfg.kernels.shadows {
        &shadowless
    } else {
        frame
    };
    match model {
        ThreadModel::Rv32 => rv32::frame::run(frame, progress),
        ThreadModel::Fast => fast::frame::run(frame, progress),
    }
}
