//! The 32-bit header-offset word of a dual-split tree node (Lin et al. 2020, §3, Fig. 4;
//! the bit layout of `docs/dst-encoding.md`, §1).
//!
//! ```text
//! bit:   31 | 30 29 | 28 27 | 26 | 25 ............................ 0
//!        C  |  A    |  B    | L  | offset (26 bits, unit = one 32-bit word / one index entry)
//! ```
//!
//! | C | L | A | B | node | offset |
//! |---|---|---|---|---|---|
//! | 0 | 1 | 00 | 00 | leaf (1 word) | first entry of the triangle-index run |
//! | 0 | 0 | split axis 0–2 | left-child size in words (01 = leaf, 11 = 3-word node) | splitting node | word of the left child; right = left + size |
//! | 1 | L | 10 | carving axis 0–2 | single-axis carving | child word (L = 0) or index run (L = 1) |
//! | 1 | L | 00 = xy, 01 = xz, 11 = yz | corner bits (28 ↔ first axis, 27 ↔ second; 1 = lower bound) | dual-axis carving | child word (L = 0) or index run (L = 1) |
//!
//! 37 of the 64 header codes are valid ([`HeaderOffset::ALL_VALID_HEADERS`]).
//!
//! Worked example: `0x5800_0010` = `0 10 11 0` + offset 16 is a splitting node on z whose
//! left child is a 3-word node at word 16 and whose right child is at word 19.

use super::DstError;
use crate::observer::DstNodeKind;
use std::fmt;

/// Largest offset + 1 a header can hold: 2^26 words (256 MiB of nodes) or index entries.
pub const OFFSET_LIMIT: u64 = 1 << 26;

const OFFSET_MASK: u32 = (1 << 26) - 1;
const BIT_C: u32 = 1 << 31;
const BIT_L: u32 = 1 << 26;
const SHIFT_A: u32 = 29;
const SHIFT_B: u32 = 27;
/// Field A value that marks a single-axis carving node (it would decode to the pair (y, y)).
const A_SINGLE: u32 = 0b10;

/// An axis pair of a dual-axis carving node (field A). Plane P0 lies on the first axis,
/// P1 on the second (Lin et al. 2020, §3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AxisPair {
    /// x and y (A = 00).
    Xy = 0b00,
    /// x and z (A = 01).
    Xz = 0b01,
    /// y and z (A = 11).
    Yz = 0b11,
}

impl AxisPair {
    /// All pairs.
    pub const ALL: [AxisPair; 3] = [AxisPair::Xy, AxisPair::Xz, AxisPair::Yz];

    /// The pair of two different axes (in any order).
    pub fn from_axes(a: usize, b: usize) -> Option<Self> {
        match (a.min(b), a.max(b)) {
            (0, 1) => Some(Self::Xy),
            (0, 2) => Some(Self::Xz),
            (1, 2) => Some(Self::Yz),
            _ => None,
        }
    }

    /// `(first, second)` axis: first = A >> 1, second = (A & 1) + 1, so A = 00, 01, 11 give
    /// (x, y), (x, z), (y, z) and A = 10 is free to mean single-axis carving.
    #[inline(always)]
    pub fn axes(self) -> (usize, usize) {
        let a = self as usize;
        (a >> 1, (a & 1) + 1)
    }
}

/// The corner type of a dual-axis carving node (field B): for each of its two planes,
/// whether the plane is a lower bound of the child region (empty space below it) or an
/// upper bound (Lin et al. 2020, §3, Fig. 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Corner {
    /// Plane P0 (first axis) is a lower bound (bit 28).
    pub first_lower: bool,
    /// Plane P1 (second axis) is a lower bound (bit 27).
    pub second_lower: bool,
}

impl Corner {
    /// The 2-bit field value.
    #[inline(always)]
    pub fn bits(self) -> u32 {
        ((self.first_lower as u32) << 1) | self.second_lower as u32
    }
    /// From the 2-bit field value.
    #[inline(always)]
    pub fn from_bits(b: u32) -> Self {
        Self {
            first_lower: b & 2 != 0,
            second_lower: b & 1 != 0,
        }
    }
}

/// A node's header-offset word. Construct with the checked constructors; read with the
/// named accessors (traversal never shifts or masks by hand). Lin et al. 2020, §3, Fig. 4.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct HeaderOffset(u32);

const _: () = assert!(std::mem::size_of::<HeaderOffset>() == 4);

