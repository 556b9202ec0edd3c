//! The BVH2 builder: binned SAH without triangle splitting, standing in for Embree 3's
//! high-quality builder (Lin et al. 2020, §4.2 builds every structure from one such BVH2).
//!
//! Builders see only primitive boxes and their centroids. The build is top-down:
//!
//! 1. every range is binned by centroid into [`BuildConfig::bins`] bins on each axis (the
//!    top levels bin in parallel chunks with rayon), and the bin boundary with the smallest
//!    SAH cost `A_L·n_L + A_R·n_R` is chosen; ranges of at most [`SWEEP_MAX`] primitives
//!    instead sweep every boundary between their sorted centroids (exact SAH);
//! 2. a range becomes a leaf when it holds at most [`BuildConfig::max_leaf_size`] primitives
//!    and a leaf is no more expensive than the best split;
//! 3. the two halves are built with `rayon::join` above [`BuildConfig::parallel_threshold`]
//!    primitives;
//! 4. past depth [`MAX_SAH_DEPTH`] the builder falls back to an object-median split so that
//!    adversarial inputs cannot produce an unbounded depth.
//!
//! The temporary tree is then flattened depth-first with the two children of every node
//! adjacent (`left = first`, `right = first + 1`), root at index 0.

use dualsplit_geometry::Aabb;
use glam::Vec3A;
use serde::{Deserialize, Serialize};

/// Depth after which ranges are split at the object median instead of by SAH.
pub const MAX_SAH_DEPTH: u32 = 64;

/// Build settings. Every field has a default; [`BuildConfig::high_quality`] is the preset used
/// for the paper's structures.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BuildConfig {
    /// Maximum triangles per leaf.
    pub max_leaf_size: u32,
    /// SAH cost of traversing an internal node (relative to one triangle test).
    pub cost_traversal: f32,
    /// SAH cost of one ray–triangle test.
    pub cost_triangle: f32,
    /// Number of SAH bins per axis (clamped to 2..=256).
    pub bins: u32,
    /// Ranges larger than this are built (and binned) in parallel.
    pub parallel_threshold: u32,
}

impl Default for BuildConfig {
    fn default() -> Self {
        Self::high_quality()
    }
}

impl BuildConfig {
    /// The preset standing in for Embree 3's high-quality builder: 32 bins, leaves of at most
    /// 4 triangles, traversal and intersection costs equal.
    pub fn high_quality() -> Self {
        Self {
            max_leaf_size: 4,
            cost_traversal: 1.0,
            cost_triangle: 1.0,
            bins: 32,
            parallel_threshold: 4096,
        }
    }

    /// A cheaper preset for tests and quick previews: 16 bins.
    pub fn fast() -> Self {
        Self {
            bins: 16,
            ..Self::high_quality()
        }
    }

    /// One triangle per leaf (every leaf a single triangle), useful for tests.
    pub fn single_triangle_leaves() -> Self {
        Self {
            max_leaf_size: 1,
            ..Self::high_quality()
        }
    }
}

/// A node of the logical (not yet encoded) binary BVH.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bvh2Node {
    /// Node bounds.
    pub bounds: Aabb,
    /// Leaf: first index into [`Bvh2::prim_ids`]. Internal: index of the left child.
    pub first: u32,
    /// Leaf: triangle count (> 0). Internal: 0.
    pub count: u32,
    /// Internal: index of the right child. Leaf: unused (0).
    pub right: u32,
}

impl Bvh2Node {
    /// True for a leaf.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
    /// Children of an internal node.
    #[inline]
    pub fn children(&self) -> [u32; 2] {
        [self.first, self.right]
    }
}

/// The logical binary BVH every other structure is derived from. Root at index 0.
///
/// For an empty input the root is a node with `count == 0` and empty bounds and no children
/// (`first == right == 0`); callers check [`Bvh2::is_empty`].
#[derive(Clone, Debug)]
pub struct Bvh2 {
    /// Nodes; index 0 is the root.
    pub nodes: Vec<Bvh2Node>,
    /// Triangle ids referenced by leaf ranges.
    pub prim_ids: Vec<u32>,
    /// SAH cost of the tree (root-normalised).
    pub sah_cost: f32,
}

enum Tmp {
    Leaf {
        bounds: Aabb,
        first: u32,
        count: u32,
    },
    Inner {
        bounds: Aabb,
        kids: Box<[Tmp; 2]>,
    },
}

