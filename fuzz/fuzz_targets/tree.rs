//! The saved-tree reader on arbitrary bytes: a tree or a typed error, never a panic or a
//! hang. An accepted tree writes back the bytes it was read from (but for a forged triangle
//! hash, which is rewritten), and answers a few rays through each of its traversals (both
//! DST decoders) without panicking.
//!
//! Each input is read twice when it has to be: first as it is, which explores the header,
//! the sizes and the checksum; then, when that fails on the checksum (as almost every random
//! change does), with its checksum recomputed (the SHA-256 of everything before the last 32
//! bytes, written there) as a forger would. The second read takes the mutated words past the
//! checksum into the structural checks (docs/tree-format.md, "Checks on load"), and an
//! accepted forgery's traversals must end without a panic. The inputs stay plain tree files,
//! so the seeds are the files `tests/saved_tree.rs` writes.
#![no_main]

use dualsplit_accel::math::{Ray, Vec3};
use dualsplit_accel::saved::SavedError;
use dualsplit_accel::{AnyTree, NoObserver, TraversalSet};
use libfuzzer_sys::fuzz_target;
use sha2::{Digest, Sha256};

fuzz_target!(|data: &[u8]| {
    let mut file = data.to_vec();
    let tree = match AnyTree::from_bytes(&file, None) {
        Ok(t) => t,
        Err(SavedError::Checksum) => {
            let n = file.len() - 32;
            let sum: [u8; 32] = Sha256::digest(&file[..n]).into();
            file[n..].copy_from_slice(&sum);
            match AnyTree::from_bytes(&file, None) {
                Ok(t) => t,
                Err(e) => {
                    assert!(
                        !matches!(e, SavedError::Checksum),
                        "a recomputed checksum is rejected"
                    );
                    return;
                }
            }
        }
        Err(_) => return,
    };
    // An accepted tree writes back the bytes it was read from, except the header's triangle
    // hash (bytes 56-87), which a loader without the scene does not check (it would mean
    // hashing the triangles again) and a writer recomputes: a forged one is rewritten.
    let back = tree.to_bytes();
    let n = file.len() - 32;
    let same = |a: &[u8], b: &[u8]| a[..56] == b[..56] && a[88..n] == b[88..n];
    assert!(
        back.len() == file.len() && same(&back, &file),
        "an accepted tree writes back other bytes"
    );
    if back[56..88] != file[56..88] {
        let h = dualsplit_accel::saved::triangle_hash(tree.image().triangle_slice());
        assert!(
            back[56..88] == h,
            "the written triangle hash is not the triangles'"
        );
    }
    let b = tree.scene_box();
    let centre = if b.is_empty() { Vec3::ZERO } else { b.center() };
    let far = centre + Vec3::splat(1.0 + b.extent().max_element());
    let rays = [
        Ray::new(far, centre - far),
        Ray::new(centre, Vec3::X),
        Ray::new(centre, Vec3::new(0.0, -1.0, 0.5)),
        Ray::new(-far, Vec3::Z),
    ];
    for &kind in tree.kinds() {
        for ray in &rays {
            let _ = TraversalSet::closest_hit(&tree, kind, ray, &mut NoObserver);
            let _ = TraversalSet::any_hit(&tree, kind, ray, &mut NoObserver);
        }
    }
});
