//! The node record of a quantized DST cluster: the exact DST's 6-bit header code with a
//! child field that is short when the child lies in the same cluster, followed by two k-bit
//! plane offsets (`docs/dstq-encoding.md`, §3).
//!
//! ```text
//! header, LSB-first in the cluster's bit stream:
//! bit:   0 .......... 5 | 6 | 7 ............................................ 31
//!        code C A B L   |   payload
//!        L = 1:           run: first index entry of the triangle run (26 bits, bits 6–31)
//!        L = 0:         X | X = 1: word address of the child's cluster (25 bits, bits 7–31)
//!                         | X = 0: bit position of the child record in this cluster
//!                         |        (W bits, bits 7 .. 7+W; W = 9 for 64-byte clusters)
//! code = C·32 + A·8 + B·2 + L: bits 31–26 of the exact DST's header-offset word
//!
//! header: 32 bits (L = 1, or X = 1)  or  7 + W bits (X = 0, "short")
//! record: header | q0 (k bits) | q1 (k bits)      internal node
//!         header                                  plain leaf (always 32 bits)
//! ```
//!
//! C, A, B and L mean what they mean in the exact DST ([`HeaderOffset`]), with one addition:
//! a splitting node's B field (the left child's size) has three values, 01 = the left record
//! is a plain leaf (32 bits), 11 = an internal record with a 32-bit header (32 + 2k bits),
//! 10 = an internal record with a short header (7 + W + 2k bits); the right child's record
//! follows the left one, in this cluster or in the child cluster. So 40 codes are valid: the
//! exact DST's 37 and the three splits with B = 10. Records are packed LSB-first into the
//! cluster's little-endian words with no alignment, so a record may straddle a word boundary.

use crate::dst::{DstError, HeaderOffset};
use crate::observer::DstNodeKind;

/// Largest cluster word address + 1: 2^25 (128 MiB of node words).
pub const CHILD_LIMIT: u64 = 1 << 25;
/// Largest run offset + 1: 2^26 index entries, as the exact DST.
pub const RUN_LIMIT: u64 = 1 << 26;

/// The record geometry of a config: plane offset bits k and local child-field bits W.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct RecordFormat {
    /// Bits per plane offset.
    pub k: u32,
    /// Bits of a local child position: enough for every bit position of a cluster.
    pub w: u32,
}

impl RecordFormat {
    /// The format of `k`-bit planes in clusters of `cluster_bytes` bytes.
    pub fn new(k: u32, cluster_bytes: u32) -> Self {
        let max_bit = cluster_bytes * 8 - 1;
        Self {
            k,
            w: 32 - max_bit.leading_zeros(),
        }
    }

    /// Bits of a short header: 7 + W.
    #[inline(always)]
    pub fn short_header_bits(&self) -> u32 {
        7 + self.w
    }
}

/// Where a record's child (or a split's left child) lies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ChildRef {
    /// The record at this bit position of the same cluster (a short header).
    Local(u32),
    /// The first root of the cluster whose frame is at this word of the node region (at bit
    /// [`super::layout::ROOT_BIT`] of the cluster).
    Cluster(u32),
}

/// The kind of a splitting node's left child record (field B).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LeftRecord {
    /// A plain leaf, 32 bits (B = 01).
    Leaf,
    /// An internal record with a 32-bit header (B = 11): a carving leaf or a node whose
    /// child is in another cluster.
    Long,
    /// An internal record with a short header (B = 10): its child is in the same cluster.
    Short,
}

const CODE_MASK: u32 = 63;
const BIT_L: u32 = 1;
const BIT_X: u32 = 1 << 6;
/// The code of a splitting node with left size field B = 10 (a short left record).
const B_SHORT: u32 = 0b10;

/// A record's header. Built with [`QHeader::split`], [`QHeader::carve`], [`QHeader::leaf`],
/// [`QHeader::carve_leaf`]; read from a cluster with [`QHeader::read`] or checked with
/// [`QHeader::decode`]; its fields only through the named accessors.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub struct QHeader(u32);

const _: () = assert!(std::mem::size_of::<QHeader>() == 4);