fn check_offset(offset: u64) -> Result<u32, DstError> {
    if offset >= OFFSET_LIMIT {
        Err(DstError::OffsetOverflow {
            given: offset,
            limit: OFFSET_LIMIT,
        })
    } else {
        Ok(offset as u32)
    }
}

impl HeaderOffset {
    /// Every valid 6-bit header code (word bits 31:26): 1 leaf + 6 splitting + 6 single-axis
    /// carving + 24 dual-axis carving = 37.
    pub const ALL_VALID_HEADERS: [u8; 37] = {
        let mut out = [0u8; 37];
        let mut n = 0;
        let mut h = 0u32;
        while h < 64 {
            if Self::header_is_valid(h) {
                out[n] = h as u8;
                n += 1;
            }
            h += 1;
        }
        assert!(n == 37);
        out
    };

    const fn header_is_valid(h: u32) -> bool {
        let c = h >> 5;
        let a = (h >> 3) & 3;
        let b = (h >> 1) & 3;
        let l = h & 1;
        if c == 0 {
            if l == 1 {
                a == 0 && b == 0
            } else {
                a < 3 && (b == 1 || b == 3)
            }
        } else if a == A_SINGLE {
            b < 3
        } else {
            true
        }
    }

    /// A plain leaf word whose run starts at index entry `first_index`.
    pub fn leaf(first_index: u64) -> Result<Self, DstError> {
        Ok(Self(BIT_L | check_offset(first_index)?))
    }

    /// A splitting node on `axis` whose left child (`left_size` = 1 or 3 words) is at word
    /// `left`; the right child is at `left + left_size`.
    ///
    /// # Panics
    /// When `axis > 2` or `left_size` is not 1 or 3 (a converter bug, not bad input).
    pub fn split(axis: usize, left_size: u32, left: u64) -> Result<Self, DstError> {
        assert!(axis < 3 && (left_size == 1 || left_size == 3));
        Ok(Self(
            ((axis as u32) << SHIFT_A) | (left_size << SHIFT_B) | check_offset(left)?,
        ))
    }

    /// A single-axis carving node on `axis`; `leaf_flag` = the offset is an index run.
    ///
    /// # Panics
    /// When `axis > 2` (a converter bug, not bad input).
    pub fn single_carve(axis: usize, leaf_flag: bool, offset: u64) -> Result<Self, DstError> {
        assert!(axis < 3);
        Ok(Self(
            BIT_C
                | (A_SINGLE << SHIFT_A)
                | ((axis as u32) << SHIFT_B)
                | ((leaf_flag as u32) << 26)
                | check_offset(offset)?,
        ))
    }

    /// A dual-axis carving node; `leaf_flag` = the offset is an index run.
    pub fn dual_carve(
        pair: AxisPair,
        corner: Corner,
        leaf_flag: bool,
        offset: u64,
    ) -> Result<Self, DstError> {
        Ok(Self(
            BIT_C
                | ((pair as u32) << SHIFT_A)
                | (corner.bits() << SHIFT_B)
                | ((leaf_flag as u32) << 26)
                | check_offset(offset)?,
        ))
    }

    /// This carving node (built with offset 0 and L = 0) pointing at `offset`: a child word,
    /// or with `leaf_flag` the first entry of an index run. Lets a converter build a
    /// carving node's header once and point copies of it anywhere.
    #[inline(always)]
    pub fn carve_pointing_at(self, leaf_flag: bool, offset: u64) -> Result<Self, DstError> {
        debug_assert!(self.0 & BIT_C != 0 && self.0 & (BIT_L | OFFSET_MASK) == 0);
        Ok(Self(
            self.0 | ((leaf_flag as u32) << 26) | check_offset(offset)?,
        ))
    }

    /// The raw word.
    #[inline(always)]
    pub fn bits(self) -> u32 {
        self.0
    }

    /// Reinterprets a raw word without checking its header (see [`HeaderOffset::decode`]).
    #[inline(always)]
    pub fn from_bits(word: u32) -> Self {
        Self(word)
    }

    /// Decodes a raw word, rejecting the 27 invalid header codes.
    pub fn decode(word: u32, at: u32) -> Result<Self, DstError> {
        if Self::header_is_valid(word >> 26) {
            Ok(Self(word))
        } else {
            Err(DstError::InvalidHeader { at, word })
        }
    }

    /// The 6-bit header (word bits 31:26).
    #[inline(always)]
    pub fn header(self) -> u8 {
        (self.0 >> 26) as u8
    }

