//! The simulated configurations: which structure, traversed how, on which units.

use crate::config::SimConfig;
use dualsplit_accel::AccelKind;
use serde::{Deserialize, Serialize};

/// The eight simulated configurations of the paper (§4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SimAccel {
    /// BVH2, child boxes tested one after another on the TM's ray-box pipeline.
    Bvh2,
    /// BVH2 with 2 ray-box pipelines (all child boxes in parallel).
    Bvh2Plus,
    /// BVH4, serial box tests.
    Bvh4,
    /// BVH4 with 4 ray-box pipelines.
    Bvh4Plus,
    /// BVH8, serial box tests.
    Bvh8,
    /// BVH8 with 8 ray-box pipelines.
    Bvh8Plus,
    /// DST decoded in software (DST*).
    DstSw,
    /// DST on the dual-split pipeline.
    Dst,
}

impl SimAccel {
    /// All eight, in the paper's table order.
    pub const ALL: [SimAccel; 8] = [
        SimAccel::Bvh2,
        SimAccel::Bvh2Plus,
        SimAccel::Bvh4,
        SimAccel::Bvh4Plus,
        SimAccel::Bvh8,
        SimAccel::Bvh8Plus,
        SimAccel::DstSw,
        SimAccel::Dst,
    ];
    /// Command-line name: `bvh2`, `bvh2+`, ..., `dst-sw`, `dst`.
    pub fn name(self) -> &'static str {
        match self {
            SimAccel::Bvh2 => "bvh2",
            SimAccel::Bvh2Plus => "bvh2+",
            SimAccel::Bvh4 => "bvh4",
            SimAccel::Bvh4Plus => "bvh4+",
            SimAccel::Bvh8 => "bvh8",
            SimAccel::Bvh8Plus => "bvh8+",
            SimAccel::DstSw => "dst-sw",
            SimAccel::Dst => "dst",
        }
    }
    /// The paper's label: `BVH2`, `BVH2+`, ..., `DST*`, `DST`.
    pub fn label(self) -> &'static str {
        match self {
            SimAccel::Bvh2 => "BVH2",
            SimAccel::Bvh2Plus => "BVH2+",
            SimAccel::Bvh4 => "BVH4",
            SimAccel::Bvh4Plus => "BVH4+",
            SimAccel::Bvh8 => "BVH8",
            SimAccel::Bvh8Plus => "BVH8+",
            SimAccel::DstSw => "DST*",
            SimAccel::Dst => "DST",
        }
    }
    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }
    /// The traversal this configuration runs.
    pub fn kind(self) -> AccelKind {
        match self {
            SimAccel::Bvh2 | SimAccel::Bvh2Plus => AccelKind::Bvh2,
            SimAccel::Bvh4 | SimAccel::Bvh4Plus => AccelKind::Bvh4,
            SimAccel::Bvh8 | SimAccel::Bvh8Plus => AccelKind::Bvh8,
            SimAccel::DstSw => AccelKind::DstSw,
            SimAccel::Dst => AccelKind::Dst,
        }
    }
    /// The "+" configurations: all child boxes of a node tested in one issue slot, on as
    /// many ray-box pipelines (§4).
    pub fn parallel_boxes(self) -> bool {
        matches!(
            self,
            SimAccel::Bvh2Plus | SimAccel::Bvh4Plus | SimAccel::Bvh8Plus
        )
    }
    /// DST and DST\*: the traversal of the dual-split tree (stack entries carry
    /// `[t_min, t_max]`).
    pub fn is_dst(self) -> bool {
        matches!(self, SimAccel::Dst | SimAccel::DstSw)
    }
    /// Ray-box pipelines per TM: the node arity for the "+" configurations (§4).
    pub fn box_pipes(self, cfg: &SimConfig) -> u32 {
        match self {
            SimAccel::Bvh2Plus => 2,
            SimAccel::Bvh4Plus => 4,
            SimAccel::Bvh8Plus => 8,
            _ => cfg.units.box_pipes,
        }
    }
}
