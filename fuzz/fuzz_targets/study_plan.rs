//! A study's `plan.json` reader (`Plan::parse`, what `Plan::load` runs on the bytes it read)
//! on arbitrary bytes: a typed error or a plan whose entries are numbered in order, within
//! `MAX_PLAN_ENTRIES`, and that survives saving and reading back unchanged.
#![no_main]

use dualsplit_report::study::Plan;
use dualsplit_report::study::plan::MAX_PLAN_ENTRIES;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    if let Ok(plan) = Plan::parse(Path::new("plan.json"), data) {
        assert!(plan.entries.len() as u64 <= MAX_PLAN_ENTRIES);
        assert!(plan.entries.iter().enumerate().all(|(i, e)| e.index == i));
        let again = serde_json::to_vec_pretty(&plan).expect("a plan serializes");
        let back = Plan::parse(Path::new("plan.json"), &again).expect("a saved plan reads back");
        assert_eq!(back, plan);
    }
});
