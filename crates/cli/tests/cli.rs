//! The command line as a user meets it: lists take commas, a missing scene file is named
//! as missing, output paths are checked before any work starts, and help texts speak the
//! user's language (no internal identifiers).
mod common;

use common::{dualsplit, stderr, stdout};
use std::process::Command;

const SUBCOMMANDS: [&str; 9] = [
    "info",
    "build",
    "stats",
    "check",
    "render",
    "bench",
    "simulate",
    "report",
    "calibrate",
];

#[test]
fn space_separated_lists_are_refused_with_the_comma_form() {
    let dir = tempfile::tempdir().unwrap();
    for (args, want) in [
        (&["report", "--tms", "32", "64"][..], "--tms 32,64"),
        (
            &["simulate", "builtin:cornell", "--accel", "bvh2", "dst"][..],
            "--accel bvh2,dst",
        ),
        (
            &["bench", "builtin:cornell", "--accel", "bvh2", "bvh4"][..],
            "--accel bvh2,bvh4",
        ),
        (
            &[
                "render",
                "builtin:cornell",
                "--eye",
                "1",
                "2",
                "3",
                "-o",
                "x.png",
            ][..],
            "--eye 1,2",
        ),
    ] {
        let o = dualsplit(args, dir.path());
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{args:?}: {}", stderr(&o));
        assert!(stdout(&o).is_empty(), "{args:?} did work: {}", stdout(&o));
    }
}

#[test]
fn comma_lists_are_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let o = dualsplit(
        &[
            "bench",
            "builtin:cornell",
            "--accel",
            "bvh2,dst",
            "--res",
            "4x3",
            "--min-seconds",
            "0.001",
            "--no-frame",
            "--json",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let accels: Vec<String> = stdout(&o)
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).expect("a JSON line");
            v["accel"].as_str().unwrap_or_default().to_string()
        })
        .collect();
    assert!(accels.iter().any(|a| a == "bvh2"), "{accels:?}");
    assert!(accels.iter().any(|a| a == "dst"), "{accels:?}");
    assert!(!accels.iter().any(|a| a == "bvh4"), "{accels:?}");
    // The machine is named beside the figures.
    let host = stdout(&o)
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).expect("a JSON line"))
        .find(|v| v.get("host").is_some())
        .expect("a host line");
    assert!(host["host"]["cpu"].is_string(), "{host}");
    assert!(host["host"]["avx2"].is_boolean(), "{host}");
    assert!(
        host["host"]["cpus"].as_u64().is_some_and(|n| n >= 1),
        "{host}"
    );
}

#[test]
fn a_missing_scene_file_says_so_and_names_the_builtins() {
    let dir = tempfile::tempdir().unwrap();
    for cmd in ["info", "stats", "check", "bench", "simulate"] {
        let o = dualsplit(&[cmd, "nope.ply"], dir.path());
        assert!(!o.status.success(), "{cmd}");
        let e = stderr(&o);
        assert!(
            e.contains("no such file") && e.contains("nope.ply"),
            "{cmd}: {e}"
        );
        assert!(e.contains("builtin:hairball"), "{cmd}: {e}");
        assert!(!e.contains("unknown scene format"), "{cmd}: {e}");
    }
    let o = dualsplit(&["report", "--out", "r", "nope.ply"], dir.path());
    assert!(stderr(&o).contains("no such file"), "{}", stderr(&o));
    let o = dualsplit(&["info", "forest"], dir.path());
    assert!(
        stderr(&o).contains("did you mean builtin:forest?"),
        "{}",
        stderr(&o)
    );
    // A scene file that exists is loaded as before.
    std::fs::write(
        dir.path().join("t.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let o = dualsplit(&["info", "t.obj"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn output_paths_are_checked_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing/x.png");
    let o = dualsplit(
        &[
            "render",
            "builtin:cornell",
            "--res",
            "4",
            "-o",
            missing.to_str().unwrap(),
        ],
        dir.path(),
    );
    assert!(!o.status.success());
    assert!(stderr(&o).contains("no such directory"), "{}", stderr(&o));
    // Nothing was loaded or rendered: the scene line comes after the check.
    assert!(stdout(&o).is_empty(), "{}", stdout(&o));

    let json = dir.path().join("missing/out.json");
    let arg = format!("--json={}", json.display());
    for cmd in ["info", "stats", "simulate"] {
        let o = dualsplit(&[cmd, "builtin:cornell", &arg], dir.path());
        assert!(!o.status.success(), "{cmd}");
        assert!(
            stderr(&o).contains("no such directory"),
            "{cmd}: {}",
            stderr(&o)
        );
        assert!(stdout(&o).is_empty(), "{cmd}: {}", stdout(&o));
    }

    let file = dir.path().join("a-file");
    std::fs::write(&file, "").unwrap();
    let o = dualsplit(
        &["report", "--out", file.to_str().unwrap(), "builtin:cornell"],
        dir.path(),
    );
    assert!(!o.status.success());
    assert!(stderr(&o).contains("not a directory"), "{}", stderr(&o));
    assert!(!dir.path().join("a-file/cache").exists());
}

#[test]
fn json_goes_to_a_file_when_one_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let o = dualsplit(&["info", "builtin:cornell", "--json=info.json"], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("info.json")).unwrap())
            .unwrap();
    assert_eq!(v["name"], "cornell");
    assert!(!stdout(&o).contains("\"name\""));
}

