//! The reference converter: the SAH decisions of [`super::from_bvh2`] written as plain nested
//! loops, with no tables, specialisations or reused arrays (Lin et al. 2020, §4.2;
//! `docs/dst-encoding.md`, §3). [`Dst::from_bvh2_reference`] emits its decisions through the
//! same encoder as [`Dst::from_bvh2`], so the two images are equal byte for byte exactly when
//! every decision is (`tests/dst_convert_reference.rs`).
//!
//! At an internal BVH node with box B and children boxes X and Y, a child's carving chain
//! starts from B and carves, one node at a time, the faces F where B differs from the
//! child's box. The state of a chain is the set S ⊆ F of faces already carved; its region is B
//! with the faces of S moved to the child's. From each state the DP tries every node that
//! carves one or two of the remaining faces, costing the node's C times the area of the
//! region it is tested in, plus the cost of the state it leads to. The split carves one
//! face of each child for free, so it enters the child's chain in that face's state, and the
//! split that costs least over 3 axes × 2 child orders wins.

use super::encode::encode;
use super::plan::{Chain, Planner, SplitPlan, face, leaf_tris, max_face, min_face};
use super::{Dst, DstConfig, DstCosts, DstError};
use crate::build::Bvh2;
use crate::image::SharedTriangles;
use dualsplit_geometry::Aabb;

impl Dst {
    /// Converts a BVH2 into a DST with the decisions of the reference DP, the chain DP
    /// and split choice written as plain nested loops (`docs/dst-encoding.md`, §3): the same
    /// image as [`Dst::from_bvh2`], made slowly and plainly, for tests to hold the fast
    /// converter to.
    ///
    /// Errors: as [`Dst::from_bvh2`].
    pub fn from_bvh2_reference(
        bvh: &Bvh2,
        triangles: impl Into<SharedTriangles>,
        cfg: &DstConfig,
    ) -> Result<Dst, DstError> {
        encode(bvh, triangles.into(), cfg, &ReferencePlanner)
    }
}

/// The reference planner: [`plan_split`], with nothing reused from node to node.
pub(super) struct ReferencePlanner;

impl Planner for ReferencePlanner {
    type Scratch = ();

    fn scratch(&self) {}

    fn plan_split(&self, bvh: &Bvh2, n: u32, cfg: &DstConfig, (): &mut ()) -> SplitPlan {
        plan_split(bvh, n, cfg)
    }
}

/// The split of internal BVH node `n`: the axis and child order whose split plus both
/// children's cheapest chains cost least (the first in axis order, then the BVH's child
/// order, on ties).
fn plan_split(bvh: &Bvh2, n: u32, cfg: &DstConfig) -> SplitPlan {
    let node = &bvh.nodes[n as usize];
    let chains = node.children().map(|c| {
        let child = &bvh.nodes[c as usize].bounds;
        ChainSolution::solve(&node.bounds, child, &cfg.costs, leaf_tris(bvh, c, cfg))
    });
    let mut best = (f32::INFINITY, 0, false);
    for axis in 0..3 {
        for swap in [false, true] {
            let [left, right] = if swap { [1, 0] } else { [0, 1] };
            // P0 carves the left child's max face, P1 the right child's min face.
            let cost = chains[left].cost(max_face(axis)) + chains[right].cost(min_face(axis));
            if cost < best.0 {
                best = (cost, axis, swap);
            }
        }
    }
    let (_, axis, swap) = best;
    let [left, right] = if swap { [1, 0] } else { [0, 1] };
    SplitPlan {
        axis,
        swap,
        left_chain: chains[left].chain(max_face(axis)),
        right_chain: chains[right].chain(min_face(axis)),
    }
}

/// The chain DP of one child: for every state (a bit set over [`ChainSolution::faces`]), the
/// cheapest cost of carving the faces not yet carved, and the first node of that chain.
struct ChainSolution {
    /// F: the faces (0–5: axis `f / 2`, max face when odd) where parent and child differ.
    faces: Vec<usize>,
    /// Cost of the cheapest chain from each state to the end.
    cost: Vec<f32>,
    /// The first node of that chain, as a bit set of the faces it carves; `None` when the
    /// chain ends in this state.
    step: Vec<Option<usize>>,
    /// The leaf's triangle cost in the child's own box (similar partitioning above a leaf;
    /// 0 otherwise), added to every chain's cost.
    leaf: f32,
}

