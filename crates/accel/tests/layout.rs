//! The accel crate's layout: no two files of `src/` import each other in a circle, beyond the
//! circles still known. Imports are read as the simulator's layout test reads them
//! ([`dualsplit_testkit::layout`]).
//!
//! The circles still known are listed in [`KNOWN_CIRCLES`], each by one import that closes
//! it; the test drops these imports before it looks for circles, fails on any other circle,
//! and fails on a listed import that is gone (so the list only shrinks).

use dualsplit_testkit::layout::{find_circle, imports, modules};
use std::path::Path;

/// The imports that close the circles still known: (importer, imported, what it takes).
const KNOWN_CIRCLES: &[(&str, &str, &str)] = &[
    (
        "observer",
        "dst::pipeline",
        "NodeStep::Dst carries the DST's ReturnCode",
    ),
    ("saved", "registry", "a saved tree is an AnyTree"),
    ("saved::header", "registry", "the header reads AnyFields"),
    ("tree", "registry", "Tree wraps an AnyTree"),
    (
        "structure",
        "wide::tree",
        "the trait's defaults take a Bvh2Tree",
    ),
    (
        "dst::pipeline",
        "dst::traverse",
        "the pipeline loop runs on the software traversal's Tracer",
    ),
    (
        "dst::encode",
        "dst::from_bvh2",
        "the encoder calls the planner, which returns the encoder's chains",
    ),
    (
        "dst::encode",
        "dst::reference",
        "the encoder calls the reference planner",
    ),
    (
        "wide::cpu::layout",
        "wide::cpu::isa",
        "the chunk layouts are generic over the ISA",
    ),
    (
        "wide::cpu::layout",
        "wide::cpu::ray",
        "the layouts take RaySimd",
    ),
    (
        "wide::cpu::isa",
        "wide::cpu::traverse",
        "the ISA entry points run the traversal loop",
    ),
];

#[test]
fn no_two_files_import_each_other_in_a_circle() {
    let mods = modules(Path::new(env!("CARGO_MANIFEST_DIR")));
    assert!(mods.contains_key("dst::traverse") && mods.contains_key("wide::cpu::traverse"));
    let mut deps = imports(&mods);
    for (from, to, why) in KNOWN_CIRCLES {
        let edge = deps.get_mut(*from).map(|d| d.remove(*to));
        assert_eq!(
            edge,
            Some(true),
            "the known import {from} -> {to} ({why}) is gone: drop it from KNOWN_CIRCLES"
        );
    }
    if let Some(c) = find_circle(&deps) {
        panic!("import circle: {c}");
    }
}
