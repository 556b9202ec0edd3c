//! BVH2 → BVH2/BVH4/BVH8 logical trees. Every leaf of the result is a leaf of the BVH2.

use super::{WideBvh, WideChild, WideNode};
use crate::Bvh2;
use dualsplit_geometry::Aabb;
use serde::{Deserialize, Serialize};

/// Costs of the adaptive BVH8 collapse (Ylitie et al. 2017; c_node = 1 and c_prim = 0.3
/// are the values public implementations use, e.g. gatling's `bvh_collapse.c`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CollapseConfig {
    /// Cost of an internal node, per unit area.
    pub cost_node: f32,
    /// Cost of one triangle in a leaf, per unit area.
    pub cost_prim: f32,
}

impl Default for CollapseConfig {
    fn default() -> Self {
        Self {
            cost_node: 1.0,
            cost_prim: 0.3,
        }
    }
}

/// A BVH2 node as a wide child: a leaf child, or an internal child to be expanded.
fn as_child(bvh: &Bvh2, i: u32) -> (Aabb, WideChild) {
    let n = &bvh.nodes[i as usize];
    if n.is_leaf() {
        (
            n.bounds,
            WideChild::Leaf {
                first: n.first,
                count: n.count,
            },
        )
    } else {
        (n.bounds, WideChild::Node(i))
    }
}

/// Generic driver: `expand(i)` lists the BVH2 nodes that become the children of the wide
/// node made from BVH2 internal node `i`. BVH2 internal-node indices in the children are
/// renumbered to wide-node indices.
fn collapse_with(bvh: &Bvh2, arity: usize, expand: impl Fn(u32) -> Vec<u32>) -> WideBvh {
    let mut out = WideBvh {
        arity,
        nodes: Vec::new(),
    };
    if bvh.is_empty() {
        out.nodes.push(WideNode::default());
        return out;
    }
    let root = &bvh.nodes[0];
    if root.is_leaf() {
        out.nodes.push(WideNode {
            children: vec![as_child(bvh, 0)],
        });
        return out;
    }
    // Work list of (wide node index, BVH2 internal node it is made from).
    out.nodes.push(WideNode::default());
    let mut work = vec![(0usize, 0u32)];
    while let Some((w, b)) = work.pop() {
        let mut children = Vec::with_capacity(arity);
        for c in expand(b) {
            let (bounds, kind) = as_child(bvh, c);
            let kind = match kind {
                WideChild::Node(src) => {
                    let idx = out.nodes.len();
                    out.nodes.push(WideNode::default());
                    work.push((idx, src));
                    WideChild::Node(idx as u32)
                }
                leaf => leaf,
            };
            children.push((bounds, kind));
        }
        debug_assert!(children.len() <= arity);
        out.nodes[w].children = children;
    }
    out
}

pub(super) fn from_bvh2(bvh: &Bvh2) -> WideBvh {
    collapse_with(bvh, 2, |i| bvh.nodes[i as usize].children().to_vec())
}

pub(super) fn dammertz4(bvh: &Bvh2) -> WideBvh {
    collapse_with(bvh, 4, |i| {
        let mut v = Vec::with_capacity(4);
        for c in bvh.nodes[i as usize].children() {
            let n = &bvh.nodes[c as usize];
            if n.is_leaf() {
                v.push(c);
            } else {
                v.extend(n.children());
            }
        }
        v
    })
}

/// Decision for representing a subtree with at most `i` roots (`i >= 2`).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Decision {
    /// Use the best with at most `i - 1` roots.
    Fewer,
    /// `k` roots from the left child, `i - k` from the right.
    Split(u8),
}

pub(super) fn ylitie8(bvh: &Bvh2, cfg: &CollapseConfig) -> WideBvh {
    const W: usize = 8;
    let n = bvh.nodes.len();
    // cost[node][i - 1] = C(node, i); dec[node][i - 1] for i >= 2; dist8[node] = the split of
    // the node's own 8 child slots.
    let mut cost = vec![[0f32; W]; n];
    let mut dec = vec![[Decision::Fewer; W]; n];
    let mut dist8 = vec![1u8; n];
    if !bvh.is_empty() {
        // Children always have larger indices than their parent: reverse order is bottom-up.
        for i in (0..n).rev() {
            let node = &bvh.nodes[i];
            let area = node.bounds.half_area();
            if node.is_leaf() {
                cost[i] = [area * node.count as f32 * cfg.cost_prim; W];
                continue;
            }
            let [l, r] = node.children().map(|c| c as usize);
            let mut dist = [(f32::INFINITY, 1u8); W + 1];
            for (roots, d) in dist.iter_mut().enumerate().skip(2) {
                for k in 1..roots {
                    let c = cost[l][k - 1] + cost[r][roots - k - 1];
                    if c < d.0 {
                        *d = (c, k as u8);
                    }
                }
            }
            dist8[i] = dist[W].1;
            cost[i][0] = dist[W].0 + area * cfg.cost_node;
            for roots in 2..=W {
                let fewer = cost[i][roots - 2];
                if fewer <= dist[roots].0 {
                    cost[i][roots - 1] = fewer;
                    dec[i][roots - 1] = Decision::Fewer;
                } else {
                    cost[i][roots - 1] = dist[roots].0;
                    dec[i][roots - 1] = Decision::Split(dist[roots].1);
                }
            }
        }
    }
    let gather = |root: u32, roots: usize, out: &mut Vec<u32>| {
        let mut stack = vec![(root, roots)];
        while let Some((node, mut roots)) = stack.pop() {
            let nd = &bvh.nodes[node as usize];
            loop {
                if nd.is_leaf() || roots == 1 {
                    out.push(node);
                    break;
                }
                match dec[node as usize][roots - 1] {
                    Decision::Fewer => roots -= 1,
                    Decision::Split(k) => {
                        let [l, r] = nd.children();
                        // Right pushed first so the left subtree's roots come first.
                        stack.push((r, roots - k as usize));
                        stack.push((l, k as usize));
                        break;
                    }
                }
            }
        }
    };
    collapse_with(bvh, W, |i| {
        let node = &bvh.nodes[i as usize];
        let [l, r] = node.children();
        let k = dist8[i as usize] as usize;
        let mut v = Vec::with_capacity(W);
        gather(l, k, &mut v);
        gather(r, W - k, &mut v);
        v
    })
}
