//! What `dualsplit simulate` computes and prints, shared by the command line and the
//! Python package so both give the same JSON: the checks made before a scene is loaded
//! ([`check_frame`]), the frames simulated two configurations at a time ([`simulate_frames`]),
//! the comparison of several configurations ([`summarize`]: frame time, energy and DRAM
//! lines, each also as a fraction of a baseline, BVH2 when it was simulated, else the first
//! configuration; per-ray work; where the threads' cycles went) and the JSON document
//! ([`SimulateJson`]).
use crate::units;
use dualsplit_accel::TraversalSet;
use dualsplit_render::{RenderError, RenderSettings, Workload};
use dualsplit_scene::Scene;
use dualsplit_sim::{
    MemoryFigures, SimAccel, SimConfig, SimError, SimResult, StallShares, ThreadModel,
};
use serde::Serialize;
use std::time::{Duration, Instant};

/// Why a `simulate` run stopped.
#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    /// The frame or the camera breaks the renderer's limits.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The configuration or the frame does not fit the simulator.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// One configuration's simulation failed.
    #[error("simulating {accel}")]
    Frame {
        /// The configuration's label.
        accel: &'static str,
        /// What failed.
        #[source]
        source: SimError,
    },
}

/// The checks made before the scene is loaded: `cfg` is valid, the frame obeys the
/// renderer's limits, and the chip and frame fit the simulator's memory bound for every
/// configuration.
pub fn check_frame(
    cfg: &SimConfig,
    settings: &RenderSettings,
    model: ThreadModel,
) -> Result<(), SimulateError> {
    cfg.validate().map_err(SimError::from)?;
    dualsplit_sim::check_model(cfg, model)?;
    dualsplit_render::validate_frame(settings)?;
    let pixels = settings.width as u64 * settings.height as u64;
    for accel in SimAccel::ALL {
        dualsplit_sim::footprint::check(cfg, accel, model, pixels).map_err(SimError::from)?;
    }
    Ok(())
}

/// Simulates one frame of `settings` per configuration in `accels` on `threads` host
/// threads in all, frames side by side and threads shared among them
/// ([`dualsplit_sim::share_threads`]; results do not depend on either), after checking the
/// camera against the renderer's limits. Each result comes with its
/// host wall time (a measurement of this machine, never part of a result). `progress` is
/// called with (configuration, pixels done, pixels total).
#[allow(clippy::too_many_arguments)]
pub fn simulate_frames<S: TraversalSet + Sync>(
    model: ThreadModel,
    scene: &Scene,
    structures: &S,
    accels: &[SimAccel],
    settings: &RenderSettings,
    cfg: &SimConfig,
    threads: usize,
    progress: &(dyn Fn(SimAccel, u64, u64) + Sync),
) -> Result<Vec<(SimResult, Duration)>, SimulateError> {
    let (workers, per_frame) = dualsplit_sim::share_threads(accels.len(), threads);
    dualsplit_render::validate(scene, settings)?;
    let sim_one = |accel: SimAccel| -> Result<(SimResult, Duration), SimulateError> {
        let t0 = Instant::now();
        let r = dualsplit_sim::simulate(
            &dualsplit_sim::FrameRequest::new(scene, structures, accel, settings, cfg)
                .with_model(model)
                .with_threads(per_frame),
            &|done, total| progress(accel, done, total),
        )
        .map_err(|source| SimulateError::Frame {
            accel: accel.label(),
            source,
        })?;
        Ok((r, t0.elapsed()))
    };
    let mut results = Vec::with_capacity(accels.len());
    for pair in accels.chunks(workers) {
        let out: Vec<Result<(SimResult, Duration), SimulateError>> = std::thread::scope(|s| {
            let handles: Vec<_> = pair
                .iter()
                .map(|&a| {
                    let f = &sim_one;
                    s.spawn(move || f(a))
                })
                .collect();
            handles
                .into_iter()
                .map(|h| h.join().expect("simulation thread panicked"))
                .collect()
        });
        for r in out {
            results.push(r?);
        }
    }
    Ok(results)
}

