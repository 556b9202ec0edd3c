//! A frame of compiled kernels: every thread of the chip runs the configuration's RV32IMF
//! kernel (`kernels/`, loaded from the committed ELF), taking pixels from the global atomic
//! counter until they run out, and writes each pixel's radiance to the frame buffer
//! (Lin et al. 2020, §4.3–4.4; the memory map of `docs/isa.md`).

use crate::fu::Pools;
use crate::kernels::{FRAME_FLOATS_PER_PIXEL, Params, elf, placement};
use crate::rv32::{FRAME_BUFFER_ADDR, FrameMemory, PARAMS_ADDR, PROGRAM_BASE, Program};
use crate::tp::{ClassCounts, Tp};
use crate::{Chip, SimAccel, SimConfig, SimError, SimResult, ThreadModel, chip::run_compiled};
use dualsplit_accel::TraversalSet;
use dualsplit_render::RenderSettings;
use dualsplit_scene::Scene;

/// Runs one frame of `accel`'s compiled kernel for `settings` on the chip of `cfg`.
pub(crate) fn run<S: TraversalSet>(
    scene: &Scene,
    structures: &S,
    accel: SimAccel,
    settings: &RenderSettings,
    cfg: &SimConfig,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<SimResult, SimError> {
    let prog = Program::from_elf(elf(accel, settings.workload))?;
    let image = structures.image(accel.kind());
    // The memory map of docs/isa.md: the image below the parameter block, the frame
    // buffer below the program.
    let image_bytes = image.triangles.end as u64 * 4;
    let frame_bytes =
        settings.width as u64 * settings.height as u64 * 4 * FRAME_FLOATS_PER_PIXEL as u64;
    for (region, bytes, limit) in [
        ("memory image", image_bytes, PARAMS_ADDR as u64),
        (
            "frame buffer",
            frame_bytes,
            (PROGRAM_BASE - FRAME_BUFFER_ADDR) as u64,
        ),
    ] {
        if bytes > limit {
            return Err(SimError::MemoryMap {
                region,
                bytes,
                limit,
            });
        }
    }
    let params = Params::new(scene, structures, accel, settings);
    let mut mem = FrameMemory::new(image, params.as_bytes(), params.frame_bytes());
    let placement = placement(&params, &prog, image, cfg.l1.line_bytes);
    let mut chip = Chip::new(cfg, accel.box_pipes(cfg));
    let mut pools: Vec<Pools> = (0..cfg.tms).map(|_| Pools::new(&cfg.units)).collect();
    let mut tps: Vec<Tp> = (0..cfg.tms * cfg.tps_per_tm)
        .map(|i| {
            Tp::new(
                &prog,
                (i / cfg.tps_per_tm) as usize,
                cfg.units.local_store_bytes,
            )
        })
        .collect();
    let total = settings.width as u64 * settings.height as u64;
    let mut counts: ClassCounts = [0; crate::rv32::run::FU_CLASSES];
    let cycles = run_compiled(
        &mut chip,
        &mut pools,
        &mut tps,
        &prog,
        &mut mem,
        &placement,
        &cfg.units,
        &mut counts,
        &mut |done| progress((done as u64).min(total), total),
    )?;
    progress(total, total);
    let rays = tps.iter().map(Tp::rays).sum();
    let stats = chip.stats();
    let instructions = crate::kernel::InstrCounts::from_classes(&counts, &stats.units);
    Ok(SimResult::assemble(
        accel,
        ThreadModel::Rv32,
        cfg,
        cycles,
        stats,
        instructions,
        rays,
        total,
        mem.frame_f32()
            .into_iter()
            .step_by(FRAME_FLOATS_PER_PIXEL)
            .collect(),
    ))
}
