//! The 80-byte compressed BVH8 node (Ylitie, Karras and Laine 2017, §3.1, Fig. 2) and the
//! conservative quantization of its child boxes.

use dualsplit_geometry::Aabb;

/// Node size in 32-bit words.
pub const NODE_WORDS: usize = 20;

/// Largest leaf-run offset from a node's triangle base (5 bits of a meta byte).
pub const LEAF_OFFSET_LIMIT: u32 = 31;

/// Meta byte of an empty slot.
pub const META_EMPTY: u8 = 0;

/// High 3 bits of an internal slot's meta byte (Ylitie's `0b001`, with `24 + k` below).
const META_INTERNAL_TAG: u8 = 0b001_00000;

/// `q_lo` and `q_hi` of an empty slot on every axis: a decoded box with `lo > hi` whenever
/// the scale is positive. Traversal never decodes it (the meta byte says the slot is empty);
/// it only makes the bytes of an empty slot one fixed value that validation checks.
pub const EMPTY_Q: (u8, u8) = (0xff, 0x00);

/// A compressed BVH8 internal node: quantization frame, child addressing and eight 8-bit
/// quantized child boxes, 80 bytes (Ylitie, Karras and Laine 2017, Fig. 2).
///
/// | bytes | field |
/// |---|---|
/// | 0–11 | `p`: the quantization origin, 3 × f32 (the union of the child boxes' minimum) |
/// | 12–14 | `e`: one u8 exponent per axis; `scale[a] = 2^(e[a] − 127)`, the f32 whose exponent field is `e[a]` (1 ≤ `e[a]` ≤ 254) |
/// | 15 | `imask`: bit `k` set ⇔ slot `k` is an internal node |
/// | 16–19 | `child_base`: absolute word index of the first internal child; the internal children follow one another in slot order, 20 words each |
/// | 20–23 | `triangle_base`: absolute word index (index region) of the node's first leaf run; its leaf runs follow from there |
/// | 24–31 | `meta[8]`: [`Meta`] byte per slot: `0x00` empty; internal `0b001_00000 \| (24 + k)`; leaf: high 3 bits the unary count `min(n, 3)` (`0b001`, `0b011`, `0b111`), low 5 bits the run's offset from `triangle_base` in words |
/// | 32–55 | `q_lo[3][8]`: quantized child minimum, axis by axis, slot by slot |
/// | 56–79 | `q_hi[3][8]`: quantized child maximum |
///
/// Decoding (the only arithmetic traversal and validation use): `lo = p + q_lo · scale`,
/// `hi = p + q_hi · scale` in f32; `q · scale` is exact, the addition rounds once. The
/// encoder picks each `q` so that the decoded box contains the exact child box
/// ([`quantize_axis`]). An axis on which some child bound is not finite gets `p = NaN`:
/// every decoded plane on it is NaN, which the slab test ignores (an unbounded slab).
/// Empty slots hold `q_lo = 0xff`, `q_hi = 0x00` ([`EMPTY_Q`]).
///
/// Worked example (x axis; y and z alike): children `[0, 1]`, `[0.5, 3]`, `[2.25, 2.5]`
/// → `p.x = 0`, extent 3, `3 / 255 ≈ 0.0118` → `scale.x = 2^-6 = 0.015625`, `e.x = 121`;
/// `q_lo = [0, 32, 144]` (exact), `q_hi = [64, 192, 160]` (exact). Child `[0.1, 0.2]`
/// instead: `q_lo = ⌊0.1 / 2^-6⌋ = 6` (0.09375), `q_hi = ⌈0.2 / 2^-6⌉ = 13` (0.203125).
/// Slots `[internal, leaf(2 triangles), internal, leaf(5), empty × 4]`, child base 20,
/// triangle base 140: `imask = 0b0101`; slot 0's node at word 20, slot 2's at word 40;
/// `meta = [0x38, 0x60, 0x3a, 0xe2, 0, 0, 0, 0]` (slot 1's run at word 140, slot 3's at
/// 142).
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct CwNode {
    /// Quantization origin.
    pub p: [f32; 3],
    /// Biased exponents of the per-axis scales.
    pub e: [u8; 3],
    /// Internal-slot mask.
    pub imask: u8,
    /// Word index of the first internal child node.
    pub child_base: u32,
    /// Word index of the first leaf run.
    pub triangle_base: u32,
    /// Per-slot meta bytes ([`Meta`]).
    pub meta: [u8; 8],
    /// Quantized minima, `q_lo[axis][slot]`.
    pub q_lo: [[u8; 8]; 3],
    /// Quantized maxima, `q_hi[axis][slot]`.
    pub q_hi: [[u8; 8]; 3],
}

