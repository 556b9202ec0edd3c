//! The storage of a memory image: 32-bit words that are either a heap vector or, for large
//! images, an anonymous memory mapping advised to use transparent huge pages.
//!
//! Why: a fresh image is written once, front to back, by the encoder. On Linux every first
//! touch of a 4 KiB page is a page fault (zeroing included); a 53 MB dragon_box DST image
//! took ≈ 13 900 of them per conversion, about a quarter of the conversion's time
//! (`docs/performance.md`, "DST on the CPU"). With `MADV_HUGEPAGE` the kernel backs the
//! mapping with 2 MiB pages where it can (27 faults for the same image). Where huge pages
//! are unavailable or the mapping fails, the words simply live in a `Vec`; the contents and
//! every reader are the same either way (readers see a `&[u32]`).
//!
//! A huge page only backs a 2 MiB-aligned, 2 MiB range that lies wholly inside an advised
//! mapping, and `mmap` aligns to 4 KiB only: a mapping of exactly the data's bytes keeps its
//! unaligned ends in 4 KiB pages, and one below 4 MiB may hold no whole aligned range at all
//! (Sponza's BVH8 copy had no huge page). So the data starts at the mapping's first 2 MiB
//! boundary, and what it covers is advised in whole huge pages ([`HugeMap`]): the mapping is
//! up to 2 MiB longer (address space, never touched) and the last huge page holds up to 2 MiB
//! of zeros beyond the data.

use memmap2::MmapMut;
use std::fmt;
use std::ops::{Deref, DerefMut};

/// Images of at least this many bytes are mapped with the huge-page advice (one huge page).
pub const MAPPED_MIN_BYTES: usize = 2 << 20;

/// The size of a transparent huge page on x86-64 and most other Linux targets.
const HUGE_PAGE: usize = 2 << 20;

/// An anonymous mapping holding `bytes` bytes from its first 2 MiB boundary on, those whole
/// huge pages advised `MADV_HUGEPAGE` (see the module docs). Zero-filled.
struct HugeMap {
    map: MmapMut,
    /// Where the data starts: the first 2 MiB boundary of `map`.
    off: usize,
    /// Bytes of data.
    bytes: usize,
}

impl HugeMap {
    /// `bytes` zeroed bytes, or `None` if the mapping fails.
    fn new(bytes: usize) -> Option<Self> {
        let covered = bytes.checked_next_multiple_of(HUGE_PAGE)?;
        let map = MmapMut::map_anon(covered.checked_add(HUGE_PAGE)?).ok()?;
        let off = map.as_ptr().align_offset(HUGE_PAGE);
        // Advice is a hint: a kernel without transparent huge pages keeps 4 KiB pages.
        #[cfg(target_os = "linux")]
        let _ = map.advise_range(memmap2::Advice::HugePage, off, covered);
        Some(Self { map, off, bytes })
    }

    #[inline(always)]
    fn bytes(&self) -> &[u8] {
        &self.map[self.off..self.off + self.bytes]
    }

    #[inline(always)]
    fn bytes_mut(&mut self) -> &mut [u8] {
        &mut self.map[self.off..self.off + self.bytes]
    }
}

/// The words of a [`super::MemoryImage`]; dereferences to `[u32]`.
pub struct Words(Buf);

enum Buf {
    Heap(Vec<u32>),
    /// `4 · len` bytes in huge pages (2 MiB-aligned, zero-filled).
    Mapped(HugeMap),
}

impl Words {
    /// `n` zeroed words; large buffers ([`MAPPED_MIN_BYTES`]) are an anonymous mapping with
    /// the transparent-huge-page advice, falling back to a vector if mapping fails.
    pub fn zeroed(n: usize) -> Words {
        if n.saturating_mul(4) >= MAPPED_MIN_BYTES
            && let Some(map) = HugeMap::new(n * 4)
        {
            return Words(Buf::Mapped(map));
        }
        Words(Buf::Heap(vec![0; n]))
    }

    /// Whether the words live in a memory mapping (large images) rather than a vector.
    pub fn is_mapped(&self) -> bool {
        matches!(self.0, Buf::Mapped(_))
    }

    /// The words as a vector (copies a mapped buffer).
    pub fn into_vec(self) -> Vec<u32> {
        match self.0 {
            Buf::Heap(v) => v,
            Buf::Mapped(_) => self.to_vec(),
        }
    }
}

impl Deref for Words {
    type Target = [u32];
    #[inline(always)]
    fn deref(&self) -> &[u32] {
        match &self.0 {
            Buf::Heap(v) => v,
            // 2 MiB-aligned and 4·len bytes long, so the cast cannot fail.
            Buf::Mapped(m) => bytemuck::cast_slice(m.bytes()),
        }
    }
}

impl DerefMut for Words {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [u32] {
        match &mut self.0 {
            Buf::Heap(v) => v,
            Buf::Mapped(m) => bytemuck::cast_slice_mut(m.bytes_mut()),
        }
    }
}

impl From<Vec<u32>> for Words {
    fn from(v: Vec<u32>) -> Words {
        Words(Buf::Heap(v))
    }
}

impl Default for Words {
    fn default() -> Words {
        Words(Buf::Heap(Vec::new()))
    }
}

impl Clone for Words {
    /// A copy with the same storage choice as [`Words::zeroed`] would make.
    fn clone(&self) -> Words {
        let mut w = Words::zeroed(self.len());
        w.copy_from_slice(self);
        w
    }
}

impl PartialEq for Words {
    fn eq(&self, other: &Words) -> bool {
        **self == **other
    }
}

impl Eq for Words {}

