//! The one place in this crate with `unsafe` code: cache prefetch hints, and the AVX2 path
//! of the CPU traversal (a token proving the CPU has AVX2, a way to run code compiled for
//! it, the ray's constants, the 8-wide box test, the sort of a node's hit children, a lane
//! picked from a register and the f64 plane distances of a triangle packet; and the DST
//! converter's chain-state areas), which `std::arch` offers only through `unsafe` calls from
//! code not itself compiled for AVX2.
//! The crate denies `unsafe_code` (its `Cargo.toml`); this leaf module allows it, and every
//! block carries a SAFETY note.
#![allow(unsafe_code)]

/// Hints the CPU to bring every cache line (64 bytes) that a `T` at `p` touches into all
/// cache levels. No effect on results; a no-op on targets other than x86-64. `p` need not
/// point into any allocation: a prefetch hint never faults and is never a read for the
/// program, so a caller can name an element of a slice without the bounds check that
/// indexing costs (`slice.as_ptr().wrapping_add(i)`).
///
/// Straight-line code: one hint every 64 bytes from `p`'s first byte (each in a successive
/// line) and one at its last byte, which together name every line a `T` there touches
/// whatever its alignment; the count is a constant, so the loop unrolls (a loop over the
/// lines from the first line's start cost 16 M of 301 M instructions of a Sponza bench
/// run). The last hint is left out where `T`'s alignment already puts the last byte in the
/// line of the last 64-byte step: an aligned `T` starts at most `64 - align` bytes into a
/// line (`align` below 64), so with `n` steps the last byte is within them when `64 - align
/// + size <= 64 n` (a BVH8 node of the CPU copy: 224 bytes aligned to 32, four hints).
#[inline(always)]
pub fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    {
        let start = p.cast::<i8>();
        let hint = |offset: usize| {
            // SAFETY: `_mm_prefetch` only needs SSE, which every x86-64 CPU has (it is in the
            // target's baseline features), and it never dereferences its pointer for the
            // program: it is a hint that cannot fault, whatever the address
            // (`wrapping_byte_add` needs no bounds either).
            unsafe {
                use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
                _mm_prefetch::<_MM_HINT_T0>(start.wrapping_byte_add(offset));
            }
        };
        let steps = size_of::<T>().div_ceil(64);
        for k in 0..steps {
            hint(64 * k);
        }
        let align = align_of::<T>().min(64);
        if 64 - align + size_of::<T>() > 64 * steps {
            hint(size_of::<T>().saturating_sub(1));
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// Where, in a node's eight-lane plane rows (`[[f32; 8]; 6]`, rows in the box word order
/// min.x, min.y, min.z, max.x, max.y, max.z), the rows of a ray's near and far planes
/// start, in bytes: per axis `a` the near plane is min (row `a`) and the far plane max (row
/// `a + 3`), swapped when the ray travels toward −a. Made only from the signs, so every
/// offset is a whole row's inside the array, and [`Avx2::slab8`] reads a row at its
/// offset with no bounds check and no multiplication.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlaneRows8 {
    /// Per axis, the near plane's row offset.
    near: [usize; 3],
    /// Per axis, the far plane's row offset.
    far: [usize; 3],
}

impl PlaneRows8 {
    /// The rows of a ray whose direction is negative (sign bit set) on axis `a` where
    /// `neg[a]`.
    #[inline(always)]
    pub fn new(neg: [bool; 3]) -> Self {
        const ROW: usize = size_of::<[f32; 8]>();
        let s = |a: usize| 3 * neg[a] as usize;
        Self {
            near: [0, 1, 2].map(|a| (a + s(a)) * ROW),
            far: [0, 1, 2].map(|a| (a + 3 - s(a)) * ROW),
        }
    }
}

/// Code that [`Avx2::vectorize`] runs compiled for AVX2 (a closure cannot carry the
/// `#[inline(always)]` that makes its body part of the AVX2 function).
pub trait Kernel {
    /// What the code returns.
    type Output;
    /// Runs the code; implementations are `#[inline(always)]`.
    fn call(self) -> Self::Output;
}

/// Proof that this CPU has AVX2 and the bit-manipulation extensions that come with it
/// (BMI1, BMI2, LZCNT, POPCNT): a value exists only when [`Avx2::detect`] found them all.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Avx2(());

impl Avx2 {
    /// The token, when the CPU running this has every feature [`Avx2::vectorize`] enables.
    pub fn detect() -> Option<Self> {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2")
            && std::is_x86_feature_detected!("bmi1")
            && std::is_x86_feature_detected!("bmi2")
            && std::is_x86_feature_detected!("lzcnt")
            && std::is_x86_feature_detected!("popcnt")
        {
            return Some(Self(()));
        }
        None
    }

    /// Runs `k` inside a function compiled with AVX2 enabled, so that `k`'s inlined code
    /// (SSE code included, which then takes the three-operand VEX forms) may use it. Enabling
    /// AVX2 does not let the compiler fuse multiplies and adds (Rust never contracts them),
    /// so every float result is the baseline build's.
    #[inline(always)]
    pub fn vectorize<K: Kernel>(self, k: K) -> K::Output {
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
            fn with_avx2<K: Kernel>(k: K) -> K::Output {
                k.call()
            }
            // SAFETY: `self` exists only when `detect` found every feature `with_avx2`
            // enables on this CPU.
            unsafe { with_avx2(k) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        k.call()
    }

    /// Slab test of eight boxes stored plane by plane (`planes[p][lane]`, planes in the box
    /// word order min.x, min.y, min.z, max.x, max.y, max.z), the same arithmetic as the
    /// 4-wide test lane by lane: near plane `p = near[a]` gives `(o[a] - p) * neg_inv[a]`
    /// (`neg_inv = -inv_dir`, so `(p - o[a]) * inv[a]` up to the sign of a zero, with the
    /// plane's load folded into the subtraction), far plane `far[a]` gives
    /// `(o[a] - p) * neg_inv_w[a]` (`neg_inv_w = -inv_dir * EXIT_WIDEN`, the exit widening
    /// folded into the reciprocal); the entry is the largest of `t_lo` and the
    /// near distances, the exit the smallest of `t_hi` and the far ones, a NaN distance
    /// keeping the running bound (`vmaxps`/`vminps` return their second operand then).
    /// Returns the entry distances and the mask of lanes with `entry <= exit` (an empty
    /// lane's box, min `+∞` and max `−∞`, has none for a finite origin and direction: its
    /// near distances are `+∞` and its far ones `−∞`).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn slab8(
        self,
        planes: &[[f32; 8]; 6],
        rows: PlaneRows8,
        o: [f32; 3],
        neg_inv: [f32; 3],
        neg_inv_w: [f32; 3],
        t_lo: f32,
        t_hi: f32,
    ) -> ([f32; 8], u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            let base = planes.as_ptr().cast::<u8>();
            // SAFETY: every intrinsic below needs at most AVX2, which `self` proves this CPU
            // has (`detect`). The only memory read is `row`'s: 32 bytes from `off` bytes
            // into `planes`, where `off` is one of `rows`' offsets, which by
            // `PlaneRows8::new` is that of a whole row of the 192-byte `planes`; `loadu`
            // needs no alignment.
            unsafe {
                let row = |off: usize| -> __m256 { _mm256_loadu_ps(base.add(off).cast()) };
                let mut entry = _mm256_set1_ps(t_lo);
                let mut exit = _mm256_set1_ps(t_hi);
                for a in 0..3 {
                    let oa = _mm256_set1_ps(o[a]);
                    let ia = _mm256_set1_ps(neg_inv[a]);
                    let tn = _mm256_mul_ps(_mm256_sub_ps(oa, row(rows.near[a])), ia);
                    let iw = _mm256_set1_ps(neg_inv_w[a]);
                    let tf = _mm256_mul_ps(_mm256_sub_ps(oa, row(rows.far[a])), iw);
                    entry = _mm256_max_ps(tn, entry);
                    exit = _mm256_min_ps(tf, exit);
                }
                let hit = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(entry, exit)) as u32;
                (bytemuck::cast(entry), hit)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (planes, rows, o, neg_inv, neg_inv_w, t_lo, t_hi);
            unreachable!("no Avx2 token exists off x86-64")
        }
    }

    /// The surface areas `x·y + y·z + z·x` of eight boxes whose extents come from a table:
    /// box `i`'s extent on axis `a` is `ext[a][(codes[i] >> 2a) & 3]` (the DST converter's
    /// chain states, `dst::from_bvh2`). The lookup is one `vpermilps` per axis (it reads the
    /// low two bits of each index), and the products and sums are the scalar expression's,
    /// in its order, unfused: each lane is the scalar area's bits.
    #[inline(always)]
    pub fn areas8(self, ext: &[[f32; 4]; 3], codes: &[u32; 8]) -> [f32; 8] {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            // SAFETY: every intrinsic below needs at most AVX2, which `self` proves this CPU
            // has (`detect`). The loads read `ext[a]` (16 bytes) and `codes` (32 bytes)
            // through references to them; `loadu` needs no alignment.
            unsafe {
                let c = _mm256_loadu_si256(codes.as_ptr().cast());
                let axis = |a: usize| {
                    let table = _mm_loadu_ps(ext[a].as_ptr());
                    let idx = _mm256_srlv_epi32(c, _mm256_set1_epi32(2 * a as i32));
                    _mm256_permutevar_ps(_mm256_set_m128(table, table), idx)
                };
                let (x, y, z) = (axis(0), axis(1), axis(2));
                let xy_yz = _mm256_add_ps(_mm256_mul_ps(x, y), _mm256_mul_ps(y, z));
                bytemuck::cast(_mm256_add_ps(xy_yz, _mm256_mul_ps(z, x)))
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (ext, codes);
            unreachable!("no Avx2 token exists off x86-64")
        }
    }

    /// Where the ray meets the planes of four triangles, `Triangle::plane_t`'s f64
    /// arithmetic on four lanes at once: vertex `i`'s coordinate on axis `a` of lane `l` is
    /// `v[3 i + a][l]`, `o` the ray's origin, `k` the watertight test's axes `(kx, ky, kz)`
    /// (each below 3) and `shear` its constants `(Sx, Sy, Sz)`. Every operation is the scalar
    /// code's, in its order, on the same widened values (f32 to f64 is exact; AVX's packed
    /// subtraction, multiplication and division round as the scalar ones do, and nothing is
    /// fused), and the result is rounded to f32 once, by the same rounding mode, so each
    /// lane is the scalar function's bits.
    #[inline(always)]
    pub fn plane_t4(
        self,
        v: &[[f32; 4]; 9],
        o: [f32; 3],
        k: [usize; 3],
        shear: [f32; 3],
    ) -> [f32; 4] {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            // SAFETY: every intrinsic below needs at most AVX, which `self` proves this CPU
            // has (`detect`). The only memory reads are the nine 16-byte `loadu`s of `v`'s
            // rows, each a whole `[f32; 4]` that `v` borrows; `loadu` needs no alignment.
            unsafe {
                let wide = |i: usize| _mm256_cvtps_pd(_mm_loadu_ps(v[i].as_ptr()));
                let (sub, mul) = (|a, b| _mm256_sub_pd(a, b), |a, b| _mm256_mul_pd(a, b));
                let add = |a, b| _mm256_add_pd(a, b);
                let splat = |x: f32| _mm256_set1_pd(x as f64);
                // (Written out: `array::map` with these closures stayed out of line.)
                let p0 = [wide(0), wide(1), wide(2)];
                let e1 = [
                    sub(wide(3), p0[0]),
                    sub(wide(4), p0[1]),
                    sub(wide(5), p0[2]),
                ];
                let e2 = [
                    sub(wide(6), p0[0]),
                    sub(wide(7), p0[1]),
                    sub(wide(8), p0[2]),
                ];
                // Padded to four, so that an axis `& 3` indexes it without a bounds check.
                let n = [
                    sub(mul(e1[1], e2[2]), mul(e1[2], e2[1])),
                    sub(mul(e1[2], e2[0]), mul(e1[0], e2[2])),
                    sub(mul(e1[0], e2[1]), mul(e1[1], e2[0])),
                    _mm256_setzero_pd(),
                ];
                let w = [
                    sub(p0[0], splat(o[0])),
                    sub(p0[1], splat(o[1])),
                    sub(p0[2], splat(o[2])),
                ];
                let num = add(add(mul(n[0], w[0]), mul(n[1], w[1])), mul(n[2], w[2]));
                let [kx, ky, kz] = [k[0] & 3, k[1] & 3, k[2] & 3];
                let den = add(
                    add(mul(n[kx], splat(shear[0])), mul(n[ky], splat(shear[1]))),
                    n[kz],
                );
                let t = mul(_mm256_div_pd(num, den), splat(shear[2]));
                bytemuck::cast(_mm256_cvtpd_ps(t))
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (v, o, k, shear);
            unreachable!("no Avx2 token exists off x86-64")
        }
    }

    /// Orders the hit lanes of an eight-lane node for a traversal stack, without branches:
    /// writes all eight lanes' `(distance bits, child word)` pairs to `out`, the lanes of
    /// `mask` first, farthest first (so the nearest is last, on top of the stack when `out`
    /// is its next eight slots), then the other lanes; returns how many lanes `mask` has and
    /// the nearest of them (the lane last among them in `out`).
    ///
    /// The sort key of a lane is its distance's bits mapped to a signed integer of the same
    /// order (the low 31 bits flipped for a negative sign), its low three bits replaced by
    /// 7 minus the lane number: distinct keys, ordered by distance except between distances
    /// that differ only in those bits (then by lane, the higher lane nearer the top, as are
    /// equal distances: the copy puts a node's likeliest occluder in its first lane, and a
    /// closest-hit ray inside several boxes at once, which all give it the same entry
    /// distance, measured faster taking the last first; `docs/cpu-traversal.md`). Lanes
    /// outside `mask` take the key `i32::MIN`, below every such key (the smallest, of −∞,
    /// is `0x807F_FFF8`), so they sort after the hit lanes. A bitonic network of six
    /// compare-exchange stages sorts the eight keys in one register.
    #[inline(always)]
    pub fn sort_hits8(
        self,
        dist: [f32; 8],
        child: &[u32; 8],
        mask: u32,
        out: &mut [[u32; 2]; 8],
    ) -> (u32, u32) {
        let nearest: u32;
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            // SAFETY: every intrinsic below needs at most AVX2, which `self` proves this CPU
            // has (`detect`). The only memory writes are the two 32-byte `storeu`s, to the
            // first and second halves of the 64-byte `out`, which `&mut` lends exclusively;
            // `storeu` needs no alignment.
            unsafe {
                let d: __m256i = bytemuck::cast(dist);
                let ord = _mm256_xor_si256(d, _mm256_srli_epi32::<1>(_mm256_srai_epi32::<31>(d)));
                let seven = _mm256_set1_epi32(7);
                let lane = _mm256_setr_epi32(7, 6, 5, 4, 3, 2, 1, 0);
                let key = _mm256_or_si256(_mm256_andnot_si256(seven, ord), lane);
                let bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
                let hit =
                    _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(mask as i32), bit), bit);
                // The nearest hit lane, the smallest key, found apart from the sort (three
                // steps rather than six), so that the next node's address does not wait
                // for the sort.
                let near = _mm256_blendv_epi8(_mm256_set1_epi32(i32::MAX), key, hit);
                let near = _mm256_min_epi32(near, _mm256_shuffle_epi32::<0x4E>(near));
                let near = _mm256_min_epi32(near, _mm256_shuffle_epi32::<0xB1>(near));
                let near = _mm256_min_epi32(near, _mm256_permute2x128_si256::<1>(near, near));
                nearest = ((_mm256_cvtsi256_si32(near) & 7) ^ 7) as u32;
                let key = _mm256_blendv_epi8(_mm256_set1_epi32(i32::MIN), key, hit);
                let key = sort8_desc(key);
                let idx = _mm256_xor_si256(_mm256_and_si256(key, seven), seven);
                let t = _mm256_permutevar8x32_epi32(d, idx);
                let c = _mm256_permutevar8x32_epi32(bytemuck::cast(*child), idx);
                let lo = _mm256_unpacklo_epi32(t, c);
                let hi = _mm256_unpackhi_epi32(t, c);
                let p = out.as_mut_ptr().cast::<__m256i>();
                _mm256_storeu_si256(p, _mm256_permute2x128_si256::<0x20>(lo, hi));
                _mm256_storeu_si256(p.add(1), _mm256_permute2x128_si256::<0x31>(lo, hi));
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (dist, child, out);
            unreachable!("no Avx2 token exists off x86-64")
        }
        (mask.count_ones(), nearest)
    }

    /// [`RayPre::new`]'s values for `ray`, bit for bit, with vector instructions and no
    /// branch: the reciprocal, the signs and `kz` as there (`RayPre::major_axis`), then
    /// `d / d[kz]` in one division whose lanes are `Sx`, `Sy` and `Sz = 1 / d[kz]` (the
    /// same correctly rounded quotients as its scalar lanes and `inv_dir[kz]`), gathered by
    /// one `vpermilps` with the axes from a table, where `RayPre::new` picks each value by
    /// comparisons and jumps.
    ///
    /// [`RayPre::new`]: dualsplit_geometry::RayPre::new
    #[inline(always)]
    pub fn ray_pre(self, ray: &dualsplit_geometry::Ray) -> dualsplit_geometry::RayPre {
        #[cfg(target_arch = "x86_64")]
        {
            use dualsplit_geometry::{RayPre, Vec3};
            use std::arch::x86_64::*;
            /// `[kx, ky, kz, 3]` per `2 kz + swap`: `(kx, ky) = (kz + 1, kz + 2) mod 3`,
            /// swapped when `d[kz] < 0` (lane 3 picks the fourth lane, `1 / d[kz]`).
            const K: [[i32; 4]; 6] = [
                [1, 2, 0, 3],
                [2, 1, 0, 3],
                [2, 0, 1, 3],
                [0, 2, 1, 3],
                [0, 1, 2, 3],
                [1, 0, 2, 3],
            ];
            let d = ray.dir;
            let kz = RayPre::major_axis(d);
            // SAFETY: every intrinsic below needs at most AVX, which `self` proves this CPU
            // has (`detect`); no memory is touched but `K`'s row, read by value. `vpermilps`
            // reads only the low two bits of each index lane.
            unsafe {
                let d4 = _mm_setr_ps(d.x, d.y, d.z, 1.0);
                let inv = _mm_div_ps(_mm_set1_ps(1.0), d4);
                let dkz = _mm_permutevar_ps(d4, _mm_set1_epi32(kz as i32));
                let swap = (_mm_cvtss_f32(dkz) < 0.0) as usize;
                let k = K[(2 * kz + swap) % K.len()];
                let s = _mm_permutevar_ps(_mm_div_ps(d4, dkz), bytemuck::cast(k));
                let inv: [f32; 4] = bytemuck::cast(inv);
                let s: [f32; 4] = bytemuck::cast(s);
                RayPre {
                    ray: *ray,
                    inv_dir: Vec3::new(inv[0], inv[1], inv[2]),
                    neg: RayPre::signs(d),
                    k: [k[0] as usize, k[1] as usize, kz],
                    shear: Vec3::new(s[0], s[1], s[3]),
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = ray;
            unreachable!("no Avx2 token exists off x86-64")
        }
    }

    /// Lane `i & 7` of `v`, picked in registers (one `vpermps`) rather than by storing `v`
    /// and loading the lane back.
    #[inline(always)]
    pub fn lane8(self, v: [f32; 8], i: usize) -> f32 {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            // SAFETY: every intrinsic below needs at most AVX2, which `self` proves this CPU
            // has (`detect`); no memory is touched. `vpermps` reads only the low three bits
            // of each index lane.
            unsafe {
                let idx = _mm256_castsi128_si256(_mm_cvtsi32_si128(i as i32));
                _mm256_cvtss_f32(_mm256_permutevar8x32_ps(bytemuck::cast(v), idx))
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (v, i);
            unreachable!("no Avx2 token exists off x86-64")
        }
    }
}

/// The eight signed keys of `v` in descending order: a bitonic network, each stage a
/// compare-exchange of lane pairs (the lower lane takes the larger key), given by the
/// permutation that swaps each pair's lanes and the blend mask of the pairs' upper lanes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn sort8_desc(v: std::arch::x86_64::__m256i) -> std::arch::x86_64::__m256i {
    use std::arch::x86_64::*;
    // SAFETY: called only from `Avx2::sort_hits8`, whose token proves AVX2 (the most
    // these intrinsics need); no memory is touched.
    unsafe {
        macro_rules! stage {
            ($v:expr, $p:expr, $upper:literal) => {{
                let (v, p) = ($v, $p);
                _mm256_blend_epi32::<$upper>(_mm256_max_epi32(v, p), _mm256_min_epi32(v, p))
            }};
        }
        let reverse = _mm256_setr_epi32(7, 6, 5, 4, 3, 2, 1, 0);
        // Sorted pairs; then quadruples: (0,3)(1,2), (0,1)(2,3); then all eight:
        // (0,7)(1,6)(2,5)(3,4), (0,2)(1,3), (0,1).
        let v = stage!(v, _mm256_shuffle_epi32::<0xB1>(v), 0xAA);
        let v = stage!(v, _mm256_shuffle_epi32::<0x1B>(v), 0xCC);
        let v = stage!(v, _mm256_shuffle_epi32::<0xB1>(v), 0xAA);
        let v = stage!(v, _mm256_permutevar8x32_epi32(v, reverse), 0xF0);
        let v = stage!(v, _mm256_shuffle_epi32::<0x4E>(v), 0xCC);
        stage!(v, _mm256_shuffle_epi32::<0xB1>(v), 0xAA)
    }
}

