//! Embree's own BVH builder (`rtcBuildBVH`) over boxes: the tree Embree would build, handed
//! back as plain nodes and leaves, so that another traversal can be run on Embree's topology
//! (to tell a tree's quality apart from the cost of traversing it).

use crate::EmbreeError;
use dualsplit_geometry::Aabb;

/// A child of a [`BuiltTree`] node: an internal node or a leaf, by index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Child {
    /// Index into [`BuiltTree::nodes`].
    Node(u32),
    /// Index into [`BuiltTree::leaves`].
    Leaf(u32),
}

/// A tree from Embree's builder: every node's children with their boxes, and every leaf's
/// primitive ids (the indices of the boxes given to [`build_tree`]). Nodes are in
/// depth-first order, the root (when internal) first.
#[derive(Clone, Debug)]
pub struct BuiltTree {
    /// Internal nodes: each child's box and reference.
    pub nodes: Vec<Vec<(Aabb, Child)>>,
    /// Leaves: primitive ids.
    pub leaves: Vec<Vec<u32>>,
    /// The root (a leaf when the builder made no internal node).
    pub root: Child,
}

/// The settings of `struct RTCBuildArguments` that shape the tree. The quality is always
/// medium (binned SAH, no spatial splits), the one Embree's scenes use by default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeArgs {
    /// Most children per node (2 to 8).
    pub branching: u32,
    /// Primitives the SAH counts as one intersection (Embree's leaf blocks).
    pub sah_block: u32,
    /// Ranges of at most this many primitives always become leaves.
    pub min_leaf: u32,
    /// Most primitives in a leaf (1 to 32, `RTC_BUILD_MAX_PRIMITIVES_PER_LEAF`).
    pub max_leaf: u32,
    /// SAH cost of a node.
    pub traversal_cost: f32,
    /// SAH cost of a block of primitives.
    pub intersection_cost: f32,
}

impl TreeArgs {
    /// What Embree 3.13 gives its own SAH builder for a triangle scene's BVH8 on AVX2
    /// (`BVH8Triangle4SceneBuilderSAH`, `kernels/bvh/bvh_builder_sah.cpp`: blocks of 4
    /// triangles, intersection cost 1, leaves of at least 4), with leaves capped at
    /// `rtcBuildBVH`'s 32 primitives.
    pub fn bvh8_triangle4() -> Self {
        Self {
            branching: 8,
            sah_block: 4,
            min_leaf: 4,
            max_leaf: 32,
            traversal_cost: 1.0,
            intersection_cost: 1.0,
        }
    }
}

/// Builds Embree's tree over `boxes` (primitive `i` is `boxes[i]`) with `args`, on every
/// core.
///
/// Errors: the library is missing ([`EmbreeError::Missing`]); `args` out of range
/// (branching outside 2..=8, `max_leaf` outside 1..=32) or `boxes` empty or over
/// `u32::MAX` boxes ([`EmbreeError::Unsupported`]); Embree reports an error.
pub fn build_tree(boxes: &[Aabb], args: &TreeArgs) -> Result<BuiltTree, EmbreeError> {
    if !(2..=8).contains(&args.branching) || !(1..=32).contains(&args.max_leaf) {
        return Err(EmbreeError::Unsupported(format!(
            "tree arguments {args:?}: branching must be 2 to 8 and max_leaf 1 to 32"
        )));
    }
    if boxes.is_empty() || boxes.len() > u32::MAX as usize {
        return Err(EmbreeError::Unsupported(format!(
            "{} boxes: the builder takes 1 to 2^32 - 1",
            boxes.len()
        )));
    }
    imp::build_tree(boxes, args)
}

#[cfg(dualsplit_embree)]
use crate::linked_tree as imp;

/// The builder when the crate was built without Embree.
#[cfg(not(dualsplit_embree))]
mod imp {
    use super::{BuiltTree, TreeArgs};
    use crate::EmbreeError;
    use dualsplit_geometry::Aabb;

    pub(super) fn build_tree(_: &[Aabb], _: &TreeArgs) -> Result<BuiltTree, EmbreeError> {
        Err(EmbreeError::Missing(crate::STATUS))
    }
}
