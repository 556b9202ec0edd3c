//! Sweep charts: for each swept key, frame time, energy and DRAM lines against the key's
//! value, one line per configuration; one chart per scene, workload, TM count and value of
//! the other swept keys. Drawn once per backend: SVG for the page, PNG beside it.

use super::page::{StudyData, StudyRow};
use super::vary::as_number;
use crate::ReportError;
use crate::charts::color;
use crate::units;
use dualsplit_sim::SimAccel;
use plotters::coord::Shift;
use plotters::prelude::*;

/// One chart.
pub struct SweepChart {
    /// What it shows.
    pub title: String,
    /// SVG text.
    pub svg: String,
    /// The same as PNG.
    pub png: Vec<u8>,
}

const W: u32 = 1050;
const H: u32 = 330;

/// A metric's value in a row.
type MetricOf = fn(&StudyRow) -> f64;

/// The metrics, their axis names and their values in a row.
const METRICS: [(&str, MetricOf); 3] = [
    ("frame time (ms)", |r| r.frame_ms),
    ("energy (J)", |r| r.energy_j),
    ("DRAM lines", |r| r.dram_lines as f64),
];

/// One chart's data: per configuration, (key value, row) points sorted by value.
struct Group {
    title: String,
    key: String,
    lines: Vec<(SimAccel, Vec<(f64, StudyRow)>)>,
}

fn groups(data: &StudyData) -> Vec<Group> {
    let mut out: Vec<Group> = Vec::new();
    for key in &data.swept_keys {
        for r in &data.rows {
            let Some(x) = r
                .varied
                .iter()
                .find(|v| &v.key == key)
                .and_then(|v| as_number(&v.value))
            else {
                continue;
            };
            let others: Vec<String> = r
                .varied
                .iter()
                .filter(|v| &v.key != key)
                .map(|v| format!("{}={}", v.key, v.value))
                .collect();
            let tms = if key == "tms" {
                String::new()
            } else {
                format!(", {} TMs", r.tms)
            };
            let mut title = format!("{key}: {} {}{tms}", r.scene, r.workload.name());
            if !others.is_empty() {
                title.push_str(&format!(" ({})", others.join(", ")));
            }
            let g = match out.iter_mut().find(|g| g.title == title) {
                Some(g) => g,
                None => {
                    out.push(Group {
                        title: title.clone(),
                        key: key.clone(),
                        lines: Vec::new(),
                    });
                    out.last_mut().expect("just pushed")
                }
            };
            match g.lines.iter_mut().find(|(a, _)| *a == r.accel) {
                Some((_, pts)) => pts.push((x, r.clone())),
                None => g.lines.push((r.accel, vec![(x, r.clone())])),
            }
        }
    }
    for g in &mut out {
        g.lines
            .sort_by_key(|(a, _)| SimAccel::ALL.iter().position(|b| b == a));
        for (_, pts) in &mut g.lines {
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
    }
    // A chart needs a line with two values of the key.
    out.retain(|g| g.lines.iter().any(|(_, p)| p.len() >= 2));
    out
}

/// Every sweep chart of the study.
pub fn charts(data: &StudyData) -> Result<Vec<SweepChart>, ReportError> {
    crate::charts::register_font();
    let mut out = Vec::new();
    for g in groups(data) {
        let err = |message: String| ReportError::Chart {
            chart: g.title.clone(),
            message,
        };
        let mut svg = String::new();
        draw(
            &SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area(),
            &g,
        )
        .map_err(err)?;
        let mut rgb = vec![0u8; (W * H * 3) as usize];
        draw(
            &BitMapBackend::with_buffer(&mut rgb, (W, H)).into_drawing_area(),
            &g,
        )
        .map_err(err)?;
        let png = crate::produce::encode_png(W, H, png::ColorType::Rgb, &rgb).map_err(|m| {
            ReportError::Png {
                what: g.title.clone(),
                message: m,
            }
        })?;
        out.push(SweepChart {
            title: g.title,
            svg,
            png,
        });
    }
    Ok(out)
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, g: &Group) -> Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let root = root.titled(&g.title, ("sans-serif", 16)).map_err(e)?;
    let (panels, key) = root.split_horizontally(W - 110);
    for (i, a) in g.lines.iter().map(|(a, _)| *a).enumerate() {
        let y = 30 + 20 * i as i32;
        key.draw(&PathElement::new(
            [(6, y), (30, y)],
            color(a).stroke_width(3),
        ))
        .map_err(e)?;
        key.draw(&Text::new(a.label(), (36, y - 7), ("sans-serif", 13)))
            .map_err(e)?;
    }
    // The key's values, evenly spaced and labelled exactly (sweeps are usually doublings
    // or small counts, which a linear axis would crowd at one end).
    let mut values: Vec<f64> = g
        .lines
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.0))
        .collect();
    values.sort_by(f64::total_cmp);
    values.dedup();
    let pos = |x: f64| values.iter().position(|&v| v == x).unwrap_or(0) as f64;
    let n = values.len() as f64;
    for (panel, (name, value)) in panels.split_evenly((1, 3)).iter().zip(METRICS) {
        let ymax = g
            .lines
            .iter()
            .flat_map(|(_, p)| p.iter().map(|q| value(&q.1)))
            .fold(0.0f64, f64::max)
            * 1.1;
        let mut chart = ChartBuilder::on(panel)
            .margin(8)
            .x_label_area_size(34)
            .y_label_area_size(68)
            .build_cartesian_2d(-0.3f64..(n - 0.7), 0f64..ymax.max(1e-12))
            .map_err(e)?;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(values.len() * 4)
            .x_label_formatter(&|x| {
                let i = x.round();
                match values.get(i as usize) {
                    Some(v) if (x - i).abs() < 1e-6 && i >= 0.0 => format_value(*v),
                    _ => String::new(),
                }
            })
            .y_label_formatter(&|y| axis_number(*y, ymax))
            .light_line_style(WHITE.mix(0.0))
            .x_desc(g.key.as_str())
            .y_desc(name)
            .axis_desc_style(("sans-serif", 12))
            .draw()
            .map_err(e)?;
        for (a, pts) in &g.lines {
            let series: Vec<(f64, f64)> = pts.iter().map(|(x, r)| (pos(*x), value(r))).collect();
            chart
                .draw_series(LineSeries::new(series.clone(), color(*a).stroke_width(2)))
                .map_err(e)?;
            chart
                .draw_series(
                    series
                        .iter()
                        .map(|&p| Circle::new(p, 3, color(*a).filled())),
                )
                .map_err(e)?;
        }
    }
    root.present().map_err(e)?;
    Ok(())
}

/// A swept value as its label: whole numbers without decimals.
fn format_value(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}

/// An axis number with enough decimals for an axis running to `max` (three significant
/// digits of the largest value).
fn axis_number(y: f64, max: f64) -> String {
    if max >= 1000.0 {
        return units::compact(y);
    }
    let decimals = (2 - max.abs().max(1e-12).log10().floor() as i32).max(0) as usize;
    format!("{y:.decimals$}")
}
