//! Contract 1 of `docs/architecture.md`: every structure is encoded once into a byte-exact
//! memory image, which CPU traversal reads and the simulator reads at the same addresses.
//!
//! Layout of every image, in 32-bit words from byte address 0:
//!
//! | region | contents |
//! |---|---|
//! | nodes | the structure's nodes, depth-first, siblings adjacent |
//! | indices | triangle-index lists of the leaves |
//! | triangles | the scene's triangles, 36 B each (9 × f32), in triangle-id order |

use std::ops::Range;

/// A structure's memory image: words plus the word ranges of its three regions.
#[derive(Clone, Debug, Default)]
pub struct MemoryImage {
    /// The image, as little-endian 32-bit words (f32 values stored as their bits).
    pub words: Vec<u32>,
    /// Word range of the node region.
    pub nodes: Range<usize>,
    /// Word range of the triangle-index region.
    pub indices: Range<usize>,
    /// Word range of the triangle region.
    pub triangles: Range<usize>,
}

impl MemoryImage {
    /// Byte address of word `i`.
    #[inline(always)]
    pub fn addr(word: usize) -> u64 {
        word as u64 * 4
    }
    /// Bytes of the node region.
    pub fn node_bytes(&self) -> u64 {
        (self.nodes.len() * 4) as u64
    }
    /// Bytes of the triangle-index region.
    pub fn index_bytes(&self) -> u64 {
        (self.indices.len() * 4) as u64
    }
    /// Bytes of the triangle region.
    pub fn triangle_bytes(&self) -> u64 {
        (self.triangles.len() * 4) as u64
    }
    /// The whole image as bytes (little-endian).
    pub fn to_bytes(&self) -> Vec<u8> {
        self.words.iter().flat_map(|w| w.to_le_bytes()).collect()
    }
}
