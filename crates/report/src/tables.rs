//! The report's tables, built once from [`ReportData`] and formatted by the HTML, Markdown
//! and CSV writers, so the three always show the same numbers.
//!
//! Layout follows the paper (Lin et al. 2020, §4): Table 3 (sizes, % of BVH2), Tables 4 and
//! 5 (frame time, energy, DRAM lines per configuration, % of BVH2), Table 6 (energy split),
//! Table 7 (TM scaling), plus the CPU section (host timings, never mixed with simulated
//! quantities). Published values sit in columns marked as the paper's.

use crate::data::{ReportData, SceneReport};
use crate::paper::{self, Metric, PaperScene};
use crate::produce::CPU_RAYS;
use crate::summary;
use crate::units;
use dualsplit_accel::AccelKind;
use dualsplit_render::{RayKind, Workload};
use dualsplit_sim::{SimAccel, SimConfig, SimResult};

/// One table cell: its text and, where it is a number, the number (written to CSV at full
/// precision).
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    /// Shown text.
    pub text: String,
    /// The number, if the cell is one.
    pub value: Option<f64>,
}

impl Cell {
    /// A text cell.
    pub fn text(s: impl Into<String>) -> Self {
        Self {
            text: s.into(),
            value: None,
        }
    }
    /// A number shown with about three significant digits.
    pub fn num(v: f64) -> Self {
        Self {
            text: fmt_num(v),
            value: Some(v),
        }
    }
    /// A percentage (`v` = 0.89 → "89%").
    pub fn pct(v: f64) -> Self {
        Self {
            text: format!("{:.0}%", v * 100.0),
            value: Some(v * 100.0),
        }
    }
    /// An integer.
    pub fn int(v: u64) -> Self {
        Self {
            text: v.to_string(),
            value: Some(v as f64),
        }
    }
    /// A missing value.
    pub fn none() -> Self {
        Self::text("—")
    }
}

/// Formats with about three significant digits.
pub fn fmt_num(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        format!("{v}")
    } else if a >= 100.0 {
        format!("{v:.1}")
    } else if a >= 10.0 {
        format!("{v:.2}")
    } else if a >= 1.0 || a == 0.0 {
        format!("{v:.3}")
    } else {
        let digits = (2 - a.log10().floor() as i32).clamp(3, 9) as usize;
        format!("{v:.digits$}")
    }
}

/// A table.
#[derive(Clone, Debug)]
pub struct Table {
    /// HTML id and CSV file stem (`table4-dragon_box`).
    pub id: String,
    /// Caption.
    pub caption: String,
    /// Column headings.
    pub header: Vec<String>,
    /// Indices of columns holding the paper's published values.
    pub paper_columns: Vec<usize>,
    /// Rows.
    pub rows: Vec<Vec<Cell>>,
}

/// A section of the report: a heading, a generated paragraph, notes and tables.
#[derive(Clone, Debug)]
pub struct Section {
    /// HTML id (`table4`).
    pub id: String,
    /// Heading.
    pub title: String,
    /// Generated paragraph comparing ours with the paper.
    pub summary: String,
    /// Notes (stand-ins, unavailable pieces).
    pub notes: Vec<String>,
    /// Tables.
    pub tables: Vec<Table>,
}

fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect()
}

/// A scene's id fragment: its index and slugged name.
pub fn scene_id(i: usize, s: &SceneReport) -> String {
    format!("{i}-{}", slug(&s.name))
}

fn paper_note(s: &SceneReport) -> String {
    match &s.paper {
        Some(m) if m.same_mesh => format!(
            "{}: the paper's {} scene ({}).",
            s.name,
            m.scene.label(),
            m.describe()
        ),
        Some(m) => format!(
            "{}: a stand-in for the paper's {} ({} triangles here, {} in the paper); compare shapes, not values.",
            s.name,
            m.scene.label(),
            s.triangles,
            m.scene.triangles()
        ),
        None => format!("{}: no counterpart in the paper.", s.name),
    }
}

