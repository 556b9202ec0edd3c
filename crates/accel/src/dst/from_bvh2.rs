//! BVH2 → DST conversion: [`Dst::from_bvh2`], and the SAH choice of carving chains and of
//! each split's child order (Lin et al. 2020, §4.2; Lin et al. 2019; `docs/dst-encoding.md`,
//! §3). The emission of the decided tree is [`super::encode`].
//!
//! With identical bounds the region entering every splitting node is exactly its BVH node's
//! box, so each child subtree costs the same whatever its parent chooses. The only choices
//! left at a BVH node are local: which axis and child order the split uses (which face of
//! each child the split plane carves for free) and how the remaining faces are carved. The
//! SAH cost of those choices is Σ C_node · SA(region where the node is tested); minimising
//! it node by node is exact, and the whole conversion is one O(1) step per BVH node.
//!
//! A carving chain covers the set F of faces where the incoming region differs from the
//! target box. [`ChainDp`] solves it exactly by dynamic programming over the 2^|F| subsets
//! of carved faces (one DP per child prices all six split choices): a step carves one face
//! or two (two on one axis = single-axis carving node, on two axes = dual-axis carving
//! node); a lone face is carved by the cheaper node type with a ±∞ no-op partner plane.
//!
//! Costs are f32 areas: for boxes more than about 1.8e19 across they overflow to +∞ (or
//! NaN, as 0 · ∞), and no option is then strictly cheaper than +∞. A chain that must reach
//! its child's box (every chain but a similar-partitioning leaf's, which may stop) then
//! takes the first option of its state, so every face is still carved and the tree stays
//! valid for any finite boxes; only the SAH choice among overflowed costs is arbitrary.
//!
//! This is the plain DP of [`super::reference`] made fast: each state's options come from
//! a table built at compile time ([`OPTIONS`]) in the reference's loop order, and the
//! cheapest is selected without branches, with the same strict `<` and the same float
//! expressions, so every decision (ties included) is the reference's
//! (`tests/dst_convert_reference.rs`). Where the CPU has AVX2 (the traversal's
//! [`SimdLevel`](crate::wide::cpu::SimdLevel)), the DP runs compiled for it and computes
//! its state areas eight at a time ([`Avx2::areas8`]), with the same operations in the same
//! order: the same bits (unit test `avx2_solve_is_the_baseline_solve`).

use super::encode::encode;
use super::plan::{Chain, Planner, SplitPlan, face, leaf_tris, max_face, min_face};
use super::{Dst, DstConfig, DstCosts, DstError};
use crate::build::Bvh2;
use crate::image::SharedTriangles;
use crate::wide::cpu::avx2_token;
use crate::wide::simd::{Avx2, Kernel};
use dualsplit_geometry::Aabb;

impl Dst {
    /// Converts a BVH2 over `triangles` into a DST (Lin et al. 2020, §4.2). In
    /// [`super::Partitioning::Identical`] mode the region entering every splitting node and
    /// leaf is exactly its BVH node's box. Time and memory are linear in the BVH's nodes.
    ///
    /// Errors: malformed BVH links, non-finite boxes, triangle ids out of range, and
    /// offsets beyond the 26-bit field ([`DstError::OffsetOverflow`]).
    pub fn from_bvh2(
        bvh: &Bvh2,
        triangles: impl Into<SharedTriangles>,
        cfg: &DstConfig,
    ) -> Result<Dst, DstError> {
        encode(bvh, triangles.into(), cfg, &FastPlanner)
    }
}

/// The exact chain DP of one child box against its parent's box (`docs/dst-encoding.md`, §3).
///
/// States are subsets S of the faces F where the parent box differs from the child box; the
/// region in state S is the parent box with the faces in S already at the child's values.
/// `cost[S]` is the cheapest SAH cost of carving the rest. A split that carves face f of the
/// child enters the chain in state {f}, so one DP per child prices all 6 split choices.
pub(super) struct ChainDp {
    faces: [usize; 6],
    /// `bit_of[f]`: the state bit of face `f` (0 when `f` is not one of F), so the state a
    /// split enters is one lookup.
    bit_of: [u8; 6],
    k: usize,
    cost: [f32; 64],
    choice: [u8; 64],
    /// Leaf cost in the full state (similar partitioning), added to every result.
    base: f32,
    /// Working arrays of [`ChainDp::solve`].
    scratch: Scratch,
    /// The AVX2 token when [`ChainDp::solve`] runs compiled for AVX2 (the same operations,
    /// so the same results; fewer instructions with VEX encodings and BMI2 shifts).
    avx2: Option<Avx2>,
}

