//! The golden configurations on 1, 2, 3 and 7 host threads give the same result.
//!
//! Its own file (no shipped meshes, so CI's pass without the large meshes does not run it
//! again): a frame on more host threads than the host has cores hands the commit turn from
//! thread to thread through the kernel's scheduler, slowly, so the frames are small.

use dualsplit_accel::Structures;
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_sim::{FrameRequest, SimAccel, SimConfig, ThreadModel, simulate};
use std::path::Path;

fn tiny() -> SimConfig {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/tiny.toml");
    SimConfig::from_toml(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Every configuration, both thread models and both workloads on `builtin:cornell`, on the
/// golden runs' tiny chip widened to 8 TMs so that every thread count splits the TMs
/// differently: the same result field for field and pixel for pixel (compared as JSON).
#[test]
fn host_threads_change_no_result() {
    let mut cfg = tiny();
    cfg.tms = 8;
    let scene = dualsplit_scene::load("builtin:cornell").unwrap();
    let structures = Structures::build(&scene.triangles, &Default::default());
    let run = |threads: usize| -> Vec<(String, String)> {
        let mut out = Vec::new();
        for (wl, w, h) in [(Workload::Cast, 16, 16), (Workload::Path, 12, 8)] {
            let settings = RenderSettings::new(w, h, wl);
            for model in ThreadModel::ALL {
                for accel in SimAccel::ALL {
                    let r = simulate(
                        &FrameRequest::new(&scene, &structures, accel, &settings, &cfg)
                            .with_model(model)
                            .with_threads(threads),
                        &|_, _| {},
                    )
                    .unwrap();
                    let key = format!("{} {} {}", model.name(), wl.name(), accel.name());
                    out.push((key, serde_json::to_string(&r).expect("a result serializes")));
                }
            }
        }
        out
    };
    let one = run(1);
    assert!(one.iter().all(|(_, r)| r.contains("\"reads\"")));
    for threads in [2, 3, 7] {
        let other = run(threads);
        assert_eq!(other.len(), one.len());
        for ((key, a), (_, b)) in one.iter().zip(&other) {
            assert!(a == b, "{key}: {threads} host threads differ from one");
        }
    }
}