/// Table 3: structure sizes in MiB and % of BVH2 (Lin et al. 2020, §4.1, Table 3).
pub fn table3(data: &ReportData) -> Section {
    let kinds = [
        AccelKind::Bvh2,
        AccelKind::Bvh4,
        AccelKind::Bvh8,
        AccelKind::Dst,
    ];
    let all: Vec<f64> = data
        .scenes
        .iter()
        .flat_map(|s| kinds.iter().filter_map(|&k| s.bytes(k)))
        .map(|b| b as f64)
        .collect();
    let (unit, scale) = units::bytes_unit(&all);
    let mut header = vec!["scene".to_string(), "triangles".into()];
    for k in &kinds {
        header.push(format!("{} {unit}", k.name().to_uppercase()));
        if *k != AccelKind::Bvh2 {
            header.push(format!("{} % of BVH2", k.name().to_uppercase()));
        }
    }
    let first_paper = header.len();
    header.push("paper scene".into());
    header.push("paper BVH2 MiB".into());
    for k in &kinds[1..] {
        header.push(format!("paper {} %", k.name().to_uppercase()));
    }
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    for s in &data.scenes {
        let mut row = vec![Cell::text(&s.name), Cell::int(s.triangles)];
        let b2 = s.bytes(AccelKind::Bvh2);
        for k in &kinds {
            let b = s.bytes(*k);
            row.push(b.map_or_else(Cell::none, |b| Cell::num(b as f64 * scale)));
            if *k != AccelKind::Bvh2 {
                row.push(match (b, b2) {
                    (Some(b), Some(b2)) if b2 > 0 => Cell::pct(b as f64 / b2 as f64),
                    _ => Cell::none(),
                });
            }
        }
        match &s.paper {
            Some(m) => {
                let p = paper::TABLE3_MIB[m.scene.index()];
                row.push(Cell::text(m.describe()));
                row.push(Cell::num(p[0]));
                for v in &p[1..] {
                    row.push(Cell::pct(v / p[0]));
                }
            }
            None => row.extend((0..5).map(|_| Cell::none())),
        }
        rows.push(row);
        for sz in s.cpu.sizes.iter().filter(|z| kinds.contains(&z.kind)) {
            if let Err(e) = &sz.bytes {
                notes.push(format!("{} size on {}: {e}", sz.kind.name(), s.name));
            }
        }
    }
    notes.sort();
    notes.dedup();
    Section {
        id: "table3".into(),
        title: "Table 3 — structure sizes".into(),
        summary: summary::table3(data),
        notes,
        tables: vec![Table {
            id: "table3".into(),
            caption: format!(
                "Nodes plus triangle-index lists, {unit} (1 KiB = 2^10 B, 1 MiB = 2^20 B); % of BVH2."
            ),
            paper_columns: (first_paper..first_paper + 5).collect(),
            header,
            rows,
        }],
    }
}

/// The value of `metric` in a simulated result, in the paper's units (ms, J, millions of
/// lines).
pub fn metric(r: &SimResult, m: Metric) -> f64 {
    match m {
        Metric::FrameMs => r.frame_ms,
        Metric::EnergyJ => r.energy.total(),
        Metric::DramLines => r.dram_lines as f64 / 1e6,
    }
}

/// The unit and scale that show `values` of `m` (in [`metric`]'s units: ms, J, millions of
/// lines) readably: µs/ms/s, µJ/mJ/J, lines/K/M. The heading is `"{name} ({unit})"`.
pub fn metric_unit(m: Metric, values: &[f64]) -> (String, f64) {
    match m {
        Metric::FrameMs => {
            let (u, s) = units::time_unit(values);
            (format!("{} ({u})", m.name()), s)
        }
        Metric::EnergyJ => {
            let (u, s) = units::energy_unit(values);
            (format!("{} ({u})", m.name()), s)
        }
        Metric::DramLines => {
            let lines: Vec<f64> = values.iter().map(|v| v * 1e6).collect();
            match units::count_unit(&lines) {
                ("", s) => (m.name().to_string(), s * 1e6),
                (u, s) => (format!("{} ({u})", m.name()), s * 1e6),
            }
        }
    }
}

