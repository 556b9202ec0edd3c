//! Calibration of the `fast` thread model against the compiled kernels.
//!
//! The `fast` model replays the real traversal's events ([`Event`]) as macro-ops; what each
//! event costs in instructions is measured here, not counted by hand. For each
//! configuration and workload, [`calibrate`] runs the compiled kernel functionally on the
//! calibration frames ([`FRAMES`]) and cuts its instruction stream into segments: one per
//! pixel (from its `rt.atominc` to its first ray's `rt.setorg`) and one per ray (from its
//! `rt.setorg` to the next segment). For each segment it records
//!
//! * the instructions per class the energy model prices (int, FP add, FP multiply, FP
//!   compare/min-max, reciprocal, local store: [`InstrCounts::from_classes`]), and
//! * the dependency stall cycles of its instruction chain: the cycles an in-order,
//!   single-issue thread waits for an operand from a functional unit's latency
//!   (`units.*_latency` of the configuration; loads and the atomic unit answer at once
//!   here, since the `fast` model times those itself), and
//! * apart from those, the cycles it waits for a ray pipeline's result (ray-box,
//!   ray-triangle, dual-split: `units.box_latency`, `tri_latency`, `dst_latency`). How much
//!   of a pipeline's latency the kernel hides behind independent work is a property of its
//!   code (a serial BVH kernel consumes each box result before the next child's test; the
//!   "+" kernels decode child slots while the wide test runs), so it is measured here and
//!   the `fast` model's pipeline ops time only the pipes' occupancy, and
//! * the words it reads through the L1 (loads and the ray instructions' memory operands,
//!   from the image, the parameter block and the program's constants) beyond the words the
//!   Rust traversal fetches in the same segment: the kernel reads a node's child words
//!   once to find the slot's kind and again in the box test, and each pixel and ray reads
//!   the parameter block. The `fast` model replays them as re-reads (one issue slot and one
//!   L1 access per word, as the TP's word reads).
//!
//! The same frames traced by the Rust traversal give each segment's events (the pixel, the
//! ray's kind, and its traversal events, by [`Recorder`]). A least-squares fit with
//! non-negative coefficients, per class, gives each event's average cost; costs are stored
//! in units of 2^-[`FRAC_BITS`] in `crates/sim/calibration.toml`, which `dualsplit
//! calibrate` writes and a test checks is what this code measures.
//!
//! Because every segment has exactly one of the pixel and the four ray-outcome events,
//! those five act as an intercept: the fitted costs reproduce the calibration frames'
//! total instructions per class (up to the fixed-point rounding).

use crate::accel::SimAccel;
use crate::config::{KernelsConfig, UnitConfig};
use crate::hw::counts::InstrCounts;
use crate::hw::fu::{FU_CLASSES, FuClass, fu_index};
use crate::hw::pipe::TmPipes;
use crate::model::fast::costs::Costs;
use crate::model::fast::costs::{
    Calibration, CalibrationError, DEPENDENCY, FRAC_BITS, L1_WORDS, PIPELINE, TARGET_NAMES,
    TARGETS, Table, workload_name,
};
use crate::model::fast::event::{EVENTS, Event};
use crate::model::fast::recorder::{Recorder, trace_ray};
use crate::model::fast::tally::Tally;
use crate::model::rv32::kernels::{Params, elf};
use crate::model::rv32::{FrameMemory, Hart, LOCAL_STORE_ADDR, Latches, Op, Program, RunError};
use dualsplit_accel::Structures;
use dualsplit_render::{PixelJob, RenderSettings, Workload};
use dualsplit_scene::Scene;
use std::collections::BTreeMap;

/// The calibration frames: builtin scenes (so that anyone can re-measure), an enclosed
/// room and an open forest (rays that miss), at sizes that give every configuration tens
/// of thousands of ray segments.
pub const FRAMES: [(&str, u32, u32); 2] = [
    ("builtin:cornell", 48, 48),
    ("builtin:forest?triangles=20000", 48, 48),
];