#[cfg(test)]
mod tests {
    use super::Avx2;

    /// The order [`Avx2::sort_hits8`] promises, computed lane by lane: the distance's bits
    /// as a signed integer of the same order, the low three bits 7 minus the lane.
    fn key(d: f32, lane: usize) -> i32 {
        let b = d.to_bits() as i32;
        ((b ^ ((b >> 31) as u32 >> 1) as i32) & !7) | (7 - lane) as i32
    }

    /// The AVX2 token; without AVX2, `None` after saying that there is nothing to test.
    fn token() -> Option<Avx2> {
        let t = Avx2::detect();
        if t.is_none() {
            eprintln!("no AVX2 on this CPU: nothing to test");
        }
        t
    }

    /// `lane8` gives each lane's bits, signed zeros and NaN included, and reads only an
    /// index's low three bits.
    #[test]
    fn lane8_picks_each_lane() {
        let Some(avx2) = token() else { return };
        let v = [
            1.5,
            -0.0,
            0.0,
            f32::NAN,
            f32::INFINITY,
            -2.25,
            f32::MIN_POSITIVE,
            7.0,
        ];
        for i in 0..16 {
            assert_eq!(avx2.lane8(v, i).to_bits(), v[i & 7].to_bits(), "lane {i}");
        }
    }

