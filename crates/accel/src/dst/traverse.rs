//! Software traversal of the encoded DST (the paper's DST*): the readable reference that the
//! pipeline loop is tested against (Lin et al. 2020, §3, Fig. 3). It is the one step loop
//! of the dual-split family ([`walk`]), generic over the records ([`DstRecords`]): the
//! exact DST's here, the quantized DST's in `dstq/traverse.rs`.
//!
//! Each stack entry carries its `[t_min, t_max]` (the region clip, kd-tree style). Sibling
//! regions may overlap, so traversal continues after a hit; a popped entry is discarded
//! when its `t_min` lies beyond `cull_limit(best_t)`, otherwise its `t_max` is clamped to
//! it. Plane distances use [`RayPre::plane_t`]; exit-role distances (a splitting node's
//! `t1`, a carving plane that ends the interval for this ray's signs) are widened by
//! [`dualsplit_geometry::EXIT_WIDEN`] (Ize 2013) exactly as the BVH slab test widens its far
//! planes, so a ray through a box corner is never rounded away and the DST still reaches the
//! same leaves as its BVH2. Every min/max is `f32::min/max` and every
//! cull comparison is written `!(a > b)`, so a NaN distance (ray lying in a plane) never
//! drops a child. Leaf triangles are tested on the ray's own interval `[ray.t_min, best_t]`.

use super::Dst;
use super::header::HeaderOffset;
use super::pipeline::{ReturnCode, le_or_nan};
use crate::image::{MemoryImage, RUN_END};
use crate::observer::{DstNodeKind, NodeStep, Observer};
use dualsplit_geometry::{Aabb, Hit, PrimId, Ray, RayPre, Triangle, cull_limit, widen_exit};

/// A traversal-stack entry: a node (its word index in the exact DST, its cluster and bit in
/// the quantized one) and its ray interval.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Entry<A = u32> {
    pub node: A,
    pub t_min: f32,
    pub t_max: f32,
}

const INLINE: usize = 64;

/// The traversal stack: 64 entries inline (deeper than any SAH tree in practice), spilling
/// to the heap beyond that so no tree depth can overflow it.
pub(crate) struct Stack<A = u32> {
    inline: [Entry<A>; INLINE],
    len: usize,
    spill: Vec<Entry<A>>,
}

impl<A: Copy + Default> Stack<A> {
    #[inline(always)]
    pub fn new() -> Self {
        Self {
            inline: [Entry::default(); INLINE],
            len: 0,
            spill: Vec::new(),
        }
    }
    #[inline(always)]
    pub fn push(&mut self, e: Entry<A>) {
        if self.len < INLINE {
            self.inline[self.len] = e;
        } else {
            self.spill.push(e);
        }
        self.len += 1;
    }
    #[inline(always)]
    pub fn pop(&mut self) -> Option<Entry<A>> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        if self.len < INLINE {
            Some(self.inline[self.len])
        } else {
            self.spill.pop()
        }
    }
}

/// The per-ray state shared by the software traversal and the pipeline loop: the best hit
/// so far and the pop rule.
pub(super) struct Tracer<'a> {
    pub r: RayPre,
    pub words: &'a [u32],
    pub index_base: usize,
    pub tri_base: usize,
    pub tris: &'a [Triangle],
    pub best: Option<Hit>,
    pub best_t: f32,
    pub stack: Stack,
}

/// Where a DST image's triangle runs are (the exact DST's and the quantized DST's: the same
/// index and triangle regions).
pub(crate) struct IndexRun<'a> {
    /// The node and index regions' words.
    pub words: &'a [u32],
    /// Word of index entry 0.
    pub index_base: usize,
    /// Word of triangle 0.
    pub tri_base: usize,
    /// The triangles.
    pub tris: &'a [Triangle],
}

