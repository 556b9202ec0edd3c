//! The node record of a quantized DST cluster: the exact DST's 32-bit header-offset word
//! with its offset field reinterpreted, followed by two k-bit plane offsets
//! (`docs/dstq-encoding.md`, §3).
//!
//! ```text
//! header word:
//! bit:   31 | 30 29 | 28 27 | 26 | 25 | 24 ..................... 0
//!        C  |  A    |  B    | L  |          offset (26 bits)
//!                             L = 1:  index entry of the triangle run (26 bits, as the DST)
//!                             L = 0:  X  | child (25 bits)
//!                                     X = 0: bit position of the child record in this cluster
//!                                     X = 1: word address of the child's cluster (its
//!                                            frame; its roots start 128 bits later)
//! record:  header (32 bits) | q0 (k bits) | q1 (k bits)      internal node: 32 + 2k bits
//!          header (32 bits)                                  plain leaf:    32 bits
//! ```
//!
//! C, A, B and L mean what they mean in the exact DST ([`HeaderOffset`]; the same 37 valid
//! codes). A splitting node's B field (left size 01 / 11) now names the left child's record
//! size, 32 or 32 + 2k bits: the right child's record follows the left one, in this cluster
//! or in the child cluster. Records are packed LSB-first into the cluster's little-endian
//! words, so a record may straddle a word boundary.

use crate::dst::{DstError, HeaderOffset};
use crate::observer::DstNodeKind;

/// Bit 25 of the offset field: the child lies in another cluster.
const BIT_X: u32 = 1 << 25;
/// Mask of the 25-bit child field.
const CHILD_MASK: u32 = BIT_X - 1;
/// Largest child bit position or cluster word address + 1: 2^25 (128 MiB of node words).
pub const CHILD_LIMIT: u64 = 1 << 25;

/// Where a record's child (or a split's left child) lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ChildRef {
    /// The record at this bit position of the same cluster.
    Local(u32),
    /// The first root of the cluster whose frame is at this word of the node region (at bit
    /// [`super::layout::ROOT_BIT`] of the cluster).
    Cluster(u32),
}

impl ChildRef {
    fn field(self) -> Result<u32, DstError> {
        let (x, v) = match self {
            ChildRef::Local(b) => (0, b),
            ChildRef::Cluster(c) => (BIT_X, c),
        };
        if v as u64 >= CHILD_LIMIT {
            return Err(DstError::OffsetOverflow {
                given: v as u64,
                limit: CHILD_LIMIT,
            });
        }
        Ok(x | v)
    }
}

/// A record's header word. Built with [`QHeader::split`], [`QHeader::carve`],
/// [`QHeader::leaf`] from an exact DST header; read with the named accessors.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub struct QHeader(HeaderOffset);

const _: () = assert!(std::mem::size_of::<QHeader>() == 4);

impl QHeader {
    /// A plain leaf whose run starts at index entry `first` (as the DST's leaf word).
    pub fn leaf(first: u64) -> Result<Self, DstError> {
        HeaderOffset::leaf(first).map(Self)
    }

    /// A splitting node on `axis` whose left child record is `left_internal` (32 + 2k bits)
    /// or a plain leaf (32 bits), found at `left`; the right one follows it.
    pub fn split(axis: usize, left_internal: bool, left: ChildRef) -> Result<Self, DstError> {
        let size = if left_internal { 3 } else { 1 };
        HeaderOffset::split(axis, size, left.field()? as u64).map(Self)
    }

    /// The exact DST carving node `exact` (its C, A, B fields) pointing at the child `child`.
    pub fn carve(exact: HeaderOffset, child: ChildRef) -> Result<Self, DstError> {
        let bare = HeaderOffset::from_bits(exact.bits() & !((1 << 27) - 1));
        bare.carve_pointing_at(false, child.field()? as u64)
            .map(Self)
    }

    /// The exact DST carving leaf `exact` (L = 1), whose run starts at entry `first`.
    pub fn carve_leaf(exact: HeaderOffset, first: u64) -> Result<Self, DstError> {
        let bare = HeaderOffset::from_bits(exact.bits() & !((1 << 27) - 1));
        bare.carve_pointing_at(true, first).map(Self)
    }

