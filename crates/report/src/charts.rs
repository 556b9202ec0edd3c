//! Charts as inline SVG, drawn with plotters' SVG backend and the embedded DejaVu Sans font
//! (through `ab_glyph`, so no system font is needed for text layout).
//!
//! * Figures 7 and 8 (Lin et al. 2020, §4.3–4.4): bars of frame time and energy per
//!   configuration as % of BVH2, one panel per scene; ours solid, the paper's faded beside.
//!   The same chart of DRAM lines read (the paper gives those in Tables 4 and 5 only).
//! * Figure 9 (§4.5): frames per second vs TM count, one line per configuration; ours on the
//!   left, the paper's corresponding scene on the right.

use crate::ReportError;
use crate::data::{ReportData, SceneReport};
use crate::paper::{self, Metric};
use crate::tables::metric;
use crate::units;
use dualsplit_render::Workload;
use dualsplit_sim::SimAccel;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

pub(crate) fn register_font() {
    REGISTER.call_once(|| {
        // The font is embedded and valid; a failure would only lose text metrics.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// The colour of a configuration: blues for BVH2, greens for BVH4, oranges for BVH8,
/// purple for DST*, red for DST.
pub fn color(a: SimAccel) -> RGBColor {
    let [r, g, b] = a.color();
    RGBColor(r, g, b)
}

fn chart_err(chart: &str) -> impl Fn(String) -> ReportError + '_ {
    move |message| ReportError::Chart {
        chart: chart.to_string(),
        message,
    }
}

/// Figure 7 (`Cast`) or 8 (`Path`) for `metric` (frame time, energy or DRAM lines): one
/// panel per scene
/// with simulated results. `None` when no scene has results.
pub fn fig78(
    data: &ReportData,
    workload: Workload,
    metric_kind: Metric,
) -> Result<Option<String>, ReportError> {
    register_font();
    let tms = data.settings.base_tms;
    let scenes: Vec<&SceneReport> = data
        .scenes
        .iter()
        .filter(|s| s.sim(SimAccel::Bvh2, workload, tms).is_some())
        .collect();
    if scenes.is_empty() {
        return Ok(None);
    }
    let id = format!("fig-{}-{:?}", workload.name(), metric_kind);
    let err = chart_err(&id);
    let (w, panel_h) = (900u32, 230u32);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (w, panel_h * scenes.len() as u32))
            .into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
        let panels = root.split_evenly((scenes.len(), 1));
        for (panel, s) in panels.iter().zip(&scenes) {
            let base = s
                .sim(SimAccel::Bvh2, workload, tms)
                .map(|r| metric(r, metric_kind));
            let mut bars = Vec::new();
            for (i, a) in SimAccel::PAPER.iter().enumerate() {
                let x = i as f64;
                if let (Some(r), Some(b)) = (s.sim(*a, workload, tms), base)
                    && b > 0.0
                {
                    bars.push((
                        x - 0.38,
                        x,
                        100.0 * metric(r, metric_kind) / b,
                        color(*a).filled(),
                    ));
                }
                if let Some(m) = &s.paper {
                    let v = paper::table45(workload, metric_kind, *a, m.scene)
                        / paper::table45(workload, metric_kind, SimAccel::Bvh2, m.scene);
                    bars.push((x, x + 0.38, 100.0 * v, color(*a).mix(0.3).filled()));
                }
            }
            let ymax = bars.iter().map(|b| b.2).fold(100.0f64, f64::max) * 1.12;
            let title = match &s.paper {
                Some(m) => format!(
                    "{} — solid: ours, faded: paper's {}",
                    s.name,
                    m.scene.label()
                ),
                None => s.name.clone(),
            };
            let mut chart = ChartBuilder::on(panel)
                .caption(title, ("sans-serif", 15))
                .margin(6)
                .x_label_area_size(24)
                .y_label_area_size(52)
                .build_cartesian_2d(-0.5f64..7.5f64, 0f64..ymax)
                .map_err(|e| err(e.to_string()))?;
            chart
                .configure_mesh()
                .disable_x_mesh()
                .x_labels(8)
                .x_label_formatter(&|x| {
                    let i = x.round();
                    if (x - i).abs() < 1e-6 && (0.0..8.0).contains(&i) {
                        SimAccel::PAPER[i as usize].label().to_string()
                    } else {
                        String::new()
                    }
                })
                .y_label_formatter(&|y| format!("{y:.0}%"))
                .light_line_style(WHITE.mix(0.0))
                .y_desc(format!("{} (% of BVH2)", metric_kind.name()))
                .axis_desc_style(("sans-serif", 12))
                .draw()
                .map_err(|e| err(e.to_string()))?;
            chart
                .draw_series(
                    bars.into_iter()
                        .map(|(x0, x1, v, style)| Rectangle::new([(x0, 0.0), (x1, v)], style)),
                )
                .map_err(|e| err(e.to_string()))?;
            chart
                .draw_series(LineSeries::new(
                    [(-0.5, 100.0), (7.5, 100.0)],
                    BLACK.mix(0.5),
                ))
                .map_err(|e| err(e.to_string()))?;
        }
        root.present().map_err(|e| err(e.to_string()))?;
    }
    Ok(Some(svg))
}

