//! The memory-image contract (README, "What is where"): every structure is encoded once
//! into a byte-exact memory image, which CPU traversal reads and the simulator reads at the
//! same addresses.
//!
//! Layout of every image, in 32-bit words from byte address 0:
//!
//! | region | contents |
//! |---|---|
//! | nodes | the structure's nodes, depth-first, siblings adjacent |
//! | indices | triangle-index lists of the leaves |
//! | triangles | the scene's triangles, 36 B each (9 × f32), in triangle-id order |
//!
//! ## BVH images (BVH2, BVH4, BVH8; Lin et al. 2020, §4.2)
//!
//! The node region starts with the root's internal node at word 0. An internal node stores
//! the boxes of its children, one offset word and the children's types ([`ChildKind`]); the
//! node types are [`crate::bvh2::Node2`] (52 B), [`crate::wide::Node4`] (100 B) and
//! [`crate::wide::Node8`] (200 B). All children of a node are stored consecutively from its
//! offset, in slot order, each taking:
//!
//! | child kind | words in the child block |
//! |---|---|
//! | internal | one whole node (13, 25 or 50 words) |
//! | leaf | one *leaf word*: the absolute word index of the leaf's triangle-index run |
//! | empty | nothing (its slot holds [`dualsplit_geometry::Aabb::DEGENERATE`]) |
//!
//! so child `k` lives at `offset + Σ_{j<k} size(kind_j)`, exactly as the DST finds its right
//! child at "left + size(left)" (Lin et al. 2020, §3). A leaf's index run is a list of triangle
//! ids whose last entry has bit 31 set ([`RUN_END`], as in the DST), so no count is stored.
//! A root that is itself a leaf (tiny scenes) is encoded as a root node with that leaf in
//! slot 0 and empty slots elsewhere; an empty scene is a root node whose slots are all empty.
//!
//! Runs are laid out in the depth-first order of the leaves. All offsets are absolute word
//! indices; the triangle of id `i` is at word `triangles.start + 9·i`.
//!
//! ## Storage
//!
//! The node and index regions are [`MemoryImage::words`] ([`Words`]: one allocation, huge
//! pages where the kernel allows). The triangle region has its addresses like the others,
//! but its data is the scene's triangles shared by every image of the scene
//! ([`SharedTriangles`]) rather than a copy per image; [`MemoryImage::to_bytes`] gives the
//! whole image, and traversal and the simulator see the same bytes at the same addresses.

mod words;

use crate::observer::{ByteAddr, Observer};
use dualsplit_geometry::{Aabb, PrimId, Triangle, Vec3};
use std::ops::Range;
use std::sync::Arc;
pub use words::{MAPPED_MIN_BYTES, PAGES_MIN_BYTES, Pages, Words};

/// Bit 31 of an index-run entry: set on the last triangle id of a leaf's run, in every
/// structure's image (BVH2, BVH4, BVH8 and DST). Triangle ids are therefore below 2^31.
pub const RUN_END: u32 = 1 << 31;

/// The scene's triangles in id order, shared (not copied) by every image built from them.
pub type SharedTriangles = Arc<[Triangle]>;

/// A structure's memory image: the word ranges of its three regions, the words of the node
/// and index regions, and the triangle region's data.
///
/// The triangle region is the scene's triangles, byte for byte and at its own addresses
/// (right after the indices), but its data is shared between the images of one scene
/// instead of copied into each (for dragon_box, 31 MB once instead of once per structure).
/// [`MemoryImage::to_bytes`] gives the whole image as one byte string.
#[derive(Clone, Default)]
pub struct MemoryImage {
    /// The node and index regions, as little-endian 32-bit words (f32 values stored as
    /// their bits); word `i` of the image for `i < indices.end`.
    pub words: Words,
    /// Word range of the node region.
    pub nodes: Range<usize>,
    /// Word range of the triangle-index region.
    pub indices: Range<usize>,
    /// Word range of the triangle region (36 B per triangle, id order).
    pub triangles: Range<usize>,
    /// The triangle region's data.
    pub triangle_data: SharedTriangles,
}