/// [`ChainDp::solve`]'s arguments, run by [`Avx2::vectorize`].
struct Solve<'a> {
    avx2: Avx2,
    dp: &'a mut ChainDp,
    region: &'a Aabb,
    target: &'a Aabb,
    costs: &'a DstCosts,
    leaf_tris: Option<u32>,
}

impl Kernel for Solve<'_> {
    type Output = ();
    #[inline(always)]
    fn call(self) {
        let Solve {
            avx2,
            dp,
            region,
            target,
            costs,
            leaf_tris,
        } = self;
        dp.solve_with(region, target, costs, leaf_tris, Some(avx2));
    }
}

/// Working arrays of one DP, kept between solves so that no array is cleared per BVH node
/// (a DP reads only entries it wrote first; most chains have k ≤ 3 faces, i.e. ≤ 8 of the
/// 64 states, so clearing dominated the planning time).
struct Scratch {
    /// Surface area of the region in each state.
    sa: [f32; 64],
    /// Node cost by option mask.
    weight: [f32; 64],
    /// For a lone-face option mask: the faces whose pair node is no dearer (only entries of
    /// single-bit masks are ever written; the others stay 0).
    cheap_partner: [u8; 64],
}

/// Start of chain length `k`'s states in [`OptionTable::range`]: Σ_{k' < k} (2^k' + 1).
const TABLE_START: [usize; 7] = {
    let mut out = [0usize; 7];
    let mut k = 1;
    while k < 7 {
        out[k] = out[k - 1] + (1 << (k - 1)) + 1;
        k += 1;
    }
    out
};

/// The DP's options for every chain length `k` ≤ 6 and state `s`: option masks (one or two
/// faces of the remaining set) `masks[range[TABLE_START[k] + s]..range[TABLE_START[k] + s + 1]]`.
struct OptionTable {
    masks: [u8; 1024],
    range: [u16; 140],
}

/// The option table, built once at compile time (672 options in all).
const OPTIONS: OptionTable = option_table(false);

/// The option table when every pair node costs no more than a lone-face node (equal costs,
/// the hardware preset): a lone face is then only ever carved as the last remaining face
/// (the dominance rule in [`ChainDp::solve`]), so the other lone options, which the rule
/// would reject anyway, are left out.
const OPTIONS_PAIRS_CHEAP: OptionTable = option_table(true);

/// Builds an option table; `pairs_cheap` keeps lone-face options only in states with one
/// face remaining.
const fn option_table(pairs_cheap: bool) -> OptionTable {
    let mut t = OptionTable {
        masks: [0; 1024],
        range: [0; 140],
    };
    let mut n = 0usize;
    let mut k = 0;
    while k < 7 {
        let full = (1usize << k) - 1;
        let mut s = 0;
        while s <= full {
            t.range[TABLE_START[k] + s] = n as u16;
            let rem = full & !s;
            let lone = !pairs_cheap || rem.count_ones() == 1;
            let mut i = 0;
            while i < k {
                if rem & 1 << i != 0 {
                    if lone {
                        t.masks[n] = 1 << i;
                        n += 1;
                    }
                    let mut j = i + 1;
                    while j < k {
                        if rem & 1 << j != 0 {
                            t.masks[n] = (1 << i | 1 << j) as u8;
                            n += 1;
                        }
                        j += 1;
                    }
                }
                i += 1;
            }
            s += 1;
        }
        t.range[TABLE_START[k] + full + 1] = n as u16;
        k += 1;
    }
    t
}

/// What the DP loop of [`ChainDp::solve`] reads.
struct DpInputs<'a> {
    /// The state with every face of F carved.
    full: usize,
    /// [`TABLE_START`] of the chain length.
    first: usize,
    /// Cost of a lone-face node: every option's weight when every pair is cheap.
    c_lone: f32,
    /// Surface area of the region in each state.
    sa: &'a [f32; 64],
    /// Node cost by option mask (not written when every pair is cheap).
    weight: &'a [f32; 64],
    /// For a lone-face option mask: the faces whose pair node is no dearer.
    cheap_partner: &'a [u8; 64],
    /// `C_tri · n` of the leaf below when the chain may stop early (similar partitioning).
    tri_weight: Option<f32>,
}

