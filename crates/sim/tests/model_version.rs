//! The golden runs and the `fast` model's calibration are results of one model version: when
//! either changes, `MODEL_VERSION` must change with it, since the report's result cache keys
//! on the version and would otherwise serve results of the old model.
//!
//! `tests/golden/versions.toml` lists every version with the SHA-256 of the two files' data
//! lines (comments left out) as recorded under it. This test fails when the current data
//! are not the ones recorded for the current `MODEL_VERSION`: re-recording either file means
//! a new version and a new entry, never an edited one.

use dualsplit_sim::MODEL_VERSION;
use sha2::{Digest, Sha256};

fn data_sha256(rel: &str) -> String {
    let p = format!("{}/{rel}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{p}: {e}"));
    let mut h = Sha256::new();
    for line in text.lines().filter(|l| !l.trim_start().starts_with('#')) {
        h.update(line.as_bytes());
        h.update(b"\n");
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

#[test]
fn golden_and_calibration_data_are_those_of_the_current_model_version() {
    let expected = data_sha256("tests/golden/expected.toml");
    let calibration = data_sha256("calibration.toml");
    let text = std::fs::read_to_string(format!(
        "{}/tests/golden/versions.toml",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("tests/golden/versions.toml");
    let table: toml::Table = text.parse().expect("versions.toml parses");
    let entries = table["version"].as_array().expect("[[version]] entries");
    let versions: Vec<i64> = entries
        .iter()
        .map(|e| e["version"].as_integer().expect("version"))
        .collect();
    assert!(
        versions.windows(2).all(|w| w[0] < w[1]),
        "versions.toml: versions must be listed once each, in increasing order: {versions:?}"
    );
    let current = entries.last().expect("at least one version");
    let want = |k: &str| current[k].as_str().unwrap_or_default().to_string();
    assert_eq!(
        versions.last().copied(),
        Some(MODEL_VERSION as i64),
        "MODEL_VERSION is {MODEL_VERSION} but versions.toml's last entry is {:?}: add an entry",
        versions.last()
    );
    assert!(
        want("expected_sha256") == expected && want("calibration_sha256") == calibration,
        "the golden expectations or the calibration changed without a MODEL_VERSION bump \
         (recorded for version {MODEL_VERSION}: expected {}, calibration {}; now {expected}, \
         {calibration}): bump MODEL_VERSION, say why in docs/changelog.md, and add a \
         [[version]] entry with these hashes",
        want("expected_sha256"),
        want("calibration_sha256"),
    );
}