    /// The 26-bit offset (word bits 25:0).
    #[inline(always)]
    pub fn offset(self) -> u32 {
        self.0 & OFFSET_MASK
    }

    /// Bit C: a carving node (single- or dual-axis).
    #[inline(always)]
    pub fn is_carving(self) -> bool {
        self.0 & BIT_C != 0
    }

    /// Bit L: for a carving node, "this carving node is a leaf" (the offset is an index run);
    /// for C = 0, a plain leaf word.
    #[inline(always)]
    pub fn is_leaf_flag(self) -> bool {
        self.0 & BIT_L != 0
    }

    #[inline(always)]
    fn field_a(self) -> u32 {
        (self.0 >> SHIFT_A) & 3
    }

    #[inline(always)]
    fn field_b(self) -> u32 {
        (self.0 >> SHIFT_B) & 3
    }

    /// True for a dual-axis carving node (C = 1, A ≠ 10).
    #[inline(always)]
    pub fn is_dual(self) -> bool {
        self.is_carving() & (self.field_a() != A_SINGLE)
    }

    /// True for a splitting node (C = 0, L = 0).
    #[inline(always)]
    pub fn is_split(self) -> bool {
        !self.is_carving() & !self.is_leaf_flag()
    }

    /// True for a plain leaf word (C = 0, L = 1).
    #[inline(always)]
    pub fn is_plain_leaf(self) -> bool {
        !self.is_carving() & self.is_leaf_flag()
    }

    /// The derived 2-bit node type of the hardware (Lin et al. 2020, §3).
    #[inline(always)]
    pub fn node_kind(self) -> DstNodeKind {
        if !self.is_carving() {
            if self.is_leaf_flag() {
                DstNodeKind::Leaf
            } else {
                DstNodeKind::Split
            }
        } else if self.field_a() == A_SINGLE {
            DstNodeKind::SingleCarve
        } else {
            DstNodeKind::DualCarve
        }
    }

    /// The axis of a splitting (field A) or single-axis carving (field B) node; for a
    /// dual-axis node, its first axis.
    #[inline(always)]
    pub fn axis(self) -> usize {
        if self.is_carving() {
            if self.field_a() == A_SINGLE {
                self.field_b() as usize
            } else {
                self.axis_pair().axes().0
            }
        } else {
            self.field_a() as usize
        }
    }

    /// The axis pair of a dual-axis carving node (meaningless for other kinds).
    #[inline(always)]
    pub fn axis_pair(self) -> AxisPair {
        match self.field_a() {
            0 => AxisPair::Xy,
            1 => AxisPair::Xz,
            _ => AxisPair::Yz,
        }
    }

    /// The raw 2-bit axis-pair field (A), for datapath-style selection.
    #[inline(always)]
    pub fn axis_pair_bits(self) -> u32 {
        self.field_a()
    }

    /// The raw 2-bit field B (left size, corner or carving axis), for datapath-style selection.
    #[inline(always)]
    pub fn field_b_bits(self) -> u32 {
        self.field_b()
    }

    /// The corner type of a dual-axis carving node.
    #[inline(always)]
    pub fn corner(self) -> Corner {
        Corner::from_bits(self.field_b())
    }

    /// The left child's size in words (1 or 3) of a splitting node.
    #[inline(always)]
    pub fn left_size(self) -> u32 {
        self.field_b()
    }

    /// Words this node occupies: 1 for a plain leaf, 3 otherwise.
    #[inline(always)]
    pub fn size_words(self) -> u32 {
        if self.is_plain_leaf() { 1 } else { 3 }
    }
}

impl fmt::Debug for HeaderOffset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let h = self.header();
        write!(
            f,
            "HeaderOffset {{ C={} A={:02b} B={:02b} L={} ({:?}",
            h >> 5,
            (h >> 3) & 3,
            (h >> 1) & 3,
            h & 1,
            self.node_kind()
        )?;
        match self.node_kind() {
            DstNodeKind::Split => {
                write!(f, " axis {} left size {}", self.axis(), self.left_size())?
            }
            DstNodeKind::SingleCarve => write!(f, " axis {}", self.axis())?,
            DstNodeKind::DualCarve => write!(f, " {:?} {:?}", self.axis_pair(), self.corner())?,
            DstNodeKind::Leaf => {}
        }
        write!(f, "), offset {} }}", self.offset())
    }
}