impl IndexRun<'_> {
    /// Intersects the run starting at index entry `first` on the ray's own interval
    /// `[ray.t_min, best_t]`, keeping the closest hit by `(t, prim)` in `best` and its `t` in
    /// `best_t` (any hit: `best` is the first hit and the traversal ends), reporting the leaf
    /// step, each entry's and triangle's fetch and each test to `obs`.
    #[inline(always)]
    pub fn test<O: Observer, const ANY: bool>(
        &self,
        first: u32,
        r: &RayPre,
        best: &mut Option<Hit>,
        best_t: &mut f32,
        obs: &mut O,
    ) -> RunResult {
        let start = self.index_base + first as usize;
        let count = self.words[start..]
            .iter()
            .position(|&e| e & RUN_END != 0)
            .map_or(0, |p| p + 1);
        obs.step(NodeStep::Leaf {
            count: count as u32,
        });
        let t_lo = r.ray.t_min;
        for i in start..start + count {
            let e = self.words[i];
            let p = PrimId(e & !RUN_END);
            obs.fetch(MemoryImage::addr(i), 4);
            obs.fetch(MemoryImage::addr(self.tri_base + 9 * p.index()), 36);
            let h = self.tris[p.index()].intersect(r, t_lo, *best_t);
            obs.triangle_test(p, h.is_some());
            if let Some(h) = h {
                if ANY {
                    *best = Some(Hit::on(p, h));
                    return RunResult::Occluded;
                }
                if Hit::keep_closest(best, p, h) {
                    *best_t = h.t;
                }
            }
        }
        RunResult::Continue
    }
}

/// What intersecting a triangle run found.
pub(crate) enum RunResult {
    /// Nothing that ends the traversal.
    Continue,
    /// Any-hit mode: an accepted hit.
    Occluded,
}

/// Starts a ray of a non-empty tree: clips it to the scene box `b` (on
/// `[ray.t_min, cull_limit(ray.t_max)]`, as the BVH culls), returning the ray and the root
/// interval, or `None` when it misses the scene. Untraceable rays miss
/// (`Ray::is_traceable`), in every structure alike.
#[inline(always)]
pub(crate) fn clip(b: Aabb, ray: &Ray) -> Option<(RayPre, f32, f32)> {
    if !ray.is_traceable() {
        return None;
    }
    let r = ray.precompute();
    let (t_min, t_max) = r.slab(b.min, b.max, ray.t_min, cull_limit(ray.t_max));
    if t_min > t_max {
        return None;
    }
    Some((r, t_min, t_max))
}

impl<'a> Tracer<'a> {
    /// Starts a ray: clips it to the scene box (on `[ray.t_min, cull_limit(ray.t_max)]`, as
    /// the BVH culls), returning the root interval or `None` when it misses the scene.
    #[inline(always)]
    pub fn start(dst: &'a Dst, ray: &Ray) -> Option<(Self, f32, f32)> {
        if dst.is_empty() {
            return None;
        }
        let (r, t_min, t_max) = clip(dst.scene_box, ray)?;
        let img = &dst.image;
        Some((
            Self {
                r,
                words: &img.words,
                index_base: img.indices.start,
                tri_base: img.triangles.start,
                tris: dst.triangles(),
                best: None,
                best_t: ray.t_max,
                stack: Stack::new(),
            },
            t_min,
            t_max,
        ))
    }

    /// The node's header word and its two planes (a plain leaf has none).
    #[inline(always)]
    pub fn fetch_node<O: Observer>(&self, node: u32, obs: &mut O) -> (HeaderOffset, f32, f32) {
        let at = node as usize;
        let w = HeaderOffset::from_bits(self.words[at]);
        if w.is_plain_leaf() {
            obs.fetch(MemoryImage::addr(at), 4);
            (w, 0.0, 0.0)
        } else {
            obs.fetch(MemoryImage::addr(at), 12);
            (
                w,
                f32::from_bits(self.words[at + 1]),
                f32::from_bits(self.words[at + 2]),
            )
        }
    }

    /// Intersects the triangle run starting at index entry `first` on the ray's own interval
    /// `[ray.t_min, best_t]` (any hit: `[ray.t_min, ray.t_max]`).
    #[inline(always)]
    pub fn test_run<O: Observer, const ANY: bool>(&mut self, first: u32, obs: &mut O) -> RunResult {
        let run = IndexRun {
            words: self.words,
            index_base: self.index_base,
            tri_base: self.tri_base,
            tris: self.tris,
        };
        run.test::<O, ANY>(first, &self.r, &mut self.best, &mut self.best_t, obs)
    }

