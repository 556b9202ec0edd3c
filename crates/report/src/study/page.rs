//! `report --from DIR`: the study assembled from whatever results `DIR/cache/` holds.
//! Missing and invalid entries are listed, never run. Written to `DIR/report/`:
//! `index.html` (table, sweep charts, missing entries, where each result was computed),
//! `results.json` and `results.csv` (simulated numbers only, so the same plan gives the
//! same bytes wherever its jobs ran) and each sweep chart as `sweep-N.svg` and `.png`.

use super::StudyError;
use super::plan::{Plan, Varied};
use super::store::{ResultStore, Stored};
use super::sweep;
use crate::ReportError;
use crate::html::esc;
use crate::paper::Metric;
use crate::tables::metric;
use dualsplit_render::Workload;
use dualsplit_sim::{SimAccel, StallShares, ThreadModel};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One stored result, as the page and `results.json` show it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudyRow {
    /// Plan entry.
    pub index: usize,
    /// Scene display name.
    pub scene: String,
    /// Configuration.
    pub accel: SimAccel,
    /// Workload.
    pub workload: Workload,
    /// TM count.
    pub tms: u32,
    /// The swept keys' values.
    pub varied: Vec<Varied>,
    /// Hardware config hash.
    pub config_hash: String,
    /// Simulated cycles.
    pub cycles: u64,
    /// Frame time, ms.
    pub frame_ms: f64,
    /// Energy per frame, J.
    pub energy_j: f64,
    /// 64-byte DRAM lines read.
    pub dram_lines: u64,
    /// Rays traced.
    pub rays: u64,
    /// Share of thread-cycles spent waiting for memory.
    #[serde(default)]
    pub memory_stall_share: f64,
    /// Achieved DRAM read bandwidth, GB/s.
    #[serde(default)]
    pub dram_gbps: f64,
    /// DRAM lines per pixel.
    #[serde(default)]
    pub lines_per_pixel: f64,
    /// Rays per pixel.
    #[serde(default)]
    pub rays_per_pixel: f64,
}

/// Where and when a result was computed (host facts: on the page, not in `results.json`).
#[derive(Clone, Debug)]
pub struct Provenance {
    /// Plan entry.
    pub index: usize,
    /// Host name.
    pub host: String,
    /// Finish time, seconds since the Unix epoch.
    pub host_time_unix_s: u64,
    /// Wall seconds.
    pub host_wall_s: f64,
}

/// The assembled study.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StudyData {
    /// Code version of plan and results.
    pub code_version: String,
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// Thread model.
    pub thread_model: ThreadModel,
    /// Swept keys, in plan order.
    pub swept_keys: Vec<String>,
    /// Entries in the plan.
    pub planned: usize,
    /// Stored results, in plan order.
    pub rows: Vec<StudyRow>,
    /// Entries with no result file.
    pub missing: Vec<usize>,
    /// Entries whose file is not a valid result, and why.
    pub invalid: Vec<(usize, String)>,
    /// Plan entry descriptions of missing and invalid entries, by index.
    #[serde(skip)]
    pub descriptions: Vec<(usize, String)>,
    /// Host facts per stored result.
    #[serde(skip)]
    pub provenance: Vec<Provenance>,
}

