//! The `[simt]` table: an RTX-style GPU with one ray-tracing unit per SM, as Vulkan-Sim
//! models it (`configs/rtx2060.toml` gives every key's source).

use crate::ranges::ConfigError;
use serde::{Deserialize, Serialize};

/// A set-associative, sectored cache: `sets` × `ways` lines of `line_bytes`, filled one
/// sector at a time (GPGPU-Sim's `S:` caches).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimtCache {
    /// Sets (any positive number; the set is the line address modulo the sets).
    pub sets: u32,
    /// Line size in bytes, a multiple of the sector size.
    pub line_bytes: u32,
    /// Ways per set.
    pub ways: u32,
    /// Hit latency in core cycles (for the L2: on top of the L1's).
    pub hit_latency: u64,
}

impl SimtCache {
    /// Capacity in bytes.
    pub fn bytes(&self) -> u64 {
        self.sets as u64 * self.ways as u64 * self.line_bytes as u64
    }
}

/// The GPU chip of the `simt` model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimtConfig {
    /// Streaming multiprocessors (SMs), one RT unit each.
    pub sms: u32,
    /// Threads per warp.
    pub warp_size: u32,
    /// Warps resident per SM.
    pub warps_per_sm: u32,
    /// Warp schedulers per SM, each issuing one warp instruction per cycle; warp slot `w`
    /// belongs to scheduler `w mod schedulers`.
    pub schedulers_per_sm: u32,
    /// Core clock in MHz.
    pub core_mhz: f64,
    /// DRAM command clock in MHz.
    pub dram_mhz: f64,
    /// Warps the RT unit holds at once.
    pub rt_max_warps: u32,
    /// Outstanding misses above which the RT unit sends no new transaction.
    pub rt_max_mshr: u32,
    /// Bytes per memory request of the RT unit (a transaction is split into chunks).
    pub chunk_bytes: u32,
    /// Cycles of the pipelined intersection test after a transaction's last chunk returns,
    /// by Vulkan-Sim's transaction type, in its `TransactionType` order.
    pub intersection_latency: [u64; 7],
    /// Cycles of a dual-split node step (DST, DST-Q) after its node's chunks return.
    pub dual_split_latency: u64,
    /// The cache the RT unit reads through.
    pub l1: SimtCache,
    /// One L2 slice per memory sub-partition; a line's slice is its line address modulo
    /// the slices.
    pub l2: SimtCache,
    /// L2 slices (memory channels × sub-partitions per channel).
    pub l2_slices: u32,
    /// Memory channels; a request's channel is `(addr >> channel_shift) mod channels`.
    pub dram_channels: u32,
    /// Address bit at which the channel index sits.
    pub channel_shift: u32,
    /// Banks per channel.
    pub dram_banks: u32,
    /// Bytes a channel transfers per DRAM command cycle (bus width × data per command).
    pub dram_bytes_per_cycle: u32,
    /// Row-to-column delay, DRAM cycles.
    pub t_rcd: u64,
    /// Row precharge, DRAM cycles.
    pub t_rp: u64,
    /// Column access (CAS) latency, DRAM cycles.
    pub t_cl: u64,
    /// Fixed latency added to every DRAM return, DRAM cycles.
    pub dram_latency: u64,
    /// Row size in bytes: the address bits below the row bits (after the channel is taken out).
    pub row_bytes: u64,
}

impl SimtConfig {
    /// Checks the values the model relies on; a typed error names the key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let bad = |field: &'static str, value: String, reason: &str| {
            Err(ConfigError::Invalid {
                field,
                value,
                reason: reason.into(),
            })
        };
        let positive: [(&'static str, u64); 15] = [
            ("simt.sms", self.sms as u64),
            ("simt.warp_size", self.warp_size as u64),
            ("simt.warps_per_sm", self.warps_per_sm as u64),
            ("simt.schedulers_per_sm", self.schedulers_per_sm as u64),
            ("simt.rt_max_warps", self.rt_max_warps as u64),
            ("simt.rt_max_mshr", self.rt_max_mshr as u64),
            ("simt.chunk_bytes", self.chunk_bytes as u64),
            ("simt.l1.sets", self.l1.sets as u64),
            ("simt.l1.ways", self.l1.ways as u64),
            ("simt.l2.sets", self.l2.sets as u64),
            ("simt.l2.ways", self.l2.ways as u64),
            ("simt.l2_slices", self.l2_slices as u64),
            ("simt.dram_channels", self.dram_channels as u64),
            ("simt.dram_banks", self.dram_banks as u64),
            (
                "simt.dram_bytes_per_cycle",
                self.dram_bytes_per_cycle as u64,
            ),
        ];
        for (field, v) in positive {
            if v == 0 {
                return bad(field, v.to_string(), "must be at least 1");
            }
        }
        if self.warp_size > 64 {
            return bad(
                "simt.warp_size",
                self.warp_size.to_string(),
                "at most 64 threads per warp",
            );
        }
        if self.sms > 4096 || self.warps_per_sm > 1024 || self.rt_max_warps > 1024 {
            return bad(
                "simt.sms",
                self.sms.to_string(),
                "sms ≤ 4096, warps_per_sm ≤ 1024, rt_max_warps ≤ 1024",
            );
        }
        if !self.chunk_bytes.is_power_of_two() || self.chunk_bytes > 4096 {
            return bad(
                "simt.chunk_bytes",
                self.chunk_bytes.to_string(),
                "a power of two up to 4096",
            );
        }
        for (field, c) in [
            ("simt.l1.line_bytes", &self.l1),
            ("simt.l2.line_bytes", &self.l2),
        ] {
            if c.line_bytes == 0
                || c.line_bytes % self.chunk_bytes != 0
                || c.line_bytes / self.chunk_bytes > 64
            {
                return bad(
                    field,
                    c.line_bytes.to_string(),
                    "a multiple of chunk_bytes, at most 64 chunks",
                );
            }
        }
        for (field, mhz) in [
            ("simt.core_mhz", self.core_mhz),
            ("simt.dram_mhz", self.dram_mhz),
        ] {
            if !(mhz.is_finite() && (1.0..=100_000.0).contains(&mhz)) {
                return bad(field, mhz.to_string(), "a clock between 1 and 100 000 MHz");
            }
        }
        if self.channel_shift > 40 {
            return bad(
                "simt.channel_shift",
                self.channel_shift.to_string(),
                "at most 40",
            );
        }
        if self.row_bytes == 0 || !self.row_bytes.is_power_of_two() {
            return bad(
                "simt.row_bytes",
                self.row_bytes.to_string(),
                "a power of two",
            );
        }
        let lat = self.intersection_latency.iter().copied().max().unwrap_or(0);
        if lat > 1_000_000 || self.dual_split_latency > 1_000_000 {
            return bad(
                "simt.intersection_latency",
                lat.max(self.dual_split_latency).to_string(),
                "at most 10^6 cycles",
            );
        }
        for (field, v) in [
            ("simt.l1.hit_latency", self.l1.hit_latency),
            ("simt.l2.hit_latency", self.l2.hit_latency),
            ("simt.t_rcd", self.t_rcd),
            ("simt.t_rp", self.t_rp),
            ("simt.t_cl", self.t_cl),
            ("simt.dram_latency", self.dram_latency),
        ] {
            if v > 1_000_000 {
                return bad(field, v.to_string(), "at most 10^6 cycles");
            }
        }
        Ok(())
    }
}
