//! The hardware dual-split pipeline as a pure step function (Lin et al. 2020, §3, Fig. 6,
//! Appendices A–C, Figs. 10–12). The traversal loop driven only by it is
//! `dst/pipeline_traverse.rs` ([`Dst::closest_hit_pipeline`](super::Dst::closest_hit_pipeline)).
//!
//! The function is written like the datapath: every stage runs for every node type and
//! 2:1 multiplexers ([`mux`]) pick operands and results, steered by header bits and the ray's
//! direction signs. There is no branch on the node type.
//!
//! ```text
//!  header ─▶ decode (C, L, A, B) ─┬─▶ component select: axis0, axis1 ─▶ (o, inv) × 2
//!                                 ├─▶ plane swap by ray sign (1-D nodes) ─▶ q0, q1
//!  FPADD ×2, FPMUL ×2:  t1 = (q0 − o0)·inv0,  t2 = (q1 − o1)·inv1
//!  FPMUL ×2 (robustness): t_i ·= (exit_i ? 1 + 2γ₃ : 1)   (Ize 2013; not in Fig. 6)
//!  FPCMP ×4: near = t_min ≤ t1, far = t_max ≥ t2, cut ≤, exit/entry steering
//!  FPMIN3 / FPMAX3: t_max_out = min(t_max, t1?, t2?), t_min_out = max(t_min, t1?, t2?)
//!  INTADD ×1: right = offset + left size;  near/far muxes;  return-code logic
//! ```
//!
//! Units: 1 INTADD, 2 FPADD, 2 FPMUL, 3 FPMIN/MAX (one 3-way min + one 3-way max),
//! 4 FPCMP, as in Table 2.
//!
//! Robustness addition (not in the paper's Fig. 6 or Table 2): each lane's plane distance
//! goes through one more FPMUL by a constant, `1 + 2γ₃` when that plane is an exit for the
//! ray (selected by the exit muxes) and `1.0` otherwise, making exit distances conservative
//! as in Ize 2013 ("Robust BVH ray traversal", JCGT 2(2)). It matches the BVH slab test's
//! widened far planes ([`dualsplit_geometry::widen_exit`]), so grazing rays through a box
//! corner keep the hit the watertight triangle test accepts. It is still branch-free; a
//! hardware unit could fold it into a constant multiplier (or skip it, trading the rare
//! grazing miss for the area).

use super::header::HeaderOffset;
use crate::observer::StepOutcome;
use dualsplit_geometry::EXIT_WIDEN;

/// The pipeline's 2-bit return code, numbered as in the paper (Lin et al. 2020, §3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum ReturnCode {
    /// 0: no intersection — pop the stack.
    Miss = 0,
    /// 1: one child — continue at `offset` with `[t_min_out, t_max_out]`.
    OneChild = 1,
    /// 2: both children — push `(offset_stack, t_min_out, t_max_in)`, continue at `offset`
    /// with `[t_min_in, t_max_out]`.
    BothChildren = 2,
    /// 3: leaf (plain leaf or carving node acting as a leaf) — intersect the triangle run
    /// at `offset`.
    Leaf = 3,
}

impl From<ReturnCode> for StepOutcome {
    /// The code in the traversal contract's terms: the same four results, in the same order.
    #[inline(always)]
    fn from(c: ReturnCode) -> Self {
        match c {
            ReturnCode::Miss => StepOutcome::Miss,
            ReturnCode::OneChild => StepOutcome::OneChild,
            ReturnCode::BothChildren => StepOutcome::BothChildren,
            ReturnCode::Leaf => StepOutcome::Leaf,
        }
    }
}

impl ReturnCode {
    /// The four codes, in order.
    pub const ALL: [ReturnCode; 4] = [Self::Miss, Self::OneChild, Self::BothChildren, Self::Leaf];

    /// From the 2-bit value.
    #[inline(always)]
    pub fn from_bits(b: u8) -> Self {
        match b & 3 {
            0 => Self::Miss,
            1 => Self::OneChild,
            2 => Self::BothChildren,
            _ => Self::Leaf,
        }
    }
}

/// The pipeline's inputs: exactly the paper's (Lin et al. 2020, §3, Fig. 6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PipelineInput {
    /// The node's header-offset word.
    pub word: HeaderOffset,
    /// Plane P0 (word 1 of the node).
    pub p0: f32,
    /// Plane P1 (word 2 of the node).
    pub p1: f32,
    /// Ray origin.
    pub origin: [f32; 3],
    /// Ray inverse direction (IEEE `1/d`, ±∞ for zero components).
    pub inv_dir: [f32; 3],
    /// Current interval start.
    pub t_min: f32,
    /// Current interval end.
    pub t_max: f32,
}

/// The pipeline's outputs (Lin et al. 2020, §3, Fig. 6).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PipelineOutput {
    /// Return code 0–3.
    pub code: ReturnCode,
    /// Next node (codes 1, 2) or triangle run (code 3).
    pub offset: u32,
    /// The far child to push (code 2).
    pub offset_stack: u32,
    /// Output interval start (see [`ReturnCode`] for how each code uses it).
    pub t_min_out: f32,
    /// Output interval end.
    pub t_max_out: f32,
}

