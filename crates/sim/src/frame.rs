//! One simulated frame: the entry point ([`simulate`]) and its checks.

use crate::config::{KernelsConfig, SimConfig};
use crate::error::SimError;
use crate::footprint;
use crate::model::{fast, rv32, simt};
use crate::request::{FrameRequest, ThreadModel};
use crate::result::SimResult;
use dualsplit_accel::TraversalSet;
use dualsplit_render::RenderSettings;

/// Whether `model` runs `cfg`'s kernel variant (`[kernels]`): the `fast` model replays costs
/// measured on the default kernels only ([`SimError::FastKernelVariant`] otherwise); the
/// `simt` model needs a `[simt]` chip ([`SimError::NoSimtChip`]).
pub fn check_model(cfg: &SimConfig, model: ThreadModel) -> Result<(), SimError> {
    if model == ThreadModel::Simt && cfg.simt.is_none() {
        return Err(SimError::NoSimtChip);
    }
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
        ThreadModel::Simt => simt::frame::run(frame, progress),
    }
}
