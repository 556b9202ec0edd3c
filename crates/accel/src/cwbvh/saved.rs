//! What the saved-tree format needs of a compressed BVH8 (`crate::saved`): a tree from the
//! parts a file holds, and the check on load.

use super::{Cwbvh, validate};
use crate::image::MemoryImage;
use std::sync::OnceLock;
use std::time::Duration;

impl Cwbvh {
    /// The tree of `image` with the counts a saved file's header records, unchecked: the
    /// loader runs [`check_structure`] on it before handing it out. The time is zero
    /// (nothing was built).
    pub(crate) fn from_parts(image: MemoryImage, internal_nodes: usize, leaves: usize) -> Self {
        Self {
            image,
            internal_nodes,
            leaves,
            time: Duration::ZERO,
            cpu: OnceLock::new(),
        }
    }
}

/// The check on load of a saved compressed BVH8 (`docs/tree-format.md`, "Checks on load"):
/// [`Cwbvh::validate`]'s walk, which reaches every node and run once from the root and
/// never panics or loops on any words. Returns the internal nodes and leaves reached, or
/// the first violation (the walk names the word in its message).
pub(crate) fn check_structure(image: &MemoryImage) -> Result<(u64, u64), (usize, String)> {
    let rep = validate::walk(image).report;
    match rep.errors.first() {
        Some(e) => Err((0, format!("{e} ({} violations)", rep.error_count))),
        None => Ok((rep.internal_nodes as u64, rep.leaves as u64)),
    }
}
