//! "Beyond the paper": the compressed 8-wide BVH (CWBVH, Ylitie et al. 2017) and the
//! quantized dual-split tree (DST-Q, the paper's §5 future work) beside BVH2, BVH8, BVH8+
//! and DST, on every scene, at the base TM count and at [`BEYOND_TMS`], both workloads:
//! sizes, the per-ray work quantization adds (from a counting observer on the CPU ray sets),
//! and the simulated frame time, energy, DRAM lines and memory-stall share as % of BVH2 on
//! the same chip. The summary answers §5's question: is a quantized DST faster than a
//! compressed wide BVH on the same hardware?

use crate::data::{ReportData, SceneReport};
use crate::produce::{BEYOND_TMS, COUNTED};
use crate::tables::{Cell, Section, Table};
use crate::units;
use dualsplit_accel::AccelKind;
use dualsplit_render::{RayKind, Workload};
use dualsplit_sim::{SimAccel, SimResult, StallShares};

/// The structures of the size table, in column order.
const SIZED: [AccelKind; 5] = [
    AccelKind::Bvh2,
    AccelKind::Bvh8,
    AccelKind::Dst,
    AccelKind::Cwbvh,
    AccelKind::DstQ,
];

/// The section.
pub fn section(data: &ReportData) -> Section {
    let mut tables = vec![sizes(data), work(data)];
    let mut notes = Vec::new();
    for workload in [Workload::Cast, Workload::Path] {
        for tms in tms_counts(data.settings.base_tms) {
            tables.push(simulated(data, workload, tms, &mut notes));
        }
    }
    notes.sort();
    notes.dedup();
    Section {
        id: "beyond".into(),
        title: "Beyond the paper — compressed wide BVH and quantized DST".into(),
        summary: summary(data),
        notes,
        tables,
    }
}

/// The TM counts of the simulated tables: the base count and [`BEYOND_TMS`].
fn tms_counts(base_tms: u32) -> Vec<u32> {
    let mut v = vec![base_tms];
    if BEYOND_TMS != base_tms {
        v.push(BEYOND_TMS);
    }
    v
}

fn sizes(data: &ReportData) -> Table {
    let all: Vec<f64> = data
        .scenes
        .iter()
        .flat_map(|s| SIZED.iter().filter_map(|&k| s.bytes(k)))
        .map(|b| b as f64)
        .collect();
    let (unit, scale) = units::bytes_unit(&all);
    let mut header = vec!["scene".to_string()];
    for k in SIZED {
        header.push(format!("{} {unit}", label(k)));
        if k != AccelKind::Bvh2 {
            header.push(format!("{} % of BVH2", label(k)));
        }
    }
    let rows = data
        .scenes
        .iter()
        .map(|s| {
            let mut row = vec![Cell::text(&s.name)];
            let b2 = s.bytes(AccelKind::Bvh2);
            for k in SIZED {
                let b = s.bytes(k);
                row.push(b.map_or_else(Cell::none, |b| Cell::num(b as f64 * scale)));
                if k != AccelKind::Bvh2 {
                    row.push(ratio(b.map(|b| b as f64), b2.map(|b| b as f64)));
                }
            }
            row
        })
        .collect();
    Table {
        id: "beyond-sizes".into(),
        caption: format!(
            "Nodes plus triangle-index lists, {unit}; % of BVH2. CWBVH: the BVH8's nodes in 80 bytes; DST-Q: the DST's records with 8-bit planes in 64-byte clusters."
        ),
        header,
        paper_columns: Vec::new(),
        rows,
    }
}

