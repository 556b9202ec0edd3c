//! The on-disk result cache under `<out>/cache/`.
//!
//! Every piece of the report (one scene's CPU measurements, one simulated frame, one render)
//! is stored as a JSON file named by a hash of its [`CacheKey`]: scene content hash,
//! structure, workload, configuration, resolution and code version
//! ([`CODE_VERSION`]). An interrupted or repeated report therefore only computes what is
//! missing; changing any part of the key computes that piece again.

use crate::ReportError;
use serde::{Serialize, de::DeserializeOwned};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Bump when the meaning or layout of a cached value changes. Simulator model changes are
/// tracked separately by [`dualsplit_sim::MODEL_VERSION`], which is also part of every key
/// (all crates share one version number, so the crate version alone does not tell).
pub const SCHEMA: u32 = 3;

/// Crate version plus [`SCHEMA`]: part of every cache key.
pub const CODE_VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "+schema");

/// What a cached value depends on. Two equal keys name the same value.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct CacheKey {
    /// What kind of piece: `cpu`, `sim`, `render`.
    pub piece: String,
    /// `Scene::content_hash`.
    pub scene_hash: String,
    /// Structure or simulated configuration name (`-` when none).
    pub structure: String,
    /// Workload name (`-` when none).
    pub workload: String,
    /// Hardware configuration as JSON (`-` when none).
    pub config: String,
    /// Resolution `WxH`.
    pub resolution: String,
    /// [`CODE_VERSION`] and [`SCHEMA`].
    pub code_version: String,
}

impl CacheKey {
    /// A key with the current code version.
    pub fn new(
        piece: &str,
        scene_hash: &str,
        structure: &str,
        workload: &str,
        config: &str,
        resolution: (u32, u32),
    ) -> Self {
        Self {
            piece: piece.into(),
            scene_hash: scene_hash.into(),
            structure: structure.into(),
            workload: workload.into(),
            config: config.into(),
            resolution: format!("{}x{}", resolution.0, resolution.1),
            code_version: format!("{CODE_VERSION}{SCHEMA}+sim{}", dualsplit_sim::MODEL_VERSION),
        }
    }

    /// File name: `<piece>-<structure>-<16 hex digits of the key's SHA-256>.json`.
    pub fn file_name(&self) -> String {
        let json = serde_json::to_string(self).unwrap_or_default();
        let d = Sha256::digest(json.as_bytes());
        let hex: String = d[..8].iter().map(|b| format!("{b:02x}")).collect();
        let tag: String = self
            .structure
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
            .collect();
        format!("{}-{}-{hex}.json", self.piece, tag)
    }
}

/// A directory of cached JSON values.
#[derive(Clone, Debug)]
pub struct Cache {
    dir: PathBuf,
}

impl Cache {
    /// A cache in `dir` (created on first write).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The cached value of `key`, if present and readable. A corrupt or outdated file (an
    /// interrupted write, an old layout) counts as missing.
    pub fn get<T: DeserializeOwned>(&self, key: &CacheKey) -> Option<T> {
        let bytes = std::fs::read(self.dir.join(key.file_name())).ok()?;
        serde_json::from_slice(&bytes).ok()
    }

    /// Stores `value` under `key`, atomically (write a temporary file, then rename).
    pub fn put<T: Serialize>(&self, key: &CacheKey, value: &T) -> Result<(), ReportError> {
        std::fs::create_dir_all(&self.dir).map_err(ReportError::io(&self.dir))?;
        let path = self.dir.join(key.file_name());
        let tmp = path.with_extension(format!("tmp{}", std::process::id()));
        let json = serde_json::to_vec(value).map_err(|source| ReportError::Json {
            path: path.clone(),
            source,
        })?;
        std::fs::write(&tmp, json).map_err(ReportError::io(&tmp))?;
        std::fs::rename(&tmp, &path).map_err(ReportError::io(&path))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn key_parts_change_the_file_name() {
        let a = CacheKey::new("sim", "abc", "dst", "path", "{}", (64, 64));
        let mut b = a.clone();
        b.resolution = "65x64".into();
        assert_ne!(a.file_name(), b.file_name());
        assert_eq!(a.file_name(), a.clone().file_name());
    }

    #[test]
    fn round_trip_and_corrupt_files() {
        let dir = std::env::temp_dir().join(format!("dualsplit-cache-test-{}", std::process::id()));
        let cache = Cache::new(&dir);
        let key = CacheKey::new("cpu", "h", "bvh2", "-", "-", (1, 1));
        assert_eq!(cache.get::<Vec<u32>>(&key), None);
        cache.put(&key, &vec![1u32, 2, 3]).unwrap();
        assert_eq!(cache.get::<Vec<u32>>(&key), Some(vec![1, 2, 3]));
        std::fs::write(dir.join(key.file_name()), b"{truncated").unwrap();
        assert_eq!(cache.get::<Vec<u32>>(&key), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
