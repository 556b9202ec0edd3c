//! The `simt` model's frame: warps of consecutive pixels on SMs, each warp costed in
//! lockstep outside the RT unit and traced in it.
//!
//! Warp `k` holds pixels `32k … 32k + 31` in scanline order (the launch index's x
//! fastest). Warps start on the SMs round-robin, one per SM in turn, until every SM's
//! warp slots are full; a warp that finishes makes room for the next. A warp alternates
//! between the SM's schedulers and the RT unit: it pays, on its scheduler, the issue cycles
//! of its slowest thread's non-traversal work (its pixel's set-up, then each ray's
//! outcome: shading, sky, light), then every thread with a ray left traces it in the RT
//! unit together ([`super::rt_unit`]).

use crate::error::SimError;
use crate::model::fast::costs::{self, Costs, FRAC_BITS};
use crate::model::fast::event::Event;
use crate::model::simt::SimtFigures;
use crate::model::simt::config::SimtConfig;
use crate::model::simt::mem::Memory;
use crate::model::simt::rt_unit::{RtUnit, RtWarp, lane};
use crate::model::simt::txn::{TxnKind, TxnRecorder};
use crate::request::FrameRequest;
use crate::request::ThreadModel;
use crate::result::SimResult;
use dualsplit_accel::TraversalSet;
use dualsplit_render::{PixelJob, RayKind, TraceResult};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// A thread of a warp: its pixel and the issue cycles its next shading phase costs.
struct Thread<'a> {
    px: u64,
    job: PixelJob<'a>,
    /// Fixed point (2^-FRAC_BITS cycles).
    cost: u64,
    live: bool,
}

/// A warp slot's warp.
struct Warp<'a> {
    threads: Vec<Thread<'a>>,
}

/// One SM: its warp slots, when each scheduler is next free, the warps whose shading ends
/// (cycle, slot), and its RT unit.
struct Sm<'a> {
    slots: Vec<Option<Warp<'a>>>,
    sched_free: Vec<u64>,
    shading: BinaryHeap<Reverse<(u64, usize)>>,
    rt: RtUnit,
}

/// Frame-wide counters outside the RT unit.
#[derive(Default)]
struct Counts {
    rays: u64,
    txns: u64,
    chunks: u64,
    by_kind: [u64; 4],
    phases: u64,
    divergent_phases: u64,
    /// Sum of threads' issue cycles and of warp size × slowest thread's, fixed point.
    lane_cost: u128,
    warp_cost: u128,
    shading_cycles: u64,
}

struct Frame<'a, S> {
    req: &'a FrameRequest<'a, S>,
    c: &'a SimtConfig,
    costs: &'static Costs,
    next_warp: u64,
    warps_total: u64,
    radiance: Vec<f32>,
    counts: Counts,
    chunk: u64,
}

impl<'a, S: TraversalSet> Frame<'a, S> {
    /// Starts the next warp in slot `slot` of `sm` at `now`; false when no pixel is left.
    fn launch(&mut self, sm: &mut Sm<'a>, slot: usize, now: u64) -> bool {
        if self.next_warp >= self.warps_total {
            return false;
        }
        let k = self.next_warp;
        self.next_warp += 1;
        let (w, total) = (self.req.settings.width as u64, self.req.pixels());
        let pixel = self.costs.cycles(Event::Pixel.index());
        let threads = (0..self.c.warp_size as u64)
            .map(|i| k * self.c.warp_size as u64 + i)
            .filter(|&px| px < total)
            .map(|px| Thread {
                px,
                job: PixelJob::new(
                    self.req.scene,
                    self.req.settings,
                    (px % w) as u32,
                    (px / w) as u32,
                ),
                cost: pixel,
                live: true,
            })
            .collect();
        sm.slots[slot] = Some(Warp { threads });
        self.shade(sm, slot, now);
        true
    }

    /// The warp in `slot` starts its shading phase at `now` on its scheduler.
    fn shade(&mut self, sm: &mut Sm<'a>, slot: usize, now: u64) {
        let Some(w) = &sm.slots[slot] else {
            return;
        };
        let live = w.threads.iter().filter(|t| t.live).count();
        let max = w
            .threads
            .iter()
            .filter(|t| t.live)
            .map(|t| t.cost)
            .max()
            .unwrap_or(0);
        let sum: u64 = w.threads.iter().filter(|t| t.live).map(|t| t.cost).sum();
        let c = &mut self.counts;
        c.phases += 1;
        if live < self.c.warp_size as usize || sum != max * live as u64 {
            c.divergent_phases += 1;
        }
        c.lane_cost += sum as u128;
        c.warp_cost += max as u128 * self.c.warp_size as u128;
        let cycles = max.div_ceil(1 << FRAC_BITS);
        c.shading_cycles += cycles;
        let s = slot % sm.sched_free.len();
        let start = now.max(sm.sched_free[s]);
        sm.sched_free[s] = start + cycles;
        sm.shading.push(Reverse((start + cycles, slot)));
    }