/// Reads the plan and every stored result of the study in `dir`.
pub fn assemble(dir: &Path) -> Result<StudyData, StudyError> {
    let plan = Plan::load(dir)?;
    let store = ResultStore::new(dir);
    let mut data = StudyData {
        code_version: plan.code_version.clone(),
        width: plan.width,
        height: plan.height,
        thread_model: plan.thread_model,
        swept_keys: plan.vary.iter().map(|v| v.key.clone()).collect(),
        planned: plan.entries.len(),
        rows: Vec::new(),
        missing: Vec::new(),
        invalid: Vec::new(),
        descriptions: Vec::new(),
        provenance: Vec::new(),
    };
    for e in &plan.entries {
        match store.read(e) {
            Stored::Valid(r) => {
                data.rows.push(StudyRow {
                    index: e.index,
                    scene: e.scene_name.clone(),
                    accel: e.accel,
                    workload: e.workload,
                    tms: e.tms,
                    varied: e.varied.clone(),
                    config_hash: e.config_hash.clone(),
                    cycles: r.result.cycles,
                    frame_ms: metric(&r.result, Metric::FrameMs),
                    energy_j: metric(&r.result, Metric::EnergyJ),
                    dram_lines: r.result.dram_lines,
                    rays: r.result.rays,
                    memory_stall_share: StallShares::of(&r.result).memory,
                    dram_gbps: r.result.memory.dram_gbps,
                    lines_per_pixel: r.result.memory.lines_per_pixel,
                    rays_per_pixel: r.result.memory.rays_per_pixel,
                });
                data.provenance.push(Provenance {
                    index: e.index,
                    host: r.host.clone(),
                    host_time_unix_s: r.host_time_unix_s,
                    host_wall_s: r.host_wall_s,
                });
            }
            Stored::Missing => {
                data.missing.push(e.index);
                data.descriptions.push((e.index, e.describe()));
            }
            Stored::Invalid(why) => {
                data.invalid.push((e.index, why));
                data.descriptions.push((e.index, e.describe()));
            }
        }
    }
    Ok(data)
}

impl StudyData {
    /// Whether every planned entry has a valid result.
    pub fn complete(&self) -> bool {
        self.missing.is_empty() && self.invalid.is_empty()
    }

    /// The missing and invalid entries' indices as Slurm `--array` text (`0-3,7,9`).
    pub fn todo_ranges(&self) -> String {
        let mut todo: Vec<usize> = self.missing.clone();
        todo.extend(self.invalid.iter().map(|(i, _)| *i));
        todo.sort_unstable();
        ranges(&todo)
    }
}

/// Sorted indices as `a-b,c` ranges.
pub fn ranges(sorted: &[usize]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < sorted.len() {
        let mut j = i;
        while j + 1 < sorted.len() && sorted[j + 1] == sorted[j] + 1 {
            j += 1;
        }
        out.push(if i == j {
            sorted[i].to_string()
        } else {
            format!("{}-{}", sorted[i], sorted[j])
        });
        i = j + 1;
    }
    out.join(",")
}

/// `key=value` of each swept key.
fn varied_text(v: &[Varied]) -> String {
    v.iter()
        .map(|x| format!("{}={}", x.key, x.value))
        .collect::<Vec<_>>()
        .join(" ")
}

/// `results.csv`: one line per stored result.
pub fn results_csv(data: &StudyData) -> String {
    let mut s = String::from("index,scene,accel,workload,tms");
    for k in &data.swept_keys {
        let _ = write!(s, ",{k}");
    }
    s.push_str(",config_hash,cycles,frame_ms,energy_j,dram_lines,rays\n");
    for r in &data.rows {
        let _ = write!(
            s,
            "{},{},{},{},{}",
            r.index,
            r.scene,
            r.accel.name(),
            r.workload.name(),
            r.tms
        );
        for k in &data.swept_keys {
            let v = r.varied.iter().find(|v| &v.key == k);
            let _ = write!(s, ",{}", v.map(|v| v.value.to_string()).unwrap_or_default());
        }
        let _ = writeln!(
            s,
            ",{},{},{:?},{:?},{},{}",
            r.config_hash, r.cycles, r.frame_ms, r.energy_j, r.dram_lines, r.rays
        );
    }
    s
}

fn write(path: &Path, bytes: &[u8]) -> Result<PathBuf, ReportError> {
    std::fs::write(path, bytes).map_err(ReportError::io(path))?;
    Ok(path.to_path_buf())
}