/// One measured segment: whether it is a pixel's (not a ray's), and its quantities.
struct Segment {
    pixel: bool,
    y: [i64; TARGETS],
}

/// Runs `prog` functionally on one thread over the whole frame and cuts it into segments.
fn kernel_segments(
    prog: &Program,
    mem: &mut FrameMemory<'_>,
    units: &UnitConfig,
    pipes: TmPipes,
) -> Result<Vec<Segment>, RunError> {
    let mut hart = Hart::new(prog, units.local_store_bytes);
    // The instructions before the first pixel (start-up) form a segment of their own.
    let mut segs = vec![Segment {
        pixel: false,
        y: [0; TARGETS],
    }];
    let mut classes = [0u64; FU_CLASSES];
    // Dependency chain: the cycle each register (and the ray, box and dual-split latches)
    // is ready, and whether a pipeline produces it.
    let mut t = 0u64;
    let mut ready = [(0u64, false); 64];
    let (mut ray_ready, mut box_ready, mut dst_ready) = ((0u64, false), (0u64, true), (0u64, true));
    let flush = |segs: &mut Vec<Segment>, classes: &mut [u64; FU_CLASSES]| {
        let m = InstrCounts::from_classes(classes, &Default::default()).mix;
        let y = &mut segs.last_mut().expect("a segment is open").y;
        for (k, v) in [m.int, m.fpadd, m.fpmul, m.fpcmp, m.fpinv, m.local]
            .into_iter()
            .enumerate()
        {
            y[k] += v as i64;
        }
        *classes = [0; FU_CLASSES];
    };
    loop {
        let Some(ins) = prog.fetch(hart.pc) else {
            // The executor names the faulting pc.
            return Err(hart
                .step(prog, mem)
                .expect_err("fetch outside the text")
                .into());
        };
        let (op, info) = (ins.op, ins.info);
        if info.fu == FuClass::Atomic || op == Op::RtSetOrg {
            flush(&mut segs, &mut classes);
            segs.push(Segment {
                pixel: info.fu == FuClass::Atomic,
                y: [0; TARGETS],
            });
        }
        // The operand the instruction waits for longest (the first such, as the TP
        // attributes it).
        let mut at = (t, false);
        let l = info.latches;
        let latches = [
            (l.has(Latches::READS_RAY), ray_ready),
            (l.has(Latches::READS_BOX), box_ready),
            (l.has(Latches::READS_DST), dst_ready),
        ];
        let regs = info.src.iter().filter_map(|r| r.index()).map(|i| ready[i]);
        for r in regs.chain(latches.into_iter().filter(|x| x.0).map(|x| x.1)) {
            if r.0 > at.0 {
                at = r;
            }
        }
        let y = &mut segs.last_mut().expect("a segment is open").y;
        y[if at.1 { PIPELINE } else { DEPENDENCY }] += (at.0 - t) as i64;
        let at = at.0;
        t = at + 1;
        let r = hart.step(prog, mem)?;
        classes[fu_index(r.info.fu)] += 1;
        let through_l1 = matches!(
            r.info.fu,
            FuClass::Load | FuClass::BoxPipe(_) | FuClass::TriPipe | FuClass::DstPipe
        );
        if through_l1 && r.mem.addr < LOCAL_STORE_ADDR {
            segs.last_mut().expect("a segment is open").y[L1_WORDS] += r.mem.words as i64;
        }
        let done = match r.info.fu {
            FuClass::BoxPipe(_) if pipes.quantized_boxes => (at + units.qbox_latency, true),
            FuClass::BoxPipe(_) => (at + units.box_latency, true),
            FuClass::TriPipe => (at + units.tri_latency, true),
            FuClass::DstPipe if pipes.quantized_dst => (at + units.qdst_latency, true),
            FuClass::DstPipe => (at + units.dst_latency, true),
            fu => (
                crate::hw::fu::unit_latency(fu, units).map_or(0, |l| at + l),
                false,
            ),
        };
        if let Some(i) = r.info.dst.index() {
            ready[i] = done;
        }
        if l.has(Latches::WRITES_RAY) {
            ray_ready = done;
        }
        if l.has(Latches::WRITES_BOX) {
            box_ready = done;
        }
        if l.has(Latches::WRITES_DST) {
            dst_ready = done;
        }
        if hart.halted {
            flush(&mut segs, &mut classes);
            return Ok(segs);
        }
    }
}

