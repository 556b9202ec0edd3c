//! Embree's own BVH builder (`rtcBuildBVH`) over boxes: the tree Embree would build, handed
//! back as plain nodes and leaves, so that another traversal can be run on Embree's topology
//! (to tell a tree's quality apart from the cost of traversing it). [`build_tree`] makes the
//! tree Embree's triangle scenes get (binned SAH); [`build_tree_split`] its high-quality
//! tree with spatial splits (Stich et al. 2009), over triangles.

use crate::EmbreeError;
use dualsplit_geometry::{Aabb, Triangle, Vec3};

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

/// The settings of `struct RTCBuildArguments` that shape the tree. The quality is medium
/// (binned SAH, no spatial splits, the one Embree's scenes use by default) for
/// [`build_tree`], high (with spatial splits) for [`build_tree_split`].
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
    check(boxes, args)?;
    imp::build_tree(boxes, args, None)
}

/// Builds Embree's high-quality tree over `triangles` (primitive `i` is `triangles[i]`)
/// with `args`, on every core: binned SAH with spatial splits, which may put a triangle in
/// several leaves (at most twice as many references as triangles), each under a box of the
/// part of the triangle on its side of the split planes ([`clipped_bounds`]). Errors as
/// [`build_tree`]'s.
pub fn build_tree_split(triangles: &[Triangle], args: &TreeArgs) -> Result<BuiltTree, EmbreeError> {
    let boxes: Vec<Aabb> = triangles.iter().map(Triangle::bounds).collect();
    check(&boxes, args)?;
    imp::build_tree(&boxes, args, Some(triangles))
}

/// [`build_tree`]'s checks of its arguments.
fn check(boxes: &[Aabb], args: &TreeArgs) -> Result<(), EmbreeError> {
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
    Ok(())
}

/// A box of the part of triangle `t` inside box `b`, or `None` when none is: the triangle
/// clipped to each of `b`'s six planes in f64 (Sutherland–Hodgman), the polygon's bounds
/// rounded outward to f32 and widened by one ulp more, then cut to `b`. It holds every point
/// of the triangle inside `b` (the clipped polygon's vertices lie within f64 rounding of the
/// exact ones), so a ray that meets that part of the triangle meets the box: a tree over
/// such boxes culls no hit.
pub fn clipped_bounds(t: &Triangle, b: &Aabb) -> Option<Aabb> {
    let mut poly: Vec<[f64; 3]> = t.v.iter().map(|p| p.to_array().map(f64::from)).collect();
    for axis in 0..3 {
        for (keep_above, plane) in [(true, b.min[axis] as f64), (false, b.max[axis] as f64)] {
            let inside = |p: &[f64; 3]| {
                if keep_above {
                    p[axis] >= plane
                } else {
                    p[axis] <= plane
                }
            };
            let mut out = Vec::with_capacity(poly.len() + 1);
            for (i, &p) in poly.iter().enumerate() {
                let q = poly[(i + 1) % poly.len()];
                if inside(&p) {
                    out.push(p);
                }
                if inside(&p) != inside(&q) {
                    let s = (plane - p[axis]) / (q[axis] - p[axis]);
                    let mut x = [0.0; 3];
                    for (a, x) in x.iter_mut().enumerate() {
                        *x = p[a] + (q[a] - p[a]) * s;
                    }
                    x[axis] = plane;
                    out.push(x);
                }
            }
            poly = out;
            if poly.is_empty() {
                return None;
            }
        }
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &poly {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    // The nearest f32 at or below (above) `x`, then one ulp further.
    let down = |x: f64| {
        let m = x as f32;
        (if f64::from(m) > x { m.next_down() } else { m }).next_down()
    };
    let up = |x: f64| {
        let m = x as f32;
        (if f64::from(m) < x { m.next_up() } else { m }).next_up()
    };
    Some(Aabb::new(
        Vec3::from(lo.map(down)).max(b.min),
        Vec3::from(hi.map(up)).min(b.max),
    ))
}

#[cfg(dualsplit_embree)]
use crate::linked_tree as imp;

/// The builder when the crate was built without Embree.
#[cfg(not(dualsplit_embree))]
mod imp {
    use super::{BuiltTree, TreeArgs};
    use crate::EmbreeError;
    use dualsplit_geometry::Aabb;

    pub(super) fn build_tree(
        _: &[Aabb],
        _: &TreeArgs,
        _: Option<&[dualsplit_geometry::Triangle]>,
    ) -> Result<BuiltTree, EmbreeError> {
        Err(EmbreeError::Missing(crate::STATUS))
    }
}
