//! Float functions the renderer needs beyond IEEE arithmetic, written once in Rust and once in
//! C (`kernels/fmath.h`) with the same operations in the same order, so the CPU renderer and
//! the simulated threads' compiled kernels compute bit-identical pixels. `sqrt` needs no
//! copy: it is correctly rounded in both (RV32F `fsqrt.s`).
//!
//! [`sin_cos`]: `x = k·π/2 + r` with `k = x·2/π` rounded half away from zero, `r` by a
//! three-part Cody–Waite reduction (`k·PIO2_1` is exact for `|k| < 2^16`), then the Cephes
//! single-precision minimax polynomials on `|r| ≤ π/4` (Moshier 1989, `sinf.c`/`cosf.c`) and
//! the quadrant `k mod 4`. Every step is a plain f32 operation (no fused multiply-add; the C
//! side compiles with `-ffp-contract=off`). Accurate to a few ulps for `|x|` up to about
//! 1e4; the renderer calls it on `[0, 2π)`.

const FRAC_2_PI: f32 = std::f32::consts::FRAC_2_PI;
// π/2 = PIO2_1 + PIO2_2 + PIO2_3 (PIO2_1 and PIO2_2 have short mantissas).
const PIO2_1: f32 = 1.570_312_5;
const PIO2_2: f32 = 4.837_513e-4;
const PIO2_3: f32 = 7.549_79e-8;
// Cephes sinf/cosf coefficients, rounded to f32 (the same literals as kernels/fmath.h).
const S1: f32 = -1.951_529_6e-4;
const S2: f32 = 8.332_161e-3;
const S3: f32 = 1.666_665_5e-1;
const C1: f32 = 2.443_315_7e-5;
const C2: f32 = 1.388_731_6e-3;
const C3: f32 = 4.166_664_6e-2;

/// `(sin x, cos x)`, bit for bit the C kernels' `f_sincos`.
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    let h = if x < 0.0 { -0.5 } else { 0.5 };
    let k = (x * FRAC_2_PI + h) as i32;
    let kf = k as f32;
    let r = ((x - kf * PIO2_1) - kf * PIO2_2) - kf * PIO2_3;
    let z = r * r;
    let s = ((S1 * z + S2) * z - S3) * z * r + r;
    let c = ((C1 * z - C2) * z + C3) * z * z - 0.5 * z + 1.0;
    match k & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// `sin x` ([`sin_cos`]).
#[inline]
pub fn sin(x: f32) -> f32 {
    sin_cos(x).0
}

/// `cos x` ([`sin_cos`]).
#[inline]
pub fn cos(x: f32) -> f32 {
    sin_cos(x).1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Error in ulps of the f32 result against the f64 reference.
    fn ulps(got: f32, want: f64) -> f64 {
        let ulp = (want.abs() as f32).max(f32::MIN_POSITIVE);
        let ulp = (f32::from_bits(ulp.to_bits() + 1) - ulp) as f64;
        (got as f64 - want).abs() / ulp
    }

    #[test]
    fn accurate_on_the_renderers_range_and_beyond() {
        let n = 200_000;
        let (mut worst_s, mut worst_c) = (0f64, 0f64);
        for i in 0..=n {
            let x = -20.0 + 40.0 * i as f32 / n as f32;
            let (s, c) = sin_cos(x);
            let (ws, wc) = ((x as f64).sin(), (x as f64).cos());
            // Absolute error near the zeros, relative elsewhere.
            if ws.abs() > 1e-3 {
                worst_s = worst_s.max(ulps(s, ws));
            } else {
                assert!((s as f64 - ws).abs() < 1e-7, "sin {x}: {s} vs {ws}");
            }
            if wc.abs() > 1e-3 {
                worst_c = worst_c.max(ulps(c, wc));
            } else {
                assert!((c as f64 - wc).abs() < 1e-7, "cos {x}: {c} vs {wc}");
            }
        }
        assert!(worst_s < 4.0 && worst_c < 4.0, "{worst_s} {worst_c} ulps");
    }

    /// The constants' bits, which `kernels/fmath.h` must spell the same.
    #[test]
    fn constants_are_the_kernels() {
        let bits = [FRAC_2_PI, PIO2_1, PIO2_2, PIO2_3, S1, S2, S3, C1, C2, C3].map(f32::to_bits);
        assert_eq!(
            bits,
            [
                0x3f22f983, 0x3fc90000, 0x39fda000, 0x33a22169, 0xb94ca1f9, 0x3c08839e, 0x3e2aaaa3,
                0x37ccf5ce, 0x3ab6061a, 0x3d2aaaa5
            ]
        );
    }

    #[test]
    fn exact_at_zero_and_bounded() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        for i in 0..10_000 {
            let (s, c) = sin_cos(std::f32::consts::TAU * i as f32 / 10_000.0);
            assert!(s.abs() <= 1.0 && c.abs() <= 1.0);
        }
    }
}