const _: () = assert!(size_of::<CwNode>() == 80);
const _: () = assert!(size_of::<CwNode>() == 4 * NODE_WORDS);

/// What one slot's meta byte (with the node's `imask`) says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Meta {
    /// No child.
    Empty,
    /// An internal child: the node at `child_base + 20 · (internal slots before it)`.
    Internal,
    /// A leaf child: its run starts `offset` words after `triangle_base`; `count_hint` is
    /// `min(n, 3)` for `n` triangles (the run itself ends at its `RUN_END` entry).
    Leaf {
        /// Words from the node's triangle base.
        offset: u32,
        /// `min(n, 3)`.
        count_hint: u32,
    },
}

impl Meta {
    /// The meta byte of slot `k`.
    pub fn byte(self, k: usize) -> u8 {
        match self {
            Meta::Empty => META_EMPTY,
            Meta::Internal => META_INTERNAL_TAG | (24 + k as u8),
            Meta::Leaf { offset, count_hint } => {
                debug_assert!(offset <= LEAF_OFFSET_LIMIT && (1..=3).contains(&count_hint));
                let unary = (1u8 << count_hint) - 1;
                (unary << 5) | offset as u8
            }
        }
    }

    /// The meta byte of a leaf of `n ≥ 1` triangles whose run is `offset` words after the
    /// triangle base.
    pub fn leaf(offset: u32, n: u32) -> Meta {
        Meta::Leaf {
            offset,
            count_hint: n.min(3),
        }
    }
}

/// One axis of a node's quantization frame: `lo = p + q · scale`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisFrame {
    /// Origin.
    pub p: f32,
    /// Biased exponent (1..=254).
    pub e: u8,
}

impl AxisFrame {
    /// `2^(e − 127)`.
    #[inline(always)]
    pub fn scale(self) -> f32 {
        scale_of(self.e)
    }
    /// The decoded plane of quantized value `q`.
    #[inline(always)]
    pub fn decode(self, q: u8) -> f32 {
        decode(self.p, self.scale(), q)
    }
}

/// The f32 whose exponent field is `e` (mantissa zero): `2^(e − 127)` for `1 ≤ e ≤ 254`.
#[inline(always)]
pub fn scale_of(e: u8) -> f32 {
    f32::from_bits((e as u32) << 23)
}

/// The decode arithmetic: `p + q · scale` in f32 (the product is exact).
#[inline(always)]
pub fn decode(p: f32, scale: f32, q: u8) -> f32 {
    p + q as f32 * scale
}

impl CwNode {
    /// A node with every slot empty.
    pub fn empty(child_base: u32, triangle_base: u32) -> Self {
        CwNode {
            p: [0.0; 3],
            e: [127; 3],
            imask: 0,
            child_base,
            triangle_base,
            meta: [META_EMPTY; 8],
            q_lo: [[EMPTY_Q.0; 8]; 3],
            q_hi: [[EMPTY_Q.1; 8]; 3],
        }
    }

