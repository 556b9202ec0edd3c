//! The report cache's entry reader on arbitrary bytes: an entry is accepted only whole and
//! verified, and what is accepted survives writing and reading back unchanged.
#![no_main]

use dualsplit_report::CacheKey;
use dualsplit_report::cache::{decode, encode};
use dualsplit_sim::SimResult;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // A fixed key (the seeds in fuzz/seeds/cache are signed with it), independent of the
    // code version that CacheKey::new would put in.
    let key = CacheKey {
        piece: "sim".into(),
        scene_hash: "2ecb2d4f01f9cefd".into(),
        structure: "dst@rv32".into(),
        workload: "path".into(),
        config: "{}".into(),
        resolution: "8x8".into(),
        code_version: "fuzz".into(),
    };
    let _ = decode::<SimResult>(&key, data);
    if let Some(v) = decode::<serde_json::Value>(&key, data) {
        let again = encode(&key, &v).expect("a decoded value encodes");
        assert_eq!(decode::<serde_json::Value>(&key, &again), Some(v));
    }
});