/// Words of a help text that name code rather than a user's concept: SCREAMING_SNAKE
/// constants (environment variables aside), paths like `a::b`, and CamelCase type names.
fn internal_identifiers(help: &str) -> Vec<String> {
    // Value placeholders (`<LIGHT_RADIUS>`) are clap's, derived from the option names.
    let mut text = String::new();
    let mut depth = 0;
    for c in help.chars() {
        match c {
            '<' => depth += 1,
            '>' if depth > 0 => depth -= 1,
            _ if depth == 0 => text.push(c),
            _ => {}
        }
    }
    let mut bad = Vec::new();
    for word in text.split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')) {
        let w = word.trim_matches(':');
        let screaming = w.contains('_')
            && w.chars()
                .all(|c| c.is_ascii_uppercase() || c == '_' || c.is_ascii_digit())
            && !w.starts_with("DUALSPLIT_");
        let path = w.contains("::");
        // `SimAccel`: two or more capitalised lower-case runs (not `TRaX`).
        let camel = w.chars().all(|c| c.is_ascii_alphabetic())
            && w.match_indices(|c: char| c.is_ascii_uppercase()).count() >= 2
            && w.char_indices()
                .filter(|(_, c)| c.is_ascii_uppercase())
                .all(|(i, _)| w[i + 1..].starts_with(|c: char| c.is_ascii_lowercase()));

        if screaming || path || camel {
            bad.push(w.to_string());
        }
    }
    bad
}

#[test]
fn help_texts_name_no_internal_identifier() {
    assert_eq!(
        internal_identifiers("see `DEFAULT_SCENES` and SimAccel, dualsplit_sim::x"),
        ["DEFAULT_SCENES", "SimAccel", "dualsplit_sim::x"]
    );
    let dir = tempfile::tempdir().unwrap();
    let mut helps = vec![stdout(&dualsplit(&["--help"], dir.path()))];
    for cmd in SUBCOMMANDS {
        let o = dualsplit(&[cmd, "--help"], dir.path());
        assert!(o.status.success(), "{cmd} --help");
        helps.push(stdout(&o));
    }
    for help in &helps {
        let bad = internal_identifiers(help);
        assert!(bad.is_empty(), "internal identifiers {bad:?} in:\n{help}");
    }
}

