//! The saved-tree reader on arbitrary bytes: a tree or a typed error, never a panic. An
//! accepted tree writes back exactly the bytes it was read from, and answers a few rays
//! through each of its traversals without panicking.
//!
//! The bytes are not given a fresh checksum: a file forged with a recomputed checksum is
//! outside the reader's guarantee (docs/tree-format.md, "Checks on load"), so what this
//! target explores is the header, the sizes and the checksum, and the seeds' traversals.
#![no_main]

use dualsplit_accel::math::{Ray, Vec3};
use dualsplit_accel::{AnyTree, NoObserver, TraversalSet};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(tree) = AnyTree::from_bytes(data, None) else {
        return;
    };
    assert!(
        tree.to_bytes() == data,
        "an accepted tree writes back other bytes"
    );
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
