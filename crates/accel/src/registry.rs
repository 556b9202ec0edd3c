//! The registry: every acceleration structure, once, in report order. Each entry names
//! the tree type of the structure's folder (which implements [`Structure`]), the
//! [`TreeKind`]s it stands for with their command-line names and saved-file codes, and the
//! traversals ([`AccelKind`]s) of each. From this list come [`AccelKind`], [`TreeKind`],
//! [`AnyTree`] and its dispatch, the saved-tree kind codes and header fields, the
//! [`Structures`](crate::Structures) set, the statistics, `dualsplit check`, the CLI's
//! value lists and Python's names. The first entry is the reference: the BVH2 every other
//! structure is derived from.
//!
//! Beside the list: [`Presets`], the settings `dualsplit build` and
//! [`Structures`](crate::Structures) derive the structures with; [`AccelError`], the
//! structures' build errors; and the structures' types the crate root re-exports.

use crate::image::ImageError;
use crate::image::MemoryImage;
use crate::observer::Observer;
use crate::query::RayQuery;
use crate::saved::SavedFields;
use crate::saved::{FieldReader, FieldWriter, SavedError, Violation};
use crate::stats::{BuildStats, StructureStats};
use crate::structure::{PlainQuery, Structure, UnitMismatch, structures};
use crate::validate::ValidationReport;
use crate::{BuildConfig, Bvh2, dst, dstq};
use dualsplit_geometry::{Aabb, Hit, Ray};
use serde::{Deserialize, Serialize};

structures! {
    /// A BVH2, BVH4 or BVH8.
    Bvh(crate::wide::BvhTree) {
        /// Binary BVH, 52-byte nodes.
        Bvh2 = "bvh2", code 1, traversals [
            /// Binary BVH, 52-byte nodes.
            Bvh2 = "bvh2",
        ];
        /// 4-wide BVH (Dammertz collapse), 100-byte nodes.
        Bvh4 = "bvh4", code 2, traversals [
            /// 4-wide BVH (Dammertz collapse), 100-byte nodes.
            Bvh4 = "bvh4",
        ];
        /// 8-wide BVH (Ylitie collapse), 200-byte nodes.
        Bvh8 = "bvh8", code 3, traversals [
            /// 8-wide BVH (Ylitie collapse), 200-byte nodes.
            Bvh8 = "bvh8",
        ];
    }
    /// A dual-split tree.
    Dst(crate::dst::DstTree) {
        /// Dual-split tree.
        Dst = "dst", code 4, traversals [
            /// Dual-split tree, software decoder (the paper's DST*): the fast CPU traversal
            /// ([`AccelKind::DST_SOFTWARE`], [`crate::DstDecoding::Software`]; command line
            /// `dst-sw`).
            #[doc(alias = "DstSoftware")]
            DstSw = "dst-sw",
            /// Dual-split tree traversed by the hardware pipeline's step function: the model
            /// of the paper's hardware, slower on a CPU ([`AccelKind::DST_PIPELINE`],
            /// [`crate::DstDecoding::Pipeline`]; command line `dst`).
            #[doc(alias = "DstPipeline")]
            Dst = "dst",
        ];
    }
    /// A compressed 8-wide BVH.
    Cwbvh(crate::cwbvh::CwbvhTree) {
        /// Compressed 8-wide BVH (80-byte nodes, quantized child boxes).
        Cwbvh = "cwbvh", code 5, traversals [
            /// Compressed 8-wide BVH (Ylitie et al. 2017): the BVH8's nodes in 80 bytes, child
            /// boxes quantized to 8 bits per plane, conservatively ([`crate::cwbvh`]; command
            /// line `cwbvh`).
            Cwbvh = "cwbvh",
        ];
    }
    /// A quantized dual-split tree.
    DstQ(crate::dstq::DstQTree) {
        /// Quantized dual-split tree (k-bit planes in collapsed clusters).
        DstQ = "dst-q", code 6, traversals [
            /// Quantized dual-split tree: the DST's planes as k-bit offsets in a local frame,
            /// several levels collapsed into one fetch (the paper's §5 future work;
            /// [`crate::dstq`]; command line `dst-q`).
            DstQ = "dst-q",
        ];
    }
    /// The toy structure of `docs/extending.md` (feature `toy`, for its test).
    Toy(crate::toy::ToyTree) if feature = "toy" {
        /// Every triangle in one leaf (`tests/toy.rs`).
        Toy = "toy", code 99, traversals [
            /// The toy's one traversal: the leaf's triangles, one after another.
            Toy = "toy",
        ];
    }
}

/// The settings the structures are derived from a BVH2 with: what `dualsplit build` and
/// [`Structures`](crate::Structures) use unless told otherwise.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Presets {
    /// The dual-split tree's conversion ([`crate::dst::DstConfig::hardware`] by default).
    pub dst: crate::dst::DstConfig,
    /// The BVH8 collapse (also the compressed BVH8's).
    pub collapse: crate::wide::CollapseConfig,
    /// The quantized DST's encoding.
    pub dstq: crate::dstq::DstQConfig,
}

/// Errors while building the structures of a scene: an image that cannot be encoded, or
/// a structure's own build error.
#[derive(Debug, thiserror::Error)]
pub enum AccelError {
    /// A memory image could not be encoded (an offset field overflowed).
    #[error(transparent)]
    Image(#[from] ImageError),
    /// The dual-split tree could not be converted or encoded.
    #[error(transparent)]
    Dst(#[from] dst::DstError),
    /// The quantized dual-split tree could not be encoded.
    #[error(transparent)]
    DstQ(#[from] dstq::DstQError),
}

impl TreeKind {
    /// The structure built when none is named (Python's `build`): the paper's dual-split
    /// tree.
    pub const DEFAULT: TreeKind = TreeKind::Dst;
}

// The structures' types at the crate root.
pub use crate::cwbvh::CwbvhTree;
pub use crate::dst::{Dst, DstConfig, DstDecoding, DstPipeline, DstTree};
pub use crate::dstq::DstQTree;
pub use crate::wide::{Bvh2Tree, BvhTree};