/// Surface area of the region in every state s < 2^K − 1 (the faces `faces[i]` with bit i of
/// s carved from `region` to `target`) into `sa[s]`, and in the full state when `with_full`
/// (only a leaf's triangle cost reads it, in similar partitioning): the extents of each axis
/// for its four carve codes, the states' face masks by doubling, then x·y + y·z + z·x per
/// state, eight states at a time with AVX2 ([`Avx2::areas8`], the same bits) from three
/// faces on (the entries past the full state that a chunk of eight writes are never read).
#[inline(always)]
fn state_areas<const K: usize>(
    faces: &[usize; 6],
    region: &Aabb,
    target: &Aabb,
    with_full: bool,
    sa: &mut [f32; 64],
    avx2: Option<Avx2>,
) {
    // ext[a][c]: the region's extent on axis a with carve code c (bit 0: min face carved to
    // `target`, bit 1: max face carved).
    let mut ext = [[0f32; 4]; 3];
    for (a, e) in ext.iter_mut().enumerate() {
        let (rl, rh) = (region.min[a], region.max[a]);
        let (tl, th) = (target.min[a], target.max[a]);
        *e = [
            (rh - rl).max(0.0),
            (rh - tl).max(0.0),
            (th - rl).max(0.0),
            (th - tl).max(0.0),
        ];
    }
    let mut fm = [0u32; 64];
    for (i, &f) in faces[..K].iter().enumerate() {
        let b = 1 << i;
        for s in 0..b {
            fm[s | b] = fm[s] | 1 << f;
        }
    }
    if let Some(avx2) = avx2
        && K >= 3
    {
        for (codes, out) in fm
            .chunks_exact(8)
            .zip(sa.chunks_exact_mut(8))
            .take((1 << K) / 8)
        {
            let codes: &[u32; 8] = codes.try_into().expect("a chunk of eight");
            out.copy_from_slice(&avx2.areas8(&ext, codes));
        }
        return;
    }
    let area = |m: u32| {
        let (x, y, z) = (
            ext[0][(m & 3) as usize],
            ext[1][(m >> 2 & 3) as usize],
            ext[2][(m >> 4 & 3) as usize],
        );
        x * y + y * z + z * x
    };
    let full = (1 << K) - 1;
    for s in 0..full {
        sa[s] = area(fm[s]);
    }
    if with_full {
        sa[full] = area(fm[full]);
    }
}

impl ChainDp {
    /// A DP ready for [`ChainDp::solve`] (reused across nodes), compiled for AVX2 where
    /// the traversal's instruction level is AVX2 ([`crate::wide::cpu::SimdLevel`]).
    pub fn new() -> Self {
        Self::with_avx2(avx2_token())
    }

    /// [`ChainDp::new`] with AVX2 code when `avx2` holds the token, baseline code otherwise.
    pub fn with_avx2(avx2: Option<Avx2>) -> Self {
        ChainDp {
            avx2,
            faces: [0; 6],
            bit_of: [0; 6],
            k: 0,
            cost: [0.0; 64],
            choice: [0; 64],
            base: 0.0,
            scratch: Scratch {
                sa: [0.0; 64],
                weight: [0.0; 64],
                cheap_partner: [0; 64],
            },
        }
    }

    /// Solves the DP from `region` (the parent box) down to `target` (the child box).
    /// `leaf_tris` is `Some(n)` when the child is a leaf of `n` triangles and similar
    /// partitioning is on: the chain may then stop early, paying `C_tri · n · SA` of the
    /// looser region instead. Costs are SAH-weighted by the area of the region in which
    /// each node is tested.
    // A dispatcher only: the body is out of line once per instruction set (`solve_base`, and
    // `Avx2::vectorize`'s function for `Solve`), so that one copy serves both children
    // (inlined twice, the split choice was 45 KB of code; out of line about 17 KB and a few
    // percent faster, single-thread bench).
    #[inline(always)]
    pub fn solve(
        &mut self,
        region: &Aabb,
        target: &Aabb,
        costs: &DstCosts,
        leaf_tris: Option<u32>,
    ) {
        match self.avx2 {
            Some(avx2) => avx2.vectorize(Solve {
                avx2,
                dp: self,
                region,
                target,
                costs,
                leaf_tris,
            }),
            None => self.solve_base(region, target, costs, leaf_tris),
        }
    }

    /// [`ChainDp::solve`] in baseline code.
    #[inline(never)]
    fn solve_base(
        &mut self,
        region: &Aabb,
        target: &Aabb,
        costs: &DstCosts,
        leaf_tris: Option<u32>,
    ) {
        self.solve_with(region, target, costs, leaf_tris, None);
    }