fn fps_panel(
    panel: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    title: &str,
    tms: &[u32],
    series: &[(SimAccel, Vec<(f64, f64)>)],
    faded: bool,
    err: &dyn Fn(String) -> ReportError,
) -> Result<(), ReportError> {
    let xmin = tms.iter().copied().min().unwrap_or(1) as f64;
    let xmax = tms.iter().copied().max().unwrap_or(2) as f64;
    let ymax = series
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.1))
        .fold(0.0f64, f64::max)
        * 1.1;
    // TM counts double from one run to the next: a log axis spaces them evenly, with a
    // tick at each count that was run and none elsewhere.
    let pad = (xmax / xmin).max(2.0).powf(0.06);
    let ticks: Vec<f64> = tms.iter().map(|&t| f64::from(t)).collect();
    let x_axis = ((xmin / pad)..(xmax * pad))
        .log_scale()
        .with_key_points(ticks);
    let mut chart = ChartBuilder::on(panel)
        .caption(title, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(52)
        .build_cartesian_2d(x_axis, 0f64..ymax.max(1e-9))
        .map_err(|e| err(e.to_string()))?;
    chart
        .configure_mesh()
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| units::compact(*y))
        .light_line_style(WHITE.mix(0.0))
        .x_desc("TMs")
        .y_desc("frames per second")
        .axis_desc_style(("sans-serif", 12))
        .draw()
        .map_err(|e| err(e.to_string()))?;
    for (a, pts) in series {
        let c = if faded {
            color(*a).mix(0.55)
        } else {
            color(*a).mix(1.0)
        };
        chart
            .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
            .map_err(|e| err(e.to_string()))?;
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
            .map_err(|e| err(e.to_string()))?;
    }
    Ok(())
}

/// The configurations' colour key, drawn beside the panels so it never covers a line.
fn legend(
    area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
    err: &dyn Fn(String) -> ReportError,
) -> Result<(), ReportError> {
    for (i, a) in SimAccel::PAPER.iter().enumerate() {
        let y = 40 + 20 * i as i32;
        area.draw(&PathElement::new(
            [(6, y), (30, y)],
            color(*a).stroke_width(3),
        ))
        .map_err(|e| err(e.to_string()))?;
        area.draw(&Text::new(a.label(), (36, y - 7), ("sans-serif", 13)))
            .map_err(|e| err(e.to_string()))?;
    }
    Ok(())
}

/// Figure 9 for one scene: frames per second of path tracing vs TM count; the paper's
/// corresponding scene (Crytek Sponza or Hairball) in a faded panel beside. `None` when the
/// scene has no scaling results.
pub fn fig9(data: &ReportData, s: &SceneReport) -> Result<Option<String>, ReportError> {
    register_font();
    let tms = &data.settings.tms;
    let ours: Vec<(SimAccel, Vec<(f64, f64)>)> = SimAccel::PAPER
        .iter()
        .map(|&a| {
            let pts = tms
                .iter()
                .filter_map(|&t| {
                    let r = s.sim(a, Workload::Path, t)?;
                    (r.frame_ms > 0.0).then(|| (f64::from(t), 1000.0 / r.frame_ms))
                })
                .collect();
            (a, pts)
        })
        .collect();
    if ours.iter().all(|(_, p)| p.len() < 2) {
        return Ok(None);
    }
    let pm = s.paper.filter(|m| m.scene.table67_index().is_some());
    let id = format!("fig9-{}", s.name);
    let err = chart_err(&id);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 340)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
        let (panels, key) = root.split_horizontally(800);
        legend(&key, &err)?;
        let (left, right) = panels.split_horizontally(if pm.is_some() { 400 } else { 800 });
        fps_panel(
            &left,
            &format!("{} (ours)", s.name),
            tms,
            &ours,
            false,
            &err,
        )?;
        if let Some(m) = pm {
            let paper_series: Vec<(SimAccel, Vec<(f64, f64)>)> = SimAccel::PAPER
                .iter()
                .map(|&a| {
                    let pts = paper::TABLE7_TMS
                        .iter()
                        .filter_map(|&t| {
                            Some((f64::from(t), 1000.0 / paper::table7(a, m.scene, t)?))
                        })
                        .collect();
                    (a, pts)
                })
                .collect();
            fps_panel(
                &right,
                &format!("paper: {} (published)", m.scene.label()),
                &paper::TABLE7_TMS,
                &paper_series,
                true,
                &err,
            )?;
        }
        root.present().map_err(|e| err(e.to_string()))?;
    }
    Ok(Some(svg))
}