    /// Encodes a node: slot `k` holds `children[k]` (at most 8; the rest empty), boxes
    /// quantized conservatively ([`quantize_axis`]).
    pub fn encode(children: &[(Aabb, Meta)], child_base: u32, triangle_base: u32) -> Self {
        assert!(children.len() <= 8, "a BVH8 node has at most 8 children");
        let mut n = CwNode::empty(child_base, triangle_base);
        for (k, &(_, m)) in children.iter().enumerate() {
            debug_assert!(m != Meta::Empty, "children are non-empty slots");
            n.meta[k] = m.byte(k);
            if m == Meta::Internal {
                n.imask |= 1 << k;
            }
        }
        for a in 0..3 {
            let bounds: Vec<(f32, f32)> =
                children.iter().map(|(b, _)| (b.min[a], b.max[a])).collect();
            let q = quantize_axis(&bounds);
            n.p[a] = q.frame.p;
            n.e[a] = q.frame.e;
            for (k, &(lo, hi)) in q.q.iter().enumerate() {
                n.q_lo[a][k] = lo;
                n.q_hi[a][k] = hi;
            }
        }
        n
    }

    /// Reads the node at word `at` of `words`.
    #[inline(always)]
    pub fn read(words: &[u32], at: usize) -> &CwNode {
        &bytemuck::cast_slice(&words[at..at + NODE_WORDS])[0]
    }

    /// The node as its 20 words.
    pub fn to_words(&self) -> [u32; NODE_WORDS] {
        bytemuck::cast(*self)
    }

    /// What slot `k` holds.
    #[inline(always)]
    pub fn slot(&self, k: usize) -> Meta {
        let m = self.meta[k];
        if self.imask & (1 << k) != 0 {
            Meta::Internal
        } else if m == META_EMPTY {
            Meta::Empty
        } else {
            Meta::Leaf {
                offset: (m & 0x1f) as u32,
                count_hint: (m >> 5).count_ones(),
            }
        }
    }

    /// Word index of slot `k`'s child node (slot `k` internal).
    #[inline(always)]
    pub fn child_node(&self, k: usize) -> u32 {
        let before = (self.imask as u32 & ((1u32 << k) - 1)).count_ones();
        self.child_base.wrapping_add(before * NODE_WORDS as u32)
    }

    /// Word index of the run of a leaf at `offset` words from the triangle base.
    #[inline(always)]
    pub fn leaf_run(&self, offset: u32) -> u32 {
        self.triangle_base.wrapping_add(offset)
    }

    /// Axis `a`'s quantization frame.
    #[inline(always)]
    pub fn frame(&self, a: usize) -> AxisFrame {
        AxisFrame {
            p: self.p[a],
            e: self.e[a],
        }
    }

    /// Slot `k`'s decoded box as six words (min.xyz, max.xyz), the words the slab test reads.
    #[inline(always)]
    pub fn box_words(&self, k: usize) -> [f32; 6] {
        let s = [
            scale_of(self.e[0]),
            scale_of(self.e[1]),
            scale_of(self.e[2]),
        ];
        [
            decode(self.p[0], s[0], self.q_lo[0][k]),
            decode(self.p[1], s[1], self.q_lo[1][k]),
            decode(self.p[2], s[2], self.q_lo[2][k]),
            decode(self.p[0], s[0], self.q_hi[0][k]),
            decode(self.p[1], s[1], self.q_hi[1][k]),
            decode(self.p[2], s[2], self.q_hi[2][k]),
        ]
    }

    /// Slot `k`'s decoded box.
    pub fn child_bounds(&self, k: usize) -> Aabb {
        crate::image::words_box(&self.box_words(k))
    }
}

/// One axis quantized: the frame and `(q_lo, q_hi)` per child.
#[derive(Clone, Debug, PartialEq)]
pub struct QuantizedAxis {
    /// Origin and exponent.
    pub frame: AxisFrame,
    /// Per child, in input order.
    pub q: Vec<(u8, u8)>,
}

/// Smallest and largest exponent of a scale (`2^-126`, `2^127`).
const EXP_MIN: i32 = -126;
const EXP_MAX: i32 = 127;

