//! The study's result store, `DIR/cache/`: one file per plan entry, named by the entry's
//! cache key, shared by every job of the study (possibly over a network file system).
//!
//! A result file is a header line, `dualsplit-result 1 sha256=<hex> bytes=<n>`, and then
//! exactly `n` bytes of JSON (a [`JobRecord`]) whose SHA-256 is `<hex>`. It is written to
//! a temporary file in the same folder, fsynced, renamed over its final name (atomic on
//! POSIX file systems, NFS included) and the folder fsynced. A reader verifies length,
//! checksum, JSON and that the record is the entry's (key, config hash, code version), so
//! a file cut short by a killed job, a disk fault or a stale version is never taken for a
//! result; it is reported as invalid and the next `run-job` replaces it. Temporary files
//! start with `.` and end in `.tmp`: a job killed before its rename leaves one behind,
//! which no reader looks at.

use super::plan::{PlanEntry, Varied, code_version};
use crate::ReportError;
use crate::cache::MAX_ENTRY_BYTES;
use dualsplit_render::Workload;
use dualsplit_sim::{SimAccel, SimResult};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Format number in the header line.
pub const RESULT_FORMAT: u32 = 1;
const MAGIC: &str = "dualsplit-result";

/// One job's result and where and when it was computed.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct JobRecord {
    /// Code version (crate, cache schema, simulator model) of the program that ran it.
    pub code_version: String,
    /// Plan entry.
    pub index: usize,
    /// The entry's cache key (the file's name).
    pub cache_key: String,
    /// Scene content hash.
    pub scene_hash: String,
    /// Configuration.
    pub accel: SimAccel,
    /// Workload.
    pub workload: Workload,
    /// TM count.
    pub tms: u32,
    /// Hash of the hardware config simulated.
    pub config_hash: String,
    /// The swept keys' values.
    pub varied: Vec<Varied>,
    /// Host name of the machine that ran it.
    pub host: String,
    /// When it finished on that host, seconds since the Unix epoch.
    pub host_time_unix_s: u64,
    /// Wall seconds the simulation took there (host measurement, not a result).
    pub host_wall_s: f64,
    /// The simulated result.
    pub result: SimResult,
}

/// What the store holds for an entry.
#[derive(Debug)]
pub enum Stored {
    /// No result file.
    Missing,
    /// A verified result.
    Valid(Box<JobRecord>),
    /// A file that is not a valid result for the entry, and why.
    Invalid(String),
}

/// `DIR/cache/`.
#[derive(Clone, Debug)]
pub struct ResultStore {
    dir: PathBuf,
}

impl ResultStore {
    /// The store of the study in `study_dir`.
    pub fn new(study_dir: &Path) -> Self {
        Self {
            dir: study_dir.join("cache"),
        }
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The result file of `entry`.
    pub fn path(&self, entry: &PlanEntry) -> PathBuf {
        self.dir.join(&entry.cache_key)
    }

    /// Reads and verifies `entry`'s result. Only a regular file (links followed) of at
    /// most [`MAX_ENTRY_BYTES`] is read, with the read stopping one byte past it: a link to
    /// `/dev/zero`, a named pipe or a larger file is [`Stored::Invalid`], never read whole
    /// or waited on.
    pub fn read(&self, entry: &PlanEntry) -> Stored {
        let path = self.path(entry);
        match dualsplit_scene::load::read_limited(&path, MAX_ENTRY_BYTES) {
            Ok(bytes) => match verify(&bytes, entry) {
                Ok(r) => Stored::Valid(Box::new(r)),
                Err(why) => Stored::Invalid(why),
            },
            Err(e) if e.is_not_found() => Stored::Missing,
            Err(e) => Stored::Invalid(e.to_string()),
        }
    }

    /// Writes `record` as `entry`'s result (atomically; see the module).
    pub fn write(&self, entry: &PlanEntry, record: &JobRecord) -> Result<PathBuf, ReportError> {
        let path = self.path(entry);
        let json = serde_json::to_vec(record).map_err(|source| ReportError::Json {
            path: path.clone(),
            source,
        })?;
        write_atomic(&path, &encode(&json))?;
        Ok(path)
    }

    /// Temporary files left by jobs killed before their rename.
    pub fn leftovers(&self) -> Vec<PathBuf> {
        let Ok(rd) = std::fs::read_dir(&self.dir) else {
            return Vec::new();
        };
        let mut v: Vec<PathBuf> = rd
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with('.') && n.ends_with(".tmp"))
            })
            .collect();
        v.sort();
        v
    }
}

