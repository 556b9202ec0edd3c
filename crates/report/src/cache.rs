//! The on-disk result cache under `<out>/cache/`.
//!
//! Every piece of the report (one scene's CPU measurements, one simulated frame, one render)
//! is stored as a file named by a hash of its [`CacheKey`]: scene content hash,
//! structure, workload, configuration, resolution and code version
//! ([`CODE_VERSION`]). An interrupted or repeated report therefore only computes what is
//! missing; changing any part of the key computes that piece again.
//!
//! ## Entry format
//!
//! An entry is two parts separated by the first newline: a header, the compact JSON object
//! `{"key": <the full CacheKey>, "sha256": "<64 hex digits>"}`, then the value as compact
//! JSON. The checksum is the SHA-256 of the key's compact JSON, a newline, and the value's
//! bytes, so it covers both. [`Cache::get`] returns a value
//! only when the header's key equals the key asked for (not only its hash in the file
//! name) and the checksum matches; anything else (a hand edit, a truncated or corrupt
//! file, a value without a header, a file that is not a regular file or is larger than
//! [`MAX_ENTRY_BYTES`]) counts as missing, so the piece is recomputed, never shown.
//!
//! Floats are written in their shortest round-trip form and read back exactly (serde_json's
//! `float_roundtrip`), so a report made from the cache is byte-identical to the fresh one
//! that filled it.

use crate::ReportError;
use serde::{Deserialize, Serialize, de::DeserializeOwned};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Bump when the meaning or layout of a cached value changes. Simulator model changes are
/// tracked separately by [`dualsplit_sim::MODEL_VERSION`], which is also part of every key
/// (all crates share one version number, so the crate version alone does not tell).
pub const SCHEMA: u32 = 5;

/// Largest cache entry [`Cache::get`] reads (a render's base64 PNG is the largest piece,
/// a few MB), and largest study result file
/// ([`ResultStore::read`](crate::study::store::ResultStore::read)).
pub const MAX_ENTRY_BYTES: u64 = 256 << 20;

/// Crate version plus [`SCHEMA`]: part of every cache key.
pub const CODE_VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "+schema");

/// What a cached value depends on. Two equal keys name the same value.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
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

    /// The cached value of `key`, if present and verified (see the module docs): a corrupt,
    /// edited, outdated or foreign entry counts as missing.
    pub fn get<T: DeserializeOwned>(&self, key: &CacheKey) -> Option<T> {
        let path = self.dir.join(key.file_name());
        let bytes = dualsplit_scene::load::read_limited(&path, MAX_ENTRY_BYTES).ok()?;
        decode(key, &bytes)
    }

    /// Stores `value` under `key`, atomically (write a temporary file, then rename).
    pub fn put<T: Serialize>(&self, key: &CacheKey, value: &T) -> Result<(), ReportError> {
        std::fs::create_dir_all(&self.dir).map_err(ReportError::io(&self.dir))?;
        let path = self.dir.join(key.file_name());
        let tmp = path.with_extension(format!("tmp{}", std::process::id()));
        let bytes = encode(key, value).map_err(|source| ReportError::Json {
            path: path.clone(),
            source,
        })?;
        std::fs::write(&tmp, bytes).map_err(ReportError::io(&tmp))?;
        std::fs::rename(&tmp, &path).map_err(ReportError::io(&path))
    }
}

/// The header line of an entry.
#[derive(Serialize, Deserialize)]
struct Header {
    key: CacheKey,
    sha256: String,
}

/// Lowercase hex of the SHA-256 of `key`'s compact JSON, a newline, and `body`.
fn checksum(key: &CacheKey, body: &[u8]) -> Result<String, serde_json::Error> {
    let mut h = Sha256::new();
    h.update(serde_json::to_vec(key)?);
    h.update(b"\n");
    h.update(body);
    Ok(h.finalize().iter().map(|b| format!("{b:02x}")).collect())
}

/// The bytes of a cache entry holding `value` under `key` (see the module docs).
pub fn encode<T: Serialize>(key: &CacheKey, value: &T) -> Result<Vec<u8>, serde_json::Error> {
    let body = serde_json::to_vec(value)?;
    let header = Header {
        key: key.clone(),
        sha256: checksum(key, &body)?,
    };
    let mut out = serde_json::to_vec(&header)?;
    out.push(b'\n');
    out.extend_from_slice(&body);
    Ok(out)
}

/// The value of a cache entry's `bytes`, if its header names exactly `key` and its
/// checksum matches; `None` for anything else. Never panics, whatever the bytes.
pub fn decode<T: DeserializeOwned>(key: &CacheKey, bytes: &[u8]) -> Option<T> {
    let nl = bytes.iter().position(|&b| b == b'\n')?;
    let (head, body) = (&bytes[..nl], &bytes[nl + 1..]);
    let header: Header = serde_json::from_slice(head).ok()?;
    if header.key != *key || header.sha256 != checksum(key, body).ok()? {
        return None;
    }
    serde_json::from_slice(body).ok()
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

    #[test]
    fn edited_entries_are_refused() {
        let key = CacheKey::new("sim", "h", "dst", "path", "{}", (8, 8));
        let good = encode(&key, &vec![1.5f64, 2.0]).unwrap();
        assert_eq!(decode::<Vec<f64>>(&key, &good), Some(vec![1.5, 2.0]));
        // A changed value, still well-formed JSON.
        let text = String::from_utf8(good.clone()).unwrap();
        let edited = text.replace("[1.5,2.0]", "[13427.97,2.0]");
        assert_ne!(edited, text);
        assert_eq!(decode::<Vec<f64>>(&key, edited.as_bytes()), None);
        // The right bytes under another key (same file name or not).
        let mut other = key.clone();
        other.config = "{\"tms\":1}".into();
        assert_eq!(decode::<Vec<f64>>(&other, &good), None);
        // A header whose key was edited, keeping its checksum: the checksum covers the key.
        let forged = text.replace("\"dst\"", "\"bvh2\"");
        assert_ne!(forged, text);
        let mut bvh2 = key.clone();
        bvh2.structure = "bvh2".into();
        assert_eq!(decode::<Vec<f64>>(&bvh2, forged.as_bytes()), None);
        assert_eq!(decode::<Vec<f64>>(&key, forged.as_bytes()), None);
        // Truncations, and a bare JSON value without a header.
        for n in 0..good.len() {
            assert_eq!(decode::<Vec<f64>>(&key, &good[..n]), None);
        }
        assert_eq!(decode::<Vec<f64>>(&key, b"[1.5,2.0]"), None);
    }

    #[cfg(unix)]
    #[test]
    fn special_files_are_not_read() {
        let dir =
            std::env::temp_dir().join(format!("dualsplit-cache-special-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let cache = Cache::new(&dir);
        let key = CacheKey::new("cpu", "h", "bvh2", "-", "-", (1, 1));
        std::os::unix::fs::symlink("/dev/zero", dir.join(key.file_name())).unwrap();
        assert_eq!(cache.get::<Vec<u32>>(&key), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
