//! `validate()` accepts what the encoder writes and catches corrupted images.

use dualsplit_accel::{AccelKind, BuildConfig, Structures};
use dualsplit_geometry::{Pcg32, Triangle, Vec3};

fn scene() -> Structures {
    let mut rng = Pcg32::new(11, 5);
    let tris: Vec<Triangle> = (0..500)
        .map(|_| {
            let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
            let d = |r: &mut Pcg32| Vec3::new(r.next_f32(), r.next_f32(), r.next_f32());
            Triangle::new(p, p + d(&mut rng), p + d(&mut rng))
        })
        .collect();
    Structures::build(&tris, &BuildConfig::default())
}

#[test]
fn clean_images_validate() {
    let s = scene();
    for rep in s.validate() {
        assert!(rep.is_ok(), "{rep:?}");
        assert_eq!(rep.triangles_referenced, 500);
        // The deepest internal node is below the root exactly when there is more than one
        // (a structure that is one leaf, as the toy is, has none and depth 0).
        assert_eq!(rep.max_depth > 0, rep.internal_nodes > 1, "{rep:?}");
    }
    // The reference BVH2 (the first report) splits 500 triangles over many levels.
    assert!(s.validate()[0].max_depth > 0);
}

#[test]
fn corruptions_are_reported() {
    let s = scene();
    for kind in [AccelKind::Bvh2, AccelKind::Bvh4, AccelKind::Bvh8] {
        let enc = s.encoded(kind).expect("a BVH kind");
        // A shrunken child box (slot 0 of the root's child 0 node lies outside its parent box
        // once the root's slot-0 max.x is lowered below its min.x + tiny).
        let mut bad = enc.clone();
        bad.image.words[3] = f32::from_bits(bad.image.words[0]).to_bits();
        let rep = bad.validate();
        assert!(!rep.is_ok(), "{kind:?}: shrunken box not reported");
        // An index entry duplicated: one triangle twice, another never.
        let mut bad = enc.clone();
        let i = bad.image.indices.start;
        bad.image.words[i + 1] = bad.image.words[i] | (bad.image.words[i + 1] & (1 << 31));
        let rep = bad.validate();
        assert!(
            rep.errors.iter().any(|e| e.contains("referenced")),
            "{kind:?}: {rep:?}"
        );
        // The root's offset pointing past the node region.
        let mut bad = enc.clone();
        let words = bad.image.nodes.len();
        let off_word = match kind {
            AccelKind::Bvh2 => 12,
            AccelKind::Bvh4 => 24,
            _ => 48,
        };
        let high = bad.image.words[off_word] & 0xF000_0000;
        bad.image.words[off_word] = high | (words as u32 & 0x0FFF_FFFF);
        let rep = bad.validate();
        assert!(
            rep.errors.iter().any(|e| e.contains("outside")),
            "{kind:?}: {rep:?}"
        );
    }
}

/// Arbitrary words give a report, never a panic or an endless walk: a root whose children
/// are the root itself (a cycle), and many random word changes.
#[test]
fn cycles_and_random_words_end_in_a_report() {
    let s = scene();
    let mut rng = Pcg32::new(3, 9);
    for kind in [AccelKind::Bvh2, AccelKind::Bvh4, AccelKind::Bvh8] {
        let enc = s.encoded(kind).expect("a BVH kind");
        let (off_word, mask) = match kind {
            AccelKind::Bvh2 => (12, (1u32 << 30) - 1),
            AccelKind::Bvh4 => (24, (1 << 28) - 1),
            _ => (48, u32::MAX),
        };
        let mut bad = enc.clone();
        bad.image.words[off_word] &= !mask;
        let rep = bad.validate();
        // Each node is walked once at most: the cycle ends.
        let node_words = bad.image.nodes.len();
        assert!(!rep.is_ok(), "{kind:?}: cycle not reported");
        assert!(rep.internal_nodes <= node_words, "{kind:?}: {rep:?}");
        let words = bad.image.indices.end;
        for _ in 0..300 {
            let mut bad = enc.clone();
            for _ in 0..4 {
                let w = rng.next_u32() as usize % words;
                bad.image.words[w] = match rng.next_u32() % 3 {
                    0 => rng.next_u32(),
                    1 => bad.image.words[w] ^ (1 << (rng.next_u32() % 32)),
                    _ => (bad.image.words[w] & 0xF000_0000) | (rng.next_u32() % words as u32),
                };
            }
            let rep = bad.validate();
            assert_eq!(rep.error_count == 0, rep.errors.is_empty());
            assert!(rep.internal_nodes <= node_words, "{kind:?}: {rep:?}");
        }
    }
}