    /// The warp in `slot` ends its shading phase at `now`: its threads with a ray left
    /// trace it (functionally, recording their transactions) and the warp goes to the RT
    /// unit; a warp with none left is done and the next starts in its slot.
    fn trace(&mut self, sm: &mut Sm<'a>, slot: usize, now: u64) -> Result<(), SimError> {
        let Some(w) = &mut sm.slots[slot] else {
            return Ok(());
        };
        let (structures, accel) = (self.req.structures, self.req.accel);
        let k = accel.kind();
        let dual_split = accel.is_dst();
        let mut rec = TxnRecorder::new();
        let mut lanes = Vec::with_capacity(w.threads.len());
        let mut active = 0;
        for t in &mut w.threads {
            let q = if t.live { t.job.next_ray() } else { None };
            let Some(q) = q else {
                if t.live {
                    self.radiance[t.px as usize] = t.job.radiance();
                    t.live = false;
                }
                lanes.push(lane(Vec::new()));
                continue;
            };
            active += 1;
            let (result, event) = match q.kind {
                RayKind::Shadow => {
                    let blocked = structures.any_hit(k, &q.ray, &mut rec);
                    let e = if blocked {
                        Event::ShadowBlocked
                    } else {
                        Event::ShadowLit
                    };
                    (TraceResult::Occluded(blocked), e)
                }
                RayKind::Primary | RayKind::Diffuse => {
                    let hit = structures.closest_hit(k, &q.ray, &mut rec);
                    let e = if hit.is_some() {
                        Event::ClosestHit
                    } else {
                        Event::ClosestMiss
                    };
                    (TraceResult::Closest(hit), e)
                }
            };
            t.job.submit(result);
            t.cost = self.costs.cycles(event.index());
            let txns = rec.take(dual_split);
            let c = &mut self.counts;
            c.rays += 1;
            c.txns += txns.len() as u64;
            for x in &txns {
                c.by_kind[x.kind as usize] += 1;
                c.chunks += (x.addr + x.bytes as u64 - 1) / self.chunk - x.addr / self.chunk + 1;
            }
            lanes.push(lane(txns));
        }
        if active == 0 {
            sm.slots[slot] = None;
            self.launch(sm, slot, now);
            return Ok(());
        }
        sm.rt.submit(RtWarp::new(slot, lanes, active), now);
        Ok(())
    }

    /// Everything `sm` has to do at `now`.
    fn step(&mut self, sm: &mut Sm<'a>, now: u64, mem: &mut Memory) -> Result<(), SimError> {
        let mut done = Vec::new();
        sm.rt.cycle(now, mem, &mut done);
        for (w, _) in done {
            self.shade(sm, w.slot, now);
        }
        while let Some(Reverse((at, slot))) = sm.shading.peek().copied() {
            if at > now {
                break;
            }
            sm.shading.pop();
            self.trace(sm, slot, now)?;
        }
        Ok(())
    }
}

