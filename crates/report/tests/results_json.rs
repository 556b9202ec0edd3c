//! `results.json` as a reader of it sees it: plain values (no `{"Ok": …}` wrappers, a
//! missing value as `{"error": …}`), every field named in `docs/results-json.md`, and read
//! back into the same data.

mod common;

use common::{fake_simulate, random_scene};
use dualsplit_report::data::ReportSettings;
use dualsplit_report::{Cache, NoProgress, Producer};
use serde_json::Value;

/// Every object key anywhere in `v`, with its path.
fn keys(v: &Value, path: &str, out: &mut Vec<(String, String)>) {
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                out.push((path.to_string(), k.clone()));
                keys(x, &format!("{path}.{k}"), out);
            }
        }
        Value::Array(a) => {
            for x in a {
                keys(x, &format!("{path}[]"), out);
            }
        }
        _ => {}
    }
}

#[test]
fn results_json_has_plain_documented_values() {
    let dir = tempfile::tempdir().unwrap();
    let settings = ReportSettings {
        width: 4,
        height: 4,
        tms: vec![32, 64],
        base_tms: 64,
        cpu_res: 4,
        full: false,
        thread_model: dualsplit_sim::ThreadModel::Fast,
    };
    // One configuration fails, so an error value is written too.
    let sim = |a: &_, b: &_, c, d: &_, e: &_, t, f: &(dyn Fn(u64, u64) + Sync)| {
        if c == dualsplit_sim::SimAccel::Bvh8 {
            Err("simulator unavailable: test".to_string())
        } else {
            fake_simulate(a, b, c, d, e, t, f)
        }
    };
    let p = Producer::new(
        Cache::new(dir.path().join("cache")),
        settings,
        &NoProgress,
        &sim,
    );
    let data = p
        .run(&[random_scene("hairball-test", 30, 3)], vec![])
        .unwrap();
    dualsplit_report::write_report(&data, dir.path()).unwrap();
    let text = std::fs::read_to_string(dir.path().join("results.json")).unwrap();
    let json: Value = serde_json::from_str(&text).unwrap();

    let mut all = Vec::new();
    keys(&json, "", &mut all);
    for (path, k) in &all {
        assert!(k != "Ok" && k != "Err", "a {k} wrapper at {path}");
    }
    let scene = &json["scenes"][0];
    assert!(
        scene["cpu"]["sizes"][0]["bytes"].is_u64(),
        "{}",
        scene["cpu"]["sizes"][0]
    );
    // 16 rays per kind from 4×4 frames: too few to time, so each throughput is an error.
    assert!(scene["cpu"]["throughput"][0]["mrays_per_s"]["error"].is_string());
    let runs = scene["sim"].as_array().unwrap();
    assert!(
        runs.iter()
            .any(|r| r["result"]["error"] == "simulator unavailable: test")
    );
    assert!(runs.iter().any(|r| r["result"]["frame_ms"].is_f64()));

    // Every field name appears in the documented schema.
    let doc = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../docs/results-json.md"
    ))
    .unwrap();
    for (path, k) in &all {
        let documented = [format!("`{k}`"), format!("`{k}[]`"), format!("\"{k}\"")]
            .iter()
            .any(|form| doc.contains(form.as_str()));
        assert!(documented, "{path}.{k} is not in docs/results-json.md");
    }

    // And it reads back into the same data.
    let back: dualsplit_report::ReportData = serde_json::from_str(&text).unwrap();
    assert_eq!(serde_json::to_value(&back).unwrap(), json);
}
