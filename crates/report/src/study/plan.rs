//! The plan of a study (`DIR/plan.json`): one entry per simulation, each complete enough
//! for a job on another machine to run it alone: the scene spec and content hash, the
//! configuration, workload, resolution, TM count, thread model, the full hardware config
//! and its hash, and the name of its result file (the report cache's key).
//!
//! The entries are what `dualsplit report` simulates (every configuration, cast and path,
//! at the base TM count; path at the other TM counts on the scaling scenes), optionally
//! narrowed to some configurations and workloads, times the cross product of the sweeps.

use super::vary::{self, Vary};
use super::{StudyError, store};
use crate::cache::{CODE_VERSION, CacheKey, SCHEMA};
use crate::produce::Producer;
use dualsplit_render::Workload;
use dualsplit_sim::{SimAccel, SimConfig, ThreadModel};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Most entries of a plan. A plan is read whole by every job, and each entry carries its
/// full configuration (about 3 KB of `plan.json`), so [`Plan::build`] refuses a larger one
/// before making any entry, and [`Plan::load`] refuses a file with more.
pub const MAX_PLAN_ENTRIES: u64 = 1 << 16;

/// Largest `plan.json` [`Plan::load`] reads: room for [`MAX_PLAN_ENTRIES`] entries of
/// 4 KiB each.
pub const MAX_PLAN_BYTES: u64 = MAX_PLAN_ENTRIES * 4096;

/// Layout version of `plan.json`.
pub const PLAN_FORMAT: u32 = 1;
/// Rays per pixel of the cast workload, as `dualsplit-render` traces the paper's scenes
/// (primary plus shadow rays); used for estimates only.
pub const CAST_RAYS_PER_PIXEL: f64 = 1.5;
/// The same for the path workload.
pub const PATH_RAYS_PER_PIXEL: f64 = 6.0;

/// The code version every result and key carries: crate version, cache schema and the
/// simulator's model version.
pub fn code_version() -> String {
    format!("{CODE_VERSION}{SCHEMA}+sim{}", dualsplit_sim::MODEL_VERSION)
}

/// A scene of the plan, loaded once by the planner.
#[derive(Clone, Debug)]
pub struct PlanScene {
    /// The spec a job loads it from (an absolute path or a `builtin:` spec).
    pub spec: String,
    /// Its display name.
    pub name: String,
    /// `Scene::content_hash`, checked by every job after loading.
    pub hash: String,
}

/// What to plan.
#[derive(Clone, Debug)]
pub struct PlanOptions {
    /// The scenes.
    pub scenes: Vec<PlanScene>,
    /// Frame size.
    pub width: u32,
    /// Frame size.
    pub height: u32,
    /// TM counts (sorted, distinct); the scaling study runs path tracing at all of them.
    pub tms: Vec<u32>,
    /// TM count of the configuration comparison.
    pub base_tms: u32,
    /// Thread model.
    pub thread_model: ThreadModel,
    /// Configurations to simulate (all eight by default).
    pub accels: Vec<SimAccel>,
    /// Workloads to simulate (cast and path by default).
    pub workloads: Vec<Workload>,
    /// The hardware config the sweeps start from.
    pub base_config: SimConfig,
    /// The sweeps.
    pub vary: Vec<Vary>,
}

/// One swept key's value in an entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Varied {
    /// Dotted key.
    pub key: String,
    /// Its value in this entry.
    pub value: toml::Value,
}

/// One simulation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlanEntry {
    /// Position in the plan (the Slurm array task id).
    pub index: usize,
    /// Scene spec.
    pub scene: String,
    /// Scene display name.
    pub scene_name: String,
    /// Scene content hash.
    pub scene_hash: String,
    /// Simulated configuration.
    pub accel: SimAccel,
    /// Workload.
    pub workload: Workload,
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// TM count (also `config.tms`).
    pub tms: u32,
    /// Thread model.
    pub thread_model: ThreadModel,
    /// The swept keys' values (empty without a sweep).
    pub varied: Vec<Varied>,
    /// The full hardware configuration.
    pub config: SimConfig,
    /// 16 hex digits of the SHA-256 of the configuration's JSON.
    pub config_hash: String,
    /// The result's file name in `cache/` (the report cache's key for this frame).
    pub cache_key: String,
}

