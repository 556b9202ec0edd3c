//! The compiled kernels (`kernels/build/*.elf`) run functionally on one hart over a whole
//! frame and must write, for every pixel, exactly the radiance the Rust renderer computes
//! (`dualsplit_render::render` with the same settings), bit for bit: all eight
//! configurations, both workloads, on `builtin:cornell`, small atrium and hairball scenes and
//! two shipped meshes (dragon_res4 and the paper's Dragon Box).

use dualsplit_accel::Structures;
use dualsplit_render::{RenderSettings, Workload, render};
use dualsplit_scene::Scene;
use dualsplit_sim::model::rv32::kernels::{
    FRAME_FLOATS_PER_PIXEL, LOCAL_STORE_BYTES, Params, elf, elf_name,
};
use dualsplit_sim::model::rv32::{Program, run_frame};
use dualsplit_sim::{KernelsConfig, SimAccel};

/// Loads a scene spec; `shipped:NAME` is the shipped mesh NAME, which when missing skips
/// the test locally and fails it under CI ([`dualsplit_testkit::scenes::shipped`]).
fn load(spec: &str) -> Option<Scene> {
    match spec.strip_prefix("shipped:") {
        Some(name) => dualsplit_testkit::scenes::shipped(name),
        None => Some(dualsplit_scene::load(spec).unwrap_or_else(|e| panic!("{spec}: {e}"))),
    }
}

/// Runs every configuration's kernel for `workload`, in every variant, and compares each
/// pixel with the renderer's.
fn check(scene: &Scene, structures: &Structures, settings: &RenderSettings) {
    for accel in SimAccel::ALL {
        let want = render(scene, structures, accel.kind(), settings, &|| {}).unwrap();
        for variant in KernelsConfig::ALL {
            check_variant(scene, structures, settings, accel, variant, &want.image);
        }
    }
}

fn check_variant(
    scene: &Scene,
    structures: &Structures,
    settings: &RenderSettings,
    accel: SimAccel,
    variant: KernelsConfig,
    want: &dualsplit_render::Image,
) {
    {
        let name = elf_name(accel, settings.workload, variant);
        let prog = Program::from_elf(elf(accel, settings.workload, variant))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let params = Params::new(scene, structures, accel, settings);
        let (frame, stats) = run_frame(
            &prog,
            structures.image(accel.kind()),
            params.as_bytes(),
            params.frame_bytes(),
            LOCAL_STORE_BYTES,
            2_000_000_000,
        )
        .unwrap_or_else(|e| panic!("{name} on {}: {e}", scene.name));
        let got: Vec<f32> = frame
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        for y in 0..settings.height {
            for x in 0..settings.width {
                let i = (y * settings.width + x) as usize * FRAME_FLOATS_PER_PIXEL;
                let w = want.get(x, y);
                for (c, g) in got[i..i + FRAME_FLOATS_PER_PIXEL].iter().enumerate() {
                    assert_eq!(
                        g.to_bits(),
                        w.to_bits(),
                        "{name} on {}: pixel ({x}, {y}) channel {c}: kernel {g:e}, renderer {w:e}",
                        scene.name
                    );
                }
            }
        }
        eprintln!(
            "{name} on {}: {} pixels bit-exact, {} instructions",
            scene.name,
            settings.width * settings.height,
            stats.instructions
        );
    }
}

fn check_scene(spec: &str, size: u32, workload: Workload) {
    let Some(scene) = load(spec) else {
        return;
    };
    let structures = Structures::build(&scene.triangles, &Default::default());
    check(
        &scene,
        &structures,
        &RenderSettings::new(size, size, workload),
    );
}

#[test]
fn cornell_cast() {
    check_scene("builtin:cornell", 16, Workload::Cast);
}

#[test]
fn cornell_path() {
    check_scene("builtin:cornell", 16, Workload::Path);
}

#[test]
fn dragon_res4_cast() {
    check_scene("shipped:dragon_res4.ply.gz", 32, Workload::Cast);
}

#[test]
fn dragon_res4_path() {
    check_scene("shipped:dragon_res4.ply.gz", 32, Workload::Path);
}

/// Axis-aligned walls (rays lying in box and split planes: NaN plane distances) and thin
/// tangled tubes (many overlapping boxes, ties at shared edges).
#[test]
fn atrium_and_hairball() {
    for workload in Workload::ALL {
        check_scene("builtin:atrium?triangles=20000", 16, workload);
        check_scene("builtin:hairball?triangles=20000", 16, workload);
    }
}

/// Two samples per pixel with a seed: the jittered camera rays.
#[test]
fn cornell_path_two_samples() {
    let scene = load("builtin:cornell").unwrap();
    let structures = Structures::build(&scene.triangles, &Default::default());
    let mut settings = RenderSettings::new(8, 8, Workload::Path);
    settings.spp = 2;
    settings.seed = 7;
    check(&scene, &structures, &settings);
}

/// The reconstructed Dragon Box (871K triangles: the deepest trees, so the kernels' fixed-size
/// traversal stacks are exercised), both workloads on one build.
#[test]
fn dragon_box() {
    let Some(scene) = load("shipped:dragon_box.ply.gz") else {
        return;
    };
    let structures = Structures::build(&scene.triangles, &Default::default());
    for workload in Workload::ALL {
        check(&scene, &structures, &RenderSettings::new(24, 24, workload));
    }
}

/// A kernel handed the other workload's parameters stops with a fault (a store to the
/// read-only parameter block) instead of rendering the wrong image.
#[test]
fn a_kernel_given_the_other_workload_faults() {
    let scene = load("builtin:cornell").unwrap();
    let structures = Structures::build(&scene.triangles, &Default::default());
    let settings = RenderSettings::new(4, 4, Workload::Cast);
    let params = Params::new(&scene, &structures, SimAccel::Bvh2, &settings);
    let prog = Program::from_elf(elf(
        SimAccel::Bvh2,
        Workload::Path,
        KernelsConfig::default(),
    ))
    .unwrap();
    let run = run_frame(
        &prog,
        structures.image(SimAccel::Bvh2.kind()),
        params.as_bytes(),
        params.frame_bytes(),
        LOCAL_STORE_BYTES,
        1_000_000,
    );
    assert!(run.is_err(), "the path kernel ran with cast parameters");
}
