//! BVH2 → DST conversion: the SAH choice of carving chains and of each split's child order
//! (Lin et al. 2020, §4.2; Lin et al. 2019; dst-spec §5).
//!
//! With identical bounds the region entering every splitting node is exactly its BVH node's
//! box, so each child subtree costs the same whatever its parent chooses. The only choices
//! left at a BVH node are local: which axis and child order the split uses (which face of
//! each child the split plane carves for free) and how the remaining faces are carved. The
//! SAH cost of those choices is Σ C_node · SA(region where the node is tested); minimising
//! it node by node is exact, and the whole conversion is one O(1) step per BVH node.
//!
//! A carving chain covers the set F of faces where the incoming region differs from the
//! target box (|F| ≤ 5 below a split). [`plan_chain`] solves it exactly by dynamic
//! programming over the 2^|F| subsets of carved faces: a step carves one face or two (two on
//! one axis = single-axis carving node, on two axes = dual-axis carving node); a lone face
//! is carved by the cheaper node type with a ±∞ no-op partner plane.

use super::header::{AxisPair, Corner};
use super::{DstConfig, DstCosts, Partitioning};
use crate::build::Bvh2;
use dualsplit_geometry::Aabb;

/// A carving node the converter decided to emit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum CarveKind {
    /// Single-axis carving on this axis.
    Single(usize),
    /// Dual-axis carving.
    Dual(AxisPair, Corner),
}

/// One carving node: its kind and planes P0, P1 in the encoding's order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct CarveStep {
    pub kind: CarveKind,
    pub p0: f32,
    pub p1: f32,
}

const NO_STEP: CarveStep = CarveStep {
    kind: CarveKind::Single(0),
    p0: f32::INFINITY,
    p1: f32::NEG_INFINITY,
};

/// A carving chain, outermost node first (at most one node per face).
#[derive(Clone, Copy, Debug)]
pub(super) struct Chain {
    steps: [CarveStep; 6],
    len: u8,
}

