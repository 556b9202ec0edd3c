//! A frame of compiled kernels: every thread of the chip runs the configuration's RV32IMF
//! kernel (`kernels/`, loaded from the committed ELF), taking pixels from the global atomic
//! counter until they run out, and writes each pixel's radiance to the frame buffer
//! (Lin et al. 2020, §4.3–4.4; the memory map of `docs/isa.md`).

use crate::config::UnitConfig;
use crate::engine::{self, Threads, Wake};
use crate::error::SimError;
use crate::frame::FrameRequest;
use crate::hw::counts::InstrCounts;
use crate::hw::fu::{ClassCounts, FU_CLASSES};
use crate::hw::{Chip, Cycle};
use crate::model::ThreadModel;
use crate::model::rv32::kernels::{FRAME_FLOATS_PER_PIXEL, Params, elf, placement};
use crate::model::rv32::placement::Placement;
use crate::model::rv32::tp::Tp;
use crate::model::rv32::{
    ExecError, FRAME_BUFFER_ADDR, FrameMemory, PARAMS_ADDR, PROGRAM_BASE, Program,
};
use crate::result::SimResult;
use dualsplit_accel::TraversalSet;

/// The thread processors of a frame, as the event loop steps them.
pub(crate) struct Compiled<'a, 'm> {
    pub(crate) tps: Vec<Tp>,
    pub(crate) prog: &'a Program,
    pub(crate) mem: &'a mut FrameMemory<'m>,
    pub(crate) placement: &'a Placement,
    pub(crate) cfg: &'a UnitConfig,
    pub(crate) counts: ClassCounts,
    /// Pixels handed out at the last progress report.
    pub(crate) handed_out: u32,
    pub(crate) progress: &'a mut dyn FnMut(u32),
}

impl Threads for Compiled<'_, '_> {
    type Error = ExecError;

    fn count(&self) -> usize {
        self.tps.len()
    }

    /// Each thread is woken at the cycle its next instruction on a shared unit can issue.
    #[inline]
    fn step(&mut self, id: usize, chip: &mut Chip, now: Cycle) -> Result<Wake, ExecError> {
        let tp = &mut self.tps[id];
        let units = chip.units(tp.tm());
        tp.run(
            self.prog,
            self.mem,
            self.cfg,
            units,
            self.placement,
            &mut self.counts,
            now,
        )
    }

    /// Reports the pixels handed out so far (global register 0) every 1024.
    fn after_cycle(&mut self) {
        if self.mem.globals[0] >= self.handed_out + 1024 {
            self.handed_out = self.mem.globals[0];
            (self.progress)(self.handed_out);
        }
    }
}

/// Runs one frame of `accel`'s compiled kernel for `settings` on the chip of `cfg`.
pub(crate) fn run<S: TraversalSet>(
    frame: &FrameRequest<'_, S>,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<SimResult, SimError> {
    let FrameRequest {
        scene,
        structures,
        accel,
        settings,
        cfg,
        ..
    } = *frame;
    let prog = Program::from_elf(elf(accel, settings.workload, cfg.kernels))?;
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
    let mut chip = Chip::new(cfg, accel.pipes(&cfg.units));
    let total = frame.pixels();
    let mut threads = Compiled {
        tps: (0..cfg.tms * cfg.tps_per_tm)
            .map(|i| {
                Tp::new(
                    &prog,
                    (i / cfg.tps_per_tm) as usize,
                    ((i % cfg.tps_per_tm) % cfg.units.icaches) as usize,
                    cfg.units.local_store_bytes,
                )
            })
            .collect(),
        prog: &prog,
        mem: &mut mem,
        placement: &placement,
        cfg: &cfg.units,
        counts: [0; FU_CLASSES],
        handed_out: 0,
        progress: &mut |done| progress((done as u64).min(total), total),
    };
    let cycles = engine::run(&mut chip, &mut threads)?;
    progress(total, total);
    let rays = threads.tps.iter().map(Tp::rays).sum();
    let counts = threads.counts;
    let stats = chip.stats();
    let instructions = InstrCounts::from_classes(&counts, &stats.units);
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
