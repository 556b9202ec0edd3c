//! The workload: threads take pixels from a global atomic counter in scanline order and run
//! each pixel's [`PixelJob`] through the real traversal with a [`Recorder`] (Lin et al.
//! 2020, §4.3–4.4). Ray paths do not depend on timing, so tracing them functionally and
//! replaying the recorded ops is exact.

use crate::accel::SimAccel;
use crate::config::KernelsConfig;
use crate::error::SimError;
use crate::hw::atomic::AtomicUnit;
use crate::hw::{Chip, Stall, Stalls};
use crate::model::fast::costs;
use crate::model::fast::event::Event;
use crate::model::fast::op::Op;
use crate::model::fast::recorder::{Recorder, Run, trace_ray};
use crate::model::fast::replay::{self, WorkSource};
use crate::model::fast::tally::Tally;
use crate::model::fast::thread::Thread;
use crate::model::rv32::Program;
use crate::model::rv32::kernels::{Params, elf, placement};
use crate::request::{FrameRequest, ThreadModel};
use crate::result::SimResult;
use dualsplit_accel::TraversalSet;
use dualsplit_render::{PixelJob, RenderSettings};
use dualsplit_scene::Scene;

/// The pixel a thread is working on: its job (the renderer's path state) and the Issue op
/// held back from its last ray's program.
struct Active<'a> {
    px: u64,
    job: PixelJob<'a>,
    /// The trailing instruction run of the previous ray's ops, not yet written: the
    /// recorder merges the next ray's set-up into it, exactly as when the whole pixel is
    /// recorded into one program.
    carry: Option<Run>,
    /// Its pixel event is not charged yet (it is, with the first ray's instructions).
    first: bool,
}

/// What tracing a ray needs and gathers: the structures and configuration, the rays and
/// the recorders' tally (counts and the first range error: no work is handed out after
/// one).
struct Tracer<'a, S> {
    structures: &'a S,
    accel: SimAccel,
    rays: u64,
    tally: Tally,
}

struct Pixels<'a, S> {
    scene: &'a Scene,
    settings: &'a RenderSettings,
    next: u64,
    total: u64,
    radiance: Vec<f32>,
    progress: &'a (dyn Fn(u64, u64) + Sync),
    /// Per thread: the pixel it is working on (updated in place, not moved per ray).
    active: Vec<Option<Active<'a>>>,
    tracer: Tracer<'a, S>,
}

impl<'a, S: TraversalSet> Tracer<'a, S> {
    /// Records the next ray of `a`'s pixel into `ops`, continuing the instruction run carried
    /// from its previous ray; false when the pixel has no ray left.
    #[inline]
    fn trace_ray(&mut self, a: &mut Active<'a>, ops: &mut Vec<Op>) -> bool {
        let Some(q) = a.job.next_ray() else {
            return false;
        };
        let mut rec = Recorder::resume(&mut self.tally, ops, a.carry.take());
        if a.first {
            rec.event(Event::Pixel);
            a.first = false;
        }
        self.rays += 1;
        let result = trace_ray(self.structures, self.accel, q.kind, &q.ray, &mut rec);
        // The ray's last instructions stay open for the next ray of the pixel.
        a.carry = rec.finish_open();
        a.job.submit(result);
        true
    }
}

impl<S: TraversalSet> WorkSource for Pixels<'_, S> {
    /// Hands out one ray's ops at a time (a pixel's rays follow one another on the same
    /// thread, the pixel taken from the global counter first): the same op sequence as the
    /// whole pixel recorded at once, but a thread's program stays small, so the replay's
    /// host memory traffic stays in cache.
    fn next(
        &mut self,
        id: usize,
        thread: &mut Thread,
        atomic: &mut AtomicUnit,
        stalls: &mut Stalls,
    ) -> Option<Vec<Op>> {
        if self.tracer.tally.error().is_some() {
            return None;
        }
        // The thread's finished program's buffer is reused for its next one.
        let mut ops = thread.take_ops();
        ops.clear();
        if let Some(a) = &mut self.active[id] {
            if self.tracer.trace_ray(a, &mut ops) {
                return self.tracer.tally.error().is_none().then_some(ops);
            }
            self.radiance[a.px as usize] = a.job.radiance();
            let carry = a.carry;
            self.active[id] = None;
            if let Some(op) = carry.and_then(Run::op) {
                // The pixel's last instructions.
                ops.push(op);
                return Some(ops);
            }
        }
        if self.next >= self.total {
            return None;
        }
        thread.atomic(atomic, stalls);
        self.tracer.tally.atomic();
        let px = self.next;
        self.next += 1;
        let w = self.settings.width as u64;
        let (x, y) = ((px % w) as u32, (px / w) as u32);
        let a = self.active[id].insert(Active {
            px,
            job: PixelJob::new(self.scene, self.settings, x, y),
            carry: None,
            first: true,
        });
        if !self.tracer.trace_ray(a, &mut ops) {
            self.radiance[px as usize] = a.job.radiance();
            self.active[id] = None;
        }
        if self.next.is_multiple_of(1024) || self.next == self.total {
            (self.progress)(self.next, self.total);
        }
        self.tracer.tally.error().is_none().then_some(ops)
    }
}

/// Simulates `frame` on the `fast` model.
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
    let total = frame.pixels();
    // The compiled kernel's placement of the frame's regions, so that the replayed loads
    // meet the caches where the kernel's do.
    let params = Params::new(scene, structures, accel, settings);
    let placement = placement(
        &params,
        &Program::from_elf(elf(accel, settings.workload, KernelsConfig::default()))?,
        structures.image(accel.kind()),
        cfg.l1.line_bytes,
    );
    let mut chip = Chip::new(cfg, accel.pipes(&cfg.units));
    let mut threads: Vec<Thread> = (0..cfg.tms * cfg.tps_per_tm)
        .map(|i| Thread::new((i / cfg.tps_per_tm) as usize))
        .collect();
    let mut work = Pixels {
        scene,
        settings,
        next: 0,
        total,
        radiance: vec![0.0; total as usize],
        progress,
        active: (0..threads.len()).map(|_| None).collect(),
        tracer: Tracer {
            structures,
            accel,
            rays: 0,
            tally: Tally::new(accel, costs::costs(accel, settings.workload)?)
                .placed_at(placement.image_base(), (params.as_bytes().len() / 4) as u16),
        },
    };
    let cycles = replay::run_with(&mut chip, &mut threads, &mut work, true, frame.threads);
    if let Some(e) = work.tracer.tally.error() {
        return Err(e.into());
    }
    // The measured dependency stalls are part of the issue runs the threads replayed.
    let mut stats = chip.stats();
    stats
        .stalls
        .count(Stall::Dependency, work.tracer.tally.dependency_cycles());
    stats
        .stalls
        .count(Stall::PipelineLatency, work.tracer.tally.pipeline_cycles());
    Ok(SimResult::assemble(
        accel,
        ThreadModel::Fast,
        cfg,
        cycles,
        stats,
        work.tracer.tally.counts(),
        work.tracer.rays,
        total,
        work.radiance,
    ))
}