impl PlanEntry {
    /// The report cache's key of this frame.
    pub fn key(&self) -> CacheKey {
        CacheKey::new(
            "sim",
            &self.scene_hash,
            &format!("{}@{}", self.accel.name(), self.thread_model.name()),
            self.workload.name(),
            &serde_json::to_string(&self.config).unwrap_or_default(),
            (self.width, self.height),
        )
    }

    /// Rays the frame traces, estimated from [`CAST_RAYS_PER_PIXEL`] /
    /// [`PATH_RAYS_PER_PIXEL`].
    pub fn estimated_rays(&self) -> f64 {
        let per_pixel = match self.workload {
            Workload::Cast => CAST_RAYS_PER_PIXEL,
            Workload::Path => PATH_RAYS_PER_PIXEL,
        };
        f64::from(self.width) * f64::from(self.height) * per_pixel
    }

    /// `key=value, …` of the swept keys (`base` without a sweep).
    pub fn varied_label(&self) -> String {
        let set: Vec<(String, toml::Value)> = self
            .varied
            .iter()
            .map(|v| (v.key.clone(), v.value.clone()))
            .collect();
        vary::describe(&set)
    }

    /// One line: index, scene, configuration, workload, TMs, swept values.
    pub fn describe(&self) -> String {
        format!(
            "#{} {} {} {} {}×{} {} TMs ({})",
            self.index,
            self.scene_name,
            self.accel.name(),
            self.workload.name(),
            self.width,
            self.height,
            self.tms,
            self.varied_label()
        )
    }
}

/// A study: its settings and its entries.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// [`PLAN_FORMAT`].
    pub format: u32,
    /// [`code_version`] of the planner; jobs refuse a plan of another version (their keys
    /// would not match).
    pub code_version: String,
    /// Frame width.
    pub width: u32,
    /// Frame height.
    pub height: u32,
    /// TM counts of the scaling study.
    pub tms: Vec<u32>,
    /// TM count of the configuration comparison.
    pub base_tms: u32,
    /// Thread model.
    pub thread_model: ThreadModel,
    /// The config the sweeps start from.
    pub base_config: SimConfig,
    /// The sweeps.
    pub vary: Vec<Vary>,
    /// The simulations.
    pub entries: Vec<PlanEntry>,
}

/// 16 hex digits of the SHA-256 of `cfg`'s JSON.
pub fn config_hash(cfg: &SimConfig) -> String {
    let json = serde_json::to_string(cfg).unwrap_or_default();
    let d = Sha256::digest(json.as_bytes());
    d[..8].iter().map(|b| format!("{b:02x}")).collect()
}

