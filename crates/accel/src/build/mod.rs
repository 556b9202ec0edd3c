//! The BVH2 builder: SAH without triangle splitting. Builders see only boxes and centroids.

use dualsplit_geometry::{Aabb, Vec3};
use serde::{Deserialize, Serialize};

/// Build settings. Every field has a default; [`BuildConfig::high_quality`] is the preset used
/// for the paper's structures.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BuildConfig {
    /// Maximum triangles per leaf.
    pub max_leaf_size: u32,
    /// SAH cost of traversing an internal node (relative to one triangle test).
    pub cost_traversal: f32,
    /// SAH cost of one ray–triangle test.
    pub cost_triangle: f32,
    /// Number of SAH bins per axis.
    pub bins: u32,
}

impl Default for BuildConfig {
    fn default() -> Self {
        Self::high_quality()
    }
}

impl BuildConfig {
    /// The preset standing in for Embree 3's high-quality builder.
    pub fn high_quality() -> Self {
        Self {
            max_leaf_size: 4,
            cost_traversal: 1.0,
            cost_triangle: 1.0,
            bins: 32,
        }
    }
}

/// A node of the logical (not yet encoded) binary BVH.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bvh2Node {
    /// Node bounds.
    pub bounds: Aabb,
    /// Leaf: first index into [`Bvh2::prim_ids`]. Internal: index of the left child.
    pub first: u32,
    /// Leaf: triangle count (> 0). Internal: 0.
    pub count: u32,
    /// Internal: index of the right child. Leaf: unused (0).
    pub right: u32,
}

impl Bvh2Node {
    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
    /// Children of an internal node.
    #[inline]
    pub fn children(&self) -> [u32; 2] {
        [self.first, self.right]
    }
}

/// The logical binary BVH every other structure is derived from. Root at index 0.
#[derive(Clone, Debug)]
pub struct Bvh2 {
    /// Nodes; index 0 is the root.
    pub nodes: Vec<Bvh2Node>,
    /// Triangle ids referenced by leaf ranges.
    pub prim_ids: Vec<u32>,
    /// SAH cost of the tree (root-normalised).
    pub sah_cost: f32,
}

impl Bvh2 {
    /// Builds a BVH2 over primitive boxes.
    pub fn build(prim_bounds: &[Aabb], cfg: &BuildConfig) -> Self {
        let centroids: Vec<Vec3> = prim_bounds.iter().map(|b| b.center()).collect();
        let mut ids: Vec<u32> = (0..prim_bounds.len() as u32).collect();
        let mut nodes = Vec::with_capacity(prim_bounds.len() * 2);
        nodes.push(Bvh2Node {
            bounds: Aabb::EMPTY,
            first: 0,
            count: 0,
            right: 0,
        });
        if !prim_bounds.is_empty() {
            build_rec(prim_bounds, &centroids, &mut ids, 0, &mut nodes, 0, cfg);
        }
        let mut bvh = Self {
            nodes,
            prim_ids: ids,
            sah_cost: 0.0,
        };
        bvh.sah_cost = bvh.compute_sah(cfg);
        bvh
    }

    /// SAH cost of the tree: Σ internal SA·c_t + Σ leaf SA·n·c_i, divided by the root SA.
    pub fn compute_sah(&self, cfg: &BuildConfig) -> f32 {
        let root = self.nodes[0].bounds.half_area().max(f32::MIN_POSITIVE);
        let mut c = 0.0f64;
        for n in &self.nodes {
            let a = n.bounds.half_area() as f64;
            c += if n.is_leaf() {
                a * n.count as f64 * cfg.cost_triangle as f64
            } else {
                a * cfg.cost_traversal as f64
            };
        }
        (c / root as f64) as f32
    }
}

