//! A study's result file reader (`store::verify`, what `ResultStore::read` runs on the bytes
//! it read) on arbitrary bytes, for entry 0 of a fixed plan (the one the seeds in
//! fuzz/seeds/study_result were made for: `dualsplit plan builtin:cornell --res 4 --tms 4
//! --accel bvh2 --workload cast`): a refusal with a reason, or a record of that entry that
//! survives writing and reading back unchanged.
#![no_main]

use dualsplit_render::Workload;
use dualsplit_report::study::plan::PlanScene;
use dualsplit_report::study::store::{encode, verify};
use dualsplit_report::study::{Plan, PlanEntry, PlanOptions};
use dualsplit_sim::{SimAccel, SimConfig, ThreadModel};
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

fn entry() -> &'static PlanEntry {
    static ENTRY: OnceLock<PlanEntry> = OnceLock::new();
    ENTRY.get_or_init(|| {
        let scene = dualsplit_scene::load("builtin:cornell").expect("cornell");
        let opts = PlanOptions {
            scenes: vec![PlanScene {
                spec: "builtin:cornell".into(),
                name: scene.name.clone(),
                hash: scene.content_hash(),
            }],
            width: 4,
            height: 4,
            tms: vec![4],
            base_tms: 4,
            thread_model: ThreadModel::Fast,
            accels: vec![SimAccel::Bvh2],
            workloads: vec![Workload::Cast],
            base_config: SimConfig::lin2020(),
            vary: Vec::new(),
        };
        Plan::build(&opts).expect("the plan").entries.remove(0)
    })
}

fuzz_target!(|data: &[u8]| {
    let entry = entry();
    if let Ok(record) = verify(data, entry) {
        assert_eq!(record.cache_key, entry.cache_key);
        let json = serde_json::to_vec(&record).expect("a record serializes");
        let back = verify(&encode(&json), entry).expect("a written record reads back");
        assert_eq!(serde_json::to_vec(&back).expect("serializes"), json);
    }
});
