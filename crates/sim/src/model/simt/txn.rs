//! Per-thread transaction lists: the real traversal run functionally with an observer
//! that turns its reads into the RT unit's memory transactions, each typed by what the
//! unit does with it once its data has returned (Vulkan-Sim's `TransactionType`).

use dualsplit_accel::{ByteAddr, NodeStep, Observer};
use dualsplit_geometry::PrimId;

/// What the RT unit does with a transaction's data: the intersection test it charges.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TxnKind {
    /// A BVH2/4/8 or CWBVH node: its child boxes are tested (Vulkan-Sim's
    /// `BVH_INTERNAL_NODE`).
    BoxNode,
    /// A DST or DST-Q node: the dual-split step (no Vulkan-Sim counterpart).
    DualSplitNode,
    /// A leaf's triangle-index entries (`BVH_PRIMITIVE_LEAF_DESCRIPTOR`).
    LeafEntries,
    /// A triangle's vertices, tested against the ray (`BVH_QUAD_LEAF`).
    Triangle,
}

impl TxnKind {
    /// Names in `kind as usize` order, as the results list them.
    pub const NAMES: [&'static str; 4] =
        ["box_node", "dual_split_node", "leaf_entries", "triangle"];

    /// Index in Vulkan-Sim's `TransactionType` order (`BVH_STRUCTURE`,
    /// `BVH_INTERNAL_NODE`, `BVH_INSTANCE_LEAF`, `BVH_PRIMITIVE_LEAF_DESCRIPTOR`,
    /// `BVH_QUAD_LEAF`, `BVH_QUAD_LEAF_HIT`, `BVH_PROCEDURAL_LEAF`); `None` for the
    /// dual-split node, which has no counterpart there.
    pub fn vulkan_sim_index(self) -> Option<usize> {
        match self {
            TxnKind::BoxNode => Some(1),
            TxnKind::LeafEntries => Some(3),
            TxnKind::Triangle => Some(4),
            TxnKind::DualSplitNode => None,
        }
    }
}

/// Longest transaction recorded: 1 KiB spans at most 33 chunks of 32 bytes.
pub const MAX_TXN_BYTES: u32 = 1024;

/// One memory transaction of a thread: `bytes` at image byte address `addr`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Txn {
    /// Byte address in the structure's image.
    pub addr: u64,
    /// Bytes read (at least 1).
    pub bytes: u32,
    /// What the unit does with the data.
    pub kind: TxnKind,
}

/// The observer that records a traversal's transactions: reads are gathered until the
/// step that uses them (a node step, a leaf, a triangle test) gives them their kind;
/// contiguous reads for the same step make one transaction.
#[derive(Debug, Default)]
pub struct TxnRecorder {
    /// The ray's transactions so far.
    pub txns: Vec<Txn>,
    /// Reads not yet typed, merged where contiguous.
    open: Vec<(u64, u32)>,
}

impl TxnRecorder {
    /// An empty recorder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Types the open reads as `kind`; a read longer than [`MAX_TXN_BYTES`] becomes several
    /// transactions (the RT unit tracks at most 64 chunks of one).
    fn close(&mut self, kind: TxnKind) {
        for (mut addr, mut bytes) in self.open.drain(..) {
            while bytes > 0 {
                let n = bytes.min(MAX_TXN_BYTES);
                self.txns.push(Txn {
                    addr,
                    bytes: n,
                    kind,
                });
                addr += n as u64;
                bytes -= n;
            }
        }
    }

    /// Ends the ray: reads no step used (none in practice) count as box-node reads; returns
    /// the transactions, leaving the recorder empty for the next ray.
    pub fn take(&mut self, dual_split: bool) -> Vec<Txn> {
        self.close(if dual_split {
            TxnKind::DualSplitNode
        } else {
            TxnKind::BoxNode
        });
        std::mem::take(&mut self.txns)
    }
}

impl Observer for TxnRecorder {
    fn fetch(&mut self, ByteAddr(addr): ByteAddr, bytes: u32) {
        if bytes == 0 {
            return;
        }
        if let Some((a, b)) = self.open.last_mut() {
            let end = *a + *b as u64;
            // Contiguous or overlapping with the previous read: one transaction.
            if addr >= *a && addr <= end {
                let new_end = end.max(addr + bytes as u64);
                if let Ok(n) = u32::try_from(new_end - *a) {
                    *b = n;
                    return;
                }
            }
        }
        self.open.push((addr, bytes));
    }

    fn step(&mut self, step: NodeStep) {
        match step {
            NodeStep::Bvh { .. } => self.close(TxnKind::BoxNode),
            NodeStep::Dst { .. } => self.close(TxnKind::DualSplitNode),
            NodeStep::Leaf { .. } => self.close(TxnKind::LeafEntries),
        }
    }

    fn triangle_test(&mut self, _prim: PrimId, _hit: bool) {
        self.close(TxnKind::Triangle);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contiguous_reads_merge_and_steps_type_them() {
        let mut r = TxnRecorder::new();
        r.fetch(ByteAddr(64), 16);
        r.fetch_box(ByteAddr(80), 24);
        r.fetch_box(ByteAddr(104), 24);
        r.step(NodeStep::Bvh {
            arity: 2,
            valid: 2,
            hits: 1,
        });
        r.fetch(ByteAddr(1000), 8);
        r.step(NodeStep::Leaf { count: 1 });
        r.fetch(ByteAddr(4000), 36);
        r.triangle_test(PrimId(3), true);
        let t = r.take(false);
        assert_eq!(
            t,
            vec![
                Txn {
                    addr: 64,
                    bytes: 64,
                    kind: TxnKind::BoxNode
                },
                Txn {
                    addr: 1000,
                    bytes: 8,
                    kind: TxnKind::LeafEntries
                },
                Txn {
                    addr: 4000,
                    bytes: 36,
                    kind: TxnKind::Triangle
                },
            ]
        );
        assert!(r.take(false).is_empty());
    }

    #[test]
    fn separate_reads_stay_separate() {
        let mut r = TxnRecorder::new();
        r.fetch(ByteAddr(0), 8);
        r.fetch(ByteAddr(100), 8);
        r.step(NodeStep::Leaf { count: 2 });
        assert_eq!(r.take(true).len(), 2);
    }
}
