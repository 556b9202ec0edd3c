//! A cluster's frame and the k-bit plane offsets quantized in it (`docs/dstq-encoding.md`,
//! §2 and §4).
//!
//! A frame holds, per axis `a`, an origin `p_a` (f32) and an 8-bit exponent `e_a`; the
//! scale is `s_a = 2^(e_a − 127)` (as in the compressed wide BVH of Ylitie et al. 2017).
//! A plane stored as the unsigned k-bit offset `q` decodes to
//!
//! ```text
//! plane = p_a + (q as f32) · s_a        (q · s_a exact: q < 2^16, s_a a power of two;
//!                                        one rounding, in the add)
//! ```
//!
//! `decode` is monotone non-decreasing in `q` (a product by a positive power of two and a
//! correctly rounded add are both monotone), so the conservative offsets are found by a
//! binary search over `q` against the very f32 expression the traversal evaluates:
//! [`quantize_up`] gives the smallest `q` whose plane is `≥ x` ("≤" planes, upper bounds),
//! [`quantize_down`] the largest `q` whose plane is `≤ x` ("≥" planes, lower bounds).

/// Exponent bias of the scale: `s = 2^(e − 127)`.
pub const EXP_BIAS: i32 = 127;

/// The scale `2^(e − 127)` of exponent byte `e`: a normal f32 for `e ≥ 1`, the subnormal
/// `2^−127` for `e = 0`.
#[inline(always)]
pub fn scale(e: u8) -> f32 {
    if e == 0 {
        f32::from_bits(1 << 22)
    } else {
        f32::from_bits((e as u32) << 23)
    }
}

/// The plane that offset `q` stands for on an axis with origin `origin` and exponent `e`:
/// `origin + q · 2^(e − 127)` in f32 (the traversal's expression, bit for bit).
#[inline(always)]
pub fn decode(origin: f32, e: u8, q: u32) -> f32 {
    origin + q as f32 * scale(e)
}

/// Largest offset of `bits`-bit planes: `2^bits − 1`.
#[inline(always)]
pub fn q_max(bits: u32) -> u32 {
    ((1u64 << bits) - 1) as u32
}

/// The smallest exponent byte `e` whose top offset reaches `hi`: `decode(lo, e, q_max) ≥ hi`.
/// Every offset then decodes inside `[lo, decode(lo, e, q_max)]`, a span that covers the
/// frame `[lo, hi]`. A flat axis (`hi ≤ lo`) gets `e = 0`. Always succeeds for finite `lo`:
/// at `e = 254` the top offset overflows to `+∞`.
pub fn choose_exponent(lo: f32, hi: f32, bits: u32) -> u8 {
    let qm = q_max(bits);
    let ext = hi as f64 - lo as f64;
    // Start a little below the estimate (log2(ext / q_max)) and step up: the first exponent
    // that reaches `hi` under f32 rounding is the answer.
    let mut e: i32 = if ext > 0.0 {
        ((ext / qm as f64).log2().floor() as i32 + EXP_BIAS - 2).clamp(0, 254)
    } else {
        0
    };
    // `decode < hi` or NaN: not there yet.
    while e < 254 && !reaches_up(decode(lo, e as u8, qm), hi) {
        e += 1;
    }
    e as u8
}

/// `p ≥ x` (false when either is NaN).
#[inline(always)]
fn reaches_up(p: f32, x: f32) -> bool {
    matches!(
        p.partial_cmp(&x),
        Some(std::cmp::Ordering::Greater | std::cmp::Ordering::Equal)
    )
}

/// `p ≤ x` (false when either is NaN).
#[inline(always)]
fn reaches_down(p: f32, x: f32) -> bool {
    matches!(
        p.partial_cmp(&x),
        Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
    )
}