    /// Decodes a raw word, rejecting the exact DST's 27 invalid header codes.
    pub fn decode(word: u32, at: u32) -> Result<Self, DstError> {
        HeaderOffset::decode(word, at).map(Self)
    }

    /// Reinterprets a raw word without checking its header.
    #[inline(always)]
    pub fn from_bits(word: u32) -> Self {
        Self(HeaderOffset::from_bits(word))
    }

    /// The raw word.
    #[inline(always)]
    pub fn bits(self) -> u32 {
        self.0.bits()
    }

    /// The fields C, A, B, L read as the exact DST's header (kind, axis, pair, corner).
    #[inline(always)]
    pub fn exact(self) -> HeaderOffset {
        self.0
    }

    /// The node kind.
    #[inline(always)]
    pub fn node_kind(self) -> DstNodeKind {
        self.0.node_kind()
    }

    /// Bit L: the offset is a triangle run (plain leaf or carving leaf).
    #[inline(always)]
    pub fn is_leaf_flag(self) -> bool {
        self.0.is_leaf_flag()
    }

    /// The 26-bit index entry of a run (L = 1).
    #[inline(always)]
    pub fn run(self) -> u32 {
        self.0.offset()
    }

    /// The child of a carving node (L = 0) or the left child of a splitting node.
    #[inline(always)]
    pub fn child(self) -> ChildRef {
        let o = self.0.offset();
        if o & BIT_X != 0 {
            ChildRef::Cluster(o & CHILD_MASK)
        } else {
            ChildRef::Local(o & CHILD_MASK)
        }
    }

    /// A splitting node's left child is an internal record (B = 11), not a plain leaf.
    #[inline(always)]
    pub fn left_is_internal(self) -> bool {
        self.0.left_size() == 3
    }

    /// Bits of this record: 32 for a plain leaf, 32 + 2k otherwise.
    #[inline(always)]
    pub fn record_bits(self, k: u32) -> u32 {
        if self.0.is_plain_leaf() {
            32
        } else {
            32 + 2 * k
        }
    }
}

/// Reads `n ≤ 32` bits at bit position `bit` of `words` (LSB-first); bits past the end
/// read as 0.
#[inline(always)]
pub fn read_bits(words: &[u32], bit: usize, n: u32) -> u32 {
    let w = bit / 32;
    let lo = words.get(w).copied().unwrap_or(0) as u64;
    let hi = words.get(w + 1).copied().unwrap_or(0) as u64;
    let v = ((hi << 32) | lo) >> (bit % 32);
    (v & ((1u64 << n) - 1)) as u32
}

/// Writes the low `n ≤ 32` bits of `v` at bit position `bit` of `words` (LSB-first).
pub fn write_bits(words: &mut [u32], bit: usize, n: u32, v: u32) {
    let mask = (1u64 << n) - 1;
    let v = (v as u64 & mask) << (bit % 32);
    let m = mask << (bit % 32);
    let w = bit / 32;
    words[w] = (words[w] & !(m as u32)) | v as u32;
    if (m >> 32) != 0 {
        words[w + 1] = (words[w + 1] & !((m >> 32) as u32)) | (v >> 32) as u32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_round_trip_across_words() {
        let mut w = [0u32; 4];
        write_bits(&mut w, 20, 32, 0xdead_beef);
        write_bits(&mut w, 52, 12, 0xabc);
        write_bits(&mut w, 64, 4, 0x5);
        assert_eq!(read_bits(&w, 20, 32), 0xdead_beef);
        assert_eq!(read_bits(&w, 52, 12), 0xabc);
        assert_eq!(read_bits(&w, 64, 4), 0x5);
        assert_eq!(read_bits(&w, 120, 32), 0);
    }

    #[test]
    fn child_refs_round_trip() {
        for c in [
            ChildRef::Local(0),
            ChildRef::Local(1000),
            ChildRef::Cluster(0),
            ChildRef::Cluster((1 << 25) - 1),
        ] {
            let h = QHeader::split(2, true, c).unwrap();
            assert_eq!(h.child(), c);
            assert!(h.left_is_internal());
            assert_eq!(h.node_kind(), DstNodeKind::Split);
        }
        assert!(QHeader::split(0, false, ChildRef::Cluster(1 << 25)).is_err());
    }
}
