//! Studies that outgrow one machine: a study is a *plan* of independent simulations
//! (`plan.json`), each run by its own job into a shared result store (`cache/`), and a page
//! assembled from whatever results are there.
//!
//! ```text
//!   plan.rs   scenes × configurations × workloads × TM counts × the cross product of the
//!             swept config keys (`--vary l1.size_bytes=32768,65536`) → Plan (plan.json)
//!   vary.rs   one dotted key of the config TOML set to a value, then validated
//!   store.rs  one result file per plan entry: checksummed, written to a temporary file,
//!             fsynced and renamed, so a half-written file is never read as a result
//!   page.rs   the assembled study: table, missing entries, results.json / results.csv
//!   sweep.rs  one chart per swept key: frame time, energy, DRAM lines against its value
//!   variants.rs  one row per combination of swept values: DST ÷ BVH2, the order of the
//!             configurations, BVH2's memory stalls and bandwidth (variants.md)
//! ```
//!
//! Nothing here schedules anything: `run-job DIR INDEX` is the unit a scheduler (Slurm job
//! arrays, `xargs -P`, a shell loop) runs, and every job is idempotent.

pub mod job;
pub mod page;
pub mod plan;
pub mod store;
pub mod sweep;
pub mod variants;
pub mod vary;

pub use plan::{Plan, PlanEntry, PlanOptions};
pub use store::{JobRecord, ResultStore};
pub use vary::Vary;

/// Why a study step failed.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A `--vary` argument is malformed or names no key of the config TOML.
    #[error("--vary {arg}: {reason}")]
    Vary {
        /// The argument as given.
        arg: String,
        /// What is wrong.
        reason: String,
    },
    /// A swept combination gives a configuration the simulator refuses.
    #[error("configuration {combo} is invalid: {source}")]
    Config {
        /// The swept values, `key=value` joined by commas.
        combo: String,
        /// The validation error.
        source: dualsplit_sim::ConfigError,
    },
    /// The plan file cannot be used.
    #[error("{path}: {reason}")]
    Plan {
        /// The plan file.
        path: std::path::PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The sweeps make more plan entries than [`plan::MAX_PLAN_ENTRIES`].
    #[error(
        "the plan would have {count} entries (scenes x configurations x workloads x TM counts x every --vary value combination); at most {limit}: sweep fewer values, or narrow --accel, --workload or the scenes"
    )]
    TooManyEntries {
        /// Entries the options make.
        count: u128,
        /// [`plan::MAX_PLAN_ENTRIES`].
        limit: u64,
    },
    /// A file of the study is not a regular file of bounded size, or cannot be read.
    #[error(transparent)]
    File(#[from] dualsplit_scene::FileError),
    /// An entry index beyond the plan.
    #[error("entry {index} is not in the plan ({len} entries, 0 to {last})", last = len.saturating_sub(1))]
    NoEntry {
        /// The index asked for.
        index: usize,
        /// Entries in the plan.
        len: usize,
    },
    /// A job could not produce its result.
    #[error("entry {index}: {reason}")]
    Job {
        /// The entry.
        index: usize,
        /// What failed.
        reason: String,
    },
    /// A file of the study could not be read or written.
    #[error(transparent)]
    Report(#[from] crate::ReportError),
}