/// Quantizes one axis of a node's child intervals `[lo, hi]` conservatively: with
/// `p = min lo`, the smallest scale `2^x` (`−126 ≤ x ≤ 127`) for which every child fits
/// 0..=255, and per child the largest `q_lo` whose decoded plane `p + q_lo · 2^x` is
/// `≤ lo` and the smallest `q_hi` whose decoded plane is `≥ hi`, both checked with the
/// decode arithmetic itself (the f64 estimate only picks where to start).
///
/// Always succeeds for finite input: `q_lo = 0` decodes to `p ≤ lo`; `x = 127` makes
/// `255 · scale` overflow to `+∞`, which contains any `hi`. When some bound is not finite
/// the axis gets `p = NaN` (every decoded plane NaN: the slab test ignores the axis, an
/// unbounded slab) with `q_lo = 0`, `q_hi = 255`.
pub fn quantize_axis(bounds: &[(f32, f32)]) -> QuantizedAxis {
    if bounds.is_empty() {
        return QuantizedAxis {
            frame: AxisFrame { p: 0.0, e: 127 },
            q: Vec::new(),
        };
    }
    if bounds
        .iter()
        .any(|&(lo, hi)| !lo.is_finite() || !hi.is_finite())
    {
        return QuantizedAxis {
            frame: AxisFrame {
                p: f32::NAN,
                e: 127,
            },
            q: vec![(0, 255); bounds.len()],
        };
    }
    let p = bounds.iter().map(|b| b.0).fold(f32::INFINITY, f32::min);
    let top = bounds.iter().map(|b| b.1).fold(f32::NEG_INFINITY, f32::max);
    let extent = top as f64 - p as f64;
    let guess = if extent > 0.0 {
        ((extent / 255.0).log2().ceil() as i32).clamp(EXP_MIN, EXP_MAX)
    } else {
        EXP_MIN
    };
    // The f64 guess may be one off either way; the decode checks decide.
    for x in (guess - 1).max(EXP_MIN)..=EXP_MAX {
        let frame = AxisFrame {
            p,
            e: (x + 127) as u8,
        };
        if let Some(q) = bounds
            .iter()
            .map(|&(lo, hi)| quantize_interval(frame, lo, hi))
            .collect::<Option<Vec<_>>>()
        {
            return QuantizedAxis { frame, q };
        }
    }
    unreachable!("a scale of 2^127 holds every finite interval above p")
}