    /// `ray_pre` gives `RayPre::new`'s bits on directions full of ties, signed zeros,
    /// infinities, NaN and subnormals, and on random ones.
    #[test]
    fn ray_pre_matches_scalar() {
        use dualsplit_geometry::{Ray, Vec3};
        let Some(avx2) = token() else { return };
        let pool = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            2.0,
            -2.0,
            f32::from_bits(1.0f32.to_bits() + 1),
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            f32::MIN_POSITIVE / 8.0,
            -3e38,
        ];
        let mut rng = dualsplit_geometry::Pcg32::new(9, 4);
        let mut cases: Vec<Vec3> = Vec::new();
        for x in pool {
            for y in pool {
                for z in pool {
                    cases.push(Vec3::new(x, y, z));
                }
            }
        }
        for _ in 0..100_000 {
            let mut c = || rng.range_f32(-4.0, 4.0);
            cases.push(Vec3::new(c(), c(), c()));
        }
        let bits = |v: Vec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        for d in cases {
            let ray = Ray::new(Vec3::new(0.5, -1.0, 2.0), d);
            let (want, got) = (ray.precompute(), avx2.ray_pre(&ray));
            assert_eq!(bits(got.inv_dir), bits(want.inv_dir), "{d:?}");
            assert_eq!(got.neg, want.neg, "{d:?}");
            assert_eq!(got.k, want.k, "{d:?}");
            assert_eq!(bits(got.shear), bits(want.shear), "{d:?}");
            assert_eq!(bytemuck::bytes_of(&got.ray), bytemuck::bytes_of(&ray));
        }
    }

    /// Every mask of eight lanes with distances drawn from a set full of ties, signed
    /// zeros, infinities, negatives and near neighbours: the hit lanes come first, each
    /// once with its own distance and child, in descending key order, and the nearest is
    /// the last of them.
    #[test]
    fn sort_hits8_orders_every_mask() {
        let Some(avx2) = token() else { return };
        let pool = [
            0.0,
            -0.0,
            1.0,
            1.0,
            f32::from_bits(1.0f32.to_bits() + 1),
            f32::from_bits(1.0f32.to_bits() + 9),
            2.5,
            -3.0,
            -3.5,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MIN_POSITIVE,
            1e30,
        ];
        let mut rng = dualsplit_geometry::Pcg32::new(8, 1);
        for round in 0..64 {
            let dist: [f32; 8] =
                std::array::from_fn(|_| pool[rng.next_u32() as usize % pool.len()]);
            let child: [u32; 8] = std::array::from_fn(|l| 100 * round + l as u32);
            for mask in 0..256u32 {
                let mut out = [[0u32; 2]; 8];
                let (k, near) = avx2.sort_hits8(dist, &child, mask, &mut out);
                assert_eq!(k, mask.count_ones());
                let mut want: Vec<usize> = (0..8).filter(|l| mask & (1 << l) != 0).collect();
                want.sort_by_key(|&l| std::cmp::Reverse(key(dist[l], l)));
                let got: Vec<[u32; 2]> = out[..k as usize].to_vec();
                let expect: Vec<[u32; 2]> = want
                    .iter()
                    .map(|&l| [dist[l].to_bits(), child[l]])
                    .collect();
                assert_eq!(got, expect, "dist {dist:?} mask {mask:#010b}");
                if let Some(&last) = want.last() {
                    assert_eq!(near as usize, last, "dist {dist:?} mask {mask:#010b}");
                }
            }
        }
    }
}
