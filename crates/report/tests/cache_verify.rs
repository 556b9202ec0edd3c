//! The cache verifies what it reads: an entry whose checksum or key does not match is
//! recomputed, never shown; and a report built from the cache is byte-identical to the
//! fresh one that filled it.

mod common;

use common::{fake_simulate, random_scene};
use dualsplit_report::data::ReportSettings;
use dualsplit_report::{Cache, NoProgress, Producer};

fn settings() -> ReportSettings {
    ReportSettings {
        width: 4,
        height: 4,
        tms: vec![32, 64, 128],
        base_tms: 64,
        cpu_res: 4,
        full: false,
        thread_model: dualsplit_sim::ThreadModel::Fast,
    }
}

fn results_json(data: &dualsplit_report::ReportData, out: &std::path::Path) -> Vec<u8> {
    dualsplit_report::write_report(data, out).unwrap();
    std::fs::read(out.join("results.json")).unwrap()
}

#[test]
fn cached_results_are_byte_identical_to_fresh_ones() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = [
        random_scene("hairball-test", 40, 1),
        random_scene("b", 30, 2),
    ];
    let p = Producer::new(
        Cache::new(dir.path().join("cache")),
        settings(),
        &NoProgress,
        &fake_simulate,
    );
    let fresh = p.run(&scenes, vec![]).unwrap();
    assert!(p.computed() > 0);
    let a = results_json(&fresh, &dir.path().join("a"));
    let p = Producer::new(
        Cache::new(dir.path().join("cache")),
        settings(),
        &NoProgress,
        &fake_simulate,
    );
    let cached = p.run(&scenes, vec![]).unwrap();
    assert_eq!(p.computed(), 0, "everything comes from the cache");
    let b = results_json(&cached, &dir.path().join("b"));
    if a != b {
        let (a, b) = (String::from_utf8_lossy(&a), String::from_utf8_lossy(&b));
        let diff: Vec<_> = a
            .lines()
            .zip(b.lines())
            .filter(|(x, y)| x != y)
            .take(5)
            .collect();
        panic!("cached results.json differs from the fresh one: {diff:#?}");
    }
}

#[test]
fn edited_entries_are_recomputed_not_shown() {
    let dir = tempfile::tempdir().unwrap();
    let cache_dir = dir.path().join("cache");
    let scenes = [random_scene("one", 20, 3)];
    let run = || {
        let p = Producer::new(
            Cache::new(&cache_dir),
            settings(),
            &NoProgress,
            &fake_simulate,
        );
        let data = p.run(&scenes, vec![]).unwrap();
        (data, p.computed())
    };
    let (fresh, _) = run();
    let a = results_json(&fresh, &dir.path().join("a"));
    // Hand-edit one simulated frame's time, keeping the entry well-formed JSON.
    let entry = std::fs::read_dir(&cache_dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.file_name().unwrap().to_string_lossy().starts_with("sim-"))
        .expect("a simulated entry");
    let text = std::fs::read_to_string(&entry).unwrap();
    let at = text.find("\"frame_ms\":").expect("frame_ms in the entry") + 11;
    let end = at + text[at..].find([',', '}']).unwrap();
    let edited = format!("{}13427.97{}", &text[..at], &text[end..]);
    assert_ne!(edited, text);
    serde_json::from_str::<serde_json::Value>(edited.split_once('\n').unwrap().1).unwrap();
    std::fs::write(&entry, edited).unwrap();
    let (again, computed) = run();
    assert_eq!(computed, 1, "exactly the edited piece is recomputed");
    assert_eq!(a, results_json(&again, &dir.path().join("b")));
    // And the recomputed entry is stored again, verified.
    assert_eq!(run().1, 0);
}
