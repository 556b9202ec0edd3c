//! Typed addresses of the simulated memory: a 4-byte word ([`WordAddr`], byte address / 4)
//! and a cache line ([`LineAddr`], byte address / line size). The memory units take these,
//! never a bare number, so a word index cannot be passed where a line is meant.

/// A 4-byte word address (byte address / 4) in the simulated memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct WordAddr(u64);

impl WordAddr {
    /// Word `word` (byte address / 4).
    #[inline(always)]
    pub const fn new(word: u64) -> Self {
        Self(word)
    }
    /// The word holding byte address `byte`.
    #[inline(always)]
    pub const fn from_byte(byte: u64) -> Self {
        Self(byte >> 2)
    }
    /// The word index.
    #[inline(always)]
    pub const fn get(self) -> u64 {
        self.0
    }
}

/// A cache-line address (byte address / line size) in the simulated memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct LineAddr(u64);

impl LineAddr {
    /// Line `line` (byte address / line size).
    #[inline(always)]
    pub const fn new(line: u64) -> Self {
        Self(line)
    }
    /// The line index.
    #[inline(always)]
    pub const fn get(self) -> u64 {
        self.0
    }
}