/// A result file's bytes: the header line, then `json` (a [`JobRecord`]'s JSON).
pub fn encode(json: &[u8]) -> Vec<u8> {
    let sum = hex(&Sha256::digest(json));
    let mut out = format!(
        "{MAGIC} {RESULT_FORMAT} sha256={sum} bytes={}\n",
        json.len()
    )
    .into_bytes();
    out.extend_from_slice(json);
    out
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Checks a result file's header, length, checksum and that it is `entry`'s (what
/// [`ResultStore::read`] does with the bytes it read; the fuzz target `study_result` runs
/// it).
pub fn verify(bytes: &[u8], entry: &PlanEntry) -> Result<JobRecord, String> {
    let nl = bytes
        .iter()
        .position(|&b| b == b'\n')
        .ok_or("no header line (cut short?)")?;
    let header = std::str::from_utf8(&bytes[..nl]).map_err(|_| "header is not text")?;
    let payload = &bytes[nl + 1..];
    let mut parts = header.split(' ');
    if parts.next() != Some(MAGIC) {
        return Err("not a dualsplit result file".into());
    }
    if parts.next() != Some(&RESULT_FORMAT.to_string()) {
        return Err(format!("result format is not {RESULT_FORMAT}"));
    }
    let sum = parts
        .next()
        .and_then(|p| p.strip_prefix("sha256="))
        .ok_or("header has no sha256")?;
    let len: usize = parts
        .next()
        .and_then(|p| p.strip_prefix("bytes="))
        .and_then(|n| n.parse().ok())
        .ok_or("header has no byte count")?;
    if payload.len() != len {
        return Err(format!(
            "{} bytes of result, header says {len} (cut short or appended to)",
            payload.len()
        ));
    }
    if hex(&Sha256::digest(payload)) != sum {
        return Err("checksum mismatch (corrupt)".into());
    }
    let r: JobRecord =
        serde_json::from_slice(payload).map_err(|e| format!("not a job record: {e}"))?;
    if r.cache_key != entry.cache_key || r.config_hash != entry.config_hash {
        return Err("the record is another entry's".into());
    }
    if r.code_version != code_version() {
        return Err(format!(
            "computed by dualsplit {}, this is {}",
            r.code_version,
            code_version()
        ));
    }
    Ok(r)
}

/// Writes `bytes` to `path` so that `path` is either absent, its old contents, or all of
/// `bytes`: a uniquely named temporary file beside it, fsync, rename, fsync the folder.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ReportError> {
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(ReportError::io(dir))?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    // Host and pid make the name unique across machines sharing the folder.
    let tmp = dir.join(format!(
        ".{name}.{}.{}.{nanos}.tmp",
        host_name(),
        std::process::id()
    ));
    let result = (|| {
        let mut f = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    })();
    if let Err(e) = result {
        // The temporary file is ours and incomplete; removing it may fail too, and the
        // write error is the one worth reporting.
        let _ = std::fs::remove_file(&tmp);
        return Err(ReportError::Io {
            path: path.to_path_buf(),
            source: e,
        });
    }
    // Make the rename itself durable. Some network file systems refuse to open a folder
    // for syncing; the rename is already visible there, so that refusal is not an error.
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

/// This machine's host name (`unknown` when it cannot be read), with characters that do
/// not belong in a file name replaced.
pub fn host_name() -> String {
    let h = gethostname::gethostname().to_string_lossy().into_owned();
    let h: String = h
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if h.is_empty() { "unknown".into() } else { h }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::plan::{Plan, PlanOptions, PlanScene};
    use dualsplit_sim::{SimConfig, ThreadModel};

    fn entry() -> PlanEntry {
        let plan = Plan::build(&PlanOptions {
            scenes: vec![PlanScene {
                spec: "builtin:cornell".into(),
                name: "cornell".into(),
                hash: "h".into(),
            }],
            width: 8,
            height: 8,
            tms: vec![1],
            base_tms: 1,
            thread_model: ThreadModel::Fast,
            accels: vec![SimAccel::Bvh2],
            workloads: vec![Workload::Cast],
            base_config: SimConfig::lin2020(),
            vary: Vec::new(),
        })
        .unwrap();
        plan.entries[0].clone()
    }

    fn record(e: &PlanEntry, cycles: u64) -> JobRecord {
        JobRecord {
            code_version: code_version(),
            index: e.index,
            cache_key: e.cache_key.clone(),
            scene_hash: e.scene_hash.clone(),
            accel: e.accel,
            workload: e.workload,
            tms: e.tms,
            config_hash: e.config_hash.clone(),
            varied: Vec::new(),
            host: host_name(),
            host_time_unix_s: 1,
            host_wall_s: 0.5,
            result: SimResult {
                cycles,
                ..Default::default()
            },
        }
    }

    #[test]
    fn written_results_verify_and_damaged_ones_do_not() {
        let dir = tempfile::tempdir().unwrap();
        let store = ResultStore::new(dir.path());
        let e = entry();
        assert!(matches!(store.read(&e), Stored::Missing));
        let path = store.write(&e, &record(&e, 1234)).unwrap();
        match store.read(&e) {
            Stored::Valid(r) => assert_eq!(r.result.cycles, 1234),
            other => panic!("{other:?}"),
        }
        assert!(store.leftovers().is_empty());
        let good = std::fs::read(&path).unwrap();
        // Cut short at every length: never valid.
        for cut in [0, 10, good.len() / 2, good.len() - 1] {
            std::fs::write(&path, &good[..cut]).unwrap();
            assert!(matches!(store.read(&e), Stored::Invalid(_)), "cut at {cut}");
        }
        // One flipped payload byte: the checksum catches it.
        let mut bad = good.clone();
        let last = bad.len() - 2;
        bad[last] ^= 1;
        std::fs::write(&path, &bad).unwrap();
        assert!(matches!(store.read(&e), Stored::Invalid(_)));
        // Another entry's valid record under this name.
        let mut other = e.clone();
        other.config_hash = "0000000000000000".into();
        std::fs::write(&path, &good).unwrap();
        assert!(matches!(store.read(&other), Stored::Invalid(_)));
    }

    #[test]
    fn rewriting_replaces_and_leaves_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let store = ResultStore::new(dir.path());
        let e = entry();
        store.write(&e, &record(&e, 1)).unwrap();
        store.write(&e, &record(&e, 2)).unwrap();
        match store.read(&e) {
            Stored::Valid(r) => assert_eq!(r.result.cycles, 2),
            other => panic!("{other:?}"),
        }
        let files: Vec<_> = std::fs::read_dir(store.dir()).unwrap().collect();
        assert_eq!(files.len(), 1);
        std::fs::write(store.dir().join(".x.tmp"), b"partial").unwrap();
        assert_eq!(store.leftovers().len(), 1);
        assert!(matches!(store.read(&e), Stored::Valid(_)));
    }
}