    /// Pops the next entry that can still hold a closer hit, clamping its `t_max`.
    #[inline(always)]
    pub fn pop<O: Observer>(&mut self, obs: &mut O) -> Option<Entry> {
        let limit = cull_limit(self.best_t);
        while let Some(e) = self.stack.pop() {
            obs.pop();
            if le_or_nan(e.t_min, limit) {
                return Some(Entry {
                    t_max: e.t_max.min(limit),
                    ..e
                });
            }
        }
        None
    }
}

#[inline(always)]
fn dst_step(kind: DstNodeKind, code: ReturnCode, carving_leaf: bool) -> NodeStep {
    NodeStep::Dst {
        kind,
        outcome: code.into(),
        carving_leaf,
    }
}

/// After a splitting node with near and far children `near`, `far` (by the ray's sign), `t1`
/// where the ray leaves the near child's half-space and `t2` where it enters the far one:
/// the entry to push (the far child, when both are hit) and the node to go on with and its
/// interval (`None`: pop). Shared by the observed traversal and the plain decoder.
#[inline(always)]
pub(super) fn split_next(
    near_hit: bool,
    far_hit: bool,
    (near, far): (u32, u32),
    (t1, t2): (f32, f32),
    t_min: f32,
    t_max: f32,
) -> (Option<Entry>, Option<(u32, f32, f32)>) {
    let far_entry = (far, t_min.max(t2), t_max);
    match (near_hit, far_hit) {
        (true, true) => (
            Some(Entry {
                node: far,
                t_min: far_entry.1,
                t_max,
            }),
            Some((near, t_min, t_max.min(t1))),
        ),
        (true, false) => (None, Some((near, t_min, t_max.min(t1)))),
        (false, true) => (None, Some(far_entry)),
        (false, false) => (None, None),
    }
}

/// The interval `(lo, hi)` left of `[t_min, t_max]` by a dual-axis carving node `w` whose
/// planes lie at ray parameters `ta` (first axis) and `tb` (second): a plane is an exit
/// plane iff its "lower bound" bit equals the ray's sign `neg` on its axis (Lin et al. 2020,
/// Fig. 2); exit planes are widened (`widen_exit`) and clamp `hi`, entry planes raise `lo`.
#[inline(always)]
pub(crate) fn dual_carve(
    neg: &[bool; 3],
    w: HeaderOffset,
    (ta, tb): (f32, f32),
    t_min: f32,
    t_max: f32,
) -> (f32, f32) {
    let (a0, a1) = w.axis_pair().axes();
    let c = w.corner();
    let (mut lo, mut hi) = (t_min, t_max);
    if neg[a0] == c.first_lower {
        hi = hi.min(widen_exit(ta));
    } else {
        lo = lo.max(ta);
    }
    if neg[a1] == c.second_lower {
        hi = hi.min(widen_exit(tb));
    } else {
        lo = lo.max(tb);
    }
    (lo, hi)
}

/// The node records of a DST image, as the one DST traversal ([`walk`]) reads them: the
/// exact DST's 12-byte nodes and 4-byte leaves, or the quantized DST's bit-packed records.
/// Node rules, distances and return codes are the walk's; a layout gives the header, the
/// two planes, and where the children and the run are.
pub(crate) trait DstRecords {
    /// Where a record is.
    type At: Copy + Default;
    /// A record read.
    type Rec: Copy;
    /// Reads the record at `at`, reporting its fetches.
    fn read<O: Observer>(&mut self, at: Self::At, obs: &mut O) -> Self::Rec;
    /// The record's node header in the exact DST's form (kind, axes, corner type).
    fn header(rec: Self::Rec) -> HeaderOffset;
    /// Bit L: the record ends in a triangle run.
    fn leaf_flag(rec: Self::Rec) -> bool;
    /// The planes P0 (on axis `a0`) and P1 (on axis `a1`).
    fn planes(&self, rec: Self::Rec, a0: usize, a1: usize) -> (f32, f32);
    /// A splitting node's left and right children.
    fn split_children(&self, rec: Self::Rec) -> (Self::At, Self::At);
    /// A carving node's child.
    fn child(&self, rec: Self::Rec) -> Self::At;
    /// The first index entry of a leaf's run.
    fn run(rec: Self::Rec) -> u32;
}