/// Writes the page and its files into `out`; returns the files written.
pub fn write_study(data: &StudyData, out: &Path) -> Result<Vec<PathBuf>, StudyError> {
    std::fs::create_dir_all(out).map_err(ReportError::io(out))?;
    let mut files = Vec::new();
    let json = serde_json::to_vec_pretty(data).map_err(|source| ReportError::Json {
        path: out.join("results.json"),
        source,
    })?;
    files.push(write(&out.join("results.json"), &json)?);
    files.push(write(
        &out.join("results.csv"),
        results_csv(data).as_bytes(),
    )?);
    let vs = super::variants::variants(data);
    files.push(write(
        &out.join("variants.md"),
        super::variants::markdown(&vs).as_bytes(),
    )?);
    let charts = sweep::charts(data)?;
    for (i, c) in charts.iter().enumerate() {
        files.push(write(
            &out.join(format!("sweep-{i}.svg")),
            c.svg.as_bytes(),
        )?);
        files.push(write(&out.join(format!("sweep-{i}.png")), &c.png)?);
    }
    let html = page_html(data, &charts);
    files.push(write(&out.join("index.html"), html.as_bytes())?);
    Ok(files)
}

fn page_html(data: &StudyData, charts: &[sweep::SweepChart]) -> String {
    let mut h = String::from(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>dualsplit study</title>\
         <style>body{font-family:sans-serif;margin:2em;max-width:1100px}table{border-collapse:collapse}\
         td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}th{background:#eee}\
         .missing{color:#a00}</style></head><body>\n<h1>Study</h1>\n",
    );
    let _ = writeln!(
        h,
        "<p>{} of {} planned simulations have results ({}×{}, {} thread model, dualsplit {}).</p>",
        data.rows.len(),
        data.planned,
        data.width,
        data.height,
        data.thread_model.name(),
        esc(&data.code_version)
    );
    if !data.complete() {
        let _ = writeln!(
            h,
            "<h2 class=\"missing\">Missing ({} entries: {})</h2>\n<p>Not run by this page; \
             run them with <code>dualsplit run-job DIR INDEX</code> or resubmit the array \
             with <code>--array={}</code>.</p>\n<ul>",
            data.missing.len() + data.invalid.len(),
            esc(&data.todo_ranges()),
            esc(&data.todo_ranges())
        );
        for (i, d) in &data.descriptions {
            let why = data
                .invalid
                .iter()
                .find(|(j, _)| j == i)
                .map(|(_, w)| format!(" — invalid file: {w}"))
                .unwrap_or_default();
            let _ = writeln!(h, "<li>{}{}</li>", esc(d), esc(&why));
        }
        h.push_str("</ul>\n");
    }
    for c in charts {
        let _ = writeln!(h, "<h2>{}</h2>\n{}", esc(&c.title), c.svg);
    }
    h.push_str("<h2>Variants</h2>\n<table><tr><th>scene</th><th>workload</th><th>TMs</th><th>variant</th><th>DST % of BVH2</th><th>order, fastest first (% of BVH2)</th><th>BVH2 memory stalls</th><th>BVH2 GB/s</th><th>BVH2 lines/px</th><th>rays/px</th></tr>\n");
    for v in super::variants::variants(data) {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.1} %</td><td>{:.0}</td><td>{:.2}</td><td>{:.2}</td></tr>",
            esc(&v.scene),
            v.workload,
            v.tms,
            esc(&v.varied),
            v.dst_text(),
            esc(&v.order_text()),
            100.0 * v.base.memory_stall_share,
            v.base.dram_gbps,
            v.base.lines_per_pixel,
            v.base.rays_per_pixel
        );
    }
    h.push_str("</table>\n");
    h.push_str("<h2>Results</h2>\n<table><tr><th>#</th><th>scene</th><th>configuration</th><th>workload</th><th>TMs</th><th>swept</th><th>frame (ms)</th><th>energy (J)</th><th>DRAM lines</th><th>host</th></tr>\n");
    for (r, p) in data.rows.iter().zip(&data.provenance) {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.4}</td><td>{:.6}</td><td>{}</td><td>{} ({:.1} s)</td></tr>",
            r.index,
            esc(&r.scene),
            r.accel.label(),
            r.workload.name(),
            r.tms,
            esc(&varied_text(&r.varied)),
            r.frame_ms,
            r.energy_j,
            r.dram_lines,
            esc(&p.host),
            p.host_wall_s
        );
    }
    h.push_str("</table>\n</body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_join_runs() {
        assert_eq!(ranges(&[0, 1, 2, 5, 7, 8]), "0-2,5,7-8");
        assert_eq!(ranges(&[]), "");
    }
}
