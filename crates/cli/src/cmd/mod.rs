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
pub mod scene;
pub mod simulate;
pub mod stats;
pub mod study_report;
pub mod trace;

use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::{BuildConfig, Structures};
use dualsplit_scene::Scene;

/// Loads `spec` and builds every structure from it (default build settings), behind a
/// spinner; errors say which step failed for which scene.
pub fn load_and_build(spec: &str, ctx: &Ctx) -> anyhow::Result<(Scene, Structures)> {
    let scene = load(spec, ctx)?;
    let s = build(&scene, ctx)?;
    Ok((scene, s))
}

/// Loads `spec` within the budgets of `ctx`, behind a spinner.
pub fn load(spec: &str, ctx: &Ctx) -> anyhow::Result<Scene> {
    let sp = ctx.spinner(format!("loading {spec}"));
    let scene = dualsplit_scene::load_with(spec, &ctx.limits)
        .with_context(|| format!("loading scene {spec}"))?;
    sp.finish_and_clear();
    Ok(scene)
}

/// Builds every structure of `scene` (default build settings), behind a spinner.
pub fn build(scene: &Scene, ctx: &Ctx) -> anyhow::Result<Structures> {
    let sp = ctx.spinner("building BVH2, BVH4, BVH8, DST");
    let s = Structures::try_build(&scene.triangles, &BuildConfig::default())
        .with_context(|| format!("building the structures of {}", scene.spec))?;
    sp.finish_and_clear();
    Ok(s)
}
