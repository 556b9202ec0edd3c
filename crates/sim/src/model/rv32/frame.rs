//! A frame of compiled kernels: every thread of the chip runs the configuration's RV32IMF
//! kernel (`kernels/`, loaded from the committed ELF), taking pixels from the global atomic
//! counter until they run out, and writes each pixel's radiance to the frame buffer
//! (Lin et al. 2020, §4.3–4.4; the memory map of `docs/isa.md`).

use crate::config::{SimConfig, UnitConfig};
use crate::engine::{self, Commit, Lane, Wake};
use crate::error::SimError;
use crate::hw::atomic::AtomicUnit;
use crate::hw::counts::InstrCounts;
use crate::hw::fu::{ClassCounts, FU_CLASSES};
use crate::hw::l1::Resident;
use crate::hw::tm::Tm;
use crate::hw::{Chip, Cycle, Stalls};
use crate::model::rv32::kernels::{FRAME_FLOATS_PER_PIXEL, Params, elf, placement};
use crate::model::rv32::placement::Placement;
use crate::model::rv32::tp::Tp;
use crate::model::rv32::uop::Uops;
use crate::model::rv32::{
    ExecError, FRAME_BUFFER_ADDR, FrameMemory, ImageView, PARAMS_ADDR, PROGRAM_BASE, Program,
};
use crate::request::FrameRequest;
use crate::request::ThreadModel;
use crate::result::SimResult;
use dualsplit_accel::TraversalSet;
use std::ops::Range;

/// The thread processors of a group of TMs, as one host thread of the event loop steps
/// them.
pub(crate) struct Compiled<'a, 'm> {
    pub(crate) tps: &'a mut [Tp],
    /// The chip's TMs the TPs are on.
    pub(crate) tms: Range<usize>,
    pub(crate) prog: &'a Program,
    /// `prog`'s instructions with their issue under `cfg`.
    pub(crate) uops: &'a Uops,
    /// The frame's memory as the local phase reads it.
    pub(crate) image: ImageView<'m>,
    pub(crate) placement: &'a Placement,
    pub(crate) cfg: &'a UnitConfig,
    pub(crate) counts: ClassCounts,
}

/// What the TPs share: the frame's memory, and the progress reports.
pub(crate) struct FrameShared<'a, 'm> {
    pub(crate) mem: &'a mut FrameMemory<'m>,
    /// Pixels handed out at the last progress report.
    pub(crate) handed_out: u32,
    pub(crate) progress: &'a mut (dyn FnMut(u32) + Send),
}

impl<'a, 'm: 'a> Lane for Compiled<'a, 'm> {
    type Error = ExecError;
    type Shared = FrameShared<'a, 'm>;

    fn count(&self) -> usize {
        self.tps.len()
    }

    fn tms(&self) -> Range<usize> {
        self.tms.clone()
    }

    #[inline]
    fn tm_of(&self, id: usize) -> usize {
        // The TP's own field, not a division by the TPs per TM.
        self.tps[id].tm() - self.tms.start
    }

    /// Each thread is woken at the cycle its next instruction on a shared unit can issue.
    #[inline]
    fn step(
        &mut self,
        id: usize,
        tm: &mut Tm,
        stalls: &mut Stalls,
        now: Cycle,
    ) -> Result<Wake, ExecError> {
        self.tps[id].run::<false, _, _>(
            self.prog,
            self.uops,
            &mut self.image,
            self.cfg,
            tm,
            stalls,
            None::<(&mut Resident, &mut AtomicUnit)>,
            self.placement,
            &mut self.counts,
            now,
        )
    }

    fn commit(
        &mut self,
        id: usize,
        tm: &mut Tm,
        stalls: &mut Stalls,
        shared: Commit<'_, Self::Shared>,
        now: Cycle,
    ) -> Result<Wake, ExecError> {
        self.tps[id].run::<true, _, _>(
            self.prog,
            self.uops,
            shared.model.mem,
            self.cfg,
            tm,
            stalls,
            Some((shared.l2, shared.atomic)),
            self.placement,
            &mut self.counts,
            now,
        )
    }

    /// Reports the pixels handed out so far (global register 0) every 1024.
    fn after_cycle(shared: &mut Self::Shared) {
        if shared.mem.globals[0] >= shared.handed_out + 1024 {
            shared.handed_out = shared.mem.globals[0];
            (shared.progress)(shared.handed_out);
        }
    }
}

/// Runs `tps` (`cfg.tps_per_tm` per TM, in TM order) to their `ebreak` on `chip` and
/// `host_threads` host threads; returns the end cycle and the instructions executed per
/// class.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_tps(
    chip: &mut Chip,
    tps: &mut [Tp],
    prog: &Program,
    mem: &mut FrameMemory<'_>,
    placement: &Placement,
    cfg: &SimConfig,
    host_threads: usize,
    progress: &mut (dyn FnMut(u32) + Send),
) -> Result<(Cycle, ClassCounts), ExecError> {
    let per_tm = cfg.tps_per_tm as usize;
    let image = mem.view();
    let uops = Uops::new(prog, &cfg.units);
    let mut rest: &mut [Tp] = tps;
    let mut lanes = Vec::new();
    for tms in engine::groups(cfg.tms as usize, host_threads) {
        let n = (tms.len() * per_tm).min(rest.len());
        let (mine, others) = std::mem::take(&mut rest).split_at_mut(n);
        rest = others;
        lanes.push(Compiled {
            tps: mine,
            tms,
            prog,
            uops: &uops,
            image,
            placement,
            cfg: &cfg.units,
            counts: [0; FU_CLASSES],
        });
    }
    let mut shared = FrameShared {
        mem,
        handed_out: 0,
        progress,
    };
    let cycles = engine::run(chip, &mut lanes, &mut shared)?;
    let mut counts: ClassCounts = [0; FU_CLASSES];
    for lane in &lanes {
        for (c, l) in counts.iter_mut().zip(lane.counts) {
            *c += l;
        }
    }
    Ok((cycles, counts))
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
    let mut tps: Vec<Tp> = (0..cfg.tms * cfg.tps_per_tm)
        .map(|i| {
            Tp::new(
                &prog,
                (i / cfg.tps_per_tm) as usize,
                ((i % cfg.tps_per_tm) % cfg.units.icaches) as usize,
                cfg.units.local_store_bytes,
            )
        })
        .collect();
    let mut report = |done: u32| progress((done as u64).min(total), total);
    let (cycles, counts) = run_tps(
        &mut chip,
        &mut tps,
        &prog,
        &mut mem,
        &placement,
        cfg,
        frame.threads,
        &mut report,
    )?;
    progress(total, total);
    let rays = tps.iter().map(Tp::rays).sum();
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
