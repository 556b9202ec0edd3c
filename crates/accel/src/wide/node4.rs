//! The 100-byte BVH4 internal node (Lin et al. 2020, §4.2).

use crate::image::{ChildKind, ImageError, NodeLayout, packed_node};
use dualsplit_geometry::Aabb;

packed_node! {
    /// BVH4 internal node: four child boxes and one packed offset/type word, 100 bytes.
    ///
    /// | bytes | words | field |
    /// |---|---|---|
    /// | 0–95 | 0–23 | child boxes, slot `k` at words `6k..6k+6`: min.xyz, max.xyz (f32) |
    /// | 96–99 | 24 | `packed`: bits 0–27 child-block offset (absolute word index), bit `28 + k` child `k` is a leaf |
    ///
    /// Children occupy slots `0..n` in order; the remaining slots hold [`Aabb::DEGENERATE`]
    /// (empty, `min.x > max.x`) and take no space in the child block. Internal children take 25
    /// words in the child block, leaf children one leaf word (see [`crate::image`]).
    ///
    /// Worked example: slots = [leaf, internal, leaf, empty], child block at word 25 →
    /// `packed = 25 | 1 << 28 | 1 << 30 = 0x5000_0019`; slot 0's leaf word is word 25, slot 1's
    /// node is at word 26, slot 2's leaf word is word 51.
    Node4, name "bvh4", arity 4, leaf_bit |k| 28 + k as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::test_support::{arb_children, roundtrip};
    use proptest::prelude::*;

    #[test]
    fn worked_example() {
        let b = Aabb::new(glam::Vec3::ZERO, glam::Vec3::ONE);
        let n = Node4::encode(
            &[
                (b, ChildKind::Leaf),
                (b, ChildKind::Internal),
                (b, ChildKind::Leaf),
            ],
            25,
        )
        .unwrap();
        assert_eq!(n.packed, 0x5000_0019);
        assert_eq!(n.kind(3), ChildKind::Empty);
    }

    #[test]
    fn offset_overflow_is_an_error() {
        let e = Node4::encode(&[], 1 << 28).unwrap_err();
        assert!(matches!(e, ImageError::OffsetOverflow { bits: 28, .. }));
    }

    proptest! {
        #[test]
        fn encode_decode_roundtrip(children in arb_children(4), offset in 0u32..(1 << 28)) {
            roundtrip::<Node4>(&children, offset);
        }
    }
}