#[test]
fn simulate_compares_configurations_and_keeps_every_number_in_json() {
    let dir = tempfile::tempdir().unwrap();
    let common = ["--res", "8x4", "--model", "fast", "--workload", "cast"];
    let mut args = vec!["simulate", "builtin:cornell", "--accel", "all"];
    args.extend(common);
    let o = dualsplit(&args, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("8×4 cast"), "{out}");
    let table = out
        .split("comparison (")
        .nth(1)
        .expect("a comparison after several configurations");
    assert!(table.starts_with("frame time, energy and DRAM lines as % of BVH2"));
    let rows: Vec<&str> = table
        .lines()
        .skip(2)
        .take_while(|l| !l.starts_with("note"))
        .collect();
    assert_eq!(rows.len(), 11, "{table}");
    assert!(
        rows[0].starts_with("BVH2 ") && rows[0].contains("100.0 %"),
        "{table}"
    );
    assert!(rows[7].starts_with("DST "), "{table}");
    assert!(rows[10].starts_with("DST-Q "), "{table}");
    // 32 pixels on 2048 threads: the chip is idle, and the output says so.
    assert!(out.contains("note: threads sat idle"), "{out}");

    // --json: settings, every result and the comparison; DST first, so BVH2 is still the
    // baseline; the camera override is applied.
    let mut args = vec![
        "simulate",
        "builtin:cornell",
        "--accel",
        "dst,bvh2",
        "--eye",
        "0,1,3.5",
        "--json",
    ];
    args.extend(common);
    let o = dualsplit(&args, dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("only JSON on stdout");
    assert_eq!(
        (v["width"].as_u64(), v["height"].as_u64()),
        (Some(8), Some(4))
    );
    assert_eq!(v["workload"], "cast");
    assert_eq!(v["camera"]["eye"], serde_json::json!([0.0, 1.0, 3.5]));
    assert_eq!(v["results"].as_array().map(Vec::len), Some(2));
    assert_eq!(v["summary"]["baseline"], "bvh2");
    let rows = v["summary"]["rows"].as_array().unwrap();
    assert_eq!(rows[0]["accel"], "dst");
    assert_eq!(rows[1]["frame_vs_baseline"].as_f64(), Some(1.0));
    let dst_ms = v["results"][0]["frame_ms"].as_f64().unwrap();
    let bvh_ms = v["results"][1]["frame_ms"].as_f64().unwrap();
    // serde_json reads floats to within an ulp or so.
    let ratio = rows[0]["frame_vs_baseline"].as_f64().unwrap();
    assert!((ratio - dst_ms / bvh_ms).abs() < 1e-12, "{ratio}");
    assert!(rows[0]["stalls"]["idle_at_end"].as_f64().unwrap() > 0.5);
    assert!(v["config"]["dram"]["e_read_nj"].as_f64().is_some());

    // A bad camera is refused before anything is simulated.
    let o = dualsplit(
        &["simulate", "builtin:cornell", "--eye", "0,0", "--res", "4"],
        dir.path(),
    );
    assert!(!o.status.success());
    assert!(stdout(&o).is_empty(), "{}", stdout(&o));
}

#[test]
fn report_says_which_paper_meshes_it_found_and_where() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = dir.path().join("meshes");
    std::fs::create_dir_all(&scenes).unwrap();
    std::fs::write(scenes.join("dragon_box.ply.gz"), "").unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec![
            "report",
            "builtin:cornell",
            "--res",
            "4",
            "--tms",
            "1,2",
            "--model",
            "fast",
            "--out",
            "r",
        ];
        args.extend(extra);
        Command::new(env!("CARGO_BIN_EXE_dualsplit"))
            .args(&args)
            .current_dir(dir.path())
            .env("DUALSPLIT_SCENES", &scenes)
            .output()
            .unwrap()
    };
    let o = run(&[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let md = std::fs::read_to_string(dir.path().join("r/report.md")).unwrap();
    let want = format!(
        "Scenes folder {} (given by DUALSPLIT_SCENES). Paper meshes found: Dragon Box",
        scenes.display()
    );
    assert!(md.contains(&want), "{md}");
    assert!(md.contains("Not found: Dragon Sponza"), "{md}");
    assert!(stderr(&o).contains(&want), "{}", stderr(&o));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r/results.json")).unwrap())
            .unwrap();
    assert_eq!(json["scene_files"]["source"], "env");

    // --scenes wins over the variable, and must name a folder.
    let o = run(&["--scenes", "nowhere"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("--scenes nowhere: no such directory"),
        "{}",
        stderr(&o)
    );
}

/// `report --dry-run` prints the plan and its time estimate without loading a scene: the
/// default plan names Dragon Box when a scenes folder holds it, `--full` the paper's setup.
#[test]
fn report_dry_run_prints_the_plan_without_loading() {
    let dir = tempfile::tempdir().unwrap();
    let scenes = dir.path().join("scenes");
    std::fs::create_dir(&scenes).unwrap();
    // An empty file under the mesh's name: a dry run must not read it.
    std::fs::write(scenes.join("dragon_box.ply.gz"), b"").unwrap();
    let s = scenes.to_str().unwrap();
    let o = dualsplit(&["report", "--dry-run", "--scenes", s], dir.path());
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("plan: 4 scenes") && e.contains("dragon_box.ply.gz"),
        "{e}"
    );
    assert!(
        e.contains("fast thread model") && e.contains("roughly"),
        "{e}"
    );
    let o = dualsplit(
        &["report", "--dry-run", "--full", "--scenes", s],
        dir.path(),
    );
    let e = stderr(&o);
    assert!(o.status.success(), "{e}");
    assert!(
        e.contains("1024×1024") && e.contains("rv32 thread model"),
        "{e}"
    );
}

/// `bench` refuses a malformed leaf-merging knob instead of quietly measuring the default.
#[test]
fn bench_refuses_a_malformed_merge_limit() {
    let dir = tempfile::tempdir().unwrap();
    for bad in ["abc", "65", "-1"] {
        let o = Command::new(env!("CARGO_BIN_EXE_dualsplit"))
            .args(["bench", "builtin:cornell", "--res", "4", "--no-frame", "-q"])
            .env("DUALSPLIT_MERGE_MAX", bad)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{bad}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("DUALSPLIT_MERGE_MAX") && stderr(&o).contains("from 0 to 64"),
            "{bad}: {}",
            stderr(&o)
        );
        assert!(stdout(&o).is_empty(), "{bad} did work: {}", stdout(&o));
    }
    let o = Command::new(env!("CARGO_BIN_EXE_dualsplit"))
        .args([
            "bench",
            "builtin:cornell",
            "--res",
            "4x3",
            "--min-seconds",
            "0.001",
        ])
        .args(["--no-frame", "-q"])
        .env("DUALSPLIT_MERGE_MAX", "0")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("subtrees of at most 0 triangles merged"),
        "{}",
        stdout(&o)
    );
}

