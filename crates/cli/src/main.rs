//! The `dualsplit` command line. Each subcommand lives in `cmd/<name>.rs` with its own
//! arguments; this file only parses and dispatches.

#[macro_use]
mod out;
mod args;
mod cmd;
mod host;
mod input;
mod lists;
mod loaded;
mod output;
mod progress;

use clap::{CommandFactory, Parser, Subcommand};

/// dualsplit: dual-split trees, BVHs and a TRaX-style hardware simulator.
#[derive(Parser)]
#[command(name = "dualsplit", version, about, long_about = None)]
struct Cli {
    /// Hide progress bars.
    #[arg(long, short, global = true)]
    quiet: bool,
    /// Most triangles a scene may have, after triangulating polygons and instancing glTF
    /// meshes (see docs/robustness.md).
    #[arg(long, global = true, value_name = "N",
          default_value_t = dualsplit_scene::Limits::DEFAULT_MAX_TRIANGLES)]
    max_triangles: u64,
    /// Most bytes of scene file content a load may hold: the file after inflating it, plus
    /// its glTF buffers (see docs/robustness.md).
    #[arg(long, global = true, value_name = "BYTES",
          default_value_t = dualsplit_scene::Limits::DEFAULT_MAX_BYTES)]
    max_scene_bytes: u64,
    /// Parse the command line and stop: exit 0 when it is valid, clap's usage error
    /// otherwise. Nothing is loaded or written (the docs' command test runs every command
    /// line the docs show with it).
    #[arg(long, global = true, hide = true)]
    parse_only: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Load a scene and print its triangles, bounds and load statistics.
    Info(cmd::info::Args),
    /// Build one structure and save it to a tree file.
    Build(cmd::build::Args),
    /// Build every structure and print sizes, node counts and build times (Table 3).
    Stats(cmd::stats::Args),
    /// Validate every structure and check per-ray equivalence against BVH2.
    Check(cmd::check::Args),
    /// Render an image with a workload on a structure.
    Render(cmd::render::Args),
    /// Measure traversal throughput (Mrays/s) per structure and ray type.
    Bench(cmd::bench::Args),
    /// Simulate a frame on the TRaX-style many-core model.
    Simulate(cmd::simulate::Args),
    /// Regenerate the paper's tables and figures.
    Report(cmd::report::Args),
    /// Write a study's plan: one independent simulation per entry, with sweeps.
    Plan(cmd::plan::Args),
    /// Run one entry of a study's plan into its result cache.
    RunJob(cmd::run_job::Args),
    /// Measure the fast thread model's per-event costs from the compiled kernels.
    Calibrate(cmd::calibrate::Args),
    /// Make a scene file: `scene dragon-box DRAGON.ply -o dragon_box.ply.gz`.
    #[command(subcommand)]
    Scene(cmd::scene::Command),
    /// Answer a file of rays (closest hits or shadow rays) with one traversal.
    Trace(cmd::trace::Args),
}

fn main() -> std::process::ExitCode {
    let raw: Vec<String> = std::env::args_os()
        .skip(1)
        .map(|a| a.to_string_lossy().into_owned())
        .collect();
    if let Some(msg) = lists::space_separated(&raw) {
        // The error shows the subcommand's usage line when there is one.
        let mut cmd = Cli::command();
        cmd.build();
        let sub = raw.iter().find(|a| !a.starts_with('-')).cloned();
        let kind = clap::error::ErrorKind::ValueValidation;
        match sub.and_then(|s| cmd.find_subcommand_mut(&s).cloned()) {
            Some(mut sub) => sub.error(kind, msg).exit(),
            None => cmd.error(kind, msg).exit(),
        }
    }
    let cli = Cli::parse();
    if cli.parse_only {
        return std::process::ExitCode::SUCCESS;
    }
    let mut ctx = progress::Ctx::new(cli.quiet);
    ctx.limits = dualsplit_scene::Limits {
        max_triangles: cli.max_triangles,
        max_bytes: cli.max_scene_bytes,
    };
    let result = match cli.command {
        Command::Info(a) => cmd::info::run(a, &ctx),
        Command::Build(a) => cmd::build::run(a, &ctx),
        Command::Stats(a) => cmd::stats::run(a, &ctx),
        Command::Check(a) => cmd::check::run(a, &ctx),
        Command::Render(a) => cmd::render::run(a, &ctx),
        Command::Bench(a) => cmd::bench::run(a, &ctx),
        Command::Simulate(a) => cmd::simulate::run(a, &ctx),
        Command::Report(a) => cmd::report::run(a, &ctx),
        Command::Plan(a) => cmd::plan::run(a, &ctx),
        Command::RunJob(a) => cmd::run_job::run(a, &ctx),
        Command::Calibrate(a) => cmd::calibrate::run(a, &ctx),
        Command::Trace(a) => cmd::trace::run(a, &ctx),
        Command::Scene(c) => cmd::scene::run(c, &ctx),
    };
    let result = result.and_then(|code| match out::take_error() {
        Some(e) => Err(anyhow::anyhow!("writing standard output: {e}")),
        None => Ok(code),
    });
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", error_text(&e));
            std::process::ExitCode::FAILURE
        }
    }
}

/// `e` and its causes, `outer: inner: ...`, skipping a cause whose text already ends the
/// message (an error that shows its source in its own text, `path: {source}`, would
/// otherwise print it twice).
fn error_text(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if out.ends_with(&text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&text);
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn causes_shown_in_their_wrapper_are_not_repeated() {
        #[derive(Debug)]
        struct At {
            source: std::io::Error,
        }
        impl std::fmt::Display for At {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "t.tree: {}", self.source)
            }
        }
        impl std::error::Error for At {
            fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
                Some(&self.source)
            }
        }
        let inner = std::io::Error::other("tree file is corrupt: checksum mismatch");
        let e = anyhow::Error::new(At { source: inner }).context("--tree t.tree");
        assert_eq!(
            super::error_text(&e),
            "--tree t.tree: t.tree: tree file is corrupt: checksum mismatch"
        );
    }
}