/// The traversal's events of the same frame, segment by segment (pixel, then its rays), with
/// the words each segment fetches.
fn event_segments(
    scene: &Scene,
    structures: &Structures,
    accel: SimAccel,
    settings: &RenderSettings,
) -> Vec<(bool, [u64; EVENTS], u64)> {
    let mut segs = Vec::new();
    let mut ops = Vec::new();
    for y in 0..settings.height {
        for x in 0..settings.width {
            let mut pixel = [0; EVENTS];
            pixel[Event::Pixel.index()] = 1;
            segs.push((true, pixel, 0));
            let mut job = PixelJob::new(scene, settings, x, y);
            while let Some(q) = job.next_ray() {
                let mut tally = Tally::new(accel, &Costs::ZERO);
                ops.clear();
                let mut rec = Recorder::new(&mut tally, &mut ops);
                let result = trace_ray(structures, accel, q.kind, &q.ray, &mut rec);
                rec.finish();
                job.submit(result);
                segs.push((false, *tally.events(), tally.counts().loads));
            }
        }
    }
    segs
}

/// Normal equations of a least-squares fit, accumulated segment by segment.
struct Normal {
    xtx: Vec<[f64; EVENTS]>,
    xty: [[f64; EVENTS]; TARGETS],
    yy: [f64; TARGETS],
    y_sum: [f64; TARGETS],
    n: f64,
}

impl Normal {
    fn new() -> Self {
        Self {
            xtx: vec![[0.0; EVENTS]; EVENTS],
            xty: [[0.0; EVENTS]; TARGETS],
            yy: [0.0; TARGETS],
            y_sum: [0.0; TARGETS],
            n: 0.0,
        }
    }

    // Index loops read as the matrix algebra they are.
    #[allow(clippy::needless_range_loop)]
    fn add(&mut self, x: &[u64; EVENTS], y: &[i64; TARGETS]) {
        let nz: Vec<usize> = (0..EVENTS).filter(|&i| x[i] != 0).collect();
        for &i in &nz {
            for &j in &nz {
                self.xtx[i][j] += (x[i] * x[j]) as f64;
            }
            for k in 0..TARGETS {
                self.xty[k][i] += x[i] as f64 * y[k] as f64;
            }
        }
        for k in 0..TARGETS {
            self.yy[k] += (y[k] as f64) * (y[k] as f64);
            self.y_sum[k] += y[k] as f64;
        }
        self.n += 1.0;
    }

    /// Non-negative least squares for quantity `k` (an active-set loop: solve on the events
    /// kept; drop the most negative coefficient or a dependent column; repeat). Events are
    /// kept in index order, so a column that is a combination of earlier ones goes.
    fn solve(&self, k: usize, seen: &[bool; EVENTS]) -> [f64; EVENTS] {
        let mut keep = *seen;
        loop {
            let idx: Vec<usize> = (0..EVENTS).filter(|&i| keep[i]).collect();
            match solve_spd(&self.xtx, &self.xty[k], &idx) {
                Err(dependent) => keep[dependent] = false,
                Ok(beta) => {
                    let worst = idx
                        .iter()
                        .zip(&beta)
                        .filter(|(_, b)| **b < 0.0)
                        .min_by(|a, b| a.1.total_cmp(b.1));
                    if let Some((&i, _)) = worst {
                        keep[i] = false;
                        continue;
                    }
                    let mut out = [0.0; EVENTS];
                    for (&i, b) in idx.iter().zip(beta) {
                        out[i] = b;
                    }
                    return out;
                }
            }
        }
    }