/// DRAM energy (J) of a simulated frame by cause: `[reads and writes, row activations,
/// background]`, from its burst and activation counts and frame time with the per-event
/// energies and
/// background power of the hardware configuration the report simulates (`lin2020`); the
/// three add up to the frame's DRAM energy.
pub fn dram_split(r: &SimResult) -> [f64; 3] {
    let d = SimConfig::lin2020().dram;
    [
        (r.dram.reads + r.dram.writes) as f64 * d.e_read_nj * 1e-9,
        r.dram.activations as f64 * d.e_activate_nj * 1e-9,
        d.background_w * r.frame_ms * 1e-3,
    ]
}

/// Tables 4 (`Cast`) and 5 (`Path`): per scene, frame time, energy and DRAM lines of every
/// configuration with % of BVH2, the paper's beside (Lin et al. 2020, §4.3–4.4).
pub fn table45(data: &ReportData, workload: Workload) -> Section {
    let (num, what) = match workload {
        Workload::Cast => (4, "ray casting + 1 shadow ray per pixel"),
        Workload::Path => (5, "path tracing, 5 diffuse bounces"),
    };
    let tms = data.settings.base_tms;
    let mut tables = Vec::new();
    let mut notes = Vec::new();
    for (i, s) in data.scenes.iter().enumerate() {
        if s.sim(SimAccel::Bvh2, workload, tms).is_none() {
            notes.push(format!(
                "{}: {}",
                s.name,
                s.sim_error().unwrap_or("no simulated results")
            ));
            continue;
        }
        notes.push(paper_note(s));
        let ours = |m: Metric| -> Vec<f64> {
            SimAccel::PAPER
                .iter()
                .filter_map(|&a| Some(metric(s.sim(a, workload, tms)?, m)))
                .collect()
        };
        let theirs = |m: Metric| -> Vec<f64> {
            s.paper.map_or_else(Vec::new, |pm| {
                SimAccel::PAPER
                    .iter()
                    .map(|&a| paper::table45(workload, m, a, pm.scene))
                    .collect()
            })
        };
        let our_units: Vec<(String, f64)> = Metric::ALL
            .iter()
            .map(|&m| metric_unit(m, &ours(m)))
            .collect();
        let paper_units: Vec<(String, f64)> = Metric::ALL
            .iter()
            .map(|&m| metric_unit(m, &theirs(m)))
            .collect();
        let mut header = vec!["configuration".to_string()];
        for (h, _) in &our_units {
            header.push(h.clone());
            header.push("% of BVH2".into());
        }
        header.push("idle at end".into());
        header.push("thread-cycles per ray".into());
        let first_paper = header.len();
        if let Some(m) = &s.paper {
            for (h, _) in &paper_units {
                header.push(format!("paper {}: {h}", m.scene.label()));
                header.push("paper %".into());
            }
        }
        let mut rows = Vec::new();
        for a in SimAccel::PAPER {
            let mut row = vec![Cell::text(a.label())];
            for (m, (_, scale)) in Metric::ALL.iter().copied().zip(&our_units) {
                let base = s.sim(SimAccel::Bvh2, workload, tms).map(|r| metric(r, m));
                match s.sim(a, workload, tms) {
                    Some(r) => {
                        let v = metric(r, m);
                        row.push(if m == Metric::DramLines && *scale == 1e6 {
                            Cell::int(r.dram_lines)
                        } else {
                            Cell::num(v * scale)
                        });
                        row.push(
                            base.filter(|b| *b > 0.0)
                                .map_or_else(Cell::none, |b| Cell::pct(v / b)),
                        );
                    }
                    None => row.extend([Cell::none(), Cell::none()]),
                }
            }
            // Threads out of work before the frame ends (a frame too small for the chip).
            row.push(s.sim(a, workload, tms).map_or_else(Cell::none, |r| {
                Cell::pct(dualsplit_sim::StallShares::of(r).idle_at_end)
            }));
            // Cycles × threads per ray: the work a ray costs the chip, memory waits included.
            row.push(s.sim(a, workload, tms).map_or_else(Cell::none, |r| {
                Cell::num(r.cycles as f64 * f64::from(r.threads) / r.rays.max(1) as f64)
            }));
            if let Some(pm) = &s.paper {
                for (m, (_, scale)) in Metric::ALL.iter().copied().zip(&paper_units) {
                    let v = paper::table45(workload, m, a, pm.scene);
                    let b = paper::table45(workload, m, SimAccel::Bvh2, pm.scene);
                    row.push(Cell::num(v * scale));
                    row.push(Cell::pct(v / b));
                }
            }
            rows.push(row);
        }
        let ncols = header.len();
        tables.push(Table {
            id: format!("table{num}-{}", scene_id(i, s)),
            caption: format!(
                "{} — {what}, {}×{}, {} TMs, {} thread model",
                s.label(),
                data.settings.width,
                data.settings.height,
                tms,
                data.settings.thread_model.name()
            ),
            paper_columns: (first_paper..ncols).collect(),
            header,
            rows,
        });
    }
    notes.extend(
        summary::idle_warnings(data, Some(workload))
            .into_iter()
            .map(|w| format!("Warning: {w}.")),
    );
    Section {
        id: format!("table{num}"),
        title: format!("Table {num} — {what}"),
        summary: summary::table45(data, workload),
        notes,
        tables,
    }
}

