//! The traversal and workload events the `fast` model charges its kernel's measured
//! instructions for.

use dualsplit_accel::{DstNodeKind, StepOutcome};

/// A traversal or workload event the `fast` model charges its kernel's instructions for.
/// Their costs are measured per configuration and workload ([`crate::model::fast::calibrate`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    /// A pixel taken from the global counter: its camera ray's set-up and the radiance
    /// written to the frame buffer.
    Pixel,
    /// A closest-hit ray (primary or diffuse) that hit: its set-up and the shading of the
    /// hit.
    ClosestHit,
    /// A closest-hit ray that missed: its set-up and the sky.
    ClosestMiss,
    /// A shadow ray that reached the light: its set-up and the light's contribution.
    ShadowLit,
    /// A shadow ray that was blocked: its set-up.
    ShadowBlocked,
    /// A traversal stack push.
    Push,
    /// A traversal stack pop.
    Pop,
    /// A leaf's triangle run set up.
    Leaf,
    /// A ray-triangle test.
    TriTest,
    /// An accepted triangle hit (closest hit updated).
    TriAccept,
    /// A BVH node visited.
    BvhNode,
    /// A valid child box of a visited BVH node tested.
    BvhChild,
    /// A hit child box (its entry kept for the sort).
    BvhHit,
    /// One compare-exchange of the entry-distance sort (`hits·(hits − 1)/2` per node).
    BvhSortPair,
    /// A DST node step of this kind and outcome (the pipeline's return code, Lin et al.
    /// 2020, §3).
    Dst(DstNodeKind, StepOutcome),
}

/// Number of [`Event`] indices.
pub const EVENTS: usize = 14 + 16;

/// The DST node kinds in the enum's order: `kind as usize` indexes the DST events.
pub const DST_KINDS: [DstNodeKind; 4] = [
    DstNodeKind::Split,
    DstNodeKind::SingleCarve,
    DstNodeKind::DualCarve,
    DstNodeKind::Leaf,
];
const _: () = {
    let mut k = 0;
    while k < 4 {
        assert!(
            DST_KINDS[k] as usize == k,
            "DST_KINDS must follow DstNodeKind's order"
        );
        k += 1;
    }
};

impl Event {
    /// A dense index below [`EVENTS`] (the calibration file's order).
    pub const fn index(self) -> usize {
        match self {
            Event::Pixel => 0,
            Event::ClosestHit => 1,
            Event::ClosestMiss => 2,
            Event::ShadowLit => 3,
            Event::ShadowBlocked => 4,
            Event::Push => 5,
            Event::Pop => 6,
            Event::Leaf => 7,
            Event::TriTest => 8,
            Event::TriAccept => 9,
            Event::BvhNode => 10,
            Event::BvhChild => 11,
            Event::BvhHit => 12,
            Event::BvhSortPair => 13,
            Event::Dst(k, c) => 14 + 4 * k as usize + c as usize,
        }
    }

    /// Every event, by index.
    pub fn all() -> [Event; EVENTS] {
        let mut all = [Event::Pixel; EVENTS];
        let fixed = [
            Event::Pixel,
            Event::ClosestHit,
            Event::ClosestMiss,
            Event::ShadowLit,
            Event::ShadowBlocked,
            Event::Push,
            Event::Pop,
            Event::Leaf,
            Event::TriTest,
            Event::TriAccept,
            Event::BvhNode,
            Event::BvhChild,
            Event::BvhHit,
            Event::BvhSortPair,
        ];
        for e in fixed {
            all[e.index()] = e;
        }
        for k in DST_KINDS {
            for c in StepOutcome::ALL {
                all[Event::Dst(k, c).index()] = Event::Dst(k, c);
            }
        }
        all
    }

    /// Its name in the calibration file (`dst_split_both_children`, …).
    pub fn name(self) -> String {
        match self {
            Event::Pixel => "pixel".into(),
            Event::ClosestHit => "closest_hit".into(),
            Event::ClosestMiss => "closest_miss".into(),
            Event::ShadowLit => "shadow_lit".into(),
            Event::ShadowBlocked => "shadow_blocked".into(),
            Event::Push => "push".into(),
            Event::Pop => "pop".into(),
            Event::Leaf => "leaf".into(),
            Event::TriTest => "tri_test".into(),
            Event::TriAccept => "tri_accept".into(),
            Event::BvhNode => "bvh_node".into(),
            Event::BvhChild => "bvh_child".into(),
            Event::BvhHit => "bvh_hit".into(),
            Event::BvhSortPair => "bvh_sort_pair".into(),
            Event::Dst(k, c) => {
                let kind = ["split", "single_carve", "dual_carve", "leaf"][k as usize];
                let code = ["miss", "one_child", "both_children", "leaf"][c as usize];
                format!("dst_{kind}_{code}")
            }
        }
    }
}

/// Compare-exchanges of the entry-distance sort of `hits` children: `hits·(hits − 1)/2`.
pub(crate) const fn bvh_pairs(hits: u64) -> u64 {
    hits * hits.saturating_sub(1) / 2
}
