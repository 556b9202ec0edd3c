//! `dualsplit calibrate`: measures the `fast` thread model's per-event costs from the
//! compiled kernels and writes the calibration file (`crates/sim/calibration.toml` in the
//! repository, compiled into the simulator).

use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_sim::SimConfig;
use dualsplit_sim::model::fast::calibrate::{FRAMES, calibrate, to_toml};
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `calibrate`.
#[derive(clap::Args)]
pub struct Args {
    /// Where to write the calibration (TOML); without it, print it.
    #[arg(long, short)]
    out: Option<PathBuf>,
}

/// Runs `calibrate`.
pub fn run(a: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    if let Some(p) = &a.out {
        crate::output::check_file(p, "--out")?;
    }
    let mut loaded = Vec::new();
    for (spec, w, h) in FRAMES {
        let (scene, structures) = super::load_and_build(spec, ctx)?;
        loaded.push((spec, scene, structures, w, h));
    }
    let frames: Vec<_> = loaded
        .iter()
        .map(|(spec, scene, s, w, h)| (*spec, scene, s, *w, *h))
        .collect();
    let bar = ctx.bar(16, "calibrating");
    let cal = calibrate(
        &frames,
        &SimConfig::lin2020().units,
        "lin2020",
        &mut |accel, w| {
            bar.set_message(format!("{} {w:?}", accel.label()));
            bar.inc(1);
        },
    )?;
    bar.finish_and_clear();
    let text = to_toml(&cal)?;
    match a.out {
        Some(p) => std::fs::write(&p, text).with_context(|| format!("writing {}", p.display()))?,
        None => out!("{text}"),
    }
    Ok(ExitCode::SUCCESS)
}