/// `simulate --json`: what was simulated and every number of the tables (host timings aside:
/// they are measurements of this machine, not results).
#[derive(Clone, Debug, Serialize)]
pub struct SimulateJson<'a> {
    /// The scene's name.
    pub scene: &'a str,
    /// The spec it was loaded from.
    pub spec: &'a str,
    /// Its triangle count.
    pub triangles: usize,
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// The workload.
    pub workload: Workload,
    /// The thread model.
    pub thread_model: ThreadModel,
    /// The camera (after overrides).
    pub camera: &'a dualsplit_scene::Camera,
    /// The light (after overrides).
    pub light: &'a dualsplit_scene::Light,
    /// The hardware configuration.
    pub config: &'a SimConfig,
    /// One result per configuration, in the order simulated.
    pub results: Vec<&'a SimResult>,
    /// Their comparison.
    pub summary: Summary,
    /// The paper's published values for this scene and workload (Table 4 for ray casting,
    /// Table 5 for path tracing), when the scene is the paper's own (SimTRaX's Dragon Box,
    /// Crytek Sponza): one per paper configuration simulated, beside ours in `summary`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub paper: Option<PaperBeside>,
}

/// The paper's absolute values for one scene and workload, beside a `simulate` run's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PaperBeside {
    /// `Table 4` (ray casting) or `Table 5` (path tracing).
    pub table: &'static str,
    /// The paper's scene.
    pub scene: &'static str,
    /// What the paper states about the frame those values are of.
    pub frame: &'static str,
    /// One row per simulated configuration of the paper's eight, in the order simulated.
    pub rows: Vec<PaperRow>,
}

/// One configuration's published values, in the paper's units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PaperRow {
    /// The configuration.
    pub accel: SimAccel,
    /// Frame time (ms).
    pub frame_ms: f64,
    /// Energy per frame (J).
    pub energy_j: f64,
    /// DRAM lines read, in millions.
    pub dram_mlines: f64,
    /// Our frame time / the paper's.
    pub ours_frame_vs_paper: Option<f64>,
    /// Our energy / the paper's.
    pub ours_energy_vs_paper: Option<f64>,
    /// Our DRAM lines / the paper's.
    pub ours_dram_lines_vs_paper: Option<f64>,
}

/// The paper's values beside `results` when `paper` is the paper's own scene (not a
/// stand-in, not the reconstructed Dragon Box); `None` otherwise.
pub fn paper_beside(
    paper: Option<crate::paper::PaperMatch>,
    workload: Workload,
    results: &[&SimResult],
) -> Option<PaperBeside> {
    use crate::paper::{Metric, table45};
    let m = paper.filter(|m| m.same_mesh && !m.reconstructed)?;
    let (table, frame) = match workload {
        Workload::Path => (
            "Table 5",
            "path tracing, five diffuse bounces, 64 TMs; the paper states no resolution",
        ),
        _ => (
            "Table 4",
            "ray casting with a shadow ray, 1024×1024, one sample per pixel, 64 TMs",
        ),
    };
    let rows: Vec<PaperRow> = results
        .iter()
        .filter_map(|r| r.accel.filter(|a| a.in_paper()).map(|a| (a, r)))
        .map(|(a, r)| {
            let v = |metric| table45(workload, metric, a, m.scene);
            let (ms, j, ml) = (v(Metric::FrameMs), v(Metric::EnergyJ), v(Metric::DramLines));
            PaperRow {
                accel: a,
                frame_ms: ms,
                energy_j: j,
                dram_mlines: ml,
                ours_frame_vs_paper: ratio(r.frame_ms, ms),
                ours_energy_vs_paper: ratio(r.energy.total(), j),
                ours_dram_lines_vs_paper: ratio(r.dram_lines as f64 / 1e6, ml),
            }
        })
        .collect();
    (!rows.is_empty()).then(|| PaperBeside {
        table,
        scene: m.scene.label(),
        frame,
        rows,
    })
}

impl<'a> SimulateJson<'a> {
    /// The document for `results`, simulated from `scene` with `settings`, `model` and `cfg`.
    pub fn new(
        scene: &'a Scene,
        settings: &RenderSettings,
        model: ThreadModel,
        cfg: &'a SimConfig,
        results: Vec<&'a SimResult>,
    ) -> Self {
        let summary = summarize(&results);
        let paper = crate::paper::PaperMatch::for_scene(&scene.name, &scene.spec)
            .map(|m| m.with_bounds(&scene.bounds));
        let paper = paper_beside(paper, settings.workload, &results);
        Self {
            scene: &scene.name,
            spec: &scene.spec,
            triangles: scene.triangles.len(),
            width: settings.width,
            height: settings.height,
            workload: settings.workload,
            thread_model: model,
            camera: &scene.camera,
            light: &scene.light,
            config: cfg,
            results,
            summary,
            paper,
        }
    }