impl QHeader {
    /// True for the 40 valid codes: the exact DST's 37 and splits with B = 10.
    pub fn code_is_valid(code: u32) -> bool {
        let exact = HeaderOffset::decode(code << 26, 0).is_ok();
        let short_split = code >> 5 == 0 && code & BIT_L == 0 && (code >> 3) & 3 < 3 && {
            (code >> 1) & 3 == B_SHORT
        };
        exact || short_split
    }

    fn with_run(code: u32, run: u64) -> Result<Self, DstError> {
        if run >= RUN_LIMIT {
            return Err(DstError::OffsetOverflow {
                given: run,
                limit: RUN_LIMIT,
            });
        }
        Ok(Self(code | (run as u32) << 6))
    }

    fn with_child(code: u32, child: ChildRef, fmt: &RecordFormat) -> Result<Self, DstError> {
        let (x, v, limit) = match child {
            ChildRef::Local(b) => (0, b, 1u64 << fmt.w),
            ChildRef::Cluster(c) => (BIT_X, c, CHILD_LIMIT),
        };
        if v as u64 >= limit {
            return Err(DstError::OffsetOverflow {
                given: v as u64,
                limit,
            });
        }
        Ok(Self(code | x | v << 7))
    }

    /// A plain leaf whose run starts at index entry `first` (as the DST's leaf word).
    pub fn leaf(first: u64) -> Result<Self, DstError> {
        Self::with_run(HeaderOffset::leaf(0)?.header() as u32, first)
    }

    /// A splitting node on `axis` whose left child record is `left`, found at `child`; the
    /// right one follows it.
    ///
    /// # Panics
    /// When `axis > 2` (a converter bug, not bad input).
    pub fn split(
        axis: usize,
        left: LeftRecord,
        child: ChildRef,
        fmt: &RecordFormat,
    ) -> Result<Self, DstError> {
        assert!(axis < 3);
        let b = match left {
            LeftRecord::Leaf => 0b01,
            LeftRecord::Long => 0b11,
            LeftRecord::Short => B_SHORT,
        };
        Self::with_child((axis as u32) << 3 | b << 1, child, fmt)
    }

    /// The exact DST carving node `exact` (its C, A, B fields) pointing at `child`.
    pub fn carve(
        exact: HeaderOffset,
        child: ChildRef,
        fmt: &RecordFormat,
    ) -> Result<Self, DstError> {
        Self::with_child(exact.header() as u32 & !BIT_L, child, fmt)
    }

    /// The exact DST carving leaf `exact` (L = 1), whose run starts at entry `first`.
    pub fn carve_leaf(exact: HeaderOffset, first: u64) -> Result<Self, DstError> {
        Self::with_run(exact.header() as u32 | BIT_L, first)
    }

    /// The header at the start of the 32 bits `raw` read at a record's position (the bits
    /// after a short header belong to the planes and are dropped). Does not check the code.
    #[inline(always)]
    pub fn read(raw: u32, fmt: &RecordFormat) -> Self {
        let short = raw & BIT_L == 0 && raw & BIT_X == 0;
        if short {
            Self(raw & ((1 << fmt.short_header_bits()) - 1))
        } else {
            Self(raw)
        }
    }

    /// [`QHeader::read`], rejecting the invalid codes.
    pub fn decode(raw: u32, fmt: &RecordFormat, at: u32) -> Result<Self, DstError> {
        if Self::code_is_valid(raw & CODE_MASK) {
            Ok(Self::read(raw, fmt))
        } else {
            Err(DstError::InvalidHeader { at, word: raw })
        }
    }

    /// The header's bits (the low [`QHeader::header_bits`] of them are stored).
    #[inline(always)]
    pub fn bits(self) -> u32 {
        self.0
    }

    /// The 6-bit code: bits 31–26 of the exact DST's header word.
    #[inline(always)]
    pub fn code(self) -> u32 {
        self.0 & CODE_MASK
    }

    /// The fields C, A, B, L read as the exact DST's header (kind, axis, pair, corner).
    #[inline(always)]
    pub fn exact(self) -> HeaderOffset {
        HeaderOffset::from_bits(self.code() << 26)
    }