/// Table 6: energy of path tracing split into DRAM (itself split into reads, row
/// activations and background power over the frame time), caches and compute (Lin et al.
/// 2020, §4.4, Table 6; the paper does not split DRAM energy).
pub fn table6(data: &ReportData) -> Section {
    let tms = data.settings.base_tms;
    let mut tables = Vec::new();
    let mut notes = Vec::new();
    for (i, s) in data.scenes.iter().enumerate() {
        if s.sim(SimAccel::Bvh2, Workload::Path, tms).is_none() {
            notes.push(format!(
                "{}: {}",
                s.name,
                s.sim_error().unwrap_or("no simulated results")
            ));
            continue;
        }
        let pm = s.paper.filter(|m| m.scene.table67_index().is_some());
        // Reads, activations, background, DRAM, caches, compute (J) per configuration; each
        // column in its own unit, as the parts differ by orders of magnitude.
        let parts = |r: &SimResult| -> [f64; 6] {
            let [reads, acts, background] = dram_split(r);
            let e = r.energy;
            [reads, acts, background, e.dram_j, e.caches_j, e.compute_j]
        };
        let column_units: Vec<(&str, f64)> = (0..6)
            .map(|c| {
                let v: Vec<f64> = SimAccel::PAPER
                    .iter()
                    .filter_map(|&a| s.sim(a, Workload::Path, tms))
                    .map(|r| parts(r)[c])
                    .collect();
                units::energy_unit(&v)
            })
            .collect();
        let mut header: Vec<String> = vec!["configuration".to_string()];
        for (h, (unit, _)) in [
            "DRAM reads and writes",
            "DRAM activations",
            "DRAM background",
            "DRAM",
            "caches",
            "compute",
        ]
        .iter()
        .zip(&column_units)
        {
            header.push(format!("{h} ({unit})"));
        }
        header.push("DRAM share".into());
        let first_paper = header.len();
        let paper_vals: Vec<f64> = pm
            .map(|m| {
                SimAccel::PAPER
                    .iter()
                    .filter_map(|&a| paper::table6(a, m.scene))
                    .flatten()
                    .collect()
            })
            .unwrap_or_default();
        let (paper_unit, paper_scale) = units::energy_unit(&paper_vals);
        if let Some(m) = pm {
            for h in ["DRAM", "caches", "compute"] {
                header.push(format!("paper {}: {h} ({paper_unit})", m.scene.label()));
            }
            header.push(format!("paper {}: DRAM share", m.scene.label()));
        }
        let mut rows = Vec::new();
        for a in SimAccel::PAPER {
            let mut row = vec![Cell::text(a.label())];
            match s.sim(a, Workload::Path, tms) {
                Some(r) => {
                    let e = r.energy;
                    row.extend(
                        parts(r)
                            .iter()
                            .zip(&column_units)
                            .map(|(v, (_, scale))| Cell::num(v * scale)),
                    );
                    let t = e.total();
                    row.push(if t > 0.0 {
                        Cell::pct(e.dram_j / t)
                    } else {
                        Cell::none()
                    });
                }
                None => row.extend((0..7).map(|_| Cell::none())),
            }
            if let Some(p) = pm.and_then(|m| paper::table6(a, m.scene)) {
                row.extend(p.iter().map(|v| Cell::num(v * paper_scale)));
                row.push(Cell::pct(p[0] / p.iter().sum::<f64>()));
            }
            rows.push(row);
        }
        let ncols = header.len();
        tables.push(Table {
            id: format!("table6-{}", scene_id(i, s)),
            caption: format!(
                "{} — path tracing energy by category; DRAM energy = reads + row activations + background power × frame time",
                s.label()
            ),
            paper_columns: (first_paper..ncols).collect(),
            header,
            rows,
        });
    }
    Section {
        id: "table6".into(),
        title: "Table 6 — energy split (path tracing)".into(),
        summary: summary::table6(data),
        notes,
        tables,
    }
}