/// "On an RTX-style GPU": frame time (µs) of each swept structure against warps per RT unit
/// (left) and MSHRs (right), log-2 axes at the swept values, the RTX 2060's value dashed.
/// `None` when no sweep frame succeeded.
pub fn rtx_sweep(rtx: &crate::data::RtxData) -> Result<Option<String>, ReportError> {
    use crate::rtx::{SWEEP_MSHR, SWEEP_WARPS, SWEEP_WORKLOAD, swept};
    register_font();
    let series = |mshr: bool| -> Vec<(SimAccel, Vec<(f64, f64)>)> {
        let values: &[u32] = if mshr { &SWEEP_MSHR } else { &SWEEP_WARPS };
        swept()
            .into_iter()
            .map(|a| {
                let pts = values
                    .iter()
                    .filter_map(|&v| {
                        let (w, m) = if mshr {
                            (rtx.base_warps, v)
                        } else {
                            (v, rtx.base_mshr)
                        };
                        let r = rtx.get(a, SWEEP_WORKLOAD, w, m)?;
                        Some((f64::from(v), r.frame_ms * 1e3))
                    })
                    .collect();
                (a, pts)
            })
            .collect()
    };
    let (warps, mshrs) = (series(false), series(true));
    if warps.iter().chain(&mshrs).all(|(_, p)| p.is_empty()) {
        return Ok(None);
    }
    let err = chart_err("rtx-sweep");
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 320)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(e.to_string()))?;
        let (panels, key) = root.split_horizontally(800);
        for (i, a) in swept().into_iter().enumerate() {
            let y = 40 + 20 * i as i32;
            key.draw(&PathElement::new(
                [(6, y), (30, y)],
                color(a).stroke_width(3),
            ))
            .map_err(|e| err(e.to_string()))?;
            key.draw(&Text::new(a.label(), (36, y - 7), ("sans-serif", 13)))
                .map_err(|e| err(e.to_string()))?;
        }
        let (left, right) = panels.split_horizontally(400);
        for (area, data, values, base, what) in [
            (
                &left,
                &warps,
                &SWEEP_WARPS[..],
                rtx.base_warps,
                "warps per RT unit",
            ),
            (
                &right,
                &mshrs,
                &SWEEP_MSHR[..],
                rtx.base_mshr,
                "MSHRs per RT unit",
            ),
        ] {
            let xmin = f64::from(values[0]);
            let xmax = f64::from(values[values.len() - 1]);
            let ymax = data
                .iter()
                .flat_map(|(_, p)| p.iter().map(|q| q.1))
                .fold(0.0f64, f64::max)
                * 1.1;
            let ticks: Vec<f64> = values.iter().map(|&v| f64::from(v)).collect();
            let x_axis = ((xmin / 1.15)..(xmax * 1.15))
                .log_scale()
                .with_key_points(ticks);
            let mut chart = ChartBuilder::on(area)
                .caption(what, ("sans-serif", 15))
                .margin(8)
                .x_label_area_size(30)
                .y_label_area_size(52)
                .build_cartesian_2d(x_axis, 0f64..ymax.max(1e-9))
                .map_err(|e| err(e.to_string()))?;
            chart
                .configure_mesh()
                .x_label_formatter(&|x| format!("{x:.0}"))
                .y_label_formatter(&|y| units::compact(*y))
                .light_line_style(WHITE.mix(0.0))
                .x_desc(what)
                .y_desc("frame time (µs)")
                .axis_desc_style(("sans-serif", 12))
                .draw()
                .map_err(|e| err(e.to_string()))?;
            let b = f64::from(base);
            chart
                .draw_series(DashedLineSeries::new(
                    [(b, 0.0), (b, ymax)],
                    4,
                    4,
                    BLACK.mix(0.4).stroke_width(1),
                ))
                .map_err(|e| err(e.to_string()))?;
            for (a, pts) in data {
                let c = color(*a).mix(1.0);
                chart
                    .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
                    .map_err(|e| err(e.to_string()))?;
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 3, c.filled())))
                    .map_err(|e| err(e.to_string()))?;
            }
        }
        root.present().map_err(|e| err(e.to_string()))?;
    }
    Ok(Some(svg))
}