    /// [`ChainDp::solve`]'s body, compiled into each instruction set's function (`avx2`:
    /// the token inside the AVX2 one).
    #[inline(always)]
    fn solve_with(
        &mut self,
        region: &Aabb,
        target: &Aabb,
        costs: &DstCosts,
        leaf_tris: Option<u32>,
        avx2: Option<Avx2>,
    ) {
        let dp = self;
        dp.k = 0;
        dp.bit_of = [0; 6];
        for f in 0..6 {
            if face(region, f) != face(target, f) {
                dp.faces[dp.k] = f;
                dp.bit_of[f] = 1 << dp.k;
                dp.k += 1;
            }
        }
        // Compiled once per chain length: the loops over the 2^k states unroll.
        match dp.k {
            0 => dp.fill::<0>(region, target, costs, leaf_tris, avx2),
            1 => dp.fill::<1>(region, target, costs, leaf_tris, avx2),
            2 => dp.fill::<2>(region, target, costs, leaf_tris, avx2),
            3 => dp.fill::<3>(region, target, costs, leaf_tris, avx2),
            4 => dp.fill::<4>(region, target, costs, leaf_tris, avx2),
            5 => dp.fill::<5>(region, target, costs, leaf_tris, avx2),
            _ => dp.fill::<6>(region, target, costs, leaf_tris, avx2),
        }
    }

    /// [`ChainDp::solve`] for `K` = k faces to carve.
    #[inline(always)]
    fn fill<const K: usize>(
        &mut self,
        region: &Aabb,
        target: &Aabb,
        costs: &DstCosts,
        leaf_tris: Option<u32>,
        avx2: Option<Avx2>,
    ) {
        let dp = self;
        let k = K;
        // Triangle cost of the leaf below (similar partitioning only; with identical bounds
        // the leaf's cost is the same for every choice and never matters).
        let leaf_cost = |sa: f32| leaf_tris.map(|n| costs.triangle * n as f32 * sa);
        let full = (1usize << k) - 1;
        let c_lone = costs.single_carve.min(costs.dual_carve);
        let Scratch {
            sa,
            weight,
            cheap_partner,
        } = &mut dp.scratch;
        state_areas::<K>(&dp.faces, region, target, leaf_tris.is_some(), sa, avx2);
        dp.base = leaf_cost(sa[full]).unwrap_or(0.0);
        // Option weights by option mask (one face = a lone-face node, two faces = a pair
        // node), and for each lone face the partners whose pair node costs no more than a
        // lone-face node: while such a partner remains, carving the face alone is dominated
        // (the DP cost never grows when more faces are already carved), so it is skipped.
        // Every pair is cheap exactly when both node types cost the same (then every option
        // weighs `c_lone`, and no lone option is dominated, so neither table is read).
        let pairs_cheap = costs.single_carve <= c_lone && costs.dual_carve <= c_lone;
        if !pairs_cheap {
            for i in 0..k {
                weight[1 << i] = c_lone;
                cheap_partner[1 << i] = 0;
            }
            for i in 0..k {
                for j in i + 1..k {
                    let c = if dp.faces[i] >> 1 == dp.faces[j] >> 1 {
                        costs.single_carve
                    } else {
                        costs.dual_carve
                    };
                    weight[1 << i | 1 << j] = c;
                    if c <= c_lone {
                        cheap_partner[1 << i] |= 1 << j;
                        cheap_partner[1 << j] |= 1 << i;
                    }
                }
            }
        }
        // The options of every state come from a table built at compile time, in the order
        // of the reference's loops (lone i, then pairs (i, j > i), for i ascending), so ties
        // go to the same option; the selection is branch-free.
        let inputs = DpInputs {
            full,
            first: TABLE_START[k],
            c_lone,
            sa,
            weight,
            cheap_partner,
            tri_weight: leaf_tris.map(|n| costs.triangle * n as f32),
        };
        // The full state needs no more carving.
        dp.cost[full] = 0.0;
        let out = (&mut dp.cost, &mut dp.choice, dp.base);
        match (pairs_cheap, inputs.tri_weight.is_some()) {
            (true, false) => Self::run::<true, false>(out, &inputs),
            (true, true) => Self::run::<true, true>(out, &inputs),
            (false, false) => Self::run::<false, false>(out, &inputs),
            (false, true) => Self::run::<false, true>(out, &inputs),
        }
    }

