//! Typed addresses of the simulated memory.

/// A 4-byte word address (byte address / 4) in the simulated memory.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct WordAddr(pub u64);

impl WordAddr {
    /// The word holding byte address `byte`.
    pub fn from_byte(byte: u64) -> Self {
        Self(byte >> 2)
    }
}
