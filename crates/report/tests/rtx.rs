//! "On an RTX-style GPU": the section appears with its columns, its figures are finite, and
//! its sentences state the numbers of the frames they were computed from.

use dualsplit_accel::{BuildConfig, Structures};
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_report::data::{ReportData, ReportSettings, RtxData, RtxRun};
use dualsplit_report::paper::PaperValues;
use dualsplit_report::rtx::{self, Figures};
use dualsplit_report::{html, tables, write};
use dualsplit_sim::{FrameRequest, SimAccel, ThreadModel};

/// Every frame of the section's plan, simulated on the Cornell box at 16×16 (the section's
/// logic does not depend on the resolution).
fn rtx_data() -> RtxData {
    let scene = dualsplit_scene::load("builtin:cornell").unwrap();
    let structures = Structures::try_build(&scene.triangles, &BuildConfig::default()).unwrap();
    let base = rtx::config().unwrap();
    let (base_warps, base_mshr) = rtx::point(&base);
    let runs = rtx::plan(&base)
        .into_iter()
        .map(|(accel, workload, warps, mshr)| {
            let cfg = rtx::with_point(&base, warps, mshr);
            let settings = RenderSettings::new(16, 16, workload);
            let result = dualsplit_sim::simulate(
                &FrameRequest::new(&scene, &structures, accel, &settings, &cfg)
                    .with_model(ThreadModel::Simt),
                &|_, _| {},
            )
            .map_err(|e| e.to_string());
            RtxRun {
                accel,
                workload,
                rt_max_warps: warps,
                rt_max_mshr: mshr,
                result,
            }
        })
        .collect();
    RtxData {
        scene: scene.name.clone(),
        spec: scene.spec.clone(),
        res: 16,
        base_warps,
        base_mshr,
        peak_dram_gbps: rtx::peak_dram_gbps(&base),
        runs,
    }
}

fn report(rtx: Option<RtxData>) -> ReportData {
    ReportData {
        code_version: "test".into(),
        settings: ReportSettings {
            width: 8,
            height: 8,
            tms: vec![64],
            base_tms: 64,
            cpu_res: 8,
            full: false,
            thread_model: ThreadModel::Fast,
        },
        scenes: vec![],
        skipped: vec![],
        scene_files: Default::default(),
        paper: PaperValues::published(),
        rtx,
    }
}

#[test]
fn the_section_shows_every_rt_structure_with_finite_figures_and_sentences_from_them() {
    let rtx = rtx_data();
    assert_eq!(rtx.error(), None);
    assert_eq!((rtx.base_warps, rtx.base_mshr), (4, 64));
    assert!((rtx.peak_dram_gbps - 336.0).abs() < 1e-9);
    let data = report(Some(rtx.clone()));
    let sec = rtx::section(&data).expect("the section");
    assert_eq!(sec.id, "rtx");
    let ids: Vec<&str> = sec.tables.iter().map(|t| t.id.as_str()).collect();
    assert_eq!(
        ids,
        ["rtx-cast", "rtx-path", "rtx-sweep-warps", "rtx-sweep-mshr"]
    );
    let structures = rtx::structures();
    for t in &sec.tables[..2] {
        assert_eq!(t.header[0], "structure");
        assert_eq!(&t.header[1..], &rtx::COLUMNS.map(String::from)[..]);
        assert_eq!(t.rows.len(), structures.len(), "{}", t.id);
        for row in &t.rows {
            for c in &row[1..] {
                let v = c.value.unwrap_or(f64::NAN);
                assert!(v.is_finite() && v >= 0.0, "{}: {row:?}", t.id);
            }
        }
    }
    for t in &sec.tables[2..] {
        assert_eq!(t.rows.len(), rtx::swept().len());
        assert!(t.rows.iter().flatten().skip(1).all(|c| c.text != "—"));
    }

    // The sentences name the fastest structure of each workload with its frame time, and
    // each dual-split structure's DRAM bytes and chunks per ray beside BVH2's.
    for workload in [Workload::Cast, Workload::Path] {
        let (best, f) = structures
            .iter()
            .map(|&a| (a, Figures::of(rtx.base(a, workload).unwrap()).unwrap()))
            .min_by(|x, y| x.1.frame_us.total_cmp(&y.1.frame_us))
            .unwrap();
        let want = format!(
            "{} is fastest ({} {:.1} µs",
            best.label(),
            best.label(),
            f.frame_us
        );
        assert!(sec.summary.contains(&want), "{want}\n{}", sec.summary);
        let b = Figures::of(rtx.base(SimAccel::Bvh2, workload).unwrap()).unwrap();
        for a in structures.iter().filter(|a| a.node_unit().is_dual_split()) {
            let d = Figures::of(rtx.base(*a, workload).unwrap()).unwrap();
            let bytes = format!("({:.0} vs {:.0})", d.dram_bytes, b.dram_bytes);
            let chunks = format!("({:.1} vs {:.1})", d.chunks, b.chunks);
            let requests = format!("({:.1} vs {:.1})", d.requests, b.requests);
            for s in [bytes, chunks, requests] {
                assert!(sec.summary.contains(&s), "{s}\n{}", sec.summary);
            }
        }
    }
    assert!(sec.summary.contains("Check against Vulkan-Sim"));
    assert!(sec.notes.iter().any(|n| n.contains("No energy is given")));

    // The section and its chart reach the page and the Markdown; same data, same bytes.
    let md = write::report_md(&data);
    assert!(md.contains("## On an RTX-style GPU"), "{md}");
    let page = html::index_html(&data).unwrap();
    let start = page
        .find("<section id=\"rtx\">")
        .expect("the section on the page");
    let end = start + page[start..].find("</section>").unwrap();
    assert!(page[start..end].contains("<svg"), "no chart in the section");
    assert_eq!(page, html::index_html(&report(Some(rtx))).unwrap());
}

#[test]
fn without_its_frames_the_report_has_no_such_section() {
    let data = report(None);
    assert!(rtx::section(&data).is_none());
    assert!(tables::sections(&data).iter().all(|s| s.id != "rtx"));
}

#[test]
fn the_plan_sweeps_the_configured_point_once() {
    let base = rtx::config().unwrap();
    let plan = rtx::plan(&base);
    let mut sorted = plan.clone();
    sorted.sort_by_key(|p| format!("{p:?}"));
    sorted.dedup();
    assert_eq!(sorted.len(), plan.len(), "a frame is planned twice");
    let base_frames = 2 * rtx::structures().len();
    let points = rtx::SWEEP_WARPS.len() + rtx::SWEEP_MSHR.len() - 2;
    assert_eq!(plan.len(), base_frames + points * rtx::swept().len());
    assert_eq!(
        rtx::scene_index(&["a".into(), "builtin:forest?triangles=9".into()]),
        1
    );
    assert_eq!(rtx::scene_index(&["a".into(), "b".into()]), 0);
}
