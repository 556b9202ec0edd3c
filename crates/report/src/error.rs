//! Typed errors of the report crate.

use std::path::PathBuf;

/// Everything that can go wrong while producing or writing a report.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A file or directory could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// JSON (de)serialization failed.
    #[error("{path}: JSON: {source}")]
    Json {
        /// The file.
        path: PathBuf,
        /// The serde_json error.
        source: serde_json::Error,
    },
    /// A CSV file could not be written.
    #[error("{path}: CSV: {source}")]
    Csv {
        /// The file.
        path: PathBuf,
        /// The csv error.
        source: csv::Error,
    },
    /// A PNG could not be encoded.
    #[error("PNG encoding of {what}: {message}")]
    Png {
        /// What was encoded.
        what: String,
        /// The encoder's message.
        message: String,
    },
    /// A chart could not be drawn.
    #[error("chart `{chart}`: {message}")]
    Chart {
        /// The chart id.
        chart: String,
        /// The plotting backend's message.
        message: String,
    },
    /// A scene's structures could not be built (an image offset overflowed).
    #[error("{scene}: building the structures: {message}")]
    Build {
        /// The scene.
        scene: String,
        /// What failed.
        message: String,
    },
    /// A scenes folder named by `--scenes` or `DUALSPLIT_SCENES` is not a folder.
    #[error("{what} {path}: no such directory")]
    ScenesDir {
        /// The folder.
        path: PathBuf,
        /// Where it was named.
        what: String,
    },
    /// A structure returned a different hit than BVH2 for some ray, so it is not timed.
    #[error("{structure} disagrees with BVH2 on {mismatches} of {rays} {ray_kind} rays")]
    Mismatch {
        /// The structure.
        structure: String,
        /// The ray kind.
        ray_kind: String,
        /// Rays whose result differs.
        mismatches: u64,
        /// Rays compared.
        rays: u64,
    },
}

impl ReportError {
    /// Wraps an I/O error with its path.
    pub fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |source| ReportError::Io { path, source }
    }
}
