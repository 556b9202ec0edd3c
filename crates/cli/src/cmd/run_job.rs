//! `dualsplit run-job DIR INDEX`: runs entry INDEX of the study in DIR and stores its
//! result in DIR/cache/; nothing to do when a valid result is already there. This is the
//! unit a Slurm array task, an `xargs -P` slot or a shell loop runs.

use crate::progress::Ctx;
use dualsplit_report::study::job::{JobOutcome, run_job};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicU64, Ordering};

/// Arguments of `dualsplit run-job`.
#[derive(clap::Args)]
pub struct Args {
    /// The study's directory (holding plan.json).
    dir: PathBuf,
    /// The plan entry to run (0-based; a Slurm array's $SLURM_ARRAY_TASK_ID).
    index: usize,
    #[command(flatten)]
    threads: crate::args::SimThreads,
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let bar = ctx.bar(0, format!("entry {}", args.index));
    let last = AtomicU64::new(0);
    let progress = |done: u64, total: u64| {
        if last.swap(done, Ordering::Relaxed) == 0 {
            bar.set_length(total);
        }
        bar.set_position(done);
    };
    let outcome = run_job(&args.dir, args.index, args.threads.get(), &progress);
    bar.finish_and_clear();
    match outcome? {
        JobOutcome::AlreadyDone(path) => {
            outln!(
                "entry {}: a valid result is already stored ({}); nothing to do",
                args.index,
                path.display()
            );
        }
        JobOutcome::Computed {
            path,
            replaced,
            wall_s,
        } => {
            if let Some(why) = replaced {
                eprintln!(
                    "entry {}: replaced an invalid result file ({why})",
                    args.index
                );
            }
            outln!(
                "entry {}: simulated in {wall_s:.1} s, stored {}",
                args.index,
                path.display()
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
