//! The accel crate's layout: no two files of `src/` import each other in a circle. Imports
//! are read as the simulator's layout test reads them ([`dualsplit_testkit::layout`], whose
//! own tests show it finds a circle through `super::`, relative and re-exported paths).

use dualsplit_testkit::layout::{find_circle, imports, modules};
use std::path::Path;

#[test]
fn no_two_files_import_each_other_in_a_circle() {
    let mods = modules(Path::new(env!("CARGO_MANIFEST_DIR")));
    assert!(mods.contains_key("dst::traverse") && mods.contains_key("wide::cpu::traverse"));
    if let Some(c) = find_circle(&imports(&mods)) {
        panic!("import circle: {c}");
    }
}

/// The check fails on this crate's graph with one import added that would close a circle:
/// the traversal contract importing the DST pipeline, which imports the contract.
#[test]
fn one_import_back_closes_a_circle() {
    let mods = modules(Path::new(env!("CARGO_MANIFEST_DIR")));
    let mut deps = imports(&mods);
    assert!(deps["dst::pipeline"].contains("observer"));
    deps.get_mut("observer")
        .expect("observer.rs")
        .insert("dst::pipeline".to_string());
    let c = find_circle(&deps).expect("observer -> dst::pipeline -> observer");
    assert!(c.contains("observer") && c.contains("dst::pipeline"), "{c}");
}