    /// The node kind.
    #[inline(always)]
    pub fn node_kind(self) -> DstNodeKind {
        self.exact().node_kind()
    }

    /// Bit L: the payload is a triangle run (plain leaf or carving leaf).
    #[inline(always)]
    pub fn is_leaf_flag(self) -> bool {
        self.0 & BIT_L != 0
    }

    /// The 26-bit index entry of a run (L = 1).
    #[inline(always)]
    pub fn run(self) -> u32 {
        self.0 >> 6
    }

    /// A header of 7 + W bits (L = 0, X = 0).
    #[inline(always)]
    pub fn is_short(self) -> bool {
        self.0 & (BIT_L | BIT_X) == 0
    }

    /// The child of a carving node (L = 0) or the left child of a splitting node.
    #[inline(always)]
    pub fn child(self, fmt: &RecordFormat) -> ChildRef {
        if self.0 & BIT_X != 0 {
            ChildRef::Cluster(self.0 >> 7)
        } else {
            ChildRef::Local((self.0 >> 7) & ((1 << fmt.w) - 1))
        }
    }

    /// A splitting node's left record kind (field B; B = 00 reads as a plain leaf).
    #[inline(always)]
    pub fn left_record(self) -> LeftRecord {
        match (self.0 >> 1) & 3 {
            0b11 => LeftRecord::Long,
            B_SHORT => LeftRecord::Short,
            _ => LeftRecord::Leaf,
        }
    }

    /// Bits of a splitting node's left child record.
    #[inline(always)]
    pub fn left_bits(self, fmt: &RecordFormat) -> u32 {
        match self.left_record() {
            LeftRecord::Leaf => 32,
            LeftRecord::Long => 32 + 2 * fmt.k,
            LeftRecord::Short => fmt.short_header_bits() + 2 * fmt.k,
        }
    }

    /// Bits of the header: 7 + W when short, else 32.
    #[inline(always)]
    pub fn header_bits(self, fmt: &RecordFormat) -> u32 {
        if self.is_short() {
            fmt.short_header_bits()
        } else {
            32
        }
    }

    /// Bits of this record: the header, plus 2k for an internal node.
    #[inline(always)]
    pub fn record_bits(self, fmt: &RecordFormat) -> u32 {
        let planes = if self.exact().is_plain_leaf() {
            0
        } else {
            2 * fmt.k
        };
        self.header_bits(fmt) + planes
    }

    /// The record kind this header makes for its parent's B field.
    pub fn as_left(self) -> LeftRecord {
        if self.exact().is_plain_leaf() {
            LeftRecord::Leaf
        } else if self.is_short() {
            LeftRecord::Short
        } else {
            LeftRecord::Long
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
    fn forty_valid_codes() {
        assert_eq!((0..64).filter(|&c| QHeader::code_is_valid(c)).count(), 40);
    }

    #[test]
    fn child_refs_round_trip() {
        let fmt = RecordFormat::new(8, 64);
        assert_eq!((fmt.w, fmt.short_header_bits()), (9, 16));
        assert_eq!(RecordFormat::new(8, 128).w, 10);
        for c in [
            ChildRef::Local(0),
            ChildRef::Local(511),
            ChildRef::Cluster(0),
            ChildRef::Cluster((1 << 25) - 1),
        ] {
            let h = QHeader::split(2, LeftRecord::Short, c, &fmt).unwrap();
            let h = QHeader::read(h.bits() | (0xffff_0000 * h.is_short() as u32), &fmt);
            assert_eq!(h.child(&fmt), c);
            assert_eq!(h.left_record(), LeftRecord::Short);
            assert_eq!(h.node_kind(), DstNodeKind::Split);
            assert_eq!(h.is_short(), matches!(c, ChildRef::Local(_)));
        }
        assert!(QHeader::split(0, LeftRecord::Leaf, ChildRef::Cluster(1 << 25), &fmt).is_err());
        assert!(QHeader::split(0, LeftRecord::Leaf, ChildRef::Local(512), &fmt).is_err());
        assert!(QHeader::leaf(1 << 26).is_err());
    }
}
