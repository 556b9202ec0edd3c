//! The compiled-kernel thread model against the renderer: every pixel bit for bit, the same
//! ray count, for all eight configurations and both workloads.

use dualsplit_accel::Structures;
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_sim::{FrameRequest, SimAccel, SimConfig, ThreadModel, simulate};

fn tiny() -> SimConfig {
    SimConfig::from_toml(include_str!("../../../configs/tiny.toml")).unwrap()
}

#[test]
fn compiled_kernels_give_the_renderers_pixels() {
    let scene = dualsplit_scene::load("builtin:cornell").unwrap();
    let s = Structures::build(&scene.triangles, &Default::default());
    let cfg = tiny();
    for workload in Workload::ALL {
        let settings = RenderSettings::new(12, 12, workload);
        for accel in SimAccel::ALL {
            let run = |m| {
                simulate(
                    &FrameRequest::new(&scene, &s, accel, &settings, &cfg).with_model(m),
                    &|_, _| {},
                )
                .unwrap()
            };
            let (rv, fast) = (run(ThreadModel::Rv32), run(ThreadModel::Fast));
            for (i, (a, b)) in rv.radiance.iter().zip(&fast.radiance).enumerate() {
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "{} {}: pixel {i}: {a} vs {b}",
                    accel.name(),
                    workload.name()
                );
            }
            assert_eq!(rv.rays, fast.rays, "{} {}", accel.name(), workload.name());
            eprintln!(
                "{} {}: rv32 {} cycles {} instr, fast {} cycles {} instr",
                accel.name(),
                workload.name(),
                rv.cycles,
                rv.instructions.total(),
                fast.cycles,
                fast.instructions.total()
            );
        }
    }
}

#[test]
fn without_shadow_rays_both_models_give_the_shadowless_renderers_pixels() {
    // kernels.shadows = false: no shadow ray in the kernels (Params.shadows = 0) or the fast
    // model; both equal the CPU renderer with RenderSettings::shadows = false, and trace
    // fewer rays than with shadow rays.
    let scene = dualsplit_scene::load("builtin:cornell").unwrap();
    let s = Structures::build(&scene.triangles, &Default::default());
    let mut cfg = tiny();
    let settings = RenderSettings::new(12, 12, Workload::Path);
    let with = simulate(
        &FrameRequest::new(&scene, &s, SimAccel::Dst, &settings, &cfg),
        &|_, _| {},
    )
    .unwrap();
    cfg.kernels.shadows = false;
    let off = RenderSettings {
        shadows: false,
        ..settings
    };
    let want = dualsplit_render::render(&scene, &s, dualsplit_accel::AccelKind::Dst, &off, &|| {})
        .unwrap();
    for m in [ThreadModel::Rv32, ThreadModel::Fast] {
        let r = simulate(
            &FrameRequest::new(&scene, &s, SimAccel::Dst, &settings, &cfg).with_model(m),
            &|_, _| {},
        )
        .unwrap();
        assert!(r.rays < with.rays, "{m:?}: {} vs {}", r.rays, with.rays);
        for (i, a) in r.radiance.iter().enumerate() {
            let (x, y) = (i as u32 % 12, i as u32 / 12);
            assert_eq!(
                a.to_bits(),
                want.image.get(x, y).to_bits(),
                "{m:?} pixel {i}"
            );
        }
    }
}

#[test]
fn a_frame_beyond_the_memory_map_is_a_typed_error() {
    let scene = dualsplit_scene::load("builtin:cornell").unwrap();
    let s = Structures::build(&scene.triangles, &Default::default());
    // 4096² pixels × 12 bytes is beyond the 128 MiB between the frame buffer and the program.
    let settings = RenderSettings::new(4096, 4096, Workload::Cast);
    let e = simulate(
        &FrameRequest::new(&scene, &s, SimAccel::Dst, &settings, &tiny())
            .with_model(ThreadModel::Rv32),
        &|_, _| {},
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            dualsplit_sim::SimError::MemoryMap {
                region: "frame buffer",
                ..
            }
        ),
        "{e}"
    );
}
