//! One module per subcommand.
pub mod bench;
pub mod build;
pub mod calibrate;
pub mod check;
pub mod info;
pub mod plan;
pub mod rays;
pub mod render;
pub mod report;
pub mod run_job;
pub mod simulate;
pub mod stats;
pub mod study_report;

use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::{BuildConfig, Structures};
use dualsplit_scene::Scene;

/// Loads `spec` and builds every structure from it (default build settings), behind a
/// spinner; errors say which step failed for which scene.
pub fn load_and_build(spec: &str, ctx: &Ctx) -> anyhow::Result<(Scene, Structures)> {
    let sp = ctx.spinner(format!("loading {spec}"));
    let scene = dualsplit_scene::load(spec).with_context(|| format!("loading scene {spec}"))?;
    sp.set_message("building BVH2, BVH4, BVH8, DST");
    let s = Structures::try_build(&scene.triangles, &BuildConfig::default())
        .with_context(|| format!("building the structures of {spec}"))?;
    sp.finish_and_clear();
    Ok((scene, s))
}
