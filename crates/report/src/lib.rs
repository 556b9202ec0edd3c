//! `dualsplit report`: the paper's results section (Lin et al. 2020, §4: Tables 3–7,
//! Figures 7–9) regenerated from one command, with the published numbers beside ours.
//!
//! The crate has three layers:
//!
//! ```text
//!   producers (produce.rs)  ──▶  ReportData (data.rs)  ──▶  renderers
//!   scene → cpu / render /        every number, serde;      tables.rs → html.rs (index.html,
//!   sim pieces, each cached        paper.rs = published      inline SVG charts from charts.rs,
//!   on disk (cache.rs)             values                    base64 PNG renders), markdown
//!                                                            (report.md), results.json, CSV
//! ```
//!
//! * [`produce::Producer`] computes each piece (host measurements, a render, one simulated
//!   frame per configuration × workload × TM count), caching each under `<out>/cache/` by
//!   scene content hash, structure, workload, configuration, resolution and code version.
//! * [`ReportData`] holds every number; `results.json` is its serialization.
//! * [`write_report`] renders it: tables are built once ([`tables`]) and formatted as HTML,
//!   Markdown and CSV, so the three always agree; summaries ([`summary`]) are computed from
//!   the numbers.
//!
//! Host timings (build times, Mrays/s) are measurements of this machine and are shown only
//! in the CPU section; simulated tables hold simulated quantities only.

pub mod beyond;
pub mod cache;
pub mod charts;
pub mod data;
mod error;
pub mod html;
pub mod memory;
pub mod paper;
mod plain;
pub mod produce;
pub mod rtx;
pub mod scenes;
pub mod simulate;
pub mod study;
pub mod summary;
pub mod tables;
pub mod units;
pub mod write;

pub use cache::{Cache, CacheKey};
pub use data::ReportData;
pub use error::ReportError;
pub use produce::{NoProgress, Producer, Progress};
pub use write::write_report;