/// A box in SIMD registers, used only inside the builder (bit-exact with [`Aabb`]: unions
/// are plain min/max).
#[derive(Clone, Copy, Debug)]
struct Box3 {
    min: Vec3A,
    max: Vec3A,
}

impl Box3 {
    const EMPTY: Box3 = Box3 {
        min: Vec3A::INFINITY,
        max: Vec3A::NEG_INFINITY,
    };
    #[inline(always)]
    fn union(self, o: Box3) -> Box3 {
        Box3 {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    #[inline(always)]
    fn grow(self, p: Vec3A) -> Box3 {
        Box3 {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }
    /// Half the surface area, 0 for an empty box (the same value as [`Aabb::half_area`]).
    #[inline(always)]
    fn half_area(self) -> f32 {
        self.aabb().half_area()
    }
    #[inline(always)]
    fn aabb(self) -> Aabb {
        Aabb::new(self.min.into(), self.max.into())
    }
}

/// A primitive reference: its box and id, moved with the partition so that every range is
/// contiguous in memory (the centroid is recomputed as `(min + max) / 2`, the same value as
/// [`Aabb::center`]).
#[derive(Clone, Copy, Debug)]
struct PrimRef {
    b: Box3,
    id: u32,
}

impl PrimRef {
    #[inline(always)]
    fn c(&self) -> Vec3A {
        (self.b.min + self.b.max) * 0.5
    }
}

struct Ctx {
    cfg: BuildConfig,
    bins: usize,
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Box3,
    cbounds: Box3,
    count: u32,
}

const EMPTY_BIN: Bin = Bin {
    bounds: Box3::EMPTY,
    cbounds: Box3::EMPTY,
    count: 0,
};

/// Ranges of at most this many primitives are split by a full SAH sweep over the sorted
/// centroids instead of by binning.
pub const SWEEP_MAX: usize = 32;

/// The chosen split of a range: SAH cost `A_L·n_L + A_R·n_R`, how to partition, and the
/// halves' (bounds, centroid bounds).
struct Split {
    cost: f32,
    how: How,
    left: (Box3, Box3),
    right: (Box3, Box3),
}

enum How {
    /// Binned: primitives whose bin on `axis` is below `bin` go left.
    Bin { axis: usize, bin: usize },
    /// Swept: the ids are already sorted on the best axis; the first `mid` go left.
    Sorted { mid: usize },
}

impl Bvh2 {
    /// Builds a BVH2 over primitive boxes (one per triangle; ids are indices).
    pub fn build(prim_bounds: &[Aabb], cfg: &BuildConfig) -> Self {
        let mut refs: Vec<PrimRef> = prim_bounds
            .iter()
            .enumerate()
            .map(|(i, b)| PrimRef {
                b: Box3 {
                    min: b.min.into(),
                    max: b.max.into(),
                },
                id: i as u32,
            })
            .collect();
        if prim_bounds.is_empty() {
            return Self {
                nodes: vec![Bvh2Node {
                    bounds: Aabb::EMPTY,
                    first: 0,
                    count: 0,
                    right: 0,
                }],
                prim_ids: Vec::new(),
                sah_cost: 0.0,
            };
        }
        let ctx = Ctx {
            cfg: *cfg,
            bins: cfg.bins.clamp(2, 256) as usize,
        };
        let (bounds, cbounds) = range_bounds(&ctx, &refs);
        let tmp = build_range(&ctx, &mut refs, 0, (bounds, cbounds), 0);
        let mut nodes =
            Vec::with_capacity(prim_bounds.len() * 2 / cfg.max_leaf_size.max(1) as usize + 1);
        nodes.push(Bvh2Node {
            bounds: Aabb::EMPTY,
            first: 0,
            count: 0,
            right: 0,
        });
        flatten(&tmp, 0, &mut nodes);
        let mut bvh = Self {
            nodes,
            prim_ids: refs.iter().map(|r| r.id).collect(),
            sah_cost: 0.0,
        };
        bvh.sah_cost = bvh.compute_sah(cfg);
        bvh
    }

    /// True when the tree holds no primitive.
    pub fn is_empty(&self) -> bool {
        self.prim_ids.is_empty()
    }

    /// Number of leaves.
    pub fn leaf_count(&self) -> usize {
        if self.is_empty() {
            return 0;
        }
        self.nodes.iter().filter(|n| n.is_leaf()).count()
    }

    /// SAH cost of the tree: Σ internal SA·c_t + Σ leaf SA·n·c_i, divided by the root SA.
    pub fn compute_sah(&self, cfg: &BuildConfig) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let root = self.nodes[0].bounds.half_area().max(f32::MIN_POSITIVE);
        let mut c = 0.0f64;
        for n in &self.nodes {
            let a = n.bounds.half_area() as f64;
            c += if n.is_leaf() {
                a * n.count as f64 * cfg.cost_triangle as f64
            } else {
                a * cfg.cost_traversal as f64
            };
        }
        (c / root as f64) as f32
    }
}

fn flatten(t: &Tmp, idx: usize, nodes: &mut Vec<Bvh2Node>) {
    match t {
        Tmp::Leaf {
            bounds,
            first,
            count,
        } => {
            nodes[idx] = Bvh2Node {
                bounds: *bounds,
                first: *first,
                count: *count,
                right: 0,
            };
        }
        Tmp::Inner { bounds, kids } => {
            let l = nodes.len();
            let placeholder = nodes[idx];
            nodes.push(placeholder);
            nodes.push(placeholder);
            nodes[idx] = Bvh2Node {
                bounds: *bounds,
                first: l as u32,
                count: 0,
                right: l as u32 + 1,
            };
            flatten(&kids[0], l, nodes);
            flatten(&kids[1], l + 1, nodes);
        }
    }
}

fn range_bounds(ctx: &Ctx, ids: &[PrimRef]) -> (Box3, Box3) {
    let f = |(b, c): (Box3, Box3), i: &PrimRef| (b.union(i.b), c.grow(i.c()));
    if ids.len() as u32 > ctx.cfg.parallel_threshold * 16 {
        use rayon::prelude::*;
        ids.par_chunks(16 * 1024)
            .map(|c| c.iter().fold((Box3::EMPTY, Box3::EMPTY), f))
            .reduce(
                || (Box3::EMPTY, Box3::EMPTY),
                |a, b| (a.0.union(b.0), a.1.union(b.1)),
            )
    } else {
        ids.iter().fold((Box3::EMPTY, Box3::EMPTY), f)
    }
}

#[inline(always)]
fn bin_of(c: f32, lo: f32, scale: f32, bins: usize) -> usize {
    // `as usize` saturates (NaN → 0), so the index is always in range.
    (((c - lo) * scale) as usize).min(bins - 1)
}

/// Bins `ids` on all three axes: `bins[axis * B + b]`.
fn bin_range(ctx: &Ctx, ids: &[PrimRef], lo: Vec3A, scale: Vec3A) -> Vec<Bin> {
    let nb = ctx.bins;
    let work = |chunk: &[PrimRef]| {
        let mut bins = vec![EMPTY_BIN; 3 * nb];
        for i in chunk {
            let c = i.c();
            let b = i.b;
            let k = ((c - lo) * scale).to_array();
            for (axis, &k) in k.iter().enumerate() {
                let bin = &mut bins[axis * nb + (k as usize).min(nb - 1)];
                bin.bounds = bin.bounds.union(b);
                bin.cbounds = bin.cbounds.grow(c);
                bin.count += 1;
            }
        }
        bins
    };
    if ids.len() as u32 > ctx.cfg.parallel_threshold * 16 {
        use rayon::prelude::*;
        ids.par_chunks(32 * 1024).map(work).reduce(
            || vec![EMPTY_BIN; 3 * nb],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(&b) {
                    x.bounds = x.bounds.union(y.bounds);
                    x.cbounds = x.cbounds.union(y.cbounds);
                    x.count += y.count;
                }
                a
            },
        )
    } else {
        work(ids)
    }
}

/// Best binned split, or `None` when every centroid coincides.
fn binned_split(ctx: &Ctx, ids: &[PrimRef], cbounds: Box3) -> Option<(Split, Vec3A, Vec3A)> {
    let nb = ctx.bins;
    let lo = cbounds.min;
    let ext = cbounds.max - cbounds.min;
    let mut scale = Vec3A::ZERO;
    for a in 0..3 {
        if ext[a] > 0.0 && ext[a].is_finite() {
            scale[a] = nb as f32 / ext[a];
        }
    }
    if scale == Vec3A::ZERO {
        return None;
    }
    let bins = bin_range(ctx, ids, lo, scale);
    let mut best: Option<Split> = None;
    let mut right_acc = vec![(Box3::EMPTY, Box3::EMPTY, 0u32); nb];
    for axis in 0..3 {
        if scale[axis] == 0.0 {
            continue;
        }
        let b = &bins[axis * nb..(axis + 1) * nb];
        let mut acc = (Box3::EMPTY, Box3::EMPTY, 0u32);
        for k in (1..nb).rev() {
            acc = (
                acc.0.union(b[k].bounds),
                acc.1.union(b[k].cbounds),
                acc.2 + b[k].count,
            );
            right_acc[k] = acc;
        }
        let mut left = (Box3::EMPTY, Box3::EMPTY, 0u32);
        for k in 0..nb - 1 {
            left = (
                left.0.union(b[k].bounds),
                left.1.union(b[k].cbounds),
                left.2 + b[k].count,
            );
            let right = right_acc[k + 1];
            if left.2 == 0 || right.2 == 0 {
                continue;
            }
            let cost = left.0.half_area() * left.2 as f32 + right.0.half_area() * right.2 as f32;
            if best.as_ref().is_none_or(|s| cost < s.cost) {
                best = Some(Split {
                    cost,
                    how: How::Bin { axis, bin: k + 1 },
                    left: (left.0, left.1),
                    right: (right.0, right.1),
                });
            }
        }
    }
    best.map(|s| (s, lo, scale))
}

/// Full SAH sweep over the centroids sorted on each axis (ties by id); leaves `ids` sorted
/// on the best axis. `None` when every centroid coincides.
fn sweep_split(ctx: &Ctx, ids: &mut [PrimRef], cbounds: Box3) -> Option<Split> {
    let n = ids.len();
    let ext = cbounds.max - cbounds.min;
    let mut right_area = [0f32; SWEEP_MAX];
    let mut best: Option<(f32, usize, usize)> = None;
    for axis in 0..3 {
        if ext[axis] <= 0.0 {
            continue;
        }
        sort_on(ids, axis);
        let mut acc = Box3::EMPTY;
        for k in (1..n).rev() {
            acc = acc.union(ids[k].b);
            right_area[k] = acc.half_area();
        }
        let mut left = Box3::EMPTY;
        for k in 0..n - 1 {
            left = left.union(ids[k].b);
            let cost = left.half_area() * (k + 1) as f32 + right_area[k + 1] * (n - k - 1) as f32;
            if best.is_none_or(|b| cost < b.0) {
                best = Some((cost, axis, k + 1));
            }
        }
    }
    let (cost, axis, mid) = best?;
    sort_on(ids, axis);
    let left = range_bounds(ctx, &ids[..mid]);
    let right = range_bounds(ctx, &ids[mid..]);
    Some(Split {
        cost,
        how: How::Sorted { mid },
        left,
        right,
    })
}

fn sort_on(ids: &mut [PrimRef], axis: usize) {
    ids.sort_unstable_by(|a, b| {
        let (ca, cb) = (a.c()[axis], b.c()[axis]);
        ca.total_cmp(&cb).then(a.id.cmp(&b.id))
    });
}

fn partition(ids: &mut [PrimRef], pred: impl Fn(&PrimRef) -> bool) -> usize {
    let mut i = 0;
    for j in 0..ids.len() {
        if pred(&ids[j]) {
            ids.swap(i, j);
            i += 1;
        }
    }
    i
}

fn build_range(
    ctx: &Ctx,
    ids: &mut [PrimRef],
    offset: u32,
    (bounds, cbounds): (Box3, Box3),
    depth: u32,
) -> Tmp {
    let n = ids.len();
    let leaf = Tmp::Leaf {
        bounds: bounds.aabb(),
        first: offset,
        count: n as u32,
    };
    if n <= 1 {
        return leaf;
    }
    let max_leaf = ctx.cfg.max_leaf_size.max(1) as usize;
    let split = if depth >= MAX_SAH_DEPTH {
        None
    } else if n <= SWEEP_MAX {
        sweep_split(ctx, ids, cbounds).map(|s| (s, Vec3A::ZERO, Vec3A::ZERO))
    } else {
        binned_split(ctx, ids, cbounds)
    };
    let (mid, lb, rb) = match split {
        Some((s, lo, scale)) => {
            let area = bounds.half_area();
            let leaf_cost = area * n as f32 * ctx.cfg.cost_triangle;
            let split_cost = area * ctx.cfg.cost_traversal + s.cost * ctx.cfg.cost_triangle;
            if n <= max_leaf && leaf_cost <= split_cost {
                return leaf;
            }
            let mid = match s.how {
                How::Sorted { mid } => mid,
                How::Bin { axis, bin } => partition(ids, |i| {
                    bin_of(i.c()[axis], lo[axis], scale[axis], ctx.bins) < bin
                }),
            };
            (mid, s.left, s.right)
        }
        None => {
            if n <= max_leaf {
                return leaf;
            }
            // All centroids coincide (or the depth limit was reached): object median on the
            // widest centroid axis, ties broken by id, so the result is deterministic.
            let axis = cbounds.aabb().largest_axis();
            let mid = n / 2;
            ids.select_nth_unstable_by(mid, |a, b| {
                let (ca, cb) = (a.c()[axis], b.c()[axis]);
                ca.total_cmp(&cb).then(a.id.cmp(&b.id))
            });
            (
                mid,
                range_bounds(ctx, &ids[..mid]),
                range_bounds(ctx, &ids[mid..]),
            )
        }
    };
    let (l, r) = ids.split_at_mut(mid);
    let (left, right) = if n as u32 > ctx.cfg.parallel_threshold {
        rayon::join(
            || build_range(ctx, l, offset, lb, depth + 1),
            || build_range(ctx, r, offset + mid as u32, rb, depth + 1),
        )
    } else {
        (
            build_range(ctx, l, offset, lb, depth + 1),
            build_range(ctx, r, offset + mid as u32, rb, depth + 1),
        )
    };
    Tmp::Inner {
        bounds: bounds.aabb(),
        kids: Box::new([left, right]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dualsplit_geometry::{Pcg32, Vec3};

    fn random_boxes(n: usize, seed: u64) -> Vec<Aabb> {
        let mut rng = Pcg32::new(seed, 1);
        (0..n)
            .map(|_| {
                let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
                let e = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 0.3;
                Aabb::new(p, p + e)
            })
            .collect()
    }

    fn check(bvh: &Bvh2, boxes: &[Aabb], max_leaf: u32) {
        let mut seen = vec![0u32; boxes.len()];
        let mut stack = vec![0usize];
        let mut reached = 0;
        while let Some(i) = stack.pop() {
            reached += 1;
            let n = bvh.nodes[i];
            if n.is_leaf() {
                assert!(n.count <= max_leaf);
                for &p in &bvh.prim_ids[n.first as usize..(n.first + n.count) as usize] {
                    seen[p as usize] += 1;
                    assert!(n.bounds.contains_box(&boxes[p as usize]));
                }
            } else {
                for c in n.children() {
                    assert!(n.bounds.contains_box(&bvh.nodes[c as usize].bounds));
                    stack.push(c as usize);
                }
                assert_eq!(n.right, n.first + 1, "siblings adjacent");
            }
        }
        assert_eq!(reached, bvh.nodes.len());
        assert!(seen.iter().all(|&s| s == 1));
    }

    #[test]
    fn builds_valid_trees() {
        for (n, seed) in [(1, 1), (2, 2), (5, 3), (100, 4), (20_000, 5)] {
            let boxes = random_boxes(n, seed);
            let bvh = Bvh2::build(&boxes, &BuildConfig::default());
            check(&bvh, &boxes, 4);
            assert!(bvh.sah_cost >= 1.0 || n == 1);
        }
    }

    #[test]
    fn coincident_centroids_split_at_median() {
        let boxes = vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 37];
        let bvh = Bvh2::build(&boxes, &BuildConfig::default());
        check(&bvh, &boxes, 4);
    }

    #[test]
    fn empty_input_gives_empty_root() {
        let bvh = Bvh2::build(&[], &BuildConfig::default());
        assert!(bvh.is_empty());
        assert_eq!(bvh.nodes.len(), 1);
        assert!(!bvh.nodes[0].is_leaf());
    }

    #[test]
    fn build_is_deterministic() {
        let boxes = random_boxes(30_000, 9);
        let a = Bvh2::build(&boxes, &BuildConfig::default());
        let b = Bvh2::build(&boxes, &BuildConfig::default());
        assert_eq!(a.nodes, b.nodes);
        assert_eq!(a.prim_ids, b.prim_ids);
    }
}
