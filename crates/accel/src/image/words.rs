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

use memmap2::MmapMut;
use std::fmt;
use std::ops::{Deref, DerefMut};

/// Images of at least this many bytes are mapped with the huge-page advice (one huge page).
pub const MAPPED_MIN_BYTES: usize = 2 << 20;

/// The words of a [`super::MemoryImage`]; dereferences to `[u32]`.
pub struct Words(Buf);

enum Buf {
    Heap(Vec<u32>),
    /// An anonymous mapping of exactly `4 · len` bytes (page-aligned, zero-filled).
    Mapped(MmapMut),
}

impl Words {
    /// `n` zeroed words; large buffers ([`MAPPED_MIN_BYTES`]) are an anonymous mapping with
    /// the transparent-huge-page advice, falling back to a vector if mapping fails.
    pub fn zeroed(n: usize) -> Words {
        if n.saturating_mul(4) >= MAPPED_MIN_BYTES
            && let Ok(map) = MmapMut::map_anon(n * 4)
        {
            // Advice is a hint: a kernel without transparent huge pages keeps 4 KiB pages.
            #[cfg(target_os = "linux")]
            let _ = map.advise(memmap2::Advice::HugePage);
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
            // Page-aligned and 4·len bytes long, so the cast cannot fail.
            Buf::Mapped(m) => bytemuck::cast_slice(&m[..]),
        }
    }
}

impl DerefMut for Words {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [u32] {
        match &mut self.0 {
            Buf::Heap(v) => v,
            Buf::Mapped(m) => bytemuck::cast_slice_mut(&mut m[..]),
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

/// An array of plain data that, when large ([`MAPPED_MIN_BYTES`]), lives in an anonymous
/// mapping advised to use transparent huge pages, as [`Words`] does; dereferences to `[T]`.
///
/// For data read at random, such as the CPU-side copies of the traversal
/// ([`crate::wide::cpu`]): with 4 KiB pages nearly every node of a large scene costs a TLB
/// miss (a two-level page walk under virtualisation); 2 MiB pages cover it with a few
/// hundred entries. The contents are the same either way.
pub struct Pages<T: bytemuck::Pod>(PagesBuf<T>);

enum PagesBuf<T> {
    Heap(Vec<T>),
    /// A page-aligned anonymous mapping of `len · size_of::<T>()` bytes.
    Mapped(MmapMut, usize),
}

impl<T: bytemuck::Pod> Pages<T> {
    /// A copy of `items`.
    pub fn from_slice(items: &[T]) -> Self {
        let bytes = std::mem::size_of_val(items);
        // A page-aligned mapping suits any alignment of `T` up to a page.
        if bytes >= MAPPED_MIN_BYTES
            && std::mem::align_of::<T>() <= 4096
            && let Ok(mut map) = MmapMut::map_anon(bytes)
        {
            #[cfg(target_os = "linux")]
            let _ = map.advise(memmap2::Advice::HugePage);
            map.copy_from_slice(bytemuck::cast_slice(items));
            return Pages(PagesBuf::Mapped(map, items.len()));
        }
        Pages(PagesBuf::Heap(items.to_vec()))
    }
}

impl<T: bytemuck::Pod> Deref for Pages<T> {
    type Target = [T];
    #[inline(always)]
    fn deref(&self) -> &[T] {
        match &self.0 {
            PagesBuf::Heap(v) => v,
            PagesBuf::Mapped(m, len) => &bytemuck::cast_slice(&m[..])[..*len],
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
            .field("mapped", &matches!(self.0, PagesBuf::Mapped(..)))
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
        assert!(big.is_mapped());
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
        let n = MAPPED_MIN_BYTES / 16 + 5;
        let big: Vec<[u32; 4]> = (0..n as u32).map(|i| [i, !i, i ^ 7, 3]).collect();
        let pages = Pages::from_slice(&big);
        assert_eq!(&pages[..], &big[..]);
        #[cfg(unix)]
        assert!(format!("{pages:?}").contains("mapped: true"));
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