/// Simulates `frame` on the `simt` model.
pub(crate) fn run<S: TraversalSet>(
    frame: &FrameRequest<'_, S>,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<SimResult, SimError> {
    let c = frame.cfg.simt.as_ref().ok_or(SimError::NoSimtChip)?;
    c.validate()?;
    let costs = costs::costs(frame.accel, frame.settings.workload)?;
    let total = frame.pixels();
    let mut f = Frame {
        req: frame,
        c,
        costs,
        next_warp: 0,
        warps_total: total.div_ceil(c.warp_size as u64),
        radiance: vec![0.0; total as usize],
        counts: Counts::default(),
        chunk: c.chunk_bytes as u64,
    };
    let mut mem = Memory::new(c);
    let mut sms: Vec<Sm> = (0..c.sms)
        .map(|_| Sm {
            slots: (0..c.warps_per_sm).map(|_| None).collect(),
            sched_free: vec![0; c.schedulers_per_sm as usize],
            shading: BinaryHeap::new(),
            rt: RtUnit::new(c),
        })
        .collect();
    // Round-robin start: one warp per SM in turn.
    'fill: for slot in 0..c.warps_per_sm as usize {
        for sm in sms.iter_mut() {
            if !f.launch(sm, slot, 0) {
                break 'fill;
            }
        }
    }
    let mut now = 0u64;
    let mut wake = vec![0u64; sms.len()];
    let mut last_progress = 0;
    loop {
        let mut next = u64::MAX;
        for (i, sm) in sms.iter_mut().enumerate() {
            if wake[i] <= now {
                f.step(sm, now, &mut mem)?;
                let shade = sm.shading.peek().map_or(u64::MAX, |Reverse((t, _))| *t);
                wake[i] = sm.rt.next_wake(now).min(shade.max(now + 1));
            }
            next = next.min(wake[i]);
        }
        if f.next_warp / 64 != last_progress {
            last_progress = f.next_warp / 64;
            progress((f.next_warp * c.warp_size as u64).min(total), total);
        }
        if next == u64::MAX {
            break;
        }
        now = next;
    }
    if sms
        .iter()
        .any(|sm| sm.rt.busy() || sm.slots.iter().any(Option::is_some))
    {
        return Err(SimError::SimtStuck { cycle: now });
    }
    progress(total, total);
    let cycles = now;
    let rt = sms.iter().fold(
        Default::default(),
        |mut a: crate::model::simt::rt_unit::RtCounts, sm| {
            let r = &sm.rt.counts;
            a.warp_cycles += r.warp_cycles;
            a.active_lane_cycles += r.active_lane_cycles;
            a.visits += r.visits;
            a.wait_cycles += r.wait_cycles;
            a.sent += r.sent;
            a.chunks += r.chunks;
            a.l1_hits += r.l1_hits;
            a.l1_merged += r.l1_merged;
            a.mshr_stall_cycles += r.mshr_stall_cycles;
            a
        },
    );
    let m = mem.counts;
    let k = &f.counts;
    let rays = k.rays.max(1) as f64;
    let ratio = |a: u64, b: u64| if b == 0 { 0.0 } else { a as f64 / b as f64 };
    let dram_bytes = m.dram_reads * mem.sector_bytes();
    let figures = SimtFigures {
        sms: c.sms,
        rt_max_warps: c.rt_max_warps,
        rt_max_mshr: c.rt_max_mshr,
        rt_occupancy: ratio(
            rt.warp_cycles,
            cycles.max(1) * c.sms as u64 * c.rt_max_warps as u64,
        ),
        rt_simt_efficiency: ratio(rt.active_lane_cycles, rt.warp_cycles * c.warp_size as u64),
        shading_simt_efficiency: if k.warp_cost == 0 {
            0.0
        } else {
            k.lane_cost as f64 / k.warp_cost as f64
        },
        shading_phases: k.phases,
        divergent_phases: k.divergent_phases,
        rt_visits: rt.visits,
        rt_wait_cycles: rt.wait_cycles,
        mshr_stall_cycles: rt.mshr_stall_cycles,
        transactions_per_ray: k.txns as f64 / rays,
        chunks_per_ray: k.chunks as f64 / rays,
        requests_per_ray: rt.chunks as f64 / rays,
        transactions_by_kind: TxnKind::NAMES
            .iter()
            .zip(k.by_kind)
            .map(|(n, v)| (n.to_string(), v))
            .collect(),
        l1_requests: rt.chunks,
        l1_hits: rt.l1_hits,
        l1_merged: rt.l1_merged,
        l2_accesses: m.l2_accesses,
        l2_hits: m.l2_hits,
        dram_reads: m.dram_reads,
        dram_activations: m.dram_activations,
        dram_bytes,
        dram_bytes_per_ray: dram_bytes as f64 / rays,
        dram_gb_per_s: dram_bytes as f64 / (cycles.max(1) as f64 / (c.core_mhz * 1e6)) / 1e9,
    };
    Ok(SimResult {
        accel: Some(frame.accel),
        thread_model: ThreadModel::Simt,
        tms: c.sms,
        threads: c.sms * c.warps_per_sm * c.warp_size,
        cycles,
        frame_ms: cycles as f64 / (c.core_mhz * 1e3),
        dram_lines: dram_bytes / 64,
        dram_activations: m.dram_activations,
        row_hit_rate: ratio(m.dram_row_hits, m.dram_reads),
        l1_hit_rate: ratio(rt.l1_hits, rt.chunks),
        l2_hit_rate: ratio(m.l2_hits, m.l2_accesses),
        rays: k.rays,
        pixels: total,
        caches: crate::hw::memory::CacheStats {
            l1_accesses: rt.chunks,
            l1_hits: rt.l1_hits,
            l1_merged: rt.l1_merged,
            l2_accesses: m.l2_accesses,
            l2_hits: m.l2_hits,
            ..Default::default()
        },
        dram: crate::hw::memory::dram::DramStats {
            reads: m.dram_reads,
            activations: m.dram_activations,
            row_hits: m.dram_row_hits,
            ..Default::default()
        },
        radiance: f.radiance,
        simt: Some(figures),
        ..SimResult::default()
    })
}