    /// R² of coefficients `b` for quantity `k`.
    fn r2(&self, k: usize, b: &[f64; EVENTS]) -> f64 {
        // Residual sum of squares: y'y − 2 b'X'y + b'X'X b.
        let mut rss = self.yy[k];
        for i in 0..EVENTS {
            rss -= 2.0 * b[i] * self.xty[k][i];
            for j in 0..EVENTS {
                rss += b[i] * self.xtx[i][j] * b[j];
            }
        }
        let mean = self.y_sum[k] / self.n;
        let tss = self.yy[k] - self.n * mean * mean;
        if tss > 0.0 { 1.0 - rss / tss } else { 1.0 }
    }
}

/// Solves `A[idx][idx] β = b[idx]` by Cholesky on the Jacobi-scaled system; `Err(i)` names
/// an event whose column depends on earlier kept ones.
#[allow(clippy::needless_range_loop)]
fn solve_spd(a: &[[f64; EVENTS]], b: &[f64; EVENTS], idx: &[usize]) -> Result<Vec<f64>, usize> {
    let n = idx.len();
    let d: Vec<f64> = idx.iter().map(|&i| a[i][i].sqrt()).collect();
    let mut l = vec![vec![0.0; n]; n];
    for r in 0..n {
        for c in 0..=r {
            let mut s = a[idx[r]][idx[c]] / (d[r] * d[c]);
            for m in 0..c {
                s -= l[r][m] * l[c][m];
            }
            if r == c {
                if s <= 1e-9 {
                    return Err(idx[r]);
                }
                l[r][r] = s.sqrt();
            } else {
                l[r][c] = s / l[c][c];
            }
        }
    }
    let mut z: Vec<f64> = (0..n).map(|r| b[idx[r]] / d[r]).collect();
    for r in 0..n {
        for m in 0..r {
            z[r] -= l[r][m] * z[m];
        }
        z[r] /= l[r][r];
    }
    for r in (0..n).rev() {
        for m in r + 1..n {
            z[r] -= l[m][r] * z[m];
        }
        z[r] /= l[r][r];
    }
    Ok(z.iter().zip(&d).map(|(v, s)| v / s).collect())
}

/// Measures the costs of every configuration and workload on `frames` (scene spec, its
/// scene and structures, width, height) with the latencies of `units`; `progress` is told
/// each table as it starts.
pub fn calibrate(
    frames: &[(&str, &Scene, &Structures, u32, u32)],
    units: &UnitConfig,
    config_name: &str,
    progress: &mut dyn FnMut(SimAccel, Workload),
) -> Result<Calibration, CalibrationError> {
    let mut tables = Vec::new();
    for workload in [Workload::Cast, Workload::Path] {
        for accel in SimAccel::ALL {
            progress(accel, workload);
            tables.push(measure(frames, accel, workload, units)?);
        }
    }
    Ok(Calibration {
        frac_bits: FRAC_BITS,
        config: config_name.to_string(),
        frames: frames
            .iter()
            .map(|(name, _, _, w, h)| (name.to_string(), *w, *h))
            .collect(),
        tables,
    })
}