/// Table 7: path-tracing frame time vs TM count with speedup over the fewest TMs (Lin et al.
/// 2020, §4.5, Table 7).
pub fn table7(data: &ReportData) -> Section {
    let tms = &data.settings.tms;
    let mut tables = Vec::new();
    let mut notes = Vec::new();
    for (i, s) in data.scenes.iter().enumerate() {
        let has = tms
            .iter()
            .all(|&t| s.sim(SimAccel::Bvh2, Workload::Path, t).is_some());
        if !has {
            if let Some(e) = s.sim_error() {
                notes.push(format!("{}: {e}", s.name));
            }
            continue;
        }
        let pm = s.paper.filter(|m| m.scene.table67_index().is_some());
        let ours: Vec<f64> = SimAccel::PAPER
            .iter()
            .flat_map(|&a| tms.iter().filter_map(move |&t| s.sim(a, Workload::Path, t)))
            .map(|r| r.frame_ms)
            .collect();
        let (unit, scale) = units::time_unit(&ours);
        let theirs: Vec<f64> = pm
            .map(|m| {
                SimAccel::PAPER
                    .iter()
                    .flat_map(|&a| {
                        paper::TABLE7_TMS
                            .iter()
                            .filter_map(move |&t| paper::table7(a, m.scene, t))
                    })
                    .collect()
            })
            .unwrap_or_default();
        let (paper_unit, paper_scale) = units::time_unit(&theirs);
        let mut header = vec!["configuration".to_string()];
        for (j, t) in tms.iter().enumerate() {
            header.push(format!("{t} TMs ({unit})"));
            if j > 0 {
                header.push(format!("speedup vs {}", tms[0]));
            }
        }
        let first_paper = header.len();
        if let Some(m) = pm {
            for t in paper::TABLE7_TMS {
                header.push(format!("paper {}: {t} TMs ({paper_unit})", m.scene.label()));
            }
        }
        let mut rows = Vec::new();
        for a in SimAccel::PAPER {
            let mut row = vec![Cell::text(a.label())];
            let first = s.sim(a, Workload::Path, tms[0]).map(|r| r.frame_ms);
            for (j, &t) in tms.iter().enumerate() {
                let v = s.sim(a, Workload::Path, t).map(|r| r.frame_ms);
                row.push(v.map_or_else(Cell::none, |v| Cell::num(v * scale)));
                if j > 0 {
                    row.push(match (first, v) {
                        (Some(f), Some(v)) if v > 0.0 => Cell {
                            text: format!("{:.2}×", f / v),
                            value: Some(f / v),
                        },
                        _ => Cell::none(),
                    });
                }
            }
            if let Some(m) = pm {
                for t in paper::TABLE7_TMS {
                    row.push(
                        paper::table7(a, m.scene, t)
                            .map_or_else(Cell::none, |v| Cell::num(v * paper_scale)),
                    );
                }
            }
            rows.push(row);
        }
        let ncols = header.len();
        tables.push(Table {
            id: format!("table7-{}", scene_id(i, s)),
            caption: format!("{} — path tracing frame time vs TM count", s.label()),
            paper_columns: (first_paper..ncols).collect(),
            header,
            rows,
        });
    }
    Section {
        id: "table7".into(),
        title: "Table 7 — scaling with the number of TMs".into(),
        summary: summary::table7(data),
        notes,
        tables,
    }
}

