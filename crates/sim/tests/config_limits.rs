//! Configuration values outside their documented ranges are typed errors naming the key and
//! the value (reproducers of earlier crashes among them), values at the ends of every range run, and
//! a chip too large for the host's memory is refused before anything is allocated.

use dualsplit_accel::Structures;
use dualsplit_geometry::{Triangle, Vec3};
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_scene::Scene;
use dualsplit_sim::ranges::{RANGES, Value};
use dualsplit_sim::{FrameRequest, SimAccel, SimConfig, SimError, ThreadModel, simulate};

fn refused(toml: &str, key: &str) -> String {
    let e = SimConfig::from_toml(toml).expect_err(toml).to_string();
    assert!(e.contains(key), "{toml}: {e}");
    e
}

#[test]
fn every_key_has_one_documented_range() {
    let keys: Vec<&str> = SimConfig::lin2020().values().iter().map(|v| v.0).collect();
    let ranged: Vec<&str> = RANGES.iter().map(|r| r.key).collect();
    assert_eq!(keys, ranged);
    // Every key of the TOML form is listed: serialise the preset, count its leaf keys.
    let text = toml::to_string(&SimConfig::lin2020()).unwrap();
    let leaves = text.lines().filter(|l| l.contains(" = ")).count();
    assert_eq!(leaves, keys.len(), "{text}");
    // The paper's chip lies inside every range.
    SimConfig::lin2020().validate().unwrap();
}

#[test]
fn the_reported_reproducers_are_refused_with_key_and_value() {
    let e = refused("tms = 4294967295", "`tms` = 4294967295");
    assert!(e.contains("from 1 to 1024"), "{e}");
    refused("tps_per_tm = 1000000", "`tps_per_tm` = 1000000");
    refused(
        "[l2]\nsize_bytes = 68719476736",
        "`l2.size_bytes` = 68719476736",
    );
    refused(
        "[units]\nbox_pipes = 4000000000",
        "`units.box_pipes` = 4000000000",
    );
    refused(
        "[dram]\nchannels = 1073741824",
        "`dram.channels` = 1073741824",
    );
    refused("[l1]\nhit_latency = 1000000000000", "`l1.hit_latency`");
    refused("tms = 65536\ntps_per_tm = 65536", "`tms` = 65536");
    refused("[energy]\nl1_nj = nan", "`energy.l1_nj` = NaN");
    refused("[energy]\nl2_nj = inf", "`energy.l2_nj` = inf");
    refused("[dram]\nbackground_w = -1.0", "`dram.background_w` = -1");
    refused("clock_ghz = 0.0", "`clock_ghz` = 0");
    // TOML integers are signed 64-bit: u64::MAX does not even parse, and the largest
    // integer TOML holds is far beyond every latency's range.
    assert!(SimConfig::from_toml("[dram]\nt_cas = 18446744073709551615").is_err());
    refused("[dram]\nt_cas = 9223372036854775807", "`dram.t_cas`");
    refused(
        "[l1]\nhit_latency = 9223372036854775807",
        "`l1.hit_latency`",
    );
    refused("[l1]\nsize_bytes = 96000", "`l1.size_bytes` = 96000");
}