/// `bench --peer embree,embree-robust,embree-avx2` checks the three Embree scenes and times
/// them with ours in one interleaved run: every ray kind gets a timing per contender and
/// each peer a summary with our best structure's ratio to it. Without Embree, the peer is
/// named in the error (and under CI, where `.ci/run` installs it, the test fails).
#[test]
fn bench_compares_with_every_embree_peer_in_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let o = dualsplit(
        &[
            "bench",
            "builtin:cornell",
            "--res",
            "8",
            "--accel",
            "bvh2,bvh8",
            "--peer",
            "embree,embree-robust,embree-avx2,embree",
            "--threads",
            "1",
            "--min-seconds",
            "0.001",
            "--no-frame",
            "-q",
            "--json",
        ],
        dir.path(),
    );
    if !dualsplit_embree::available() {
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains("--peer embree"), "{}", stderr(&o));
        assert!(
            std::env::var_os("CI").is_none(),
            "Embree is missing under CI: .ci/run installs libembree-dev"
        );
        return;
    }
    assert!(o.status.success(), "{}", stderr(&o));
    let lines: Vec<serde_json::Value> = stdout(&o)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let kinds = ["primary", "shadow", "diffuse"];
    for name in ["bvh2", "bvh8", "embree", "embree-robust", "embree-avx2"] {
        for kind in kinds {
            let n = lines
                .iter()
                .filter(|l| l["accel"] == name && l["ray_kind"] == kind)
                .filter(|l| l["mrays_per_s"].as_f64().is_some_and(|m| m > 0.0))
                .count();
            assert_eq!(n, 1, "{name} {kind}: {}", stdout(&o));
        }
    }
    let summaries: Vec<&serde_json::Value> = lines
        .iter()
        .filter(|l| l.get("ratio_best_to_peer").is_some())
        .collect();
    let peers: Vec<&str> = summaries
        .iter()
        .map(|l| l["peer"].as_str().unwrap())
        .collect();
    // The repeated peer is measured once.
    assert_eq!(
        peers,
        ["embree", "embree-robust", "embree-avx2"],
        "{}",
        stdout(&o)
    );
    for s in summaries {
        for kind in kinds {
            let r = s["ratio_best_to_peer"][kind].as_f64().unwrap_or(f64::NAN);
            assert!(r.is_finite() && r > 0.0, "{kind}: {s}");
            assert!(
                s["agreement"][kind]["rays"].as_u64() > Some(0),
                "{kind}: {s}"
            );
        }
    }
}

/// `--sim-threads` on `simulate` and `run-job`: the same JSON and the same stored result
/// on one host thread and on three (the default chip's 64 TMs split three ways), and 0 is
/// refused.
#[test]
fn sim_threads_change_no_result() {
    let dir = tempfile::tempdir().unwrap();
    let sim = |threads: &str| {
        let o = dualsplit(
            &[
                "-q",
                "simulate",
                "builtin:cornell",
                "--res",
                "12x8",
                "--workload",
                "cast",
                "--accel",
                "bvh2,dst",
                "--json",
                "--sim-threads",
                threads,
            ],
            dir.path(),
        );
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
    };
    let one = sim("1");
    assert!(one.contains("\"frame_ms\""), "{one}");
    assert_eq!(sim("3"), one);
    let o = dualsplit(
        &["simulate", "builtin:cornell", "--sim-threads", "0"],
        dir.path(),
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("positive"), "{}", stderr(&o));

    // run-job: one entry stored with three threads, then again with one after removing it.
    let o = dualsplit(
        &[
            "-q",
            "plan",
            "builtin:cornell",
            "--res",
            "8",
            "--out",
            "study",
            "--accel",
            "dst",
            "--workload",
            "cast",
            "--tms",
            "64",
            "--model",
            "fast",
            "--sim-threads",
            "3",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("--sim-threads"), "{}", stdout(&o));
    let stored = |threads: &str| {
        let o = dualsplit(
            &["-q", "run-job", "study", "0", "--sim-threads", threads],
            dir.path(),
        );
        assert!(o.status.success(), "{}", stderr(&o));
        let cache = dir.path().join("study/cache");
        let file = std::fs::read_dir(&cache)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| !p.file_name().unwrap().to_string_lossy().starts_with('.'))
            .expect("a stored result");
        let text = std::fs::read_to_string(&file).unwrap();
        std::fs::remove_file(&file).unwrap();
        // The simulated result, without the host's name, time and wall time.
        let v: serde_json::Value = serde_json::from_str(text.split_once('\n').unwrap().1).unwrap();
        v["result"].to_string()
    };
    assert_eq!(stored("3"), stored("1"));
}