fn build_rec(
    pb: &[Aabb],
    cent: &[Vec3],
    ids: &mut [u32],
    offset: u32,
    nodes: &mut Vec<Bvh2Node>,
    node: usize,
    cfg: &BuildConfig,
) {
    let bounds = ids
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.union(pb[i as usize]));
    let n = ids.len();
    nodes[node] = Bvh2Node {
        bounds,
        first: offset,
        count: n as u32,
        right: 0,
    };
    if n <= 1 {
        return;
    }
    let cb = ids
        .iter()
        .fold(Aabb::EMPTY, |b, &i| b.grow(cent[i as usize]));
    const B: usize = 32;
    let mut best = (f32::INFINITY, 0usize, 0usize);
    for axis in 0..3 {
        let lo = cb.min[axis];
        let ext = cb.max[axis] - lo;
        if ext <= 0.0 {
            continue;
        }
        let scale = B as f32 / ext;
        let mut bb = [Aabb::EMPTY; B];
        let mut bc = [0u32; B];
        for &i in ids.iter() {
            let b = (((cent[i as usize][axis] - lo) * scale) as usize).min(B - 1);
            bb[b] = bb[b].union(pb[i as usize]);
            bc[b] += 1;
        }
        let mut right_area = [0.0f32; B];
        let mut acc = Aabb::EMPTY;
        for b in (1..B).rev() {
            acc = acc.union(bb[b]);
            right_area[b] = acc.half_area();
        }
        let (mut acc, mut nl) = (Aabb::EMPTY, 0u32);
        for b in 0..B - 1 {
            acc = acc.union(bb[b]);
            nl += bc[b];
            let nr = n as u32 - nl;
            if nl == 0 || nr == 0 {
                continue;
            }
            let c = acc.half_area() * nl as f32 + right_area[b + 1] * nr as f32;
            if c < best.0 {
                best = (c, axis, b + 1);
            }
        }
    }
    let leaf_cost = bounds.half_area() * n as f32 * cfg.cost_triangle;
    let split_cost = bounds.half_area() * cfg.cost_traversal + best.0 * cfg.cost_triangle;
    if best.0.is_finite() && (split_cost < leaf_cost || n > cfg.max_leaf_size as usize) {
        let (axis, split) = (best.1, best.2);
        let lo = cb.min[axis];
        let scale = B as f32 / (cb.max[axis] - lo);
        let mid = partition(ids, |i| {
            (((cent[i as usize][axis] - lo) * scale) as usize).min(B - 1) < split
        });
        split_here(pb, cent, ids, offset, nodes, node, cfg, mid);
    } else if n > cfg.max_leaf_size as usize {
        // All centroids coincide: split in the middle of the id list.
        split_here(pb, cent, ids, offset, nodes, node, cfg, n / 2);
    }
}

#[allow(clippy::too_many_arguments)]
fn split_here(
    pb: &[Aabb],
    cent: &[Vec3],
    ids: &mut [u32],
    offset: u32,
    nodes: &mut Vec<Bvh2Node>,
    node: usize,
    cfg: &BuildConfig,
    mid: usize,
) {
    let l = nodes.len();
    nodes.push(Bvh2Node {
        bounds: Aabb::EMPTY,
        first: 0,
        count: 0,
        right: 0,
    });
    nodes.push(Bvh2Node {
        bounds: Aabb::EMPTY,
        first: 0,
        count: 0,
        right: 0,
    });
    nodes[node].first = l as u32;
    nodes[node].right = l as u32 + 1;
    nodes[node].count = 0;
    let (a, b) = ids.split_at_mut(mid);
    build_rec(pb, cent, a, offset, nodes, l, cfg);
    build_rec(pb, cent, b, offset + mid as u32, nodes, l + 1, cfg);
}

fn partition(ids: &mut [u32], pred: impl Fn(u32) -> bool) -> usize {
    let mut i = 0;
    for j in 0..ids.len() {
        if pred(ids[j]) {
            ids.swap(i, j);
            i += 1;
        }
    }
    i
}