#[test]
fn both_ends_of_every_range_are_accepted_and_one_past_them_refused() {
    for r in RANGES {
        let base = SimConfig::lin2020();
        let Value::Int(_) = base.values().iter().find(|v| v.0 == r.key).unwrap().1 else {
            continue;
        };
        let (section, name) = r.key.split_once('.').unwrap_or(("", r.key));
        let toml = |v: u64| {
            if section.is_empty() {
                format!("{name} = {v}")
            } else {
                format!("[{section}]\n{name} = {v}")
            }
        };
        // Cache sizes and line counts are tied to each other, and the refresh interval to
        // t_RFC: keep the ends where they fit.
        let tied = matches!(
            r.key,
            "l1.size_bytes"
                | "l2.size_bytes"
                | "l1.associativity"
                | "l2.associativity"
                | "dram.t_rfc"
                | "dram.t_refi"
        );
        for v in [r.min as u64, r.max as u64] {
            if !tied {
                SimConfig::from_toml(&toml(v)).unwrap_or_else(|e| panic!("{}: {e}", toml(v)));
            }
        }
        if r.min > 0.0 {
            refused(&toml(r.min as u64 - 1), r.key);
        }
        refused(&toml(r.max as u64 + 1), r.key);
    }
    // The tied ends, with the sizes they need.
    SimConfig::from_toml("[l1]\nsize_bytes = 1073741824\n[l2]\nsize_bytes = 1073741824").unwrap();
    SimConfig::from_toml("[l1]\nsize_bytes = 64\n[l2]\nsize_bytes = 64").unwrap();
    SimConfig::from_toml("[l1]\nassociativity = 64\n[l2]\nassociativity = 64").unwrap();
    SimConfig::from_toml("[dram]\nt_rfc = 65536\nt_refi = 16777216").unwrap();
    SimConfig::from_toml("[dram]\nt_rfc = 0\nt_refi = 0").unwrap();
    SimConfig::from_toml("[dram]\nt_rfc = 0\nt_rp = 0\nt_ras = 0\nt_refi = 1").unwrap();
    // Refresh windows (t_RP + burst × t_RFC) and t_RAS before each must leave a tick to
    // activate in: 8 × 31 = 248 > 28 + 8 × 27 + 3 = 247; 8 × 30 = 240 is not.
    SimConfig::from_toml("[dram]\nt_rfc = 27\nt_ras = 3\nt_refi = 31").unwrap();
    refused(
        "[dram]\nt_rfc = 27\nt_ras = 3\nt_refi = 30",
        "`dram.t_refi`",
    );
    refused("[dram]\nt_rfc = 220\nt_refi = 220", "`dram.t_refi`");
    refused(
        "[dram]\nrefresh_burst = 1\nt_rfc = 220\nt_refi = 300",
        "`dram.t_refi`",
    );
}

/// A 50-triangle soup in front of the camera.
fn scene() -> (Scene, Structures) {
    let mut tris = Vec::new();
    for i in 0..50 {
        let x = (i % 10) as f32 * 0.2 - 1.0;
        let y = (i / 10) as f32 * 0.2 - 0.5;
        tris.push(Triangle::new(
            Vec3::new(x, y, 0.0),
            Vec3::new(x + 0.15, y, 0.1),
            Vec3::new(x, y + 0.15, 0.2),
        ));
    }
    let scene = Scene::from_triangles("soup", "test:soup", tris, Default::default()).unwrap();
    let s = Structures::build(&scene.triangles, &Default::default());
    (scene, s)
}

#[test]
fn chips_at_the_ends_of_the_ranges_simulate() {
    let (scene, s) = scene();
    let settings = RenderSettings::new(6, 4, Workload::Path);
    let small = "tms = 1\ntps_per_tm = 1\n[units]\nbox_pipes = 1\n[dram]\nchannels = 1\nbanks_per_channel = 1\nread_queue = 1\nt_cas = 0\nt_rcd = 0\nt_rp = 0\nt_ras = 0\nt_rc = 0\nt_rrd = 0\nt_rtp = 0\nt_ccd = 0\nt_burst = 1\n[l1]\nsize_bytes = 64\nbanks = 1\n[l2]\nsize_bytes = 64\nbanks = 1\nhit_latency = 0";
    let m = 65536;
    let slow = format!(
        "tms = 2\ntps_per_tm = 2\n[l1]\nhit_latency = {m}\n[l2]\nhit_latency = {m}\n[dram]\nt_cas = {m}\nt_burst = {m}\nt_rc = {m}\n[units]\nbox_latency = {m}\ntri_latency = {m}\ndst_latency = {m}\nfpinv_latency = {m}\natomic_latency = {m}\nint_latency = {m}\nfpadd_latency = {m}\nfpmul_latency = {m}\nfpcmp_latency = {m}\nfpminmax_latency = {m}\nconv_latency = {m}\nbranch_latency = {m}\nintmul_latency = {m}\nlocal_store_latency = {m}"
    );
    for model in [ThreadModel::Fast, ThreadModel::Rv32] {
        let mut cycles = Vec::new();
        for toml in [small, slow.as_str()] {
            let cfg = SimConfig::from_toml(toml).unwrap();
            let r = simulate(
                &FrameRequest::new(&scene, &s, SimAccel::Dst, &settings, &cfg).with_model(model),
                &|_, _| {},
            )
            .unwrap_or_else(|e| panic!("{model:?} {toml}: {e}"));
            assert_eq!(r.pixels, 24);
            assert!(r.rays >= 24, "{model:?}: {} rays", r.rays);
            assert!(r.energy.total().is_finite() && r.energy.total() > 0.0);
            cycles.push(r.cycles);
        }
        // Latencies of 2^16 make a frame slower, never faster (a wrapped sum would), and at
        // least one of them lies on the frame's critical path (the first ray's loads miss
        // to DRAM, whose L1 and L2 latencies alone are 2^17).
        assert!(
            cycles[1] > cycles[0] && cycles[1] > 2 * m,
            "{model:?}: {cycles:?}"
        );
    }
}

