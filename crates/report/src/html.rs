//! `index.html`: one self-contained page (inline CSS, inline SVG charts, base64 PNG renders,
//! HTML tables; no script, no network).

use crate::ReportError;
use crate::charts;
use crate::data::ReportData;
use crate::paper::Metric;
use crate::tables::{Section, Table, sections};
use dualsplit_render::Workload;
use std::fmt::Write;

/// Escapes text for HTML.
pub fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

const CSS: &str = "body{font-family:sans-serif;max-width:1180px;margin:24px auto;padding:0 16px;color:#222}\
h1{margin-bottom:4px}h2{border-bottom:2px solid #ccc;padding-bottom:4px;margin-top:36px}\
table{border-collapse:collapse;margin:10px 0 18px;font-size:13px}\
th,td{border:1px solid #ccc;padding:3px 7px;text-align:right}th{background:#eee}\
td:first-child,th:first-child{text-align:left}td.paper,th.paper{background:#f3f3f3;color:#777}\
caption{text-align:left;font-weight:bold;padding:4px 0}.summary{background:#eef5ff;padding:8px 12px;border-left:4px solid #58a}\
.note{color:#666;font-size:13px;margin:2px 0}.warn{background:#fff3e0;border-left:4px solid #e90;padding:8px 12px}\
.renders{display:flex;flex-wrap:wrap;gap:16px}.renders figure{margin:0;text-align:center;font-size:13px}\
.renders img{width:256px;height:256px;border:1px solid #ccc}\
.chart svg{max-width:100%;height:auto}.meta{color:#555;font-size:14px}";

/// Formats one table as HTML.
pub fn table_html(t: &Table) -> String {
    let mut h = String::new();
    let _ = write!(
        h,
        "<table id=\"{}\"><caption>{}</caption><thead><tr>",
        esc(&t.id),
        esc(&t.caption)
    );
    for (i, c) in t.header.iter().enumerate() {
        let cls = if t.paper_columns.contains(&i) {
            " class=\"paper\""
        } else {
            ""
        };
        let _ = write!(h, "<th{cls}>{}</th>", esc(c));
    }
    h.push_str("</tr></thead><tbody>");
    for row in &t.rows {
        h.push_str("<tr>");
        for (i, c) in row.iter().enumerate() {
            let cls = if t.paper_columns.contains(&i) {
                " class=\"paper\""
            } else {
                ""
            };
            let _ = write!(h, "<td{cls}>{}</td>", esc(&c.text));
        }
        h.push_str("</tr>");
    }
    h.push_str("</tbody></table>\n");
    h
}

fn section_html(s: &Section, charts: &[(String, String)]) -> String {
    let mut h = String::new();
    let _ = writeln!(
        h,
        "<section id=\"{}\"><h2>{}</h2>",
        esc(&s.id),
        esc(&s.title)
    );
    let _ = writeln!(h, "<p class=\"summary\">{}</p>", esc(&s.summary));
    for n in &s.notes {
        let _ = writeln!(h, "<p class=\"note\">{}</p>", esc(n));
    }
    for t in &s.tables {
        h.push_str(&table_html(t));
    }
    for (caption, svg) in charts {
        let _ = writeln!(
            h,
            "<figure class=\"chart\">{svg}<figcaption>{}</figcaption></figure>",
            esc(caption)
        );
    }
    h.push_str("</section>\n");
    h
}