fn measure(
    frames: &[(&str, &Scene, &Structures, u32, u32)],
    accel: SimAccel,
    workload: Workload,
    units: &UnitConfig,
) -> Result<Table, CalibrationError> {
    let prog = Program::from_elf(elf(accel, workload, KernelsConfig::default()))?;
    let mut normal = Normal::new();
    let (mut seen, mut instructions) = ([false; EVENTS], 0);
    let (mut measured, mut counts) = ([0i128; TARGETS], [0u64; EVENTS]);
    for &(name, scene, structures, w, h) in frames {
        let settings = RenderSettings::new(w, h, workload);
        let params = Params::new(scene, structures, accel, &settings);
        let mut mem = FrameMemory::new(
            structures.image(accel.kind()),
            params.as_bytes(),
            params.frame_bytes(),
        );
        let error = |source| CalibrationError::Run {
            accel: accel.name(),
            workload: workload_name(workload),
            scene: name.to_string(),
            source,
        };
        let kernel = kernel_segments(&prog, &mut mem, units, accel.pipes(units)).map_err(error)?;
        let events = event_segments(scene, structures, accel, &settings);
        // The kernel's segments: start-up, then per pixel its own and its rays', then the
        // last `rt.atominc` that finds no pixel left.
        let inner = kernel.get(1..kernel.len().saturating_sub(1)).unwrap_or(&[]);
        if inner.len() != events.len() || inner.iter().zip(&events).any(|(k, e)| k.pixel != e.0) {
            return Err(CalibrationError::Segments {
                accel: accel.name(),
                workload: workload_name(workload),
                scene: name.to_string(),
                kernel: inner.len(),
                traversal: events.len(),
            });
        }
        instructions += prog_instructions(&kernel);
        for (k, (_, x, fetched)) in inner.iter().zip(&events) {
            let mut y = k.y;
            y[L1_WORDS] -= *fetched as i64;
            normal.add(x, &y);
            for (i, &n) in x.iter().enumerate() {
                seen[i] |= n != 0;
                counts[i] += n;
            }
            for (t, &v) in measured.iter_mut().zip(&y) {
                *t += v as i128;
            }
        }
    }
    let mut cost = BTreeMap::new();
    let mut fixed = [[0u32; TARGETS]; EVENTS];
    let (mut r2, mut total_error) = ([0.0; TARGETS], [0.0; TARGETS]);
    for k in 0..TARGETS {
        let beta = normal.solve(k, &seen);
        r2[k] = round6(normal.r2(k, &beta));
        for (e, b) in beta.iter().enumerate() {
            fixed[e][k] = (b * (1 << FRAC_BITS) as f64).round() as u32;
        }
    }
    let costs = Costs::from_fixed(fixed);
    let fitted = costs.totals(&counts);
    for k in 0..TARGETS {
        let m = measured[k] as f64;
        total_error[k] = if m > 0.0 {
            round6(fitted[k] as f64 / m - 1.0)
        } else {
            0.0
        };
    }
    let mut unseen = Vec::new();
    for e in Event::all() {
        if seen[e.index()] {
            cost.insert(e.name(), fixed[e.index()]);
        } else if matches!(e, Event::Dst(..)) == accel.is_dst() {
            unseen.push(e.name());
        }
    }
    Ok(Table {
        accel,
        workload: workload_name(workload).to_string(),
        segments: normal.n as u64,
        instructions,
        total_error,
        r2,
        unseen,
        cost,
    })
}

/// Instructions of all segments (the pixel hand-outs', rays', start-up and end).
fn prog_instructions(segs: &[Segment]) -> u64 {
    segs.iter()
        .map(|s| s.y[..DEPENDENCY].iter().sum::<i64>() as u64)
        .sum()
}

/// `x` rounded to 6 decimals (the file records fit quality, not noise).
fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// The calibration file's text for `c`.
pub fn to_toml(c: &Calibration) -> Result<String, CalibrationError> {
    let body = toml::to_string(c).map_err(|e| CalibrationError::Format(e.to_string()))?;
    Ok(format!(
        "# Costs of the `fast` thread model's events, measured from the compiled kernels by\n\
         # `dualsplit calibrate` (crates/sim/src/model/fast/calibrate.rs). Do not edit: re-measure.\n\
         # Per event: {} in 1/{} units.\n\n{body}",
        TARGET_NAMES.join(", "),
        1 << FRAC_BITS
    ))
}
