//! The one place in this crate with `unsafe` code: cache prefetch hints, and the AVX2 path
//! of the CPU traversal (a token proving the CPU has AVX2, a way to run code compiled for
//! it, and the 8-wide box test), which `std::arch` offers only through `unsafe` calls from
//! code not itself compiled for AVX2. The crate denies `unsafe_code` (its `Cargo.toml`); this
//! leaf module allows it, and every block carries a SAFETY note.
#![allow(unsafe_code)]

/// Hints the CPU to bring every cache line (64 bytes) that `*r` touches into all cache
/// levels. No effect on results; a no-op on targets other than x86-64.
///
/// Straight-line code: one hint every 64 bytes from `r`'s first byte (each in a successive
/// line) and one at its last byte, which together name every line `*r` touches whatever its
/// alignment; the count is a constant, so the loop unrolls (a loop over the lines from the
/// first line's start cost 16 M of 301 M instructions of a Sponza bench run). The last hint
/// is left out where `T`'s alignment already puts the last byte in the line of the last
/// 64-byte step: `*r` starts at most `64 - align` bytes into a line (`align` below 64), so
/// with `n` steps the last byte is within them when `64 - align + size <= 64 n` (a BVH8
/// node of the CPU copy: 224 bytes aligned to 32, four hints).
#[inline(always)]
pub fn prefetch<T>(r: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        let start = (r as *const T).cast::<i8>();
        let hint = |offset: usize| {
            // SAFETY: `_mm_prefetch` only needs SSE, which every x86-64 CPU has (it is in the
            // target's baseline features), and it never dereferences its pointer for the
            // program: it is a hint that cannot fault, whatever the address. The offsets
            // are within `*r` (`wrapping_byte_add` needs no bounds anyway).
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
    let _ = r;
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
    /// Returns the entry distances and the mask of lanes with `entry <= exit` whose child
    /// word is not `u32::MAX` (an empty lane).
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn slab8(
        self,
        planes: &[[f32; 8]; 6],
        child: &[u32; 8],
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
                let words: __m256i = bytemuck::cast(*child);
                let empty = _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(
                    words,
                    _mm256_set1_epi32(-1),
                ))) as u32;
                (bytemuck::cast(entry), hit & !empty)
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = (planes, child, rows, o, neg_inv, neg_inv_w, t_lo, t_hi);
            unreachable!("no Avx2 token exists off x86-64")
        }
    }
}