impl Plan {
    /// Builds the plan; every swept combination is validated before any entry is made.
    /// A plan of more than [`MAX_PLAN_ENTRIES`] entries is refused before any is made.
    pub fn build(opts: &PlanOptions) -> Result<Self, StudyError> {
        let varies_tms = opts.vary.iter().any(|v| v.key == "tms");
        let specs: Vec<String> = opts
            .scenes
            .iter()
            .map(|s| format!("{} {}", s.name, s.spec))
            .collect();
        let scaling = Producer::scaling_specs(&specs);
        let count = Self::count(opts, &scaling, varies_tms);
        if count > u128::from(MAX_PLAN_ENTRIES) {
            return Err(StudyError::TooManyEntries {
                count,
                limit: MAX_PLAN_ENTRIES,
            });
        }
        let mut entries = Vec::new();
        for combo in vary::cross_product(&opts.vary) {
            let mut base = opts.base_config.clone();
            base.tms = opts.base_tms;
            let swept = vary::apply(&base, &combo)?;
            dualsplit_sim::check_model(&swept, opts.thread_model).map_err(|e| {
                StudyError::Vary {
                    arg: vary::describe(&combo),
                    reason: e.to_string(),
                }
            })?;
            // A swept `tms` replaces the TM scaling study: one TM count per combination.
            let (base_tms, all_tms) = if varies_tms {
                (swept.tms, vec![swept.tms])
            } else {
                (opts.base_tms, opts.tms.clone())
            };
            for (si, scene) in opts.scenes.iter().enumerate() {
                let mut frames = Vec::new();
                for workload in [Workload::Cast, Workload::Path] {
                    for accel in SimAccel::ALL {
                        frames.push((accel, workload, base_tms));
                    }
                }
                if scaling[si] {
                    for &t in all_tms.iter().filter(|&&t| t != base_tms) {
                        for accel in SimAccel::ALL {
                            frames.push((accel, Workload::Path, t));
                        }
                    }
                }
                for (accel, workload, tms) in frames {
                    if !opts.accels.contains(&accel) || !opts.workloads.contains(&workload) {
                        continue;
                    }
                    let mut config = swept.clone();
                    config.tms = tms;
                    let mut e = PlanEntry {
                        index: entries.len(),
                        scene: scene.spec.clone(),
                        scene_name: scene.name.clone(),
                        scene_hash: scene.hash.clone(),
                        accel,
                        workload,
                        width: opts.width,
                        height: opts.height,
                        tms,
                        thread_model: opts.thread_model,
                        varied: combo
                            .iter()
                            .map(|(key, value)| Varied {
                                key: key.clone(),
                                value: value.clone(),
                            })
                            .collect(),
                        config_hash: config_hash(&config),
                        config,
                        cache_key: String::new(),
                    };
                    e.cache_key = e.key().file_name();
                    entries.push(e);
                }
            }
        }
        Ok(Self {
            format: PLAN_FORMAT,
            code_version: code_version(),
            width: opts.width,
            height: opts.height,
            tms: opts.tms.clone(),
            base_tms: opts.base_tms,
            thread_model: opts.thread_model,
            base_config: opts.base_config.clone(),
            vary: opts.vary.clone(),
            entries,
        })
    }

    /// The number of entries [`Plan::build`] makes: the same for every swept combination
    /// (a swept `tms` leaves no scaling entries), counted without making any.
    fn count(opts: &PlanOptions, scaling: &[bool], varies_tms: bool) -> u128 {
        let accels = SimAccel::ALL
            .iter()
            .filter(|a| opts.accels.contains(a))
            .count() as u128;
        let workloads = Workload::ALL
            .iter()
            .filter(|w| opts.workloads.contains(w))
            .count() as u128;
        let path = u128::from(opts.workloads.contains(&Workload::Path));
        let others = opts.tms.iter().filter(|&&t| t != opts.base_tms).count() as u128;
        let per_combo: u128 = scaling
            .iter()
            .map(|&s| {
                let scaled = if s && !varies_tms {
                    others * accels * path
                } else {
                    0
                };
                accels * workloads + scaled
            })
            .sum();
        opts.vary
            .iter()
            .fold(per_combo, |n, v| n.saturating_mul(v.values.len() as u128))
    }

    /// `DIR/plan.json`.
    pub fn path(dir: &Path) -> PathBuf {
        dir.join("plan.json")
    }

