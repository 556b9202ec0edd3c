//! The Obj parser on arbitrary bytes: every input ends in a mesh or a typed error, within
//! small budgets, never a panic, an abort or a hang.
#![no_main]

use dualsplit_scene::Limits;
use dualsplit_scene::load::{self, Format};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// Budgets small enough that no input takes long or holds much memory.
const LIMITS: Limits = Limits {
    max_triangles: 1 << 16,
    max_bytes: 1 << 24,
};

fuzz_target!(|data: &[u8]| {
    // A folder that does not exist: no external glTF buffer can be read.
    let path = Path::new("/nonexistent-dualsplit-fuzz/scene.obj");
    let _ = load::parse_bytes_with(path, Format::Obj, data, &LIMITS);
});