fn work(data: &ReportData) -> Table {
    let header = [
        "scene",
        "ray kind",
        "rays",
        "BVH8 nodes/ray",
        "CWBVH nodes/ray",
        "CWBVH extra box tests",
        "CWBVH extra triangle tests",
        "DST nodes/ray",
        "DST-Q nodes/ray",
        "DST-Q extra plane tests",
        "DST-Q extra triangle tests",
    ]
    .map(String::from)
    .to_vec();
    let mut rows = Vec::new();
    for s in &data.scenes {
        for rk in [RayKind::Primary, RayKind::Shadow, RayKind::Diffuse] {
            let get = |k| {
                s.cpu
                    .counts
                    .iter()
                    .find(|c| c.kind == k && c.ray_kind == rk)
            };
            let [Some(b8), Some(cw), Some(d), Some(q)] = COUNTED.map(get) else {
                continue;
            };
            rows.push(vec![
                Cell::text(&s.name),
                Cell::text(format!("{rk:?}").to_lowercase()),
                Cell::int(b8.rays),
                Cell::num(b8.nodes),
                Cell::num(cw.nodes),
                extra(cw.box_tests, b8.box_tests),
                extra(cw.triangle_tests, b8.triangle_tests),
                Cell::num(d.nodes),
                Cell::num(q.nodes),
                extra(q.plane_tests, d.plane_tests),
                extra(q.triangle_tests, d.triangle_tests),
            ]);
        }
    }
    Table {
        id: "beyond-work".into(),
        caption: "Per-ray work on the CPU ray sets (the rays the CPU timings use), counted by the traversals themselves: internal nodes stepped, and what quantization adds over the exact structure — child boxes tested (CWBVH over BVH8), planes tested (DST-Q over DST) and triangles tested. Closest hits and shadow answers are identical (checked ray by ray)."
            .into(),
        header,
        paper_columns: Vec::new(),
        rows,
    }
}

fn simulated(data: &ReportData, workload: Workload, tms: u32, notes: &mut Vec<String>) -> Table {
    let header = [
        "scene",
        "configuration",
        "frame time (ms)",
        "frame time % of BVH2",
        "energy % of BVH2",
        "DRAM lines % of BVH2",
        "memory-stall share",
        "DRAM GB/s",
    ]
    .map(String::from)
    .to_vec();
    let mut rows = Vec::new();
    for s in &data.scenes {
        let base = s.sim(SimAccel::Bvh2, workload, tms);
        for a in SimAccel::BEYOND {
            let Some(r) = s.sim(a, workload, tms) else {
                notes.push(format!(
                    "{} {} at {tms} TMs on {}: not simulated{}.",
                    a.label(),
                    workload.name(),
                    s.name,
                    s.sim_error().map_or(String::new(), |e| format!(" ({e})"))
                ));
                continue;
            };
            let of = |f: fn(&SimResult) -> f64| ratio(Some(f(r)), base.map(f));
            rows.push(vec![
                Cell::text(&s.name),
                Cell::text(a.label()),
                Cell::num(r.frame_ms),
                of(|r| r.frame_ms),
                of(|r| r.energy.total()),
                of(|r| r.dram_lines as f64),
                Cell::pct(StallShares::of(r).memory),
                Cell::num(r.memory.dram_gbps),
            ]);
        }
    }
    Table {
        id: format!("beyond-{}-{tms}", workload.name()),
        caption: format!(
            "{} at {tms} TMs (lin2020 chip otherwise), compiled kernels: frame time, energy and DRAM lines as % of BVH2 on the same chip; memory-stall share: the threads' cycles waiting for load data.",
            match workload {
                Workload::Cast => "Ray casting with a shadow ray",
                Workload::Path => "Path tracing",
            }
        ),
        header,
        paper_columns: Vec::new(),
        rows,
    }
}

