//! The variants table of a study: one row per scene, workload, TM count and combination of
//! swept values, with what a validation study compares between variants — DST's frame
//! time as a share of BVH2's, the order of the configurations by frame time, and BVH2's
//! memory-stall share, DRAM bandwidth, lines and rays per pixel. `report --from DIR` writes
//! it as `variants.md` beside the page, so a document can quote it as it was generated.

use super::page::{StudyData, StudyRow};
use dualsplit_sim::SimAccel;
use std::fmt::Write as _;

/// One variant: the results that share a scene, workload, TM count and swept values.
#[derive(Clone, Debug)]
pub struct Variant {
    /// Scene display name.
    pub scene: String,
    /// Workload name.
    pub workload: &'static str,
    /// TM count.
    pub tms: u32,
    /// `key=value` of each swept key (empty when nothing is swept).
    pub varied: String,
    /// DST's frame time ÷ BVH2's, when both ran.
    pub dst_vs_bvh2: Option<f64>,
    /// The configurations, fastest first, with frame times in ms.
    pub order: Vec<(SimAccel, f64)>,
    /// BVH2's row (or the first configuration's when BVH2 did not run).
    pub base: StudyRow,
}

impl Variant {
    /// The order as text: `DST 79.1 < BVH2 100.0` (frame time as % of the base's).
    pub fn order_text(&self) -> String {
        let base = self.base.frame_ms;
        self.order
            .iter()
            .map(|(a, ms)| format!("{} {:.1}", a.label(), 100.0 * ms / base))
            .collect::<Vec<_>>()
            .join(" < ")
    }

    /// DST's frame time as % of BVH2's, or a dash.
    pub fn dst_text(&self) -> String {
        self.dst_vs_bvh2
            .map_or_else(|| "—".to_string(), |x| format!("{:.1}", 100.0 * x))
    }
}

/// The variants of `data`, in the order their first result appears.
pub fn variants(data: &StudyData) -> Vec<Variant> {
    let mut out: Vec<(Vec<&StudyRow>, Variant)> = Vec::new();
    for r in &data.rows {
        let varied = r
            .varied
            .iter()
            .map(|v| format!("{}={}", v.key, v.value))
            .collect::<Vec<_>>()
            .join(" ");
        let key = (r.scene.as_str(), r.workload.name(), r.tms, varied.as_str());
        match out
            .iter_mut()
            .find(|(_, v)| (v.scene.as_str(), v.workload, v.tms, v.varied.as_str()) == key)
        {
            Some((rows, _)) => rows.push(r),
            None => out.push((
                vec![r],
                Variant {
                    scene: r.scene.clone(),
                    workload: r.workload.name(),
                    tms: r.tms,
                    varied,
                    dst_vs_bvh2: None,
                    order: Vec::new(),
                    base: r.clone(),
                },
            )),
        }
    }
    out.into_iter()
        .map(|(rows, mut v)| {
            let find = |a: SimAccel| rows.iter().find(|r| r.accel == a);
            if let Some(b) = find(SimAccel::Bvh2) {
                v.base = (*b).clone();
                if let Some(d) = find(SimAccel::Dst) {
                    v.dst_vs_bvh2 = Some(d.frame_ms / b.frame_ms);
                }
            }
            let mut order: Vec<(SimAccel, f64)> =
                rows.iter().map(|r| (r.accel, r.frame_ms)).collect();
            order.sort_by(|a, b| a.1.total_cmp(&b.1));
            v.order = order;
            v
        })
        .collect()
}

/// The variants as a Markdown table.
pub fn markdown(variants: &[Variant]) -> String {
    let mut s = String::from(
        "| scene | workload | TMs | variant | BVH2 frame (ms) | DST % of BVH2 | order, fastest first (% of BVH2) | BVH2 memory stalls | BVH2 GB/s | BVH2 lines/px | rays/px |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for v in variants {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.4} | {} | {} | {:.1} % | {:.0} | {:.2} | {:.2} |",
            v.scene,
            v.workload,
            v.tms,
            if v.varied.is_empty() {
                "(as configured)"
            } else {
                &v.varied
            },
            v.base.frame_ms,
            v.dst_text(),
            v.order_text(),
            100.0 * v.base.memory_stall_share,
            v.base.dram_gbps,
            v.base.lines_per_pixel,
            v.base.rays_per_pixel,
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::plan::Varied;
    use dualsplit_render::Workload;

    fn row(accel: SimAccel, ms: f64, l2: i64) -> StudyRow {
        StudyRow {
            index: 0,
            scene: "s".into(),
            accel,
            workload: Workload::Path,
            tms: 64,
            varied: vec![Varied {
                key: "l2.hit_latency".into(),
                value: toml::Value::Integer(l2),
            }],
            config_hash: String::new(),
            cycles: 0,
            frame_ms: ms,
            energy_j: 0.0,
            dram_lines: 0,
            rays: 0,
            memory_stall_share: 0.25,
            dram_gbps: 120.0,
            lines_per_pixel: 18.0,
            rays_per_pixel: 7.0,
        }
    }

    #[test]
    fn groups_by_swept_values_and_orders_by_frame_time() {
        let data = StudyData {
            code_version: String::new(),
            width: 1,
            height: 1,
            thread_model: dualsplit_sim::ThreadModel::Rv32,
            swept_keys: vec!["l2.hit_latency".into()],
            planned: 4,
            rows: vec![
                row(SimAccel::Bvh2, 2.0, 3),
                row(SimAccel::Dst, 1.5, 3),
                row(SimAccel::Bvh2, 2.0, 5),
                row(SimAccel::Dst, 2.2, 5),
            ],
            missing: vec![],
            invalid: vec![],
            descriptions: vec![],
            provenance: vec![],
        };
        let v = variants(&data);
        assert_eq!(v.len(), 2);
        assert_eq!(v[0].varied, "l2.hit_latency=3");
        assert_eq!(v[0].dst_vs_bvh2, Some(0.75));
        assert_eq!(v[0].order[0].0, SimAccel::Dst);
        assert_eq!(v[1].order[0].0, SimAccel::Bvh2);
        let md = markdown(&v);
        assert!(md.contains("| 75.0 | DST 75.0 < BVH2 100.0 |"), "{md}");
        assert!(md.contains("| 110.0 | BVH2 100.0 < DST 110.0 |"), "{md}");
    }
}
