//! The simulator's layout (`docs/simulator.md`, "Code layout"): the hardware units under
//! `src/hw/` import nothing from the thread models (`src/model/`) or from what is built on
//! them, and no two files of `src/` import each other in a circle. Imports are read from the
//! source by [`dualsplit_testkit::layout`] (whose own tests show it finds a circle through
//! `super::`, relative and re-exported paths).

use dualsplit_testkit::layout::{find_circle, imports, modules};
use std::path::Path;

fn crate_modules() -> std::collections::BTreeMap<String, String> {
    modules(Path::new(env!("CARGO_MANIFEST_DIR")))
}

#[test]
fn hardware_units_import_no_thread_model() {
    let mods = crate_modules();
    assert!(mods.contains_key("hw::tm") && mods.contains_key("model::rv32::tp"));
    let built_on_models = [
        "model", "engine", "frame", "request", "result", "error", "accel",
    ];
    for (m, deps) in imports(&mods) {
        if m.starts_with("hw") {
            for d in deps {
                assert!(
                    !built_on_models
                        .iter()
                        .any(|b| d == *b || d.starts_with(&format!("{b}::"))),
                    "{m} imports {d}"
                );
            }
        }
    }
}

#[test]
fn no_two_files_import_each_other_in_a_circle() {
    let deps = imports(&crate_modules());
    if let Some(c) = find_circle(&deps) {
        panic!("import circle: {c}");
    }
}
