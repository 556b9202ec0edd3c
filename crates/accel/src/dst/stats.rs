//! DST statistics as values: node counts by kind, bytes, the comparison with the BVH2's
//! size (Lin et al. 2020, Table 3), and per-ray traversal averages (formatted elsewhere).

use super::Dst;
use crate::build::Bvh2;
use crate::observer::CountingObserver;
use dualsplit_geometry::Ray;
use serde::Serialize;

/// Node counts and sizes of a converted DST. Conversion time is measured by the caller.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct DstStats {
    /// Splitting nodes.
    pub splitting: u64,
    /// Single-axis carving nodes (including those acting as leaves).
    pub single_carving: u64,
    /// Dual-axis carving nodes (including those acting as leaves).
    pub dual_carving: u64,
    /// Plain leaf words.
    pub leaves: u64,
    /// Carving nodes acting as leaves (L bit set).
    pub carving_leaves: u64,
    /// Triangle-index entries.
    pub index_entries: u64,
    /// Bytes of node words: 12 per internal node, 4 per plain leaf.
    pub node_bytes: u64,
    /// Bytes of the triangle-index list (4 per entry).
    pub index_bytes: u64,
    /// Nodes + index list + the 24-byte scene box.
    pub total_bytes: u64,
    /// The source BVH2's size in the paper's layout ([`bvh2_size_bytes`]).
    pub bvh2_bytes: u64,
}

impl DstStats {
    /// Adds `o`'s node and entry counts (not the byte totals) to these.
    pub(super) fn add_counts(&mut self, o: &DstStats) {
        self.splitting += o.splitting;
        self.single_carving += o.single_carving;
        self.dual_carving += o.dual_carving;
        self.leaves += o.leaves;
        self.carving_leaves += o.carving_leaves;
        self.index_entries += o.index_entries;
    }

    /// Internal (12-byte) nodes.
    pub fn internal_nodes(&self) -> u64 {
        self.splitting + self.single_carving + self.dual_carving
    }

    /// [`DstStats::total_bytes`] as a percentage of the BVH2's size (Table 3 reports
    /// 60–70 %).
    pub fn percent_of_bvh2(&self) -> f64 {
        if self.bvh2_bytes == 0 {
            0.0
        } else {
            100.0 * self.total_bytes as f64 / self.bvh2_bytes as f64
        }
    }
}

/// Size of a BVH2 in the paper's layout (Lin et al. 2020, §4.1): 52 B per internal node
/// (two child boxes + one offset/type word; leaves live in their parent's word) plus 4 B
/// per triangle-index entry.
pub fn bvh2_size_bytes(bvh: &Bvh2) -> u64 {
    let internal = bvh.nodes.iter().filter(|n| !n.is_leaf()).count() as u64;
    52 * internal + 4 * bvh.prim_ids.len() as u64
}

/// Per-ray averages of a set of closest-hit traversals, to compare partitioning modes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct DstTraceStats {
    /// Rays traced.
    pub rays: u64,
    /// Internal nodes visited per ray.
    pub nodes: f64,
    /// Leaves (plain or carving) entered per ray.
    pub leaves: f64,
    /// Ray–plane tests per ray.
    pub plane_tests: f64,
    /// Ray–triangle tests per ray.
    pub triangle_tests: f64,
    /// Bytes fetched per ray.
    pub bytes: f64,
}

impl Dst {
    /// Traces `rays` (closest hit, software traversal) and averages the counters per ray;
    /// `dualsplit stats` uses it to show what similar partitioning changes.
    pub fn trace_stats(&self, rays: &[Ray]) -> DstTraceStats {
        let mut total = CountingObserver::default();
        for r in rays {
            let mut o = CountingObserver::default();
            self.closest_hit(r, &mut o);
            total.add(&o);
        }
        let n = rays.len().max(1) as f64;
        DstTraceStats {
            rays: rays.len() as u64,
            nodes: total.nodes as f64 / n,
            leaves: total.leaves as f64 / n,
            plane_tests: total.plane_tests as f64 / n,
            triangle_tests: total.triangle_tests as f64 / n,
            bytes: total.bytes as f64 / n,
        }
    }
}