/// Construction steps of the CPU build table, as named by `Structures::stats`.
const BUILD_STEPS: [&str; 4] = ["bvh2", "bvh4", "bvh8", "dst"];

/// The CPU section: build times and single-thread Mrays/s per structure and ray kind
/// (host measurements of this machine).
pub fn cpu(data: &ReportData) -> Section {
    let mut build_rows = Vec::new();
    for s in &data.scenes {
        let c = &s.cpu;
        let mut row = vec![Cell::text(&s.name), Cell::int(s.triangles)];
        for name in BUILD_STEPS {
            row.push(
                c.build_ms
                    .iter()
                    .find(|b| b.structure == name)
                    .map_or_else(Cell::none, |b| Cell::num(b.ms)),
            );
        }
        row.push(Cell::num(c.all_structures_ms));
        build_rows.push(row);
    }
    let mut header = vec!["scene".to_string(), "ray kind".into(), "rays".into()];
    header.extend(
        AccelKind::ALL
            .iter()
            .map(|k| format!("{} Mrays/s", k.name())),
    );
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    for s in &data.scenes {
        for rk in [RayKind::Primary, RayKind::Shadow, RayKind::Diffuse] {
            // Timings on fewer rays measure warm caches and start-up more than traversal.
            let rays = s
                .cpu
                .throughput
                .iter()
                .find(|t| t.ray_kind == rk)
                .map_or(0, |t| t.rays);
            if rays < CPU_RAYS as u64 {
                notes.push(format!(
                    "{}: {rays} {} rays, fewer than the {CPU_RAYS} a timing needs; left out.",
                    s.name,
                    rk.name()
                ));
                continue;
            }
            let mut row = vec![
                Cell::text(&s.name),
                Cell::text(format!("{rk:?}").to_lowercase()),
            ];
            let mut n = 0;
            let mut cells = Vec::new();
            for k in AccelKind::ALL {
                match s
                    .cpu
                    .throughput
                    .iter()
                    .find(|t| t.kind == k && t.ray_kind == rk)
                {
                    Some(t) => {
                        n = t.rays;
                        match &t.mrays_per_s {
                            Ok(v) => cells.push(Cell::num(*v)),
                            Err(e) => {
                                // A structure that is not built says so once; a
                                // disagreement with BVH2 names its scene.
                                notes.push(if e.contains("disagrees") {
                                    format!("{}: {e}", s.name)
                                } else {
                                    format!("{}: {e}", k.name())
                                });
                                cells.push(Cell::none());
                            }
                        }
                    }
                    None => cells.push(Cell::none()),
                }
            }
            row.push(Cell::int(n));
            row.extend(cells);
            rows.push(row);
        }
    }
    notes.sort();
    notes.dedup();
    let mut tables = vec![Table {
        id: "cpu-build".into(),
        caption: "Host build times (ms, wall clock; the BVH2 builder uses all cores).".into(),
        header: [
            "scene",
            "triangles",
            "BVH2 SAH build (ms)",
            "BVH4 collapse (ms)",
            "BVH8 collapse (ms)",
            "DST conversion (ms)",
            "all, incl. encoding (ms)",
        ]
        .iter()
        .map(|h| h.to_string())
        .collect(),
        paper_columns: vec![],
        rows: build_rows,
    }];
    if !rows.is_empty() {
        tables.push(Table {
            id: "cpu-mrays".into(),
            caption: format!(
                "Single-thread Mrays/s on {CPU_RAYS} rays of each kind from frames of the path workload at {0}×{0}, each structure checked ray by ray against BVH2 before timing.",
                data.settings.cpu_res
            ),
            header,
            paper_columns: vec![],
            rows,
        });
    }
    Section {
        id: "cpu".into(),
        title: "CPU — build times and traversal throughput (host, this machine)".into(),
        summary: summary::cpu(data),
        notes,
        tables,
    }
}

