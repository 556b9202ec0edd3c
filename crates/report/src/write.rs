//! Writes a report directory: `index.html`, `report.md`, `results.json` and one CSV per
//! table under `csv/`.

use crate::ReportError;
use crate::data::ReportData;
use crate::html::index_html;
use crate::tables::{Table, sections};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// Formats one table as Markdown (paper columns are marked with "paper" in their heading).
pub fn table_md(t: &Table) -> String {
    let mut m = String::new();
    let _ = writeln!(m, "**{}** (`{}`)\n", t.caption, t.id);
    let _ = writeln!(m, "| {} |", t.header.join(" | "));
    let _ = writeln!(m, "|{}", "---|".repeat(t.header.len()));
    for row in &t.rows {
        let cells: Vec<&str> = row.iter().map(|c| c.text.as_str()).collect();
        let _ = writeln!(m, "| {} |", cells.join(" | "));
    }
    m.push('\n');
    m
}

/// The Markdown report: the same sections and tables as the page, without charts.
pub fn report_md(data: &ReportData) -> String {
    let mut m = String::from("# Hardware-Accelerated Dual-Split Trees, regenerated\n\n");
    let st = &data.settings;
    let _ = writeln!(
        m,
        "Lin et al. 2020, §4. Simulated at {}×{}, {} TMs (scaling over {} TMs). Columns whose heading starts with \"paper\" are the published values; stand-in scenes are labelled. Dragon Box is SimTRaX's scene (the Stanford dragon in a closed 12-triangle box, the camera inside it; `dualsplit scene dragon-box`) wherever that file is found; the scene table names which Dragon Box a run used. The paper states its resolution (1024×1024) only for Table 4; it states none for Table 5 or the other tables.\n",
        st.width,
        st.height,
        st.base_tms,
        st.tms_list()
    );
    let _ = writeln!(m, "{}\n", data.scene_files.describe());
    if let Some(e) = data.sim_error() {
        let _ = writeln!(m, "> {e}\n");
    }
    for s in &data.skipped {
        let _ = writeln!(m, "> scene {} skipped: {}\n", s.spec, s.error);
    }
    for sec in sections(data) {
        let _ = writeln!(m, "## {}\n\n{}\n", sec.title, sec.summary);
        for n in &sec.notes {
            let _ = writeln!(m, "- {n}");
        }
        if !sec.notes.is_empty() {
            m.push('\n');
        }
        for t in &sec.tables {
            m.push_str(&table_md(t));
        }
    }
    m
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<(), ReportError> {
    std::fs::write(path, bytes).map_err(ReportError::io(path))
}

/// Writes every output into `out`; returns the paths written.
pub fn write_report(data: &ReportData, out: &Path) -> Result<Vec<PathBuf>, ReportError> {
    let csv_dir = out.join("csv");
    std::fs::create_dir_all(&csv_dir).map_err(ReportError::io(&csv_dir))?;
    let mut written = Vec::new();
    let p = out.join("index.html");
    write_file(&p, index_html(data)?.as_bytes())?;
    written.push(p);
    let p = out.join("report.md");
    write_file(&p, report_md(data).as_bytes())?;
    written.push(p);
    let p = out.join("results.json");
    let json = serde_json::to_vec_pretty(data).map_err(|source| ReportError::Json {
        path: p.clone(),
        source,
    })?;
    write_file(&p, &json)?;
    written.push(p);
    for sec in sections(data) {
        for t in &sec.tables {
            let p = csv_dir.join(format!("{}.csv", t.id));
            let csv_err = |source| ReportError::Csv {
                path: p.clone(),
                source,
            };
            let mut w = csv::Writer::from_path(&p).map_err(csv_err)?;
            w.write_record(&t.header).map_err(csv_err)?;
            for row in &t.rows {
                let rec: Vec<String> = row
                    .iter()
                    .map(|c| c.value.map_or_else(|| c.text.clone(), |v| v.to_string()))
                    .collect();
                w.write_record(&rec).map_err(csv_err)?;
            }
            w.flush().map_err(ReportError::io(&p))?;
            written.push(p);
        }
    }
    Ok(written)
}
