//! The one place in this crate with `unsafe` code: a cache prefetch hint, which `std::arch`
//! offers only as an `unsafe` intrinsic. The crate denies `unsafe_code` (its `Cargo.toml`);
//! this leaf module allows it, and every block carries a SAFETY note.
#![allow(unsafe_code)]

/// Hints the CPU to bring the cache line holding `*r` into all cache levels. No effect on
/// results; a no-op on targets other than x86-64.
#[inline(always)]
pub fn prefetch<T>(r: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `_mm_prefetch` only needs SSE, which every x86-64 CPU has (it is in the target's
    // baseline features), and it never dereferences its pointer for the program: it is a hint
    // that cannot fault. The pointer comes from a live reference anyway.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>((r as *const T).cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = r;
}
