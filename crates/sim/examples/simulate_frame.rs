//! Run one simulation from code: a 16 × 16 primary-ray frame of the Cornell box on the
//! TRaX-style chip with the dual-split pipeline, the threads executing the compiled kernels.
//!
//! `cargo run --release -p dualsplit-sim --example simulate_frame`

use dualsplit_accel::{BuildConfig, Structures};
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_sim::{FrameRequest, SimAccel, SimConfig, simulate};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let scene = dualsplit_scene::load("builtin:cornell")?;
    let structures = Structures::try_build(&scene.triangles, &BuildConfig::default())?;
    let settings = RenderSettings::new(16, 16, Workload::Cast);
    let r = simulate(
        &FrameRequest::new(
            &scene,
            &structures,
            SimAccel::Dst,
            &settings,
            &SimConfig::lin2020(),
        ),
        &|_, _| {},
    )?;
    println!("{} cycles, {:.4} ms per frame", r.cycles, r.frame_ms);
    assert!(r.cycles > 0);
    Ok(())
}
