//! The 200-byte BVH8 internal node (Lin et al. 2020, §4.2).

use crate::image::{ChildKind, ImageError, NodeLayout, box_words};
use dualsplit_geometry::Aabb;

/// BVH8 internal node: eight child boxes, an offset word and a child-types word, 200 bytes.
///
/// | bytes | words | field |
/// |---|---|---|
/// | 0–191 | 0–47 | child boxes, slot `k` at words `6k..6k+6`: min.xyz, max.xyz (f32) |
/// | 192–195 | 48 | `offset`: child-block offset (absolute word index, all 32 bits) |
/// | 196–199 | 49 | `types`: bits `2k..2k+2` type of slot `k`: 0 empty, 1 internal, 2 leaf |
///
/// The paper stores the types in their own word "since it will not leave enough space for
/// the child offset if packed together" (Lin et al. 2020, §4.2). Empty slots also hold
/// [`Aabb::DEGENERATE`]. Internal children take 50 words in the child block, leaf children
/// one leaf word (see [`crate::image`]).
///
/// Worked example: slots = [internal, leaf, leaf, empty × 5], child block at word 50 →
/// `offset = 50`, `types = 0b10_10_01 = 0x29`; slot 0's node is at word 50, slot 1's leaf
/// word at 100, slot 2's at 101.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Node8 {
    /// Child boxes.
    pub boxes: [[f32; 6]; 8],
    /// Child-block offset.
    pub offset: u32,
    /// Two type bits per slot.
    pub types: u32,
}

const _: () = assert!(size_of::<Node8>() == 200);

const TYPE_INTERNAL: u32 = 1;
const TYPE_LEAF: u32 = 2;

impl NodeLayout for Node8 {
    const NAME: &'static str = "bvh8";
    const ARITY: usize = 8;
    const WORDS: usize = 50;
    const OFFSET_BITS: u32 = 32;

    fn encode(children: &[(Aabb, ChildKind)], offset: u32) -> Result<Self, ImageError> {
        assert!(children.len() <= 8, "a BVH8 node has at most 8 children");
        let mut n = Node8 {
            boxes: [box_words(Aabb::DEGENERATE); 8],
            offset,
            types: 0,
        };
        for (k, &(b, kind)) in children.iter().enumerate() {
            let t = match kind {
                ChildKind::Empty => continue,
                ChildKind::Internal => TYPE_INTERNAL,
                ChildKind::Leaf => TYPE_LEAF,
            };
            n.boxes[k] = box_words(b);
            n.types |= t << (2 * k);
        }
        Ok(n)
    }

    #[inline(always)]
    fn offset(&self) -> u32 {
        self.offset
    }

    #[inline(always)]
    fn kind(&self, k: usize) -> ChildKind {
        match (self.types >> (2 * k)) & 3 {
            TYPE_INTERNAL => ChildKind::Internal,
            TYPE_LEAF => ChildKind::Leaf,
            _ => ChildKind::Empty,
        }
    }

    #[inline(always)]
    fn box_words(&self, k: usize) -> &[f32; 6] {
        &self.boxes[k]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::test_support::{arb_children, roundtrip};
    use proptest::prelude::*;

    #[test]
    fn worked_example() {
        let b = Aabb::new(glam::Vec3::ZERO, glam::Vec3::ONE);
        let n = Node8::encode(
            &[
                (b, ChildKind::Internal),
                (b, ChildKind::Leaf),
                (b, ChildKind::Leaf),
            ],
            50,
        )
        .unwrap();
        assert_eq!((n.offset, n.types), (50, 0x29));
        assert_eq!(n.child_bounds(7), Aabb::DEGENERATE);
    }

    proptest! {
        #[test]
        fn encode_decode_roundtrip(children in arb_children(8), offset in any::<u32>()) {
            roundtrip::<Node8>(&children, offset);
        }
    }
}
