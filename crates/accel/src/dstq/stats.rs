//! Sizes of a quantized DST as values (formatted elsewhere): node counts by kind, clusters,
//! bytes, bytes per node and how full the lines are (Lin et al. 2020, Table 3 quantity).

use serde::Serialize;

/// Node counts and sizes of a [`super::DstQ`] ([`super::DstQ::stats`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct DstQStats {
    /// Clusters.
    pub clusters: u64,
    /// Splitting-node records.
    pub splitting: u64,
    /// Single-axis carving records (including those acting as leaves).
    pub single_carving: u64,
    /// Dual-axis carving records (including those acting as leaves).
    pub dual_carving: u64,
    /// Plain-leaf records.
    pub leaves: u64,
    /// Carving records acting as leaves (L bit set).
    pub carving_leaves: u64,
    /// Triangle-index entries.
    pub index_entries: u64,
    /// Bits holding frames and records (the rest of the lines is padding).
    pub used_bits: u64,
    /// Bytes of the node region: whole lines, padding included.
    pub node_bytes: u64,
    /// Bytes of the triangle-index list (4 per entry).
    pub index_bytes: u64,
    /// Nodes + index list + the 24-byte scene box (as [`crate::dst::DstStats::total_bytes`]).
    pub total_bytes: u64,
}

impl DstQStats {
    /// Internal-node records (splitting and carving).
    pub fn internal_nodes(&self) -> u64 {
        self.splitting + self.single_carving + self.dual_carving
    }

    /// Leaves as the exact DST counts them: plain-leaf records and carving records acting
    /// as leaves.
    pub fn leaf_count(&self) -> u64 {
        self.leaves + self.carving_leaves
    }

    /// Records of every kind (internal nodes and plain leaves).
    pub fn nodes(&self) -> u64 {
        self.internal_nodes() + self.leaves
    }

    /// Node-region bytes per record (the exact DST: 12 per internal node, 4 per leaf).
    pub fn bytes_per_node(&self) -> f64 {
        self.node_bytes as f64 / self.nodes().max(1) as f64
    }

    /// Fraction of the node region holding frames and records.
    pub fn fill(&self) -> f64 {
        self.used_bits as f64 / (8 * self.node_bytes).max(1) as f64
    }
}