/// The exact DST's records: one header word, and the two plane words of an internal node.
struct ExactRecords<'a> {
    words: &'a [u32],
}

/// A record of the exact DST read: its header and its planes (zero for a plain leaf).
#[derive(Clone, Copy)]
struct ExactRec {
    w: HeaderOffset,
    p0: f32,
    p1: f32,
}

impl DstRecords for ExactRecords<'_> {
    type At = u32;
    type Rec = ExactRec;

    #[inline(always)]
    fn read<O: Observer>(&mut self, node: u32, obs: &mut O) -> ExactRec {
        let at = node as usize;
        let w = HeaderOffset::from_bits(self.words[at]);
        if w.is_plain_leaf() {
            obs.fetch(MemoryImage::addr(at), 4);
            ExactRec {
                w,
                p0: 0.0,
                p1: 0.0,
            }
        } else {
            obs.fetch(MemoryImage::addr(at), 12);
            ExactRec {
                w,
                p0: f32::from_bits(self.words[at + 1]),
                p1: f32::from_bits(self.words[at + 2]),
            }
        }
    }
    #[inline(always)]
    fn header(rec: ExactRec) -> HeaderOffset {
        rec.w
    }
    #[inline(always)]
    fn leaf_flag(rec: ExactRec) -> bool {
        rec.w.is_leaf_flag()
    }
    #[inline(always)]
    fn planes(&self, rec: ExactRec, _: usize, _: usize) -> (f32, f32) {
        (rec.p0, rec.p1)
    }
    #[inline(always)]
    fn split_children(&self, rec: ExactRec) -> (u32, u32) {
        let left = rec.w.offset();
        (left, left + rec.w.left_size())
    }
    #[inline(always)]
    fn child(&self, rec: ExactRec) -> u32 {
        rec.w.offset()
    }
    #[inline(always)]
    fn run(rec: ExactRec) -> u32 {
        rec.w.offset()
    }
}

