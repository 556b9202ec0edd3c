//! The memory-system section: for every scene and workload at the base TM count, what the
//! caches and the DRAM did per configuration. These are the figures that say which regime a
//! frame is in (bound by compute and latency, or by DRAM bandwidth), on which every frame
//! time comparison rests.

use crate::data::ReportData;
use crate::tables::{Cell, Section, Table, scene_id};
use dualsplit_render::Workload;
use dualsplit_sim::{SimAccel, StallShares};

/// The "Memory system" section.
pub fn section(data: &ReportData) -> Section {
    let tms = data.settings.base_tms;
    let mut tables = Vec::new();
    for workload in Workload::ALL {
        for (i, s) in data.scenes.iter().enumerate() {
            if s.sim(SimAccel::Bvh2, workload, tms).is_none() {
                continue;
            }
            let header: Vec<String> = [
                "configuration",
                "L1 hit",
                "L2 hit",
                "L2 bank-conflict cycles",
                "DRAM row hit",
                "DRAM read latency mean (cycles)",
                "DRAM read latency p95 (cycles)",
                "DRAM GB/s",
                "lines / pixel",
                "rays / pixel",
                "memory stall",
            ]
            .map(String::from)
            .to_vec();
            let rows = SimAccel::PAPER
                .iter()
                .filter_map(|&a| {
                    let r = s.sim(a, workload, tms)?;
                    let m = &r.memory;
                    Some(vec![
                        Cell::text(a.label()),
                        Cell::pct(m.l1_hit_rate),
                        Cell::pct(m.l2_hit_rate),
                        Cell::int(m.l2_bank_conflict_cycles),
                        Cell::pct(m.dram_row_hit_rate),
                        Cell::num(m.dram_latency_mean_cycles),
                        Cell::int(m.dram_latency_p95_cycles),
                        Cell::num(m.dram_gbps),
                        Cell::num(m.lines_per_pixel),
                        Cell::num(m.rays_per_pixel),
                        Cell::pct(StallShares::of(r).memory),
                    ])
                })
                .collect();
            tables.push(Table {
                id: format!("memory-{}-{}", workload.name(), scene_id(i, s)),
                caption: format!(
                    "{} — {}, {}×{}, {} TMs, {} thread model",
                    s.label(),
                    workload.name(),
                    data.settings.width,
                    data.settings.height,
                    tms,
                    data.settings.thread_model.name()
                ),
                header,
                paper_columns: Vec::new(),
                rows,
            });
        }
    }
    Section {
        id: "memory".into(),
        title: "Memory system — caches and DRAM per configuration".into(),
        summary: "Hit rates, L2 bank-conflict cycles, the DRAM's row-hit rate, read latency \
                  (arrival at the DRAM to data) and achieved bandwidth over the frame, and DRAM \
                  lines and rays per pixel. A reading of them (an inference, not a measurement): a \
                  frame near the DRAM's sustainable bandwidth with a large memory-stall share is \
                  bandwidth-bound: there the structure that \
                  moves the fewest lines wins; a frame far from it is bound by latency and \
                  issue."
            .into(),
        notes: Vec::new(),
        tables,
    }
}
