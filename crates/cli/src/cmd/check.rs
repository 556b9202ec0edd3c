//! `dualsplit check`.
use crate::progress::Ctx;
use std::process::ExitCode;

/// Arguments of `dualsplit check`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params.
    scene: Option<String>,
}

/// Runs the subcommand.
pub fn run(_args: Args, _ctx: &Ctx) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`dualsplit check` is coming soon")
}