/// The generated paragraph: sizes, the work quantization adds, and §5's question.
pub fn summary(data: &ReportData) -> String {
    let mut out = Vec::new();
    // Sizes.
    let size_of = |s: &SceneReport, k| Some(s.bytes(k)? as f64 / s.bytes(AccelKind::Bvh2)? as f64);
    let sized: Vec<String> = data
        .scenes
        .iter()
        .filter_map(|s| {
            Some(format!(
                "{}: CWBVH {:.0}%, DST-Q {:.0}% of BVH2 (BVH8 {:.0}%, DST {:.0}%)",
                s.name,
                100.0 * size_of(s, AccelKind::Cwbvh)?,
                100.0 * size_of(s, AccelKind::DstQ)?,
                100.0 * size_of(s, AccelKind::Bvh8)?,
                100.0 * size_of(s, AccelKind::Dst)?
            ))
        })
        .collect();
    if !sized.is_empty() {
        out.push(format!("Sizes — {}.", sized.join("; ")));
    }
    // The question: DST-Q against CWBVH and CWBVH+ on the same chip.
    let mut cases = 0;
    let (mut beats_cw, mut beats_cwp, mut beats_dst) = (0, 0, 0);
    let mut lines = Vec::new();
    for s in &data.scenes {
        for workload in [Workload::Cast, Workload::Path] {
            for tms in tms_counts(data.settings.base_tms) {
                let ms = |a| s.sim(a, workload, tms).map(|r| r.frame_ms);
                let (Some(b2), Some(q), Some(cw), Some(cwp), Some(d)) = (
                    ms(SimAccel::Bvh2),
                    ms(SimAccel::DstQ),
                    ms(SimAccel::Cwbvh),
                    ms(SimAccel::CwbvhPlus),
                    ms(SimAccel::Dst),
                ) else {
                    continue;
                };
                cases += 1;
                beats_cw += usize::from(q < cw);
                beats_cwp += usize::from(q < cwp);
                beats_dst += usize::from(q < d);
                lines.push(format!(
                    "{} {} at {tms} TMs: DST-Q {:.0}%, CWBVH {:.0}%, CWBVH+ {:.0}%, DST {:.0}% of BVH2",
                    s.name,
                    workload.name(),
                    100.0 * q / b2,
                    100.0 * cw / b2,
                    100.0 * cwp / b2,
                    100.0 * d / b2
                ));
            }
        }
    }
    if cases == 0 {
        out.push("No scene has all of BVH2, DST, DST-Q, CWBVH and CWBVH+ simulated; the question of §5 is not answered here.".into());
    } else {
        out.push(format!(
            "Is a quantized DST faster than a compressed wide BVH on the same hardware (§5)? In the {cases} simulated cases (scene × workload × TM count) DST-Q is faster than CWBVH (one quantized ray-box pipeline) in {beats_cw}, than CWBVH+ (eight) in {beats_cwp}, and than the exact DST in {beats_dst}. {}.",
            lines.join("; ")
        ));
    }
    out.join(" ")
}

/// The table heading of a structure: its command-line name upper-cased (`DST-Q`), the DST
/// under one name for both decoders.
fn label(k: AccelKind) -> String {
    match k {
        AccelKind::DstSw => "DST".into(),
        k => k.name().to_uppercase(),
    }
}

/// `a / b` as a percentage cell, or none.
fn ratio(a: Option<f64>, b: Option<f64>) -> Cell {
    match (a, b) {
        (Some(a), Some(b)) if b > 0.0 => Cell::pct(a / b),
        _ => Cell::none(),
    }
}

/// How much larger `q` is than `exact`, as a signed percentage (`+3.1%`).
fn extra(q: f64, exact: f64) -> Cell {
    if exact > 0.0 {
        let v = q / exact - 1.0;
        Cell {
            text: format!("{:+.1}%", 100.0 * v),
            value: Some(100.0 * v),
        }
    } else {
        Cell::none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extra_is_signed_percent() {
        assert_eq!(extra(1.031, 1.0).text, "+3.1%");
        assert_eq!(extra(0.5, 1.0).text, "-50.0%");
        assert_eq!(extra(1.0, 0.0).text, "—");
    }

    #[test]
    fn the_tms_counts_are_base_and_beyond() {
        assert_eq!(tms_counts(64), vec![64, BEYOND_TMS]);
        assert_eq!(tms_counts(BEYOND_TMS), vec![BEYOND_TMS]);
    }
}