    /// Writes `DIR/plan.json` atomically.
    pub fn save(&self, dir: &Path) -> Result<PathBuf, StudyError> {
        let path = Self::path(dir);
        let json = serde_json::to_vec_pretty(self).map_err(|e| StudyError::Plan {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        if json.len() as u64 > MAX_PLAN_BYTES {
            return Err(StudyError::Plan {
                path,
                reason: format!(
                    "{} bytes; a plan file holds at most {MAX_PLAN_BYTES} (shorter scene paths or fewer entries)",
                    json.len()
                ),
            });
        }
        store::write_atomic(&path, &json)?;
        Ok(path)
    }

    /// Reads `DIR/plan.json` and checks it: a regular file (links followed) of at most
    /// [`MAX_PLAN_BYTES`] and [`MAX_PLAN_ENTRIES`] entries, its format, that this program's
    /// code version made it, that entries are numbered in order and that each entry's
    /// result file name is the key of its contents.
    pub fn load(dir: &Path) -> Result<Self, StudyError> {
        let path = Self::path(dir);
        let bad = |reason: String| StudyError::Plan {
            path: path.clone(),
            reason,
        };
        let bytes = dualsplit_scene::load::read_limited(&path, MAX_PLAN_BYTES).map_err(|e| {
            if e.is_not_found() {
                bad("no such file (write one with `dualsplit plan --out DIR`)".into())
            } else {
                StudyError::File(e)
            }
        })?;
        Self::parse(&path, &bytes)
    }

    /// The plan in `bytes`, the contents of the plan file `path`, with the checks of
    /// [`Plan::load`] but the file's type and size (the fuzz target `study_plan` runs it).
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, StudyError> {
        let bad = |reason: String| StudyError::Plan {
            path: path.to_path_buf(),
            reason,
        };
        let plan: Plan =
            serde_json::from_slice(bytes).map_err(|e| bad(format!("not a study plan: {e}")))?;
        if plan.entries.len() as u64 > MAX_PLAN_ENTRIES {
            return Err(bad(format!(
                "{} entries; at most {MAX_PLAN_ENTRIES}",
                plan.entries.len()
            )));
        }
        if plan.format != PLAN_FORMAT {
            return Err(bad(format!(
                "plan format {} (this program reads {PLAN_FORMAT})",
                plan.format
            )));
        }
        if plan.code_version != code_version() {
            return Err(bad(format!(
                "made by dualsplit {}, this is {}: plan again with this program",
                plan.code_version,
                code_version()
            )));
        }
        for (i, e) in plan.entries.iter().enumerate() {
            if e.index != i {
                return Err(bad(format!("entry {i} is numbered {}", e.index)));
            }
            if e.cache_key != e.key().file_name() || e.config_hash != config_hash(&e.config) {
                return Err(bad(format!(
                    "entry {i}: its key or config hash does not match its contents"
                )));
            }
            if e.config.tms != e.tms {
                return Err(bad(format!("entry {i}: config.tms differs from tms")));
            }
        }
        Ok(plan)
    }

    /// Estimated rays of every entry together.
    pub fn estimated_rays(&self) -> f64 {
        self.entries.iter().map(PlanEntry::estimated_rays).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn opts(vary: Vec<Vary>) -> PlanOptions {
        PlanOptions {
            scenes: vec![PlanScene {
                spec: "builtin:cornell".into(),
                name: "cornell".into(),
                hash: "h".into(),
            }],
            width: 16,
            height: 16,
            tms: vec![2, 4],
            base_tms: 2,
            thread_model: ThreadModel::Fast,
            accels: vec![SimAccel::Bvh2, SimAccel::Dst],
            workloads: vec![Workload::Cast, Workload::Path],
            base_config: SimConfig::lin2020(),
            vary,
        }
    }

    #[test]
    fn the_entry_count_is_known_before_building_and_bounded() {
        let base = SimConfig::lin2020();
        let cases = [
            vec![],
            vec!["l1.size_bytes=32768,65536"],
            vec!["tms=2,4,8"],
            vec!["tms=2,8", "units.dst_pipes=1,2,3"],
        ];
        for vary in cases {
            let v: Vec<Vary> = vary
                .iter()
                .map(|a| Vary::parse(a, &base).unwrap())
                .collect();
            for workloads in [
                vec![Workload::Cast],
                vec![Workload::Path],
                Workload::ALL.to_vec(),
            ] {
                let mut o = opts(v.clone());
                o.workloads = workloads;
                o.tms = vec![2, 4, 4, 8];
                let plan = Plan::build(&o).unwrap();
                let scaling = Producer::scaling_specs(&["cornell builtin:cornell".to_string()]);
                let varies_tms = o.vary.iter().any(|v| v.key == "tms");
                assert_eq!(
                    Plan::count(&o, &scaling, varies_tms),
                    plan.entries.len() as u128,
                    "{vary:?}"
                );
            }
        }
        let values: Vec<String> = (1..=64).map(|i| i.to_string()).collect();
        let sweeps: Vec<Vary> = ["dst_pipes", "box_pipes", "tri_pipes"]
            .iter()
            .map(|k| Vary::parse(&format!("units.{k}={}", values.join(",")), &base).unwrap())
            .collect();
        let e = Plan::build(&opts(sweeps)).unwrap_err();
        assert!(
            matches!(e, StudyError::TooManyEntries { count, limit } if count == 64 * 64 * 64 * 6 && limit == MAX_PLAN_ENTRIES),
            "{e}"
        );
    }

    #[test]
    fn entries_are_the_cross_product_with_distinct_keys() {
        let base = SimConfig::lin2020();
        let v = Vary::parse("l1.size_bytes=32768,65536", &base).unwrap();
        let plan = Plan::build(&opts(vec![v])).unwrap();
        // 2 values × (2 configurations × 2 workloads at 2 TMs + 2 path at 4 TMs).
        assert_eq!(plan.entries.len(), 2 * (4 + 2));
        let mut keys: Vec<&str> = plan.entries.iter().map(|e| e.cache_key.as_str()).collect();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), plan.entries.len());
        assert!(plan.entries.iter().all(|e| e.config.tms == e.tms));
        let sizes: Vec<u64> = plan
            .entries
            .iter()
            .map(|e| e.config.l1.size_bytes)
            .collect();
        assert!(sizes.contains(&32768) && sizes.contains(&65536));
    }

    #[test]
    fn without_a_sweep_keys_match_the_report_cache() {
        let plan = Plan::build(&opts(Vec::new())).unwrap();
        let e = &plan.entries[0];
        let mut cfg = SimConfig::lin2020();
        cfg.tms = e.tms;
        let report_key = CacheKey::new(
            "sim",
            "h",
            &format!("{}@fast", e.accel.name()),
            e.workload.name(),
            &serde_json::to_string(&cfg).unwrap(),
            (16, 16),
        );
        assert_eq!(e.cache_key, report_key.file_name());
    }

    #[test]
    fn kernel_variants_sweep_on_rv32_and_are_refused_on_fast() {
        let base = SimConfig::lin2020();
        let v = || Vary::parse("kernels.node_fetch=operand,loads", &base).unwrap();
        let e = Plan::build(&opts(vec![v()])).unwrap_err();
        assert!(e.to_string().contains("--model rv32"), "{e}");
        let mut o = opts(vec![v()]);
        o.thread_model = ThreadModel::Rv32;
        let plan = Plan::build(&o).unwrap();
        assert_eq!(plan.entries.len(), 2 * (4 + 2));
        assert!(
            plan.entries
                .iter()
                .any(|e| e.config.kernels.node_fetch == dualsplit_sim::NodeFetch::Loads)
        );
        // A name that is not a choice: refused when parsed or when planned.
        let bad = Vary::parse("kernels.node_fetch=memory", &base).and_then(|v| {
            let mut o = opts(vec![v]);
            o.thread_model = ThreadModel::Rv32;
            Plan::build(&o)
        });
        assert!(bad.is_err());
    }

    #[test]
    fn a_swept_tms_replaces_the_scaling_study() {
        let base = SimConfig::lin2020();
        let v = Vary::parse("tms=8,16", &base).unwrap();
        let plan = Plan::build(&opts(vec![v])).unwrap();
        assert_eq!(plan.entries.len(), 2 * 4);
        let tms: Vec<u32> = plan.entries.iter().map(|e| e.tms).collect();
        assert!(tms.iter().all(|t| [8, 16].contains(t)));
    }

    #[test]
    fn save_load_round_trip_and_tamper_check() {
        let dir = tempfile::tempdir().unwrap();
        let plan = Plan::build(&opts(Vec::new())).unwrap();
        plan.save(dir.path()).unwrap();
        assert_eq!(Plan::load(dir.path()).unwrap(), plan);
        let mut bad = plan.clone();
        bad.entries[0].config.l1.size_bytes = 32768;
        bad.save(dir.path()).unwrap();
        assert!(Plan::load(dir.path()).is_err());
    }
}