    /// The DP proper, over the states from `full - 1` down to 0, specialised on whether
    /// every pair node is no dearer than a lone-face node (`PAIRS_CHEAP`: the option table
    /// then holds no dominated lone option, so none needs the partner test) and on whether
    /// the chain may stop early above a leaf (`STOP`, similar partitioning).
    #[inline(always)]
    fn run<const PAIRS_CHEAP: bool, const STOP: bool>(
        (cost, choice, base): (&mut [f32; 64], &mut [u8; 64], f32),
        d: &DpInputs,
    ) {
        let table = if PAIRS_CHEAP {
            &OPTIONS_PAIRS_CHEAP
        } else {
            &OPTIONS
        };
        let tri_weight = d.tri_weight.unwrap_or(0.0);
        for s in (0..d.full).rev() {
            let sa = d.sa[s];
            let stop = if STOP {
                tri_weight * sa - base
            } else {
                f32::INFINITY
            };
            let (mut best_c, mut best_t) = (stop, 0u8);
            let rem = (d.full & !s) as u8;
            let (lo, hi) = (
                table.range[d.first + s] as usize,
                table.range[d.first + s + 1] as usize,
            );
            for &t in &table.masks[lo..hi] {
                let w = if PAIRS_CHEAP {
                    d.c_lone
                } else {
                    d.weight[t as usize]
                };
                let c = w * sa + cost[s | t as usize];
                let allowed = PAIRS_CHEAP || rem & d.cheap_partner[t as usize] == 0;
                let better = (c < best_c) & allowed;
                // A chain that may not stop takes its first allowed option when no cost is
                // below +∞ (costs overflowed or are NaN), so it still carves every face.
                let first = !STOP & (best_t == 0) & allowed;
                best_c = if better { c } else { best_c };
                best_t = if better | first { t } else { best_t };
            }
            cost[s] = best_c;
            choice[s] = best_t;
        }
    }

    /// The state entered when the split carves face `f` of the child (if it is one of F).
    #[inline(always)]
    fn start(&self, carved_by_split: usize) -> usize {
        // (A state bit is at most 1 << 5: the mask only spares the bounds checks of the
        // lookups by state.)
        self.bit_of[carved_by_split] as usize & 63
    }

    /// Cost of the chain when the split carves face `f`.
    #[inline(always)]
    pub fn cost(&self, carved_by_split: usize) -> f32 {
        self.cost[self.start(carved_by_split)] + self.base
    }

    /// [`ChainDp::cost`] of every face.
    #[inline(always)]
    pub fn face_costs(&self) -> [f32; 6] {
        std::array::from_fn(|f| self.cost(f))
    }

    /// The cheapest chain when the split carves face `f`, outermost node first.
    #[inline(always)]
    pub fn chain(&self, carved_by_split: usize) -> Chain {
        let full = (1usize << self.k) - 1;
        let mut chain = Chain::EMPTY;
        let mut s = self.start(carved_by_split);
        while s != full && self.choice[s & 63] != 0 {
            let t = self.choice[s & 63] as usize;
            let i = t.trailing_zeros() as usize;
            let rest = t & !(1 << i);
            let mut faces = 1u64 << self.faces[i];
            if rest != 0 {
                faces |= 1 << self.faces[rest.trailing_zeros() as usize];
            }
            chain.push(faces);
            s |= t;
        }
        chain
    }
}

/// The fast planner: [`plan_split`], each planning thread reusing two [`ChainDp`]s.
pub(super) struct FastPlanner;

impl Planner for FastPlanner {
    type Scratch = [ChainDp; 2];

    fn scratch(&self) -> [ChainDp; 2] {
        [ChainDp::new(), ChainDp::new()]
    }

    #[inline(always)]
    fn plan_split(&self, bvh: &Bvh2, n: u32, cfg: &DstConfig, dps: &mut [ChainDp; 2]) -> SplitPlan {
        plan_split(bvh, n, cfg, dps)
    }
}