impl ChainSolution {
    /// Solves the chain from `parent` down to `child`. `leaf_tris` is the leaf's triangle
    /// count when the child is a leaf and partitioning is similar: the chain may then stop
    /// early, the leaf's `C_tri · n` being paid over the looser region instead.
    fn solve(parent: &Aabb, child: &Aabb, costs: &DstCosts, leaf_tris: Option<u32>) -> Self {
        let faces: Vec<usize> = (0..6)
            .filter(|&f| face(parent, f) != face(child, f))
            .collect();
        let k = faces.len();
        let full = (1 << k) - 1;
        // The area of the region in state `s`: the parent box with the faces in `s` moved
        // to the child's.
        let area = |s: usize| {
            let mut region = *parent;
            for (i, &f) in faces.iter().enumerate() {
                if s & 1 << i != 0 {
                    let a = f / 2;
                    if f % 2 == 1 {
                        region.max[a] = child.max[a];
                    } else {
                        region.min[a] = child.min[a];
                    }
                }
            }
            half_area(&region)
        };
        // A lone face is carved by the cheaper node type, with a no-op partner plane; two
        // faces on one axis by a single-axis node, on two axes by a dual-axis node.
        let lone = costs.single_carve.min(costs.dual_carve);
        let pair = |i: usize, j: usize| {
            if faces[i] / 2 == faces[j] / 2 {
                costs.single_carve
            } else {
                costs.dual_carve
            }
        };
        let tri = leaf_tris.map(|n| costs.triangle * n as f32);
        let leaf = tri.map_or(0.0, |w| w * area(full));
        let mut cost = vec![0.0; full + 1];
        let mut step = vec![None; full + 1];
        // Every step carves at least one more face, so a state's successors come after it.
        for s in (0..full).rev() {
            let sa = area(s);
            // Stopping here leaves the leaf's triangles tested over this region.
            let mut best = tri.map_or(f32::INFINITY, |w| w * sa - leaf);
            let mut choice = None;
            let mut consider = |t: usize, c_node: f32| {
                let c = c_node * sa + cost[s | t];
                if c < best {
                    best = c;
                    choice = Some(t);
                } else if choice.is_none() && tri.is_none() {
                    // No cost below +∞ so far (overflowed or NaN): a chain that may not stop
                    // keeps its first option, so it still carves every face.
                    choice = Some(t);
                }
            };
            let remaining: Vec<usize> = (0..k).filter(|i| s & 1 << i == 0).collect();
            for (a, &i) in remaining.iter().enumerate() {
                // Carving face i alone is dominated while a partner it pairs with no dearer
                // remains (a chain never costs more from a state with more faces carved).
                if !remaining.iter().any(|&j| j != i && pair(i, j) <= lone) {
                    consider(1 << i, lone);
                }
                for &j in &remaining[a + 1..] {
                    consider(1 << i | 1 << j, pair(i, j));
                }
            }
            cost[s] = best;
            step[s] = choice;
        }
        ChainSolution {
            faces,
            cost,
            step,
            leaf,
        }
    }

    /// The state entered when the split carves face `f`: `{f}` if `f` is one of F, else
    /// nothing carved.
    fn start(&self, f: usize) -> usize {
        self.faces
            .iter()
            .position(|&g| g == f)
            .map_or(0, |i| 1 << i)
    }

    /// The cost of the chain when the split carves face `f`.
    fn cost(&self, f: usize) -> f32 {
        self.cost[self.start(f)] + self.leaf
    }

    /// The cheapest chain when the split carves face `f`, outermost node first.
    fn chain(&self, f: usize) -> Chain {
        let mut chain = Chain::EMPTY;
        let mut s = self.start(f);
        while let Some(t) = self.step[s] {
            let carved = self
                .faces
                .iter()
                .enumerate()
                .filter(|(i, _)| t & 1 << i != 0);
            chain.push(carved.fold(0, |m, (_, &f)| m | 1 << f));
            s |= t;
        }
        chain
    }
}

/// The cost model's area of a region: x·y + y·z + z·x of its extents (half the surface
/// area; an inverted axis counts as zero width).
fn half_area(b: &Aabb) -> f32 {
    let e = b.extent();
    e.x * e.y + e.y * e.z + e.z * e.x
}
