//! Tests of the `simt` model on builtin scenes.

use crate::config::SimConfig;
use crate::frame::simulate;
use crate::model::simt::config::SimtConfig;
use crate::request::FrameRequest;
use crate::request::ThreadModel;
use crate::{SimAccel, SimResult};
use dualsplit_accel::Structures;
use dualsplit_render::{RenderSettings, Workload};

/// The committed RTX 2060 chip.
pub(crate) const RTX2060: &str = include_str!("../../../../../configs/rtx2060.toml");

/// Its `[simt]` table.
pub(crate) fn rtx() -> SimtConfig {
    SimConfig::from_toml(RTX2060).unwrap().simt.unwrap()
}

fn frame(accel: SimAccel, workload: Workload, cfg: &SimConfig, res: u32) -> SimResult {
    let scene = dualsplit_scene::load("builtin:cornell").unwrap();
    let s = Structures::build(&scene.triangles, &Default::default());
    let settings = RenderSettings::new(res, res, workload);
    let req = FrameRequest::new(&scene, &s, accel, &settings, cfg).with_model(ThreadModel::Simt);
    simulate(&req, &|_, _| {}).unwrap()
}

#[test]
fn the_committed_config_parses_and_validates() {
    let c = rtx();
    assert_eq!((c.sms, c.rt_max_warps, c.rt_max_mshr), (30, 4, 64));
    assert_eq!(c.l2.bytes() * c.l2_slices as u64, 3 << 20);
    assert_eq!(c.l1.bytes(), 64 << 10);
    let mut bad = c.clone();
    bad.chunk_bytes = 24;
    assert!(bad.validate().is_err());
    bad = c;
    bad.l1.line_bytes = 100;
    assert!(bad.validate().is_err());
}

#[test]
fn a_trax_config_is_a_typed_error() {
    let scene = dualsplit_scene::load("builtin:cornell").unwrap();
    let s = Structures::build(&scene.triangles, &Default::default());
    let settings = RenderSettings::new(8, 8, Workload::Cast);
    let cfg = SimConfig::lin2020();
    let req = FrameRequest::new(&scene, &s, SimAccel::Bvh2, &settings, &cfg)
        .with_model(ThreadModel::Simt);
    let e = simulate(&req, &|_, _| {}).unwrap_err();
    assert!(e.to_string().contains("[simt]"), "{e}");
}

#[test]
fn frames_finish_with_the_renderers_image_and_sane_figures() {
    let cfg = SimConfig::from_toml(RTX2060).unwrap();
    for accel in [
        SimAccel::Bvh2,
        SimAccel::Cwbvh,
        SimAccel::Dst,
        SimAccel::DstQ,
    ] {
        for workload in [Workload::Cast, Workload::Path] {
            let r = frame(accel, workload, &cfg, 32);
            let f = r.simt.as_ref().unwrap();
            assert!(r.cycles > 0 && r.rays >= 32 * 32, "{accel:?} {workload:?}");
            assert!(f.rt_occupancy > 0.0 && f.rt_occupancy <= 1.0, "{f:?}");
            assert!(f.rt_simt_efficiency > 0.0 && f.rt_simt_efficiency <= 1.0);
            assert!(f.shading_simt_efficiency > 0.0 && f.shading_simt_efficiency <= 1.0);
            // Sharing within a warp never sends more chunks than the threads' lists hold.
            assert!(f.requests_per_ray <= f.chunks_per_ray + 1e-9, "{f:?}");
            assert!(f.chunks_per_ray >= f.transactions_per_ray);
            assert_eq!(f.l1_requests, f.l1_hits + f.l1_merged + f.l2_accesses);
            assert!(f.dram_reads <= f.l2_accesses);
            let dual = f.transactions_by_kind["dual_split_node"];
            let boxes = f.transactions_by_kind["box_node"];
            assert_eq!(accel.is_dst(), dual > 0 && boxes == 0, "{accel:?}");
            // The same image as the renderer.
            let scene = dualsplit_scene::load("builtin:cornell").unwrap();
            let s = Structures::build(&scene.triangles, &Default::default());
            let settings = RenderSettings::new(32, 32, workload);
            let img = dualsplit_render::render(&scene, &s, accel.kind(), &settings, &|| {})
                .unwrap()
                .image
                .pixels;
            assert_eq!(img.len(), r.radiance.len());
            for (a, b) in img.iter().zip(&r.radiance) {
                assert_eq!(a.to_bits(), b.to_bits());
            }
        }
    }
}

#[test]
fn frames_are_deterministic() {
    let cfg = SimConfig::from_toml(RTX2060).unwrap();
    let a = frame(SimAccel::Bvh8, Workload::Path, &cfg, 24);
    let b = frame(SimAccel::Bvh8, Workload::Path, &cfg, 24);
    assert_eq!(a.cycles, b.cycles);
    assert_eq!(a.simt, b.simt);
}

#[test]
fn one_rt_warp_or_one_mshr_is_slower_than_the_rtx2060s() {
    let base = SimConfig::from_toml(RTX2060).unwrap();
    let with = |warps: u32, mshr: u32| {
        let mut c = base.clone();
        let s = c.simt.as_mut().unwrap();
        (s.rt_max_warps, s.rt_max_mshr) = (warps, mshr);
        frame(SimAccel::Bvh2, Workload::Cast, &c, 48).cycles
    };
    let (one, four) = (with(1, 64), with(4, 64));
    assert!(one > four, "1 warp {one} vs 4 warps {four}");
    let (few, many) = (with(4, 1), with(4, 64));
    assert!(few > many, "1 MSHR {few} vs 64 {many}");
}