impl std::fmt::Debug for MemoryImage {
    /// The regions and sizes (not the contents: a scene's image has millions of words).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MemoryImage")
            .field("words", &self.words)
            .field("nodes", &self.nodes)
            .field("indices", &self.indices)
            .field("triangles", &self.triangles)
            .field("triangle_count", &self.triangle_data.len())
            .finish()
    }
}

impl MemoryImage {
    /// An image of `nodes` node words and `indices` index words, zeroed for the encoder to
    /// fill, followed by the triangle region holding `triangles` (shared, not copied).
    pub fn with_triangles(nodes: usize, indices: usize, triangles: SharedTriangles) -> MemoryImage {
        let tri_start = nodes + indices;
        MemoryImage {
            words: Words::zeroed(tri_start),
            nodes: 0..nodes,
            indices: nodes..tri_start,
            triangles: tri_start..tri_start + 9 * triangles.len(),
            triangle_data: triangles,
        }
    }

    /// Byte address of word `i`.
    #[inline(always)]
    pub fn addr(word: usize) -> ByteAddr {
        ByteAddr(word as u64 * 4)
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
    /// The whole image as bytes (little-endian): nodes, indices, triangles.
    pub fn to_bytes(&self) -> Vec<u8> {
        let tris: &[u32] = bytemuck::cast_slice(&self.triangle_data);
        self.words
            .iter()
            .chain(tris)
            .flat_map(|w| w.to_le_bytes())
            .collect()
    }
    /// The triangle region viewed as triangles (id order).
    #[inline]
    pub fn triangle_slice(&self) -> &[Triangle] {
        &self.triangle_data
    }
    /// Triangle `prim`, read from the image, reporting the 36-byte fetch to `obs`.
    #[inline(always)]
    pub fn fetch_triangle<O: Observer>(&self, prim: PrimId, obs: &mut O) -> Triangle {
        let w = self.triangles.start + 9 * prim.index();
        obs.fetch(Self::addr(w), 36);
        self.triangle_slice()[prim.index()]
    }
}

/// Errors while encoding a memory image.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ImageError {
    /// A child offset does not fit the node's offset field.
    #[error("{structure}: offset {given} does not fit the {bits}-bit offset field (limit {limit})")]
    OffsetOverflow {
        /// Which node layout.
        structure: &'static str,
        /// The offset to be stored (word index).
        given: u64,
        /// Field width in bits.
        bits: u32,
        /// Largest storable offset.
        limit: u64,
    },
    /// A compressed-BVH8 node's leaf runs span more index words than its 5-bit run
    /// offsets reach (the last leaf's run must start within `limit` words of the node's
    /// triangle base): too many triangles per leaf ([`crate::cwbvh`]).
    #[error(
        "{structure}: a leaf run starts {words} words after the node's triangle base (limit {limit}); use smaller leaves"
    )]
    LeafSpan {
        /// Which node layout.
        structure: &'static str,
        /// Offset of the run that does not fit, in words from the triangle base.
        words: u64,
        /// Largest storable offset.
        limit: u64,
    },
    /// A triangle id is too large for a 31-bit index-list entry.
    #[error("triangle id {given} does not fit a 31-bit index entry (limit {limit})")]
    PrimOverflow {
        /// The id.
        given: u64,
        /// Largest storable id.
        limit: u64,
    },
}

/// The type of one child slot of a BVH node (see the module table).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ChildKind {
    /// Empty slot: degenerate box, takes no space in the child block.
    Empty,
    /// Internal child: a whole node in the child block.
    Internal,
    /// Leaf child: one leaf word in the child block.
    Leaf,
}

/// A BVH internal-node layout stored in a memory image (BVH2, BVH4, BVH8).
///
/// Implementors are `#[repr(C)]` plain-old-data structs of exactly `WORDS` words, read from
/// the image with a bytemuck cast.
pub trait NodeLayout: bytemuck::Pod {
    /// Structure name (for errors and reports).
    const NAME: &'static str;
    /// Child slots.
    const ARITY: usize;
    /// Node size in 32-bit words.
    const WORDS: usize;
    /// Bits of the offset field.
    const OFFSET_BITS: u32;