/// The smallest `q ∈ [0, q_max]` with `decode(origin, e, q) ≥ x`: an upper-bound ("≤")
/// plane rounded up. When no offset reaches `x` (x beyond the frame, `+∞`, NaN) it returns
/// `q_max`, whose plane is at or above the frame's top (see [`choose_exponent`]).
pub fn quantize_up(x: f32, origin: f32, e: u8, bits: u32) -> u32 {
    let (mut lo, mut hi) = (0u32, q_max(bits));
    if !reaches_up(decode(origin, e, hi), x) {
        return hi;
    }
    // Invariant: decode(hi) >= x; answer in [lo, hi].
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if decode(origin, e, mid) >= x {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    hi
}

/// The largest `q ∈ [0, q_max]` with `decode(origin, e, q) ≤ x`: a lower-bound ("≥") plane
/// rounded down. When no offset is that low (x below the frame, `−∞`, NaN) it returns 0,
/// whose plane is the frame's origin, its bottom.
pub fn quantize_down(x: f32, origin: f32, e: u8, bits: u32) -> u32 {
    let (mut lo, mut hi) = (0u32, q_max(bits));
    if !reaches_down(decode(origin, e, lo), x) {
        return 0;
    }
    // Invariant: decode(lo) <= x; answer in [lo, hi].
    while lo < hi {
        let mid = lo + (hi - lo).div_ceil(2);
        if decode(origin, e, mid) <= x {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    lo
}

/// A cluster's frame as stored in its first 16 bytes: origin `p` (3 × f32, words 0–2) and
/// exponent bytes `e` (word 3, bytes 0–2; byte 3 holds the cluster's record count).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Origin per axis (the frame box's min corner).
    pub origin: [f32; 3],
    /// Exponent byte per axis: scale `2^(e − 127)`.
    pub exp: [u8; 3],
}

impl Frame {
    /// The frame of the box `[lo, hi]` for `bits`-bit offsets.
    pub fn of_box(lo: [f32; 3], hi: [f32; 3], bits: u32) -> Self {
        Self {
            origin: lo,
            exp: std::array::from_fn(|a| choose_exponent(lo[a], hi[a], bits)),
        }
    }

    /// Decodes the plane of offset `q` on axis `a`.
    #[inline(always)]
    pub fn plane(&self, a: usize, q: u32) -> f32 {
        decode(self.origin[a], self.exp[a], q)
    }

    /// The four frame words (origin bits, then the exponent bytes with `count` in byte 3).
    pub fn words(&self, count: u8) -> [u32; 4] {
        [
            self.origin[0].to_bits(),
            self.origin[1].to_bits(),
            self.origin[2].to_bits(),
            u32::from_le_bytes([self.exp[0], self.exp[1], self.exp[2], count]),
        ]
    }

    /// Reads a frame from its four words (any words decode: a frame has no invalid value).
    #[inline(always)]
    pub fn from_words(w: [u32; 4]) -> Self {
        let e = w[3].to_le_bytes();
        Self {
            origin: [
                f32::from_bits(w[0]),
                f32::from_bits(w[1]),
                f32::from_bits(w[2]),
            ],
            exp: [e[0], e[1], e[2]],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_is_a_power_of_two() {
        assert_eq!(scale(127), 1.0);
        assert_eq!(scale(128), 2.0);
        assert_eq!(scale(1), f32::MIN_POSITIVE);
        assert_eq!(scale(0), f32::MIN_POSITIVE / 2.0);
    }

    #[test]
    fn worked_example() {
        // The example of docs/dstq-encoding.md, §5: x ∈ [1.5, 3.25] with 8-bit offsets.
        let e = choose_exponent(1.5, 3.25, 8);
        assert_eq!(e, 120); // s = 2^-7: 255 · 2^-7 = 1.9921875 ≥ 1.75, 2^-8 would not do
        assert_eq!(quantize_up(2.0, 1.5, e, 8), 64);
        assert_eq!(quantize_up(2.001, 1.5, e, 8), 65);
        assert_eq!(quantize_down(2.001, 1.5, e, 8), 64);
        assert_eq!(decode(1.5, e, 65), 2.0078125);
        assert_eq!(quantize_up(f32::INFINITY, 1.5, e, 8), 255);
        assert_eq!(quantize_down(f32::NEG_INFINITY, 1.5, e, 8), 0);
    }

    #[test]
    fn frame_words_round_trip() {
        let f = Frame::of_box([-1.0, 0.0, 1e-40], [2.0, 0.0, 1e30], 10);
        assert_eq!(Frame::from_words(f.words(7)), f);
        assert_eq!(f.words(7)[3] >> 24, 7);
    }
}
