//! `run-job`: one plan entry, simulated and stored, unless a valid result is already there.

use super::StudyError;
use super::plan::{Plan, PlanEntry, code_version};
use super::store::{JobRecord, ResultStore, Stored, host_name};
use crate::produce::structure_bytes;
use dualsplit_accel::{AccelKind, BuildConfig, Structures};
use dualsplit_render::RenderSettings;
use dualsplit_sim::SimAccel;
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// What `run-job` did.
#[derive(Debug)]
pub enum JobOutcome {
    /// A valid result was already stored.
    AlreadyDone(PathBuf),
    /// Simulated and stored; `replaced` says why an existing file was not valid.
    Computed {
        /// The result file.
        path: PathBuf,
        /// Why the file that was there before was not a result.
        replaced: Option<String>,
        /// Wall seconds of the simulation.
        wall_s: f64,
    },
}

/// Runs entry `index` of the study in `dir` on `threads` host threads (the result does
/// not depend on them); `progress(done, total)` gets pixel counts.
pub fn run_job(
    dir: &Path,
    index: usize,
    threads: usize,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<JobOutcome, StudyError> {
    let plan = Plan::load(dir)?;
    let entry = plan.entries.get(index).ok_or(StudyError::NoEntry {
        index,
        len: plan.entries.len(),
    })?;
    let store = ResultStore::new(dir);
    let replaced = match store.read(entry) {
        Stored::Valid(_) => return Ok(JobOutcome::AlreadyDone(store.path(entry))),
        Stored::Missing => None,
        Stored::Invalid(why) => Some(why),
    };
    let t0 = Instant::now();
    let result = simulate_entry(entry, threads, progress)?;
    let wall_s = t0.elapsed().as_secs_f64();
    let record = JobRecord {
        code_version: code_version(),
        index,
        cache_key: entry.cache_key.clone(),
        scene_hash: entry.scene_hash.clone(),
        accel: entry.accel,
        workload: entry.workload,
        tms: entry.tms,
        config_hash: entry.config_hash.clone(),
        varied: entry.varied.clone(),
        host: host_name(),
        host_time_unix_s: SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0),
        host_wall_s: wall_s,
        result,
    };
    let path = store.write(entry, &record)?;
    Ok(JobOutcome::Computed {
        path,
        replaced,
        wall_s,
    })
}

/// Loads the entry's scene (checking its content hash), builds its structures with the
/// report's settings and simulates the frame on `threads` host threads.
pub fn simulate_entry(
    entry: &PlanEntry,
    threads: usize,
    progress: &(dyn Fn(u64, u64) + Sync),
) -> Result<dualsplit_sim::SimResult, StudyError> {
    let fail = |reason: String| StudyError::Job {
        index: entry.index,
        reason,
    };
    let scene = dualsplit_scene::load(&entry.scene)
        .map_err(|e| fail(format!("loading scene {}: {e}", entry.scene)))?;
    let hash = scene.content_hash();
    if hash != entry.scene_hash {
        return Err(fail(format!(
            "scene {} has content hash {hash}, the plan was made with {}: the file changed",
            entry.scene, entry.scene_hash
        )));
    }
    let structures = Structures::try_build(&scene.triangles, &BuildConfig::high_quality())
        .map_err(|e| fail(format!("building the structures: {e}")))?;
    if matches!(entry.accel, SimAccel::Dst | SimAccel::DstSw) {
        structure_bytes(&structures, AccelKind::Dst).map_err(fail)?;
    }
    let settings = RenderSettings::new(entry.width, entry.height, entry.workload);
    dualsplit_sim::simulate(
        &dualsplit_sim::FrameRequest::new(
            &scene,
            &structures,
            entry.accel,
            &settings,
            &entry.config,
        )
        .with_model(entry.thread_model)
        .with_threads(threads),
        progress,
    )
    .map_err(|e| fail(format!("simulating: {e}")))
}