impl Chain {
    pub const EMPTY: Chain = Chain {
        steps: [NO_STEP; 6],
        len: 0,
    };
    pub fn steps(&self) -> &[CarveStep] {
        &self.steps[..self.len as usize]
    }
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// Face `f` of a box: axis `f >> 1`, the max face when `f & 1 == 1`.
#[inline(always)]
fn face(b: &Aabb, f: usize) -> f32 {
    if f & 1 == 1 {
        b.max[f >> 1]
    } else {
        b.min[f >> 1]
    }
}

#[inline(always)]
fn set_face(b: &mut Aabb, f: usize, v: f32) {
    if f & 1 == 1 {
        b.max[f >> 1] = v;
    } else {
        b.min[f >> 1] = v;
    }
}

/// The carving node covering face set `t` (one or two faces of `faces`), with its cost.
fn step_for(faces: &[usize], i: usize, j: Option<usize>, target: &Aabb, c: &DstCosts) -> CarveStep {
    let fi = faces[i];
    match j {
        Some(j) => {
            let fj = faces[j];
            let (a, b) = (fi >> 1, fj >> 1);
            if a == b {
                CarveStep {
                    kind: CarveKind::Single(a),
                    p0: target.max[a],
                    p1: target.min[a],
                }
            } else {
                let (f0, f1) = if a < b { (fi, fj) } else { (fj, fi) };
                let pair = AxisPair::from_axes(a, b).expect("two different axes");
                CarveStep {
                    kind: CarveKind::Dual(
                        pair,
                        Corner {
                            first_lower: f0 & 1 == 0,
                            second_lower: f1 & 1 == 0,
                        },
                    ),
                    p0: face(target, f0),
                    p1: face(target, f1),
                }
            }
        }
        None => {
            let a = fi >> 1;
            let upper = fi & 1 == 1;
            if c.single_carve <= c.dual_carve {
                // Single-axis node whose other plane is a ±∞ no-op (never 0.0: dst-spec §4.4).
                CarveStep {
                    kind: CarveKind::Single(a),
                    p0: if upper { target.max[a] } else { f32::INFINITY },
                    p1: if upper {
                        f32::NEG_INFINITY
                    } else {
                        target.min[a]
                    },
                }
            } else {
                // Dual-axis node whose partner plane is a −∞ lower bound on another axis.
                let b = if a == 0 { 1 } else { 0 };
                let pair = AxisPair::from_axes(a, b).expect("two different axes");
                let v = face(target, fi);
                let (p0, p1, corner) = if a < b {
                    (
                        v,
                        f32::NEG_INFINITY,
                        Corner {
                            first_lower: !upper,
                            second_lower: true,
                        },
                    )
                } else {
                    (
                        f32::NEG_INFINITY,
                        v,
                        Corner {
                            first_lower: true,
                            second_lower: !upper,
                        },
                    )
                };
                CarveStep {
                    kind: CarveKind::Dual(pair, corner),
                    p0,
                    p1,
                }
            }
        }
    }
}

/// Cost and chain of the cheapest carving from `region` down to `target` (dst-spec §5.2).
///
/// `leaf_tris` is `Some(n)` when the chain sits above a leaf of `n` triangles and
/// similar partitioning is on: the chain may then stop early, paying `C_tri · n · SA` of the
/// looser region instead. Costs are SAH-weighted by the area of the region in which each
/// node is tested. `want_chain = false` skips reconstruction (cost only).
pub(super) fn plan_chain(
    region: &Aabb,
    target: &Aabb,
    costs: &DstCosts,
    leaf_tris: Option<u32>,
    want_chain: bool,
) -> (f32, Chain) {
    let mut faces = [0usize; 6];
    let mut k = 0;
    for f in 0..6 {
        if face(region, f) != face(target, f) {
            faces[k] = f;
            k += 1;
        }
    }
    // Triangle cost of the leaf below (similar partitioning only; identical bounds never
    // stops early, and the leaf's cost is then the same for every choice).
    let leaf_cost = |sa: f32| leaf_tris.map(|n| costs.triangle * n as f32 * sa);
    if k == 0 {
        return (leaf_cost(target.half_area()).unwrap_or(0.0), Chain::EMPTY);
    }
    let c_lone = costs.single_carve.min(costs.dual_carve);
    let full = (1usize << k) - 1;
    let mut sa = [0f32; 64];
    for (s, slot) in sa.iter_mut().enumerate().take(full + 1) {
        let mut b = *region;
        for (i, &f) in faces[..k].iter().enumerate() {
            if s >> i & 1 == 1 {
                set_face(&mut b, f, face(target, f));
            }
        }
        *slot = b.half_area();
    }
    // cost[s]: cheapest completion once the faces in `s` are carved (relative to the
    // target: the full set costs nothing extra; similar mode may stop anywhere).
    let base = leaf_cost(sa[full]).unwrap_or(0.0);
    let mut cost = [0f32; 64];
    let mut choice = [0u8; 64]; // the step taken from s (face mask); 0 = stop
    cost[full] = 0.0;
    for s in (0..full).rev() {
        let stop = leaf_cost(sa[s]).map_or(f32::INFINITY, |c| c - base);
        let mut best = (stop, 0u8);
        let rem = full & !s;
        for i in 0..k {
            if rem >> i & 1 == 0 {
                continue;
            }
            let c = c_lone * sa[s] + cost[s | 1 << i];
            if c < best.0 {
                best = (c, 1 << i);
            }
            for j in i + 1..k {
                if rem >> j & 1 == 0 {
                    continue;
                }
                let node = if faces[i] >> 1 == faces[j] >> 1 {
                    costs.single_carve
                } else {
                    costs.dual_carve
                };
                let c = node * sa[s] + cost[s | 1 << i | 1 << j];
                if c < best.0 {
                    best = (c, (1 << i | 1 << j) as u8);
                }
            }
        }
        cost[s] = best.0;
        choice[s] = best.1;
    }
    let total = cost[0] + base;
    if !want_chain {
        return (total, Chain::EMPTY);
    }
    let mut chain = Chain::EMPTY;
    let mut s = 0usize;
    while s != full && choice[s] != 0 {
        let t = choice[s] as usize;
        let i = t.trailing_zeros() as usize;
        let rest = t & !(1 << i);
        let j = (rest != 0).then(|| rest.trailing_zeros() as usize);
        chain.steps[chain.len as usize] = step_for(&faces[..k], i, j, target, costs);
        chain.len += 1;
        s |= t;
    }
    (total, chain)
}

/// The split chosen for an internal BVH node: axis, which BVH child is the left (lower)
/// child, and both children's incoming regions and carving chains.
pub(super) struct SplitPlan {
    pub axis: usize,
    pub left: u32,
    pub right: u32,
    pub left_chain: Chain,
    pub right_chain: Chain,
}

fn leaf_tris(bvh: &Bvh2, n: u32, cfg: &DstConfig) -> Option<u32> {
    let node = &bvh.nodes[n as usize];
    (cfg.partitioning == Partitioning::Similar && node.is_leaf()).then_some(node.count)
}

/// Chooses axis and child order of the splitting node for internal BVH node `n`, whose
/// region is exactly its box: for each axis and order, the split plane carves the left
/// child's max face and the right child's min face; the rest is left to the children's
/// chains. Picks the cheapest (first in axis, then order, on ties).
pub(super) fn plan_split(bvh: &Bvh2, n: u32, cfg: &DstConfig) -> SplitPlan {
    let node = &bvh.nodes[n as usize];
    let b = node.bounds;
    let [x, y] = node.children();
    let (bx, by) = (bvh.nodes[x as usize].bounds, bvh.nodes[y as usize].bounds);
    let (lx, ly) = (leaf_tris(bvh, x, cfg), leaf_tris(bvh, y, cfg));
    let mut best = (f32::INFINITY, 0usize, false);
    for axis in 0..3 {
        for swap in [false, true] {
            let (lo, hi, llo, lhi) = if swap {
                (by, bx, ly, lx)
            } else {
                (bx, by, lx, ly)
            };
            let mut rl = b;
            rl.max[axis] = lo.max[axis];
            let mut rr = b;
            rr.min[axis] = hi.min[axis];
            let c = plan_chain(&rl, &lo, &cfg.costs, llo, false).0
                + plan_chain(&rr, &hi, &cfg.costs, lhi, false).0;
            if c < best.0 || best.0.is_nan() && !c.is_nan() {
                best = (c, axis, swap);
            }
        }
    }
    let (_, axis, swap) = best;
    let (left, right, lo, hi, llo, lhi) = if swap {
        (y, x, by, bx, ly, lx)
    } else {
        (x, y, bx, by, lx, ly)
    };
    let mut left_region = b;
    left_region.max[axis] = lo.max[axis];
    let mut right_region = b;
    right_region.min[axis] = hi.min[axis];
    let left_chain = plan_chain(&left_region, &lo, &cfg.costs, llo, true).1;
    let right_chain = plan_chain(&right_region, &hi, &cfg.costs, lhi, true).1;
    SplitPlan {
        axis,
        left,
        right,
        left_chain,
        right_chain,
    }
}