/// The one DST traversal (the exact DST's and the quantized DST's), from the root record
/// `root` on the clipped interval `[t_min, t_max]` of `r`: the node rules of Lin et al.
/// 2020, §3, Figs. 2–3, each step reported to `obs`, each run tested on the ray's own
/// interval `[ray.t_min, best_t]`, popped entries culled against `cull_limit(best_t)`.
#[inline(always)]
pub(crate) fn walk<R: DstRecords, O: Observer, const ANY: bool>(
    recs: &mut R,
    runs: &IndexRun<'_>,
    r: &RayPre,
    root: R::At,
    (mut t_min, mut t_max): (f32, f32),
    obs: &mut O,
) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    let mut best_t = r.ray.t_max;
    let mut stack = Stack::<R::At>::new();
    let mut node = root;
    loop {
        let rec = recs.read(node, obs);
        let w = R::header(rec);
        // `Some(run)` when the node ends in a triangle run; `None` when it pops.
        let run = match w.node_kind() {
            DstNodeKind::Leaf => {
                obs.step(dst_step(DstNodeKind::Leaf, ReturnCode::Leaf, false));
                Some(R::run(rec))
            }
            DstNodeKind::Split => {
                let a = w.axis();
                let (p0, p1) = recs.planes(rec, a, a);
                let (left, right) = recs.split_children(rec);
                // t1: where the ray leaves the near child's half-space (exit role,
                // widened); t2: where it enters the far one (Lin et al. 2020, Fig. 3).
                let (near, far, t1, t2) = if r.neg[a] {
                    (right, left, r.exit_t(a, p1), r.plane_t(a, p0))
                } else {
                    (left, right, r.exit_t(a, p0), r.plane_t(a, p1))
                };
                let near_hit = le_or_nan(t_min, t1);
                let far_hit = le_or_nan(t2, t_max);
                obs.step(dst_step(
                    DstNodeKind::Split,
                    ReturnCode::from_bits(near_hit as u8 + far_hit as u8),
                    false,
                ));
                match (near_hit, far_hit) {
                    (true, true) => {
                        stack.push(Entry {
                            node: far,
                            t_min: t_min.max(t2),
                            t_max,
                        });
                        obs.push();
                        node = near;
                        t_max = t_max.min(t1);
                        continue;
                    }
                    (true, false) => {
                        node = near;
                        t_max = t_max.min(t1);
                        continue;
                    }
                    (false, true) => {
                        node = far;
                        t_min = t_min.max(t2);
                        continue;
                    }
                    (false, false) => None,
                }
            }
            kind => {
                // Carving: exit planes clamp t_max, entry planes raise t_min.
                let (lo, hi) = if kind == DstNodeKind::SingleCarve {
                    let a = w.axis();
                    let (p0, p1) = recs.planes(rec, a, a);
                    // t1: the exit plane after the sign swap (widened); t2: entry.
                    let (t1, t2) = if r.neg[a] {
                        (r.exit_t(a, p1), r.plane_t(a, p0))
                    } else {
                        (r.exit_t(a, p0), r.plane_t(a, p1))
                    };
                    (t_min.max(t2), t_max.min(t1))
                } else {
                    let (a0, a1) = w.axis_pair().axes();
                    let (p0, p1) = recs.planes(rec, a0, a1);
                    let t = (r.plane_t(a0, p0), r.plane_t(a1, p1));
                    dual_carve(&r.neg, w, t, t_min, t_max)
                };
                let hit = le_or_nan(lo, hi);
                let leaf = R::leaf_flag(rec);
                let code = ReturnCode::from_bits(hit as u8 * (1 + 2 * leaf as u8));
                obs.step(dst_step(kind, code, leaf));
                if hit {
                    t_min = lo;
                    t_max = hi;
                    if !leaf {
                        node = recs.child(rec);
                        continue;
                    }
                    Some(R::run(rec))
                } else {
                    None
                }
            }
        };
        if let Some(first) = run
            && let RunResult::Occluded = runs.test::<O, ANY>(first, r, &mut best, &mut best_t, obs)
        {
            return best;
        }
        // Pop the next entry that can still hold a closer hit, clamping its t_max.
        let limit = cull_limit(best_t);
        loop {
            let Some(e) = stack.pop() else {
                return best;
            };
            obs.pop();
            if le_or_nan(e.t_min, limit) {
                (node, t_min, t_max) = (e.node, e.t_min, e.t_max.min(limit));
                break;
            }
        }
    }
}

impl Dst {
    /// Closest hit of `ray` (software decoder, DST*), ordered by `(t, prim)`. With an
    /// observer that observes nothing ([`Observer::OBSERVES_NOTHING`]) it runs the plain
    /// decoder of `fast.rs` (same nodes, triangles from a leaf-ordered copy); both give the
    /// same answer, bit for bit.
    pub fn closest_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        if O::OBSERVES_NOTHING {
            return self.traverse_fast::<false>(ray);
        }
        self.traverse::<O, false>(ray, obs)
    }

    /// True when `ray` hits any triangle within `[t_min, t_max]` (software decoder; the
    /// plain decoder when nothing is observed, as [`Dst::closest_hit`]).
    pub fn any_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        if O::OBSERVES_NOTHING {
            return self.traverse_fast::<true>(ray).is_some();
        }
        self.traverse::<O, true>(ray, obs).is_some()
    }

    #[inline(always)]
    fn traverse<O: Observer, const ANY: bool>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        if self.is_empty() {
            return None;
        }
        let (r, t_min, t_max) = clip(self.scene_box, ray)?;
        let img = &self.image;
        let runs = IndexRun {
            words: &img.words,
            index_base: img.indices.start,
            tri_base: img.triangles.start,
            tris: self.triangles(),
        };
        let mut recs = ExactRecords { words: &img.words };
        walk::<_, O, ANY>(&mut recs, &runs, &r, 0, (t_min, t_max), obs)
    }
}