    /// Encodes a node from its children (at most `ARITY`, filled into slots in order, the
    /// rest empty) and the word offset of its child block.
    fn encode(children: &[(Aabb, ChildKind)], offset: u32) -> Result<Self, ImageError>;
    /// The word offset of the child block.
    fn offset(&self) -> u32;
    /// Kind of slot `k`.
    fn kind(&self, k: usize) -> ChildKind;
    /// The six words of slot `k`'s box as stored: min.xyz, max.xyz (the degenerate box
    /// for an empty slot). Traversal slab-tests these words in place ([`NodeLayout::child_bounds`]
    /// builds an [`Aabb`] from them).
    fn box_words(&self, k: usize) -> &[f32; 6];
    /// Box of slot `k` (degenerate for an empty slot).
    #[inline(always)]
    fn child_bounds(&self, k: usize) -> Aabb {
        words_box(self.box_words(k))
    }

    /// Size in words of a child of kind `kind` inside a child block.
    #[inline(always)]
    fn child_words(kind: ChildKind) -> u32 {
        match kind {
            ChildKind::Empty => 0,
            ChildKind::Internal => Self::WORDS as u32,
            ChildKind::Leaf => 1,
        }
    }

    /// Reads the node at word `at` of `words`.
    #[inline(always)]
    fn read(words: &[u32], at: usize) -> &Self {
        // Word-aligned layouts: the cast checks nothing at run time.
        &bytemuck::cast_slice(&words[at..at + Self::WORDS])[0]
    }

    /// Checks that `offset` fits the offset field.
    fn check_offset(offset: u32) -> Result<u32, ImageError> {
        let limit = (1u64 << Self::OFFSET_BITS) - 1;
        if offset as u64 > limit {
            return Err(ImageError::OffsetOverflow {
                structure: Self::NAME,
                given: offset as u64,
                bits: Self::OFFSET_BITS,
                limit,
            });
        }
        Ok(offset)
    }
}

/// Writes a box as 6 f32 words: min.xyz, max.xyz.
#[inline]
pub(crate) fn box_words(b: Aabb) -> [f32; 6] {
    [b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z]
}

/// Reads a box from 6 f32 words.
#[inline(always)]
pub(crate) fn words_box(w: &[f32; 6]) -> Aabb {
    Aabb::new(Vec3::new(w[0], w[1], w[2]), Vec3::new(w[3], w[4], w[5]))
}

/// True for the box of an empty slot (`min > max` on x, as in [`Aabb::DEGENERATE`]).
#[inline(always)]
pub(crate) fn is_degenerate_box(w: &[f32; 6]) -> bool {
    w[0] > w[3]
}

/// Boxes and packed word of a layout that keeps its child-type bits in the offset word
/// (BVH2, BVH4): empty slots get the degenerate box, and slot `k` of a leaf child sets bit
/// `leaf_bit(k)` of `offset_word`.
pub(crate) fn encode_packed<const N: usize>(
    children: &[(Aabb, ChildKind)],
    offset_word: u32,
    leaf_bit: impl Fn(usize) -> u32,
) -> ([[f32; 6]; N], u32) {
    assert!(
        children.len() <= N,
        "a {N}-wide node has at most {N} children"
    );
    let mut boxes = [box_words(Aabb::DEGENERATE); N];
    let mut packed = offset_word;
    for (k, &(b, kind)) in children.iter().enumerate() {
        if kind == ChildKind::Empty {
            continue;
        }
        boxes[k] = box_words(b);
        if kind == ChildKind::Leaf {
            packed |= 1 << leaf_bit(k);
        }
    }
    (boxes, packed)
}

/// The kind of a slot in a packed layout: empty when its box is degenerate, else leaf when
/// bit `leaf_bit` of `packed` is set.
#[inline(always)]
pub(crate) fn packed_kind(b: &[f32; 6], packed: u32, leaf_bit: u32) -> ChildKind {
    if is_degenerate_box(b) {
        ChildKind::Empty
    } else if packed & (1 << leaf_bit) != 0 {
        ChildKind::Leaf
    } else {
        ChildKind::Internal
    }
}

