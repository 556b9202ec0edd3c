//! The vocabulary that planning and emission share (`docs/dst-encoding.md`, §2–3): a split's
//! decision ([`SplitPlan`]: its axis, child order and both children's carving chains), a
//! carving chain packed in eight bytes ([`Chain`]), the carving node each chain step
//! becomes ([`StepTable`]), and the [`Planner`] trait through which the encoder
//! ([`super::encode`]) asks for decisions. The planners are the fast chain DP
//! ([`super::from_bvh2`]) and the plain reference DP ([`super::reference`]).

use super::header::{AxisPair, Corner, HeaderOffset};
use super::{DstConfig, DstCosts, DstError, Partitioning};
use crate::build::Bvh2;
use dualsplit_geometry::{Aabb, Vec3};

/// Who decides the splits the encoder emits: one decision per internal BVH node, in any
/// order, from any thread (the encoder plans subtrees in parallel).
pub(super) trait Planner: Sync {
    /// Working memory one planning thread reuses from node to node.
    type Scratch;

    /// Fresh working memory for one planning thread.
    fn scratch(&self) -> Self::Scratch;

    /// The split of internal BVH node `n`: axis, child order and both children's chains.
    fn plan_split(
        &self,
        bvh: &Bvh2,
        n: u32,
        cfg: &DstConfig,
        scratch: &mut Self::Scratch,
    ) -> SplitPlan;
}

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

/// A carving chain, outermost node first (at most one node per face), packed into eight
/// bytes so the planning pass can keep every chain until emission: step `i` is the 6-bit
/// mask of the faces it carves (bit `f` = face `f`) at bits `6i..6i+6`, the step count at
/// bits 36..39. A step's carving node is rebuilt from its faces and the target box
/// ([`Chain::step`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Chain(u64);

impl Chain {
    pub const EMPTY: Chain = Chain(0);

    /// Number of carving nodes.
    #[inline(always)]
    pub fn len(self) -> usize {
        (self.0 >> 36) as usize
    }

    #[inline(always)]
    pub fn is_empty(self) -> bool {
        self.len() == 0
    }

    /// Appends a step carving the faces in `faces` (one or two bits).
    #[inline(always)]
    pub fn push(&mut self, faces: u64) {
        let n = self.len();
        self.0 = (self.0 & ((1 << 36) - 1)) | faces << (6 * n) | ((n + 1) as u64) << 36;
    }

    /// The faces step `i` carves, as a 6-bit mask (bit `f` = face `f`).
    #[inline(always)]
    pub fn faces(self, i: usize) -> usize {
        (self.0 >> (6 * i)) as usize & 63
    }
}

/// Where a carving node's plane comes from: face 0–5 of the box the chain carves down to,
/// or a ±∞ no-op plane.
const PLUS_INF: u8 = 6;
const MINUS_INF: u8 = 7;

/// A carving node as a function of the faces it carves: its header (offset 0, L = 0),
/// whether it is dual-axis, and the sources of P0 and P1 (a face 0–5, [`PLUS_INF`] or
/// [`MINUS_INF`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct StepTemplate {
    pub header: HeaderOffset,
    pub dual: bool,
    pub planes: [u8; 2],
}

/// The carving node of every face set a chain step can carve (one face or two), built once
/// per conversion with [`step_for`], so emission is a lookup and two plane selects.
pub(super) struct StepTable([StepTemplate; 64]);

impl StepTable {
    pub fn new(costs: &DstCosts) -> Result<Self, DstError> {
        // A probe box whose coordinates are the face numbers: step_for's planes name their
        // faces.
        let probe = Aabb {
            min: Vec3::new(0.0, 2.0, 4.0),
            max: Vec3::new(1.0, 3.0, 5.0),
        };
        let source = |p: f32| {
            if p == f32::INFINITY {
                PLUS_INF
            } else if p == f32::NEG_INFINITY {
                MINUS_INF
            } else {
                p as u8
            }
        };
        let mut table = [StepTemplate {
            header: HeaderOffset::single_carve(0, false, 0)?,
            dual: false,
            planes: [PLUS_INF, MINUS_INF],
        }; 64];
        for (m, t) in table.iter_mut().enumerate() {
            if !(1..=2).contains(&m.count_ones()) {
                continue;
            }
            let fi = m.trailing_zeros() as usize;
            let rest = m & !(1 << fi);
            let fj = (rest != 0).then(|| rest.trailing_zeros() as usize);
            let step = step_for(fi, fj, &probe, costs);
            let (header, dual) = match step.kind {
                CarveKind::Single(axis) => (HeaderOffset::single_carve(axis, false, 0)?, false),
                CarveKind::Dual(pair, corner) => {
                    (HeaderOffset::dual_carve(pair, corner, false, 0)?, true)
                }
            };
            *t = StepTemplate {
                header,
                dual,
                planes: [source(step.p0), source(step.p1)],
            };
        }
        Ok(StepTable(table))
    }

    /// The template of the step carving face set `faces`.
    #[inline(always)]
    pub fn get(&self, faces: usize) -> &StepTemplate {
        &self.0[faces]
    }
}

/// The values [`StepTemplate::planes`] select from, for a chain carving down to `target`.
#[inline(always)]
pub(super) fn plane_values(target: &Aabb) -> [f32; 8] {
    let (lo, hi) = (target.min, target.max);
    [
        lo.x,
        hi.x,
        lo.y,
        hi.y,
        lo.z,
        hi.z,
        f32::INFINITY,
        f32::NEG_INFINITY,
    ]
}

/// Face `f` of a box: axis `f >> 1`, the max face when `f & 1 == 1`.
#[inline(always)]
pub(super) fn face(b: &Aabb, f: usize) -> f32 {
    if f & 1 == 1 {
        b.max[f >> 1]
    } else {
        b.min[f >> 1]
    }
}

/// The carving node that carves face `fi` (and face `fj > fi` when given) down to `target`.
fn step_for(fi: usize, fj: Option<usize>, target: &Aabb, c: &DstCosts) -> CarveStep {
    match fj {
        Some(fj) => {
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
                // Single-axis node whose other plane is a ±∞ no-op: (±∞ − o)·inv is never
                // NaN for a finite origin, and 0.0 as "no plane" would be a real plane at
                // coordinate 0.
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

/// The split chosen for an internal BVH node: axis, which BVH child is the left (lower)
/// child (`swap`: the second), and both children's carving chains.
pub(super) struct SplitPlan {
    pub axis: usize,
    pub swap: bool,
    pub left_chain: Chain,
    pub right_chain: Chain,
}

/// The triangle count of BVH node `n` when it is a leaf and partitioning is similar (its
/// chain may then stop early), else `None`.
pub(super) fn leaf_tris(bvh: &Bvh2, n: u32, cfg: &DstConfig) -> Option<u32> {
    let node = &bvh.nodes[n as usize];
    (cfg.partitioning == Partitioning::Similar && node.is_leaf()).then_some(node.count)
}

/// Face index of the max face on `axis` (carved for the left child by P0) and of the min
/// face (carved for the right child by P1).
pub(super) const fn max_face(axis: usize) -> usize {
    2 * axis + 1
}
pub(super) const fn min_face(axis: usize) -> usize {
    2 * axis
}