/// `(q_lo, q_hi)` of `[lo, hi]` in `frame` (see [`quantize_axis`]), or `None` when `hi`
/// lies beyond `p + 255 · scale`.
fn quantize_interval(frame: AxisFrame, lo: f32, hi: f32) -> Option<(u8, u8)> {
    let s = frame.scale() as f64;
    let est = |v: f32| ((v as f64 - frame.p as f64) / s).clamp(0.0, 255.0);
    let mut q_lo = est(lo).floor() as u8;
    while q_lo > 0 && frame.decode(q_lo) > lo {
        q_lo -= 1;
    }
    while q_lo < 255 && frame.decode(q_lo + 1) <= lo {
        q_lo += 1;
    }
    let mut q_hi = est(hi).ceil() as u8;
    while q_hi < 255 && frame.decode(q_hi) < hi {
        q_hi += 1;
    }
    if frame.decode(q_hi) < hi {
        return None;
    }
    while q_hi > 0 && frame.decode(q_hi - 1) >= hi {
        q_hi -= 1;
    }
    // `lo ≤ hi` gives `q_lo ≤ q_hi`; a `q_lo` pushed past an inverted input is clipped.
    Some((q_lo.min(q_hi), q_hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use proptest::prelude::*;

    fn b(lo: f32, hi: f32) -> Aabb {
        Aabb::new(Vec3::splat(lo), Vec3::splat(hi))
    }

    #[test]
    fn worked_example() {
        let q = quantize_axis(&[(0.0, 1.0), (0.5, 3.0), (2.25, 2.5)]);
        assert_eq!(q.frame, AxisFrame { p: 0.0, e: 121 });
        assert_eq!(q.frame.scale(), 0.015625);
        assert_eq!(q.q, vec![(0, 64), (32, 192), (144, 160)]);
        let q = quantize_axis(&[(0.0, 1.0), (0.5, 3.0), (0.1, 0.2)]);
        assert_eq!(q.q[2], (6, 13));
        let ch = [
            (b(0.0, 1.0), Meta::Internal),
            (b(0.0, 1.0), Meta::leaf(0, 2)),
            (b(0.0, 3.0), Meta::Internal),
            (b(0.0, 1.0), Meta::leaf(2, 5)),
        ];
        let n = CwNode::encode(&ch, 20, 140);
        assert_eq!(n.imask, 0b0101);
        assert_eq!(n.meta, [0x38, 0x60, 0x3a, 0xe2, 0, 0, 0, 0]);
        assert_eq!((n.child_node(0), n.child_node(2)), (20, 40));
        assert_eq!(
            n.slot(3),
            Meta::Leaf {
                offset: 2,
                count_hint: 3
            }
        );
        assert_eq!(n.leaf_run(2), 142);
        assert_eq!(n.slot(4), Meta::Empty);
    }

    /// Far from the origin the scale (4) is below the ulp (8): the decode check, not the
    /// f64 quotient, picks the bytes (docs/cwbvh-encoding.md, §4).
    #[test]
    fn rounding_example() {
        let iv = [
            (1e8, 100_000_504.0),
            (100_000_496.0, 100_000_512.0),
            (1e8, 100_001_000.0),
        ];
        let q = quantize_axis(&iv);
        assert_eq!(q.frame, AxisFrame { p: 1e8, e: 129 });
        // `1e8 + 4` rounds (tie to even) to `1e8`: `q_lo = 1` is the largest still below.
        assert_eq!(q.q, vec![(1, 126), (125, 127), (1, 250)]);
        assert_eq!(q.frame.decode(1), 1e8);
        assert_eq!(q.frame.decode(125), 100_000_496.0);
        assert_eq!(q.frame.decode(127), 100_000_512.0);
        assert_eq!(q.frame.decode(249), 100_000_992.0);
    }

    #[test]
    fn leaf_meta_bytes() {
        assert_eq!(Meta::leaf(0, 1).byte(0), 0b001_00000);
        assert_eq!(Meta::leaf(31, 2).byte(0), 0b011_11111);
        assert_eq!(Meta::leaf(5, 40).byte(0), 0b111_00101);
        assert_eq!(Meta::Internal.byte(7), 0b001_11111);
    }

    /// A coordinate from anywhere in ±2^60 (any exponent, subnormals and zero included),
    /// a value near a power of two, or an ordinary one.
    fn coordinate() -> impl Strategy<Value = f32> {
        prop_oneof![
            (any::<bool>(), 0u32..187, 0u32..1 << 23)
                .prop_map(|(neg, e, m)| f32::from_bits(u32::from(neg) << 31 | e << 23 | m)),
            (-60i32..60, -2i32..=2)
                .prop_map(|(x, d)| f32::from_bits(((2f32.powi(x)).to_bits() as i32 + d) as u32)),
            -4.0f32..4.0,
            Just(0.0f32),
            Just(-0.0f32),
        ]
    }

    /// A child interval: two coordinates, or a flat one, or one offset from a far corner
    /// by a small or large extent.
    fn interval() -> impl Strategy<Value = (f32, f32)> {
        prop_oneof![
            (coordinate(), coordinate()).prop_map(|(a, b)| (a.min(b), a.max(b))),
            coordinate().prop_map(|a| (a, a)),
            (coordinate(), 0f32..1e3).prop_map(|(a, d)| (a, a + d)),
            (-1.0e18f32..1.0e18, 0f32..1.0).prop_map(|(a, d)| (a, a + d)),
        ]
    }

    /// Children intervals, all near one far point sometimes (a small node far from the
    /// origin, where quantization steps are coarser than a child).
    fn node_intervals() -> impl Strategy<Value = Vec<(f32, f32)>> {
        prop_oneof![
            prop::collection::vec(interval(), 1..=8),
            (
                coordinate(),
                prop::collection::vec((0f32..4.0, 0f32..4.0), 1..=8)
            )
                .prop_map(|(c, v)| v.into_iter().map(|(a, d)| (c + a, c + a + d)).collect()),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 4096, ..ProptestConfig::default() })]

        /// Fails when a decoded interval does not contain its exact interval.
        #[test]
        fn quantized_boxes_contain_exact_boxes(iv in node_intervals()) {
            let q = quantize_axis(&iv);
            prop_assert!((1..=254).contains(&q.frame.e));
            for (&(lo, hi), &(ql, qh)) in iv.iter().zip(&q.q) {
                let (dl, dh) = (q.frame.decode(ql), q.frame.decode(qh));
                prop_assert!(dl <= lo && hi <= dh, "[{lo}, {hi}] in [{dl}, {dh}] {q:?}");
                prop_assert!(ql <= qh);
                // Tightest: one step in would lose the bound (or pass `q_hi`).
                prop_assert!(ql == qh || q.frame.decode(ql + 1) > lo);
                prop_assert!(qh == 0 || q.frame.decode(qh - 1) < hi);
            }
            // The smallest exponent: one below it, some child no longer fits.
            if q.frame.e > 1 {
                let lower = AxisFrame { p: q.frame.p, e: q.frame.e - 1 };
                prop_assert!(iv.iter().any(|&(lo, hi)| quantize_interval(lower, lo, hi).is_none()));
            }
        }

        /// Nodes of random children: encode, read back from words, same slots, boxes that
        /// contain the children's.
        #[test]
        fn encode_decode_roundtrip(
            iv in prop::collection::vec((interval(), interval(), interval(), 0u32..3, 1u32..6), 0..=8),
            child_base in any::<u32>(),
            triangle_base in any::<u32>(),
        ) {
            let children: Vec<(Aabb, Meta)> = iv
                .iter()
                .enumerate()
                .map(|(k, &(x, y, z, kind, n))| {
                    let bx = Aabb::new(Vec3::new(x.0, y.0, z.0), Vec3::new(x.1, y.1, z.1));
                    let m = if kind == 0 { Meta::Internal } else { Meta::leaf(3 * k as u32, n) };
                    (bx, m)
                })
                .collect();
            let n = CwNode::encode(&children, child_base, triangle_base);
            let words = n.to_words();
            let back = CwNode::read(&words, 0);
            prop_assert_eq!(back, &n);
            let mut internal = 0u32;
            for k in 0..8 {
                match children.get(k) {
                    Some(&(bx, m)) => {
                        prop_assert_eq!(back.slot(k), m);
                        prop_assert!(back.child_bounds(k).contains_box(&bx));
                        if m == Meta::Internal {
                            prop_assert_eq!(back.child_node(k), child_base.wrapping_add(20 * internal));
                            internal += 1;
                        }
                    }
                    None => {
                        prop_assert_eq!(back.slot(k), Meta::Empty);
                        prop_assert_eq!(back.meta[k], 0);
                    }
                }
            }
        }
    }

    #[test]
    fn degenerate_and_non_finite_axes() {
        // A flat axis: every plane decodes to p exactly.
        let q = quantize_axis(&[(5.0, 5.0), (5.0, 5.0)]);
        assert_eq!((q.frame.p, q.q[0]), (5.0, (0, 0)));
        // Subnormals.
        let tiny = f32::from_bits(3);
        let q = quantize_axis(&[(0.0, tiny), (tiny, tiny)]);
        assert_eq!(q.frame.e, 1);
        assert!(q.frame.decode(q.q[1].0) <= tiny && q.frame.decode(q.q[1].1) >= tiny);
        // A 2^60-wide axis far from the origin, and the whole f32 range.
        let big = 2f32.powi(60);
        for iv in [
            [(-big, -big + 1.0), (big - 3.0, big)],
            [(-f32::MAX, 0.0), (1.0, f32::MAX)],
        ] {
            let q = quantize_axis(&iv);
            for (&(lo, hi), &(ql, qh)) in iv.iter().zip(&q.q) {
                assert!(
                    q.frame.decode(ql) <= lo && q.frame.decode(qh) >= hi,
                    "{q:?}"
                );
            }
        }
        let q = quantize_axis(&[(0.0, 1.0), (f32::NAN, 2.0)]);
        assert!(q.frame.p.is_nan() && q.frame.decode(0).is_nan());
    }
}