/// Defines a packed node layout (BVH2, BVH4): `$arity` child boxes (words `6k..6k + 6`)
/// followed by one word holding the child-block offset in its low `32 − $arity` bits and one
/// leaf bit per slot, `leaf_bit(k)`. The layouts differ only in these constants, so the
/// struct and its [`NodeLayout`] implementation are written once here; the doc comment given
/// (the byte table and a worked example) goes on the struct.
macro_rules! packed_node {
    ($(#[$doc:meta])* $node:ident, name $name:literal, arity $arity:literal,
     leaf_bit |$k:ident| $leaf_bit:expr) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        #[repr(C)]
        pub struct $node {
            /// Child boxes.
            pub boxes: [[f32; 6]; $arity],
            /// The child-block offset (the low [`NodeLayout::OFFSET_BITS`] bits) and the
            /// child-type bits (the table above).
            pub packed: u32,
        }

        const _: () = assert!(size_of::<$node>() == 4 * <$node as NodeLayout>::WORDS);

        impl $node {
            /// The packed-word bit that marks child `k` a leaf.
            #[inline(always)]
            fn leaf_bit($k: usize) -> u32 {
                $leaf_bit
            }

            const OFFSET_MASK: u32 = (1 << <$node as NodeLayout>::OFFSET_BITS) - 1;
        }

        impl NodeLayout for $node {
            const NAME: &'static str = $name;
            const ARITY: usize = $arity;
            const WORDS: usize = 6 * $arity + 1;
            const OFFSET_BITS: u32 = 32 - $arity;

            fn encode(children: &[(Aabb, ChildKind)], offset: u32) -> Result<Self, ImageError> {
                let (boxes, packed) = $crate::image::encode_packed::<$arity>(
                    children,
                    Self::check_offset(offset)?,
                    Self::leaf_bit,
                );
                Ok($node { boxes, packed })
            }

            #[inline(always)]
            fn offset(&self) -> u32 {
                self.packed & Self::OFFSET_MASK
            }

            #[inline(always)]
            fn kind(&self, k: usize) -> ChildKind {
                $crate::image::packed_kind(&self.boxes[k], self.packed, Self::leaf_bit(k))
            }

            #[inline(always)]
            fn box_words(&self, k: usize) -> &[f32; 6] {
                &self.boxes[k]
            }
        }
    };
}
pub(crate) use packed_node;

#[cfg(test)]
pub(crate) mod test_support {
    use super::*;
    use proptest::prelude::*;

    /// Up to `arity` children: non-empty ones first (internal or leaf), finite boxes.
    pub fn arb_children(arity: usize) -> impl Strategy<Value = Vec<(Aabb, ChildKind)>> {
        let child = (
            prop::array::uniform3(-1e6f32..1e6),
            prop::array::uniform3(0f32..1e3),
            prop::bool::ANY,
        )
            .prop_map(|(p, e, leaf)| {
                let min = Vec3::from(p);
                (
                    Aabb::new(min, min + Vec3::from(e)),
                    if leaf {
                        ChildKind::Leaf
                    } else {
                        ChildKind::Internal
                    },
                )
            });
        prop::collection::vec(child, 0..=arity)
    }

    /// Encodes, reads back through the word image, and compares every slot.
    pub fn roundtrip<L: NodeLayout>(children: &[(Aabb, ChildKind)], offset: u32) {
        let n = L::encode(children, offset).unwrap();
        let words: Vec<u32> = bytemuck::cast_slice(std::slice::from_ref(&n)).to_vec();
        assert_eq!(words.len(), L::WORDS);
        let back = L::read(&words, 0);
        assert_eq!(back.offset(), offset);
        for k in 0..L::ARITY {
            match children.get(k) {
                Some(&(b, kind)) => {
                    assert_eq!(back.kind(k), kind);
                    assert_eq!(back.child_bounds(k), b);
                }
                None => {
                    assert_eq!(back.kind(k), ChildKind::Empty);
                    assert_eq!(back.child_bounds(k), Aabb::DEGENERATE);
                }
            }
        }
    }
}