/// Every section in page order.
pub fn sections(data: &ReportData) -> Vec<Section> {
    let mut v = vec![
        table3(data),
        table45(data, Workload::Cast),
        table45(data, Workload::Path),
        crate::memory::section(data),
        table6(data),
        table7(data),
        crate::beyond::section(data),
    ];
    v.extend(crate::rtx::section(data));
    v.push(cpu(data));
    v
}

/// The paper scene a scene corresponds to, for charts.
pub fn paper_scene(s: &SceneReport) -> Option<PaperScene> {
    s.paper.map(|m| m.scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn number_formatting() {
        assert_eq!(fmt_num(123.456), "123.5");
        assert_eq!(fmt_num(12.345), "12.35");
        assert_eq!(fmt_num(1.5), "1.500");
        assert_eq!(fmt_num(0.01234), "0.0123");
        assert_eq!(Cell::pct(0.891).text, "89%");
    }

    /// The three parts of Table 6's DRAM energy add up to the simulator's DRAM energy, for
    /// both thread models.
    #[test]
    fn dram_split_adds_up_to_the_simulated_dram_energy() {
        let scene = dualsplit_scene::load("builtin:cornell").unwrap();
        let s = dualsplit_accel::Structures::try_build(
            &scene.triangles,
            &dualsplit_accel::BuildConfig::default(),
        )
        .unwrap();
        let settings = dualsplit_render::RenderSettings::new(8, 8, Workload::Path);
        let mut cfg = SimConfig::lin2020();
        cfg.tms = 2;
        for model in dualsplit_sim::ThreadModel::ALL {
            let r = dualsplit_sim::simulate(
                &dualsplit_sim::FrameRequest::new(&scene, &s, SimAccel::Dst, &settings, &cfg)
                    .with_model(model),
                &|_, _| {},
            )
            .unwrap();
            let parts = dram_split(&r);
            assert!(parts.iter().all(|p| *p > 0.0), "{parts:?}");
            let sum: f64 = parts.iter().sum();
            assert!(
                (sum - r.energy.dram_j).abs() <= 1e-12 * r.energy.dram_j.max(1.0),
                "{model:?}: {parts:?} sum to {sum}, DRAM energy {}",
                r.energy.dram_j
            );
        }
    }

    #[test]
    fn units_follow_the_values() {
        assert_eq!(
            metric_unit(Metric::FrameMs, &[0.0089, 0.5]).0,
            "frame time (µs)"
        );
        assert_eq!(metric_unit(Metric::FrameMs, &[12.0]).0, "frame time (ms)");
        assert_eq!(metric_unit(Metric::EnergyJ, &[0.02]).0, "energy (mJ)");
        let (h, scale) = metric_unit(Metric::DramLines, &[0.0123]);
        assert_eq!((h.as_str(), scale), ("DRAM lines (K)", 1e3));
        assert_eq!(metric_unit(Metric::DramLines, &[0.0000390]).0, "DRAM lines");
        assert_eq!(metric_unit(Metric::DramLines, &[3.5]).1, 1.0);
    }
}
