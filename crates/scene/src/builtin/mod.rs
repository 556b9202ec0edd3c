//! Builtin procedural scenes, `builtin:NAME?key=value&...`: `hairball`, `forest`, `atrium`,
//! `cornell`. Deterministic from their seed.

use crate::{Scene, SceneError};

/// Generates the builtin scene named by `spec` (the part after `builtin:`).
pub fn generate(spec: &str) -> Result<Scene, SceneError> {
    Err(SceneError::Builtin {
        spec: spec.to_string(),
        message: "not implemented yet".into(),
    })
}
