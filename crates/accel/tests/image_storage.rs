//! Image storage (contract 1): every image of a scene shares the scene's triangles instead of
//! copying them, and the whole image — node words, index runs, triangle region — is still
//! one byte string with the triangle region at its own addresses.

use dualsplit_accel::{AccelKind, BuildConfig, MemoryImage, Structures};
use dualsplit_geometry::{Pcg32, Triangle, Vec3};
use std::sync::Arc;

/// Every image a `Structures` holds (both DST kinds read the same image).
const KINDS: [AccelKind; 4] = [
    AccelKind::Bvh2,
    AccelKind::Bvh4,
    AccelKind::Bvh8,
    AccelKind::Dst,
];

fn random_triangles(n: usize, seed: u64) -> Vec<Triangle> {
    let mut rng = Pcg32::new(seed, 1);
    let mut p = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
    (0..n).map(|_| Triangle::new(p(), p(), p())).collect()
}

/// The byte string `to_bytes` must give: the node and index words, then the triangles in id
/// order, 36 bytes each, all little-endian.
fn expected_bytes(img: &MemoryImage, tris: &[Triangle]) -> Vec<u8> {
    let mut out = Vec::new();
    for w in img.words.iter() {
        out.extend_from_slice(&w.to_le_bytes());
    }
    for t in tris {
        for v in t.v {
            for c in [v.x, v.y, v.z] {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
    }
    out
}

#[test]
fn structures_share_one_copy_of_the_triangles() {
    let tris = random_triangles(3000, 7);
    let s = Structures::build(&tris, &BuildConfig::default());
    assert_eq!(&s.triangles[..], &tris[..]);
    for kind in KINDS {
        let img = s.image(kind);
        assert!(
            Arc::ptr_eq(&img.triangle_data, &s.triangles),
            "{kind:?}: the image holds its own copy of the triangles"
        );
        assert_eq!(img.triangle_slice(), &tris[..], "{kind:?}");
    }
}

#[test]
fn the_triangle_region_follows_the_indices_at_its_own_addresses() {
    let tris = random_triangles(500, 11);
    let s = Structures::build(&tris, &BuildConfig::default());
    for kind in KINDS {
        let img = s.image(kind);
        assert_eq!(img.nodes.start, 0, "{kind:?}");
        assert_eq!(img.nodes.end, img.indices.start, "{kind:?}");
        assert_eq!(img.indices.end, img.words.len(), "{kind:?}");
        assert_eq!(img.triangles.start, img.indices.end, "{kind:?}");
        assert_eq!(img.triangles.len(), 9 * tris.len(), "{kind:?}");
        assert_eq!(img.to_bytes(), expected_bytes(img, &tris), "{kind:?}");
        assert_eq!(
            img.to_bytes().len() as u64,
            img.node_bytes() + img.index_bytes() + img.triangle_bytes(),
            "{kind:?}"
        );
    }
}

#[test]
fn large_images_live_in_huge_page_mappings_and_small_ones_in_vectors() {
    // 150 000 triangles make a DST image of over 2 MiB of node and index words.
    let big = Structures::build(&random_triangles(150_000, 3), &BuildConfig::default());
    let small = Structures::build(&random_triangles(50, 5), &BuildConfig::default());
    let (big_img, small_img) = (big.image(AccelKind::Dst), small.image(AccelKind::Dst));
    assert!(big_img.words.len() * 4 >= dualsplit_accel::image::MAPPED_MIN_BYTES);
    #[cfg(unix)]
    assert!(big_img.words.is_mapped());
    assert!(!small_img.words.is_mapped());
    // Either storage reads the same: the images validate and a clone compares equal.
    for s in [&big, &small] {
        for rep in s.validate() {
            assert!(rep.is_ok(), "{rep:?}");
        }
        let img = s.image(AccelKind::Dst).clone();
        assert_eq!(img.words, s.image(AccelKind::Dst).words);
    }
}