    /// The document as pretty-printed JSON, as `simulate --json` prints it.
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        serde_json::to_string_pretty(self)
    }
}

/// One configuration's row of the comparison (every number of the printed tables except
/// host timings).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    /// The configuration.
    pub accel: Option<SimAccel>,
    /// Frame time (ms).
    pub frame_ms: f64,
    /// Frame time / the baseline's.
    pub frame_vs_baseline: Option<f64>,
    /// Total energy (J).
    pub energy_j: f64,
    /// Energy / the baseline's.
    pub energy_vs_baseline: Option<f64>,
    /// 64-byte DRAM lines read.
    pub dram_lines: u64,
    /// DRAM lines / the baseline's.
    pub dram_lines_vs_baseline: Option<f64>,
    /// Instructions per ray.
    pub instructions_per_ray: f64,
    /// Thread-cycles (cycles × threads) per ray.
    pub thread_cycles_per_ray: f64,
    /// Where the thread-cycles went.
    pub stalls: StallShares,
    /// The memory system's figures.
    pub memory: MemoryFigures,
}

/// The comparison: the baseline and one row per configuration, in the order simulated.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// The configuration the ratios divide by.
    pub baseline: Option<SimAccel>,
    /// One row per configuration.
    pub rows: Vec<Row>,
}

fn ratio(v: f64, base: f64) -> Option<f64> {
    (base > 0.0).then(|| v / base)
}

/// The comparison of `results`: BVH2 is the baseline when present, else the first result.
pub fn summarize(results: &[&SimResult]) -> Summary {
    let base = results
        .iter()
        .find(|r| r.accel == Some(SimAccel::Bvh2))
        .or_else(|| results.first())
        .copied();
    let rows = results
        .iter()
        .map(|r| {
            let rays = r.rays.max(1) as f64;
            let rel = |f: fn(&SimResult) -> f64| base.and_then(|b| ratio(f(r), f(b)));
            Row {
                accel: r.accel,
                frame_ms: r.frame_ms,
                frame_vs_baseline: rel(|x| x.frame_ms),
                energy_j: r.energy.total(),
                energy_vs_baseline: rel(|x| x.energy.total()),
                dram_lines: r.dram_lines,
                dram_lines_vs_baseline: rel(|x| x.dram_lines as f64),
                instructions_per_ray: r.instructions.total() as f64 / rays,
                thread_cycles_per_ray: r.cycles as f64 * f64::from(r.threads) / rays,
                stalls: StallShares::of(r),
                memory: r.memory,
            }
        })
        .collect();
    Summary {
        baseline: base.and_then(|b| b.accel),
        rows,
    }
}

fn pct(v: Option<f64>) -> String {
    v.map_or_else(|| "—".into(), |v| format!("{:.1} %", 100.0 * v))
}