/// A 2:1 multiplexer: `a` when `s`, else `b`. Written as a conditional expression, which
/// the compiler lowers to a select (`cmov`, a blend); indexing a two-element array instead
/// costs a stack round trip per mux (callgrind: 44 M of the 512 M host instructions of
/// the functional traversal of a simulated dragon_box 96² DST frame).
#[inline(always)]
pub fn mux<T: Copy>(s: bool, a: T, b: T) -> T {
    if s { a } else { b }
}

/// The comparator `a ≤ b` with NaN counted as true: a NaN plane distance (the ray lies in
/// the plane) never drops a child or culls a node.
#[inline(always)]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // the negated form is exactly the NaN rule
pub fn le_or_nan(a: f32, b: f32) -> bool {
    !(a > b)
}

/// One dual-split pipeline operation (Lin et al. 2020, §3, Fig. 6; Apps. A–C).
#[inline(always)]
pub fn step(i: &PipelineInput) -> PipelineOutput {
    let w = i.word;
    // ---- decode (bit logic) -------------------------------------------------------------
    let is_carving = w.is_carving();
    let leaf_flag = w.is_leaf_flag();
    let is_split = w.is_split();
    let is_plain_leaf = w.is_plain_leaf();
    let is_dual = w.is_dual();
    let field_a = w.axis_pair_bits() as usize;
    let field_b = w.field_b_bits();
    // Component select (App. A): 1-D nodes use one axis for both planes (splitting: field A;
    // single-axis carving: field B); dual-axis nodes use the pair (A >> 1, (A & 1) + 1).
    let axis_1d = mux(is_carving, field_b as usize & 3, field_a) % 3;
    let axis0 = mux(is_dual, field_a >> 1, axis_1d);
    let axis1 = mux(is_dual, (field_a & 1) + 1, axis_1d);
    let (o0, inv0) = (i.origin[axis0], i.inv_dir[axis0]);
    let (o1, inv1) = (i.origin[axis1], i.inv_dir[axis1]);
    let neg0 = inv0.is_sign_negative();
    let neg1 = inv1.is_sign_negative();
    // 1-D nodes: the ray sign swaps (P0, P1) so that q0 is the exit plane, q1 the entry
    // plane (App. A). 2-D nodes keep the plane order.
    let swap = !is_dual & neg0;
    let q0 = mux(swap, i.p1, i.p0);
    let q1 = mux(swap, i.p0, i.p1);
    // ---- effective corner: which plane clamps t_max (exit) ------------------------------
    // 1-D nodes: q0 is the exit plane, q1 the entry plane. Dual-axis nodes: a plane is an
    // exit iff its "lower bound" bit equals the ray's sign on its axis (Fig. 2).
    let corner = w.corner();
    let exit0 = mux(is_dual, neg0 == corner.first_lower, true);
    let exit1 = mux(is_dual, neg1 == corner.second_lower, false);
    // ---- FPADD ×2, FPMUL ×2 --------------------------------------------------------------
    // Robustness addition to Fig. 6 (Ize 2013): one more FPMUL per lane multiplies the
    // lane's distance by EXIT_WIDEN = 1 + 2γ₃ when it plays the exit role and by 1.0
    // (exact) otherwise, the factor selected by the same exit muxes. The result is
    // bit-identical to `widen_exit(plane_t)` in the software decoder and the BVH slab test.
    let t1 = (q0 - o0) * inv0 * mux(exit0, EXIT_WIDEN, 1.0);
    let t2 = (q1 - o1) * inv1 * mux(exit1, EXIT_WIDEN, 1.0);
    // ---- FPCMP: splitting-node child tests (NaN-permissive) --------
    let near_hit = le_or_nan(i.t_min, t1);
    let far_hit = le_or_nan(t2, i.t_max);
    // A splitting node hit on one side only keeps the untouched bound of that side:
    // near-only → [t_min, min(t_max, t1)], far-only → [max(t_min, t2), t_max].
    let use_t1 = exit0 & !(is_split & !near_hit);
    let use_t2 = !exit1 & !(is_split & near_hit & !far_hit);
    // ---- FPMIN3 / FPMAX3 (f32::min/max return the non-NaN operand) -----------------------
    let t_max_out = i
        .t_max
        .min(mux(use_t1, t1, i.t_max))
        .min(mux(exit1, t2, i.t_max));
    let t_min_out = i
        .t_min
        .max(mux(!exit0, t1, i.t_min))
        .max(mux(use_t2, t2, i.t_min));
    // ---- FPCMP: carving cull -------------------------------------------------------------
    let carve_hit = le_or_nan(t_min_out, t_max_out);
    // ---- INTADD and offset muxes ---------------------------------------------------------
    let left = w.offset();
    let right = left.wrapping_add(field_b);
    let near = mux(neg0, right, left);
    let far = mux(neg0, left, right);
    let offset = mux(is_split, mux(near_hit, near, far), left);
    // ---- return-code logic ---------------------------------------------------------------
    let split_code = near_hit as u8 + far_hit as u8;
    let carve_code = carve_hit as u8 * (1 + 2 * leaf_flag as u8);
    let code = mux(is_plain_leaf, 3, mux(is_split, split_code, carve_code));
    PipelineOutput {
        code: ReturnCode::from_bits(code),
        offset,
        offset_stack: far,
        t_min_out,
        t_max_out,
    }
}