/// The whole page.
pub fn index_html(data: &ReportData) -> Result<String, ReportError> {
    let mut h = String::new();
    h.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">");
    h.push_str("<title>dualsplit report — Hardware-Accelerated Dual-Split Trees</title>");
    let _ = writeln!(h, "<style>{CSS}</style></head><body>");
    h.push_str("<h1>Hardware-Accelerated Dual-Split Trees, regenerated</h1>\n");
    let st = &data.settings;
    let _ = writeln!(
        h,
        "<p class=\"meta\">Reproduces the results section of Lin, Vasiou, Yuksel, Kopta and Brunvand, HPG 2020 (§4, Tables 3–7, Figures 7–9). \
Simulated at {}×{}, 1 spp, {} TMs for Tables 4–6, TM scaling over {} TMs{}; the threads {}. Code version {}. Grey columns and faded bars are the paper's published values; \
scenes marked “stand-in” are not the paper's meshes, so compare trends rather than values. \
Dragon Box is SimTRaX's scene (the Stanford dragon in a closed 12-triangle box, the camera inside it; <code>dualsplit scene dragon-box</code>) wherever that file is found; the scene table names which Dragon Box a run used. \
The paper states its resolution (1024×1024) only for Table 4; it states none for Table 5 or the other tables.</p>",
        st.width,
        st.height,
        st.base_tms,
        st.tms_list(),
        if st.full {
            " (the paper's full setup)"
        } else {
            " (the quick default setup; `--full` runs the paper's)"
        },
        match st.thread_model {
            dualsplit_sim::ThreadModel::Rv32 =>
                "execute the compiled RV32IMF kernels instruction by instruction (thread model rv32)",
            dualsplit_sim::ThreadModel::Fast =>
                "replay the traversal with per-event costs measured from the compiled kernels (thread model fast, within 13 % of the kernels' frame time and 10 % of their energy and DRAM lines)",
            dualsplit_sim::ThreadModel::Simt =>
                "run warps on an RTX-style GPU with an RT unit per SM, as Vulkan-Sim models it (thread model simt)",
        },
        esc(&data.code_version)
    );
    let _ = writeln!(
        h,
        "<p class=\"meta\" id=\"scene-files\">{}</p>",
        esc(&data.scene_files.describe())
    );
    if let Some(e) = data.sim_error() {
        let _ = writeln!(h, "<p class=\"warn\" id=\"sim-unavailable\">{}</p>", esc(e));
    }
    for s in &data.skipped {
        let _ = writeln!(
            h,
            "<p class=\"warn\">scene {} skipped: {}</p>",
            esc(&s.spec),
            esc(&s.error)
        );
    }
    h.push_str("<section id=\"renders\"><h2>Scenes</h2><div class=\"renders\">\n");
    for s in &data.scenes {
        let _ = writeln!(
            h,
            "<figure><img alt=\"{}\" src=\"data:image/png;base64,{}\"><figcaption>{}<br>{} triangles</figcaption></figure>",
            esc(&s.name),
            s.render_png_base64,
            esc(&s.label()),
            s.triangles
        );
    }
    h.push_str("</div></section>\n");

    for sec in sections(data) {
        let mut cs = Vec::new();
        let fig = |w, n| -> Result<Vec<(String, String)>, ReportError> {
            let mut v = Vec::new();
            for (m, what) in [
                (Metric::FrameMs, "render times"),
                (Metric::EnergyJ, "energy use"),
                (
                    Metric::DramLines,
                    "DRAM lines read (the paper's values from its table)",
                ),
            ] {
                if let Some(svg) = charts::fig78(data, w, m)? {
                    v.push((
                        format!("Figure {n}, {what}: % of BVH2 (solid: ours; faded: paper)."),
                        svg,
                    ));
                }
            }
            Ok(v)
        };
        match sec.id.as_str() {
            "table4" => cs = fig(Workload::Cast, 7)?,
            "table5" => cs = fig(Workload::Path, 8)?,
            "table7" => {
                for s in data.scaling_scenes() {
                    if let Some(svg) = charts::fig9(data, s)? {
                        cs.push((
                            format!("Figure 9: frames per second vs TM count, {}.", s.label()),
                            svg,
                        ));
                    }
                }
            }
            "rtx" => {
                if let Some(svg) = data
                    .rtx
                    .as_ref()
                    .map(charts::rtx_sweep)
                    .transpose()?
                    .flatten()
                {
                    cs.push((
                        format!(
                            "Frame time of {} ({}) against warps per RT unit (left) and MSHRs (right); dashed: the RTX 2060's value.",
                            crate::rtx::SWEEP_WORKLOAD.name(),
                            data.rtx.as_ref().map_or("", |r| r.scene.as_str())
                        ),
                        svg,
                    ));
                }
            }
            _ => {}
        }
        h.push_str(&section_html(&sec, &cs));
    }
    h.push_str("</body></html>\n");
    Ok(h)
}