/// The comparison as a text table.
pub fn table(s: &Summary) -> String {
    let base = s.baseline.map_or("?", |a| a.label());
    let header = [
        "config".to_string(),
        "frame time".into(),
        format!("% {base}"),
        "energy".into(),
        format!("% {base}"),
        "DRAM lines".into(),
        format!("% {base}"),
        "memory stall".into(),
        "unit stall".into(),
        "idle at end".into(),
        "L1 hit".into(),
        "L2 hit".into(),
        "row hit".into(),
        "DRAM lat. mean/p95".into(),
        "GB/s".into(),
        "lines/px".into(),
        "rays/px".into(),
    ];
    let mut rows = vec![header.to_vec()];
    for r in &s.rows {
        rows.push(vec![
            r.accel.map_or("?", |a| a.label()).to_string(),
            units::time_ms(r.frame_ms),
            pct(r.frame_vs_baseline),
            units::energy_j(r.energy_j),
            pct(r.energy_vs_baseline),
            units::count(r.dram_lines as f64),
            pct(r.dram_lines_vs_baseline),
            pct(Some(r.stalls.memory)),
            pct(Some(r.stalls.units())),
            pct(Some(r.stalls.idle_at_end)),
            pct(Some(r.memory.l1_hit_rate)),
            pct(Some(r.memory.l2_hit_rate)),
            pct(Some(r.memory.dram_row_hit_rate)),
            format!(
                "{:.0}/{}",
                r.memory.dram_latency_mean_cycles, r.memory.dram_latency_p95_cycles
            ),
            format!("{:.1}", r.memory.dram_gbps),
            format!("{:.2}", r.memory.lines_per_pixel),
            format!("{:.2}", r.memory.rays_per_pixel),
        ]);
    }
    let widths: Vec<usize> = (0..rows[0].len())
        .map(|c| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0))
        .collect();
    let mut out = String::new();
    for row in &rows {
        let cells: Vec<String> = row
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(c, (cell, w))| {
                let pad = w - cell.chars().count();
                if c == 0 {
                    format!("{cell}{}", " ".repeat(pad))
                } else {
                    format!("{}{cell}", " ".repeat(pad))
                }
            })
            .collect();
        out.push_str(cells.join("  ").trim_end());
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use dualsplit_sim::EnergySplit;

    fn result(accel: SimAccel, frame_ms: f64, lines: u64) -> SimResult {
        let mut r = SimResult {
            accel: Some(accel),
            threads: 4,
            cycles: 100,
            frame_ms,
            energy: EnergySplit {
                dram_j: frame_ms / 10.0,
                caches_j: 0.0,
                compute_j: 0.0,
            },
            dram_lines: lines,
            rays: 10,
            ..Default::default()
        };
        r.stalls.memory = 100;
        r.stalls.idle = 40;
        r
    }

    #[test]
    fn bvh2_is_the_baseline_when_present() {
        let d = result(SimAccel::Dst, 3.0, 600);
        let b = result(SimAccel::Bvh2, 4.0, 800);
        let s = summarize(&[&d, &b]);
        assert_eq!(s.baseline, Some(SimAccel::Bvh2));
        assert_eq!(s.rows[0].frame_vs_baseline, Some(0.75));
        assert_eq!(s.rows[0].dram_lines_vs_baseline, Some(0.75));
        assert_eq!(s.rows[1].energy_vs_baseline, Some(1.0));
        assert_eq!(s.rows[0].stalls.memory, 0.25);
        assert_eq!(s.rows[0].stalls.idle_at_end, 0.1);
        assert_eq!(s.rows[0].thread_cycles_per_ray, 40.0);
        let t = table(&s);
        assert!(t.contains("% BVH2"), "{t}");
        assert!(t.contains("75.0 %"), "{t}");

        let s = summarize(&[&d, &result(SimAccel::Bvh8, 6.0, 900)]);
        assert_eq!(s.baseline, Some(SimAccel::Dst));
        assert_eq!(s.rows[1].frame_vs_baseline, Some(2.0));
    }

    #[test]
    fn the_paper_s_absolute_values_stand_beside_simtrax_s_dragon_box_only() {
        use crate::paper::{PaperMatch, PaperScene};
        let b = result(SimAccel::Bvh2, 2.91 * 1.5, 1_060_000);
        let simtrax = PaperMatch::for_scene("dragon_box", "dragon_box.ply.gz");
        let p = paper_beside(simtrax, Workload::Cast, &[&b]).unwrap();
        assert_eq!(p.table, "Table 4");
        assert!(p.frame.contains("1024×1024"), "{}", p.frame);
        let row = p.rows[0];
        // Table 4, Dragon Box, BVH2: 2.91 ms, 0.54 J, 2.12 M lines.
        assert_eq!(
            (row.frame_ms, row.energy_j, row.dram_mlines),
            (2.91, 0.54, 2.12)
        );
        assert!((row.ours_frame_vs_paper.unwrap() - 1.5).abs() < 1e-12);
        assert!((row.ours_dram_lines_vs_paper.unwrap() - 0.5).abs() < 1e-12);
        let p = paper_beside(simtrax, Workload::Path, &[&b]).unwrap();
        assert_eq!(p.table, "Table 5");
        assert!(p.frame.contains("states no resolution"), "{}", p.frame);
        // No paper values for a reconstruction or a stand-in.
        let recon = PaperMatch::for_scene("dragon_box_recon", "dragon_box_recon.ply.gz");
        assert_eq!(paper_beside(recon, Workload::Cast, &[&b]), None);
        let stand_in = PaperMatch::for_scene("hairball", "builtin:hairball");
        assert_eq!(stand_in.map(|m| m.scene), Some(PaperScene::Hairball));
        assert_eq!(paper_beside(stand_in, Workload::Cast, &[&b]), None);
        assert_eq!(paper_beside(None, Workload::Cast, &[&b]), None);
    }
}
