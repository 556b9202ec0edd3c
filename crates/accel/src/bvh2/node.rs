//! The 52-byte BVH2 internal node (Lin et al. 2020, §4.2).

use crate::image::{ChildKind, ImageError, NodeLayout, packed_node};
use dualsplit_geometry::Aabb;

packed_node! {
    /// BVH2 internal node: two child boxes and one packed offset/type word, 52 bytes.
    ///
    /// | bytes | words | field |
    /// |---|---|---|
    /// | 0–23 | 0–5 | child 0 box: min.x, min.y, min.z, max.x, max.y, max.z (f32) |
    /// | 24–47 | 6–11 | child 1 box, same order |
    /// | 48–51 | 12 | `packed`: bits 0–29 child-block offset (absolute word index), bit 30 child 1 is a leaf, bit 31 child 0 is a leaf |
    ///
    /// A slot whose box is degenerate (`min.x > max.x`, [`Aabb::DEGENERATE`]) is empty; this
    /// only occurs in the root of a scene with zero or one leaf. Children are stored
    /// consecutively from the offset (internal child: 13 words, leaf child: one leaf word; see
    /// [`crate::image`]).
    ///
    /// Worked example: child 0 an internal node, child 1 a leaf, child block at word 13 →
    /// `packed = 13 | 1 << 30 = 0x4000_000D`; child 0 is the node at word 13 and child 1's leaf
    /// word is word 13 + 13 = 26.
    Node2, name "bvh2", arity 2, leaf_bit |k| 31 - k as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::test_support::{arb_children, roundtrip};
    use proptest::prelude::*;

    #[test]
    fn worked_example() {
        let b = Aabb::new(glam::Vec3::ZERO, glam::Vec3::ONE);
        let n = Node2::encode(&[(b, ChildKind::Internal), (b, ChildKind::Leaf)], 13).unwrap();
        assert_eq!(n.packed, 0x4000_000D);
        let words: &[u32] = bytemuck::cast_slice(std::slice::from_ref(&n));
        assert_eq!(words.len(), 13);
        assert_eq!(words[3], 1.0f32.to_bits());
    }

    #[test]
    fn offset_overflow_is_an_error() {
        let e = Node2::encode(&[], 1 << 30).unwrap_err();
        assert!(matches!(e, ImageError::OffsetOverflow { bits: 30, .. }));
    }

    proptest! {
        #[test]
        fn encode_decode_roundtrip(children in arb_children(2), offset in 0u32..(1 << 30)) {
            roundtrip::<Node2>(&children, offset);
        }
    }
}
