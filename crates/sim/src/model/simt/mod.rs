//! The `simt` thread model: an RTX-style GPU, SMs running warps of 32 threads in lockstep
//! with one ray-tracing unit each, as Vulkan-Sim models it (Saed et al., MICRO 2022).
//!
//! * [`config`]: the chip (`[simt]`; `configs/rtx2060.toml` cites Vulkan-Sim for every key);
//! * [`txn`]: per-thread transaction lists from the real traversal's observed reads;
//! * [`rt_unit`]: the RT unit (warps, 32-byte chunks shared within a warp, MSHRs,
//!   intersection latency by transaction type);
//! * [`mem`]: the RT unit's L1, the L2 and the GDDR6 channels;
//! * [`frame`]: warps of pixels on the SMs, their non-traversal work costed in lockstep.
//!
//! `docs/simulator.md`, "The `simt` model", lists its sources and simplifications.

pub mod config;
pub mod frame;
pub mod mem;
pub mod rt_unit;
pub mod txn;

use crate::{NodeUnit, SimAccel};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The structures an RT unit holds, one configuration each, from the registry: the
/// configurations whose nodes a hardware unit tests (the BVHs and CWBVH test their boxes in
/// the unit, DST and DST-Q run the dual-split step there), without the "+" ones. (The TRaX
/// chip's "+" configurations differ from these only in how a TM issues a node's tests,
/// which the RT unit does its own way; DST\* decodes its nodes in software.)
pub fn rt_accels() -> impl Iterator<Item = SimAccel> {
    SimAccel::ALL
        .into_iter()
        .filter(|a| !a.parallel_boxes() && a.node_unit() != NodeUnit::SoftwareDualSplit)
}

/// What the `simt` model reports beyond the common figures of a [`crate::SimResult`].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SimtFigures {
    /// SMs (one RT unit each).
    pub sms: u32,
    /// Warps an RT unit holds.
    pub rt_max_warps: u32,
    /// The RT unit's MSHR limit.
    pub rt_max_mshr: u32,
    /// Mean warps resident in an RT unit over the frame, divided by `rt_max_warps`.
    pub rt_occupancy: f64,
    /// In the RT unit: thread-cycles of threads with a ray still working (entry to their
    /// last intersection test's end) per warp-cycle × warp size.
    pub rt_simt_efficiency: f64,
    /// Outside it: the threads' issue cycles per warp size × the slowest thread's, over
    /// every shading phase (finished threads count as idle).
    pub shading_simt_efficiency: f64,
    /// Shading phases of warps.
    pub shading_phases: u64,
    /// Of which diverged (threads idle or with unequal work).
    pub divergent_phases: u64,
    /// Warp visits to RT units.
    pub rt_visits: u64,
    /// Warp-cycles spent waiting for a place in an RT unit.
    pub rt_wait_cycles: u64,
    /// RT-unit cycles in which the MSHR limit held a transaction back.
    pub mshr_stall_cycles: u64,
    /// Transactions per ray, from the threads' lists (before sharing in the warp).
    pub transactions_per_ray: f64,
    /// Their 32-byte chunks per ray.
    pub chunks_per_ray: f64,
    /// Chunk requests the RT units sent per ray (after sharing in the warp).
    pub requests_per_ray: f64,
    /// Transactions by kind (`box_node`, `dual_split_node`, `leaf_entries`, `triangle`).
    pub transactions_by_kind: BTreeMap<String, u64>,
    /// Chunk requests to the RT units' L1.
    pub l1_requests: u64,
    /// Of which hit.
    pub l1_hits: u64,
    /// Of which joined an outstanding miss of the same chunk.
    pub l1_merged: u64,
    /// L2 sector accesses.
    pub l2_accesses: u64,
    /// Of which hit.
    pub l2_hits: u64,
    /// DRAM sector reads.
    pub dram_reads: u64,
    /// DRAM row activations.
    pub dram_activations: u64,
    /// DRAM bytes read.
    pub dram_bytes: u64,
    /// DRAM bytes read per ray.
    pub dram_bytes_per_ray: f64,
    /// DRAM read bandwidth over the frame, GB/s.
    pub dram_gb_per_s: f64,
}

#[cfg(test)]
pub(crate) mod tests;
