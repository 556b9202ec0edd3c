//! The header-offset word: round trips over all 37 valid header codes, rejection of the
//! others, the 26-bit offset limit, and the `Debug` format.

use dualsplit_accel::DstNodeKind;
use dualsplit_accel::dst::{AxisPair, Corner, DstError, HeaderOffset, OFFSET_LIMIT};
use proptest::prelude::*;

/// Builds the word for header code `h` through the typed constructors.
fn construct(h: u8, offset: u64) -> HeaderOffset {
    let (c, a, b, l) = (h >> 5, (h >> 3) & 3, (h >> 1) & 3, h & 1 == 1);
    let w = if c == 0 && l {
        HeaderOffset::leaf(offset)
    } else if c == 0 {
        HeaderOffset::split(a as usize, b as u32, offset)
    } else if a == 0b10 {
        HeaderOffset::single_carve(b as usize, l, offset)
    } else {
        let pair = [AxisPair::Xy, AxisPair::Xz, AxisPair::Yz, AxisPair::Yz][a as usize];
        HeaderOffset::dual_carve(pair, Corner::from_bits(b as u32), l, offset)
    };
    w.expect("valid offset")
}

#[test]
fn there_are_37_valid_codes() {
    let valid = HeaderOffset::ALL_VALID_HEADERS;
    assert_eq!(valid.len(), 37);
    let count = |k: DstNodeKind| {
        valid
            .iter()
            .filter(|&&h| HeaderOffset::from_bits((h as u32) << 26).node_kind() == k)
            .count()
    };
    assert_eq!(count(DstNodeKind::Leaf), 1);
    assert_eq!(count(DstNodeKind::Split), 6);
    assert_eq!(count(DstNodeKind::SingleCarve), 6);
    assert_eq!(count(DstNodeKind::DualCarve), 24);
    for h in 0u32..64 {
        let ok = HeaderOffset::decode(h << 26, 5).is_ok();
        assert_eq!(ok, valid.contains(&(h as u8)), "code {h:06b}");
        if !ok {
            assert_eq!(
                HeaderOffset::decode(h << 26, 5),
                Err(DstError::InvalidHeader {
                    at: 5,
                    word: h << 26
                })
            );
        }
    }
}

proptest! {
    #[test]
    fn round_trip_every_valid_code(i in 0usize..37, offset in 0u64..OFFSET_LIMIT) {
        let h = HeaderOffset::ALL_VALID_HEADERS[i];
        let w = construct(h, offset);
        prop_assert_eq!(w.header(), h);
        prop_assert_eq!(w.offset() as u64, offset);
        let back = HeaderOffset::decode(w.bits(), 0).unwrap();
        prop_assert_eq!(back, w);
        // The accessors agree with the fields.
        let (c, a, b, l) = (h >> 5, (h >> 3) & 3, (h >> 1) & 3, h & 1 == 1);
        prop_assert_eq!(w.is_carving(), c == 1);
        prop_assert_eq!(w.is_leaf_flag(), l);
        match w.node_kind() {
            DstNodeKind::Leaf => prop_assert_eq!(w.size_words(), 1),
            DstNodeKind::Split => {
                prop_assert_eq!(w.axis(), a as usize);
                prop_assert_eq!(w.left_size(), b as u32);
                prop_assert_eq!(w.size_words(), 3);
            }
            DstNodeKind::SingleCarve => prop_assert_eq!(w.axis(), b as usize),
            DstNodeKind::DualCarve => {
                let (x, y) = w.axis_pair().axes();
                prop_assert!(x < y && y < 3);
                prop_assert_eq!(w.axis_pair() as u8, a);
                prop_assert_eq!(w.corner().bits(), b as u32);
                prop_assert_eq!(w.axis(), x);
            }
        }
    }
}

#[test]
fn axis_pairs_decode_as_documented() {
    assert_eq!(AxisPair::Xy.axes(), (0, 1));
    assert_eq!(AxisPair::Xz.axes(), (0, 2));
    assert_eq!(AxisPair::Yz.axes(), (1, 2));
    for p in AxisPair::ALL {
        let (a, b) = p.axes();
        assert_eq!(AxisPair::from_axes(b, a), Some(p));
    }
    assert_eq!(AxisPair::from_axes(1, 1), None);
}

#[test]
fn offset_overflow_is_a_typed_error() {
    let too_big = OFFSET_LIMIT;
    let err = Err(DstError::OffsetOverflow {
        given: too_big,
        limit: 1 << 26,
    });
    assert_eq!(HeaderOffset::leaf(too_big), err);
    assert_eq!(HeaderOffset::split(0, 3, too_big), err);
    assert_eq!(HeaderOffset::single_carve(2, true, too_big), err);
    assert_eq!(
        HeaderOffset::dual_carve(AxisPair::Xz, Corner::from_bits(3), false, too_big),
        err
    );
    // The largest offset still fits, unwrapped.
    assert_eq!(
        HeaderOffset::leaf(too_big - 1).unwrap().offset() as u64,
        too_big - 1
    );
    let msg = HeaderOffset::leaf(too_big).unwrap_err().to_string();
    assert!(msg.contains("67108864"), "{msg}");
}

#[test]
fn debug_prints_header_bits() {
    let w = HeaderOffset::split(2, 3, 16).unwrap();
    assert_eq!(w.bits(), 0x5800_0010);
    let s = format!("{w:?}");
    assert!(s.contains("C=0 A=10 B=11 L=0"), "{s}");
    assert!(s.contains("offset 16"), "{s}");
    let d = HeaderOffset::dual_carve(
        AxisPair::Yz,
        Corner {
            first_lower: true,
            second_lower: false,
        },
        true,
        7,
    )
    .unwrap();
    assert!(format!("{d:?}").contains("C=1 A=11 B=10 L=1"), "{d:?}");
}
