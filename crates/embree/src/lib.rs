//! Intel Embree 3 as an oracle and a speed peer for dualsplit's structures.
//!
//! [`EmbreeScene`] puts a scene's triangles into one Embree triangle mesh and traces single
//! rays with `rtcIntersect1` / `rtcOccluded1`. [`agree`] compares its answers with ours and
//! explains the differences (ties, grazing rays, interval ends); [`agree_closest`] and
//! [`agree_occluded`] do so for whole ray sets.
//!
//! The library is optional. `build.rs` looks for Debian's `libembree3.so` (package
//! `libembree-dev`, Embree 3.13); without it the crate still builds, [`available`] is
//! false and [`EmbreeScene::new`] returns [`EmbreeError::Missing`] saying why.
//!
//! This is the workspace's only crate with `unsafe` code: the C calls in `linked.rs`, each
//! with its SAFETY note, behind a safe API.

pub mod agree;
mod check;
mod error;
#[cfg(dualsplit_embree)]
mod ffi;
#[cfg(dualsplit_embree)]
mod linked;
#[cfg(dualsplit_embree)]
mod linked_tree;
#[cfg(not(dualsplit_embree))]
mod missing;
mod options;
mod scene;
pub mod tree;

pub use agree::{Agreement, Differences, Verdict, classify};
pub use check::{TErrors, agree_closest, agree_occluded, t_errors};
pub use error::{EmbreeError, ErrorCode};
pub use options::EmbreeOptions;
pub use scene::EmbreeScene;

/// What `build.rs` found: `"linked /path/libembree3.so"`, or why the library is missing.
pub const STATUS: &str = env!("DUALSPLIT_EMBREE_STATUS");

/// Whether the crate was built with the library.
pub const fn available() -> bool {
    cfg!(dualsplit_embree)
}