impl fmt::Debug for Words {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Words")
            .field("len", &self.len())
            .field("mapped", &self.is_mapped())
            .finish()
    }
}

/// An array of plain data that, when large ([`PAGES_MIN_BYTES`]), lives in 2 MiB-aligned
/// transparent huge pages, as [`Words`] does; dereferences to `[T]`.
///
/// For data read at random, such as the CPU-side copies of the traversal
/// ([`crate::wide::cpu`]): with 4 KiB pages nearly every node of a large scene costs a TLB
/// miss (a two-level page walk under virtualisation); 2 MiB pages cover it with a few
/// entries. The contents are the same either way. Figures: `docs/cpu-traversal.md`.
pub struct Pages<T: bytemuck::Pod>(PagesBuf<T>);

/// Arrays of [`Pages`] from this many bytes on live in huge pages: beyond 64 pages of 4 KiB,
/// the reach of a Zen 3 core's first-level data TLB (64 entries; AMD's Software
/// Optimization Guide for family 19h), at the cost of up to one huge page of zeros after the
/// data.
pub const PAGES_MIN_BYTES: usize = 256 << 10;

enum PagesBuf<T> {
    Heap(Vec<T>),
    /// `len · size_of::<T>()` bytes in huge pages.
    Mapped(HugeMap, std::marker::PhantomData<T>),
}

impl<T: bytemuck::Pod> Pages<T> {
    /// A copy of `items`.
    pub fn from_slice(items: &[T]) -> Self {
        let bytes = std::mem::size_of_val(items);
        // A 2 MiB-aligned start suits any alignment of `T` up to that.
        if bytes >= PAGES_MIN_BYTES
            && std::mem::align_of::<T>() <= HUGE_PAGE
            && let Some(mut map) = HugeMap::new(bytes)
        {
            map.bytes_mut().copy_from_slice(bytemuck::cast_slice(items));
            return Pages(PagesBuf::Mapped(map, std::marker::PhantomData));
        }
        Pages(PagesBuf::Heap(items.to_vec()))
    }

    /// Whether the array lives in a memory mapping (large arrays) rather than a vector.
    pub fn is_mapped(&self) -> bool {
        matches!(self.0, PagesBuf::Mapped(..))
    }
}

impl<T: bytemuck::Pod> Deref for Pages<T> {
    type Target = [T];
    #[inline(always)]
    fn deref(&self) -> &[T] {
        match &self.0 {
            PagesBuf::Heap(v) => v,
            PagesBuf::Mapped(m, _) => bytemuck::cast_slice(m.bytes()),
        }
    }
}

impl<T: bytemuck::Pod> Default for Pages<T> {
    fn default() -> Self {
        Pages(PagesBuf::Heap(Vec::new()))
    }
}

impl<T: bytemuck::Pod> Clone for Pages<T> {
    fn clone(&self) -> Self {
        Self::from_slice(self)
    }
}

impl<T: bytemuck::Pod> fmt::Debug for Pages<T> {
    /// The length and storage, not the contents.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Pages")
            .field("len", &self.len())
            .field("mapped", &self.is_mapped())
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_buffers_are_vectors_and_large_ones_are_zeroed_mappings() {
        let small = Words::zeroed(10);
        assert!(!small.is_mapped());
        assert_eq!(&small[..], &[0; 10]);
        let n = MAPPED_MIN_BYTES / 4 + 3;
        let mut big = Words::zeroed(n);
        #[cfg(unix)]
        {
            assert!(big.is_mapped());
            // The data starts a huge page, so the kernel can back all of it with them.
            assert_eq!(big.as_ptr() as usize % HUGE_PAGE, 0);
        }
        assert_eq!(big.len(), n);
        assert!(big.iter().all(|&w| w == 0));
        big[n - 1] = 7;
        big[0] = 9;
        let copy = big.clone();
        assert_eq!(copy, big);
        assert_eq!((copy[0], copy[n - 1]), (9, 7));
        assert_eq!(big.into_vec().len(), n);
        assert_eq!(Words::zeroed(0).len(), 0);
    }

    #[test]
    fn pages_copy_small_and_large_slices() {
        let small: Vec<[u32; 4]> = (0..10).map(|i| [i, i + 1, i + 2, i + 3]).collect();
        assert_eq!(&Pages::from_slice(&small)[..], &small[..]);
        assert!(!Pages::from_slice(&small).is_mapped());
        // Below one huge page, and several huge pages with a partial last one.
        for n in [PAGES_MIN_BYTES / 16 + 1, 3 * HUGE_PAGE / 16 + 5] {
            let big: Vec<[u32; 4]> = (0..n as u32).map(|i| [i, !i, i ^ 7, 3]).collect();
            let pages = Pages::from_slice(&big);
            assert_eq!(&pages[..], &big[..]);
            #[cfg(unix)]
            {
                assert!(pages.is_mapped());
                assert_eq!(pages.as_ptr() as usize % HUGE_PAGE, 0);
            }
        }
        let n = MAPPED_MIN_BYTES / 16 + 5;
        let big: Vec<[u32; 4]> = (0..n as u32).map(|i| [i, !i, i ^ 7, 3]).collect();
        let pages = Pages::from_slice(&big);
        assert_eq!(&pages.clone()[..], &big[..]);
        assert!(Pages::<u32>::default().is_empty());
    }

    #[test]
    fn vectors_convert_both_ways() {
        let w = Words::from(vec![1, 2, 3]);
        assert_eq!(&w[..], &[1, 2, 3]);
        assert_eq!(w.into_vec(), vec![1, 2, 3]);
    }
}
