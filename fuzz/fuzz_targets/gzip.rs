//! Inflating arbitrary bytes as a `.ply.gz` against a small byte budget, then parsing what
//! comes out: a gzip bomb stops at the budget with a typed error.
#![no_main]

use dualsplit_scene::load::{self, Format};
use dualsplit_scene::{Limits, SceneError};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

/// Budgets small enough that no input takes long or holds much memory.
const LIMITS: Limits = Limits {
    max_triangles: 1 << 16,
    max_bytes: 1 << 22,
};

fuzz_target!(|data: &[u8]| {
    let path = Path::new("/nonexistent-dualsplit-fuzz/scene.ply.gz");
    match load::maybe_gunzip_with(path, data.to_vec(), &LIMITS) {
        Ok(bytes) => {
            assert!(bytes.len() as u64 <= LIMITS.max_bytes);
            let _ = load::parse_bytes_with(path, Format::Ply, &bytes, &LIMITS);
        }
        Err(SceneError::Limit { limit, .. }) => assert_eq!(limit, LIMITS.max_bytes),
        Err(_) => {}
    }
});
