/* Float math of the kernels, bit for bit the same as crates/geometry/src/fmath.rs (one
 * implementation in both languages, so simulated and CPU-rendered pixels agree).
 * sqrt is the IEEE (correctly rounded) fsqrt.s; max/min are fmax.s/fmin.s, which return the
 * other operand when one is NaN, like Rust's f32::max/min. (They also order -0 below +0,
 * which Rust leaves unspecified: every max/min of the kernels either feeds only comparisons
 * or cannot see two zeros of different sign.) */
#ifndef FMATH_H
#define FMATH_H

#include <stdint.h>

static inline float f_sqrt(float x)
{
    float r;
    __asm__("fsqrt.s %0, %1" : "=f"(r) : "f"(x));
    return r;
}

/* Rust's f32::max: the larger operand, the non-NaN one if one is NaN. */
static inline float f_max(float a, float b)
{
    float r;
    __asm__("fmax.s %0, %1, %2" : "=f"(r) : "f"(a), "f"(b));
    return r;
}

/* Rust's f32::min: the smaller operand, the non-NaN one if one is NaN. */
static inline float f_min(float a, float b)
{
    float r;
    __asm__("fmin.s %0, %1, %2" : "=f"(r) : "f"(a), "f"(b));
    return r;
}

static inline float f_abs(float x)
{
    return __builtin_fabsf(x);
}

/* Rust's f32::signum for non-NaN x: 1.0 or -1.0 with x's sign (+0 -> 1, -0 -> -1). */
static inline float f_signum(float x)
{
    return __builtin_copysignf(1.0f, x);
}

/* sin and cos (fmath.rs: `sin_cos`): x = k * pi/2 + r with k = x * 2/pi rounded half away
 * from zero and r by a three-part Cody-Waite reduction (k * PIO2_1 is exact for |k| < 2^16),
 * then the Cephes single-precision polynomials on |r| <= pi/4 and the quadrant k mod 4.
 * Accurate to a few ulps for |x| up to about 1e4 (the renderer calls it on [0, 2 pi)). */
#define FM_FRAC_2_PI 0.636619772367581343075535053490057448f /* 0x3F22F983 */
/* pi/2 = PIO2_1 + PIO2_2 + PIO2_3 (PIO2_1 and PIO2_2 have short mantissas) */
#define FM_PIO2_1 1.5703125f   /* 0x3FC90000 */
#define FM_PIO2_2 4.837513e-4f /* 0x39FDA000 */
#define FM_PIO2_3 7.54979e-8f  /* 0x33A22169 */
/* Cephes sinf/cosf coefficients rounded to f32 (the literals of fmath.rs) */
#define FM_S1 -1.9515296e-4f /* 0xB94CA1F9 */
#define FM_S2 8.332161e-3f   /* 0x3C08839E */
#define FM_S3 1.6666655e-1f  /* 0x3E2AAAA3 */
#define FM_C1 2.4433157e-5f  /* 0x37CCF5CE */
#define FM_C2 1.3887316e-3f  /* 0x3AB6061A */
#define FM_C3 4.1666646e-2f  /* 0x3D2AAAA5 */

static inline void f_sincos(float x, float *s_out, float *c_out)
{
    float h = x < 0.0f ? -0.5f : 0.5f;
    int32_t k = (int32_t)(x * FM_FRAC_2_PI + h);
    float kf = (float)k;
    float r = ((x - kf * FM_PIO2_1) - kf * FM_PIO2_2) - kf * FM_PIO2_3;
    float z = r * r;
    float s = ((FM_S1 * z + FM_S2) * z - FM_S3) * z * r + r;
    float c = ((FM_C1 * z - FM_C2) * z + FM_C3) * z * z - 0.5f * z + 1.0f;
    switch (k & 3) {
    case 0:
        *s_out = s;
        *c_out = c;
        break;
    case 1:
        *s_out = c;
        *c_out = -s;
        break;
    case 2:
        *s_out = -s;
        *c_out = -c;
        break;
    default:
        *s_out = -c;
        *c_out = s;
        break;
    }
}

#endif