/// Chooses axis and child order of the splitting node for internal BVH node `n`, whose
/// region is exactly its box: for each axis and order, the split plane carves the left
/// child's max face and the right child's min face; the rest is left to the children's
/// chains. Picks the cheapest (first in axis, then order, on ties).
/// `dps` are reused working DPs (see [`ChainDp::new`]).
fn plan_split(bvh: &Bvh2, n: u32, cfg: &DstConfig, dps: &mut [ChainDp; 2]) -> SplitPlan {
    let node = &bvh.nodes[n as usize];
    let b = node.bounds;
    let [x, y] = node.children();
    let (bx, by) = (bvh.nodes[x as usize].bounds, bvh.nodes[y as usize].bounds);
    let [dx, dy] = dps;
    dx.solve(&b, &bx, &cfg.costs, leaf_tris(bvh, x, cfg));
    dy.solve(&b, &by, &cfg.costs, leaf_tris(bvh, y, cfg));
    let (cx, cy) = (dx.face_costs(), dy.face_costs());
    let mut best = (f32::INFINITY, 0usize, false);
    for axis in 0..3 {
        for swap in [false, true] {
            let (lo, hi) = if swap { (&cy, &cx) } else { (&cx, &cy) };
            let c = lo[max_face(axis)] + hi[min_face(axis)];
            if c < best.0 {
                best = (c, axis, swap);
            }
        }
    }
    let (_, axis, swap) = best;
    let (lo, hi) = if swap { (&dy, &dx) } else { (&dx, &dy) };
    SplitPlan {
        axis,
        swap,
        left_chain: lo.chain(max_face(axis)),
        right_chain: hi.chain(min_face(axis)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dualsplit_geometry::{Pcg32, Vec3};

    /// A random child box inside `region` with each face equal to the region's with
    /// probability one half (so every chain length 0–6 occurs), sometimes flat.
    fn child(rng: &mut Pcg32, region: &Aabb) -> Aabb {
        let mut b = *region;
        for a in 0..3 {
            let (lo, hi) = (region.min[a], region.max[a]);
            let mut t = [rng.next_f32(), rng.next_f32()];
            t.sort_by(f32::total_cmp);
            if rng.below(8) == 0 {
                t[1] = t[0];
            }
            if rng.below(2) == 0 {
                b.min[a] = lo + (hi - lo) * t[0];
            }
            if rng.below(2) == 0 {
                b.max[a] = (lo + (hi - lo) * t[1]).max(b.min[a]);
            }
        }
        b
    }

    /// The AVX2 code of [`ChainDp::solve`] finds the baseline code's costs (bit for bit),
    /// choices and leaf cost in every state, under the presets' and random node costs, with
    /// and without an early stop above a leaf, for boxes up to 1e30 across (whose areas
    /// overflow to +∞).
    #[test]
    fn avx2_solve_is_the_baseline_solve() {
        let Some(avx2) = Avx2::detect() else {
            eprintln!("no AVX2 on this CPU: only the baseline code runs here");
            return;
        };
        let mut rng = Pcg32::new(0x5eed, 7);
        let (mut base, mut vec) = (ChainDp::with_avx2(None), ChainDp::with_avx2(Some(avx2)));
        let mut lengths = [0usize; 7];
        for case in 0..40_000 {
            let costs = match case % 3 {
                0 => DstConfig::hardware().costs,
                1 => DstConfig::software().costs,
                _ => DstCosts {
                    split: 1.0,
                    single_carve: rng.range_f32(0.1, 2.0),
                    dual_carve: rng.range_f32(0.1, 2.0),
                    triangle: rng.range_f32(0.1, 4.0),
                },
            };
            let scale = [1.0, 1e3, 1e19, 1e30][rng.below(4) as usize];
            let p = |rng: &mut Pcg32| rng.range_f32(-scale, scale);
            let (a, b) = (
                Vec3::new(p(&mut rng), p(&mut rng), p(&mut rng)),
                Vec3::new(p(&mut rng), p(&mut rng), p(&mut rng)),
            );
            let region = Aabb::new(a.min(b), a.max(b));
            let target = child(&mut rng, &region);
            let leaf_tris = (rng.below(2) == 0).then(|| 1 + rng.below(8));
            base.solve(&region, &target, &costs, leaf_tris);
            vec.solve(&region, &target, &costs, leaf_tris);
            assert_eq!(base.k, vec.k);
            lengths[base.k] += 1;
            let states = 1 << base.k;
            let bits = |c: &[f32; 64]| c[..states].iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let what = format!("case {case}: {region:?} → {target:?}, {costs:?}, {leaf_tris:?}");
            assert_eq!(bits(&base.cost), bits(&vec.cost), "{what}: costs");
            assert_eq!(
                base.choice[..states],
                vec.choice[..states],
                "{what}: choices"
            );
            assert_eq!(base.base.to_bits(), vec.base.to_bits(), "{what}: leaf cost");
        }
        assert!(
            lengths.iter().all(|&n| n > 0),
            "every chain length: {lengths:?}"
        );
    }
}