#[test]
fn chips_too_large_for_the_host_are_refused_before_allocating() {
    let (scene, s) = scene();
    let settings = RenderSettings::new(4, 4, Workload::Cast);
    // 2^20 threads with 1 MiB local stores (1 TiB) for the kernels; 1024 L1s of 1 GiB
    // (26 TiB of tags) for either model.
    let stores = "tms = 1024\ntps_per_tm = 1024\n[units]\nlocal_store_bytes = 1048576";
    let caches = "tms = 1024\n[l1]\nsize_bytes = 1073741824";
    for (model, toml) in [
        (ThreadModel::Rv32, stores),
        (ThreadModel::Rv32, caches),
        (ThreadModel::Fast, caches),
    ] {
        let cfg = SimConfig::from_toml(toml).unwrap();
        match simulate(
            &FrameRequest::new(&scene, &s, SimAccel::Bvh2, &settings, &cfg).with_model(model),
            &|_, _| {},
        ) {
            Err(e @ SimError::Memory(_)) => {
                let SimError::Memory(too_large) = &e else {
                    unreachable!()
                };
                assert!(too_large.need.total() > too_large.limit);
                let msg = e.to_string();
                assert!(
                    msg.contains("at most 8192 MiB") && msg.contains("lower tms"),
                    "{msg}"
                );
            }
            other => panic!("{model:?} {toml}: {:?}", other.map(|r| r.cycles)),
        }
    }
}

#[test]
fn docs_list_every_range() {
    let doc = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/robustness.md"
    ))
    .unwrap();
    let table: String = RANGES
        .iter()
        .map(|r| format!("| `{}` | {} |\n", r.key, r.describe()))
        .collect();
    assert!(
        doc.contains(&table),
        "docs/robustness.md must hold this table:\n{table}"
    );
}

/// `[kernels]` takes only its keys with their types; the rv32 model runs every variant, and
/// the fast model, calibrated on the default kernels, refuses another with a typed error.
#[test]
fn kernel_variants_are_checked_and_fast_runs_only_the_default() {
    for (toml, key) in [
        ("[kernels]\nparity = 1", "parity"),
        ("[kernels]\nparity = \"yes\"", "parity"),
        ("[kernels]\nnode_fetch = \"memory\"", "node_fetch"),
        ("[kernels]\nnode_fetch = true", "node_fetch"),
    ] {
        let e = SimConfig::from_toml(toml).expect_err(toml);
        assert!(
            matches!(e, dualsplit_sim::ConfigError::Parse(_)),
            "{toml}: {e}"
        );
        assert!(e.to_string().contains(key), "{toml}: {e}");
    }
    let e = SimConfig::from_toml("[kernels]\nnode_fetch = \"memory\"").unwrap_err();
    assert!(e.to_string().contains("operand"), "the valid names: {e}");
    refused("[kernels]\nvariant = \"paper\"", "variant");
    let (scene, s) = scene();
    let settings = RenderSettings::new(4, 4, Workload::Cast);
    for toml in ["parity = false", "node_fetch = \"operand\""] {
        let cfg =
            SimConfig::from_toml(&format!("tms = 1\ntps_per_tm = 2\n[kernels]\n{toml}")).unwrap();
        assert_ne!(cfg.kernels, dualsplit_sim::KernelsConfig::default());
        let frame =
            |model| FrameRequest::new(&scene, &s, SimAccel::Dst, &settings, &cfg).with_model(model);
        let r = simulate(&frame(ThreadModel::Rv32), &|_, _| {}).unwrap();
        assert_eq!(r.pixels, 16);
        let e = simulate(&frame(ThreadModel::Fast), &|_, _| {}).unwrap_err();
        assert!(matches!(e, SimError::FastKernelVariant { .. }), "{e}");
        assert!(e.to_string().contains("--model rv32"), "{e}");
    }
}
