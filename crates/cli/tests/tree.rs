//! `--tree FILE` on `check`, `bench`, `render` and `simulate`: a tree saved by `build` is
//! used instead of building, answers exactly as a build would (same image bytes, same
//! simulation), and a tree of another scene, a damaged file or a structure the file does
//! not hold is refused with a message naming it and a nonzero exit.
mod common;

use common::{dualsplit, stderr, stdout};
use std::path::Path;

const SCENE: &str = "builtin:cornell";

/// `dualsplit build scene --accel kind -o name` in `dir`; returns the file's path.
fn build(scene: &str, kind: &str, name: &str, dir: &Path) -> String {
    let o = dualsplit(&["build", scene, "--accel", kind, "-o", name], dir);
    assert!(o.status.success(), "build {kind}: {}", stderr(&o));
    assert!(dir.join(name).is_file());
    name.to_string()
}

/// Runs `args`, expects a nonzero exit and returns standard error.
fn refused(args: &[&str], dir: &Path) -> String {
    let o = dualsplit(args, dir);
    assert!(
        !o.status.success(),
        "{args:?} succeeded: {}{}",
        stdout(&o),
        stderr(&o)
    );
    assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
    stderr(&o)
}

#[test]
fn check_compares_a_saved_tree_with_a_fresh_bvh2() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dst = build(SCENE, "dst", "c.dst", d);
    let o = dualsplit(&["check", SCENE, "--tree", &dst, "--rays", "3000"], d);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("tree c.dst (dst) loaded in"), "{out}");
    assert!(
        out.contains("reference: bvh2 built from the scene"),
        "{out}"
    );
    assert!(out.contains("check passed"), "{out}");
    // One validation line (the DST against the fresh BVH2), and rows for both DST
    // traversals only: 3 ray kinds × 2.
    let rows: Vec<&str> = out
        .lines()
        .filter(|l| l.contains(" primary ") || l.contains(" shadow ") || l.contains(" diffuse "))
        .collect();
    assert_eq!(rows.len(), 6, "{out}");
    assert!(rows.iter().all(|r| {
        let kind = r.split_whitespace().next();
        kind == Some("dst-sw") || kind == Some("dst")
    }));
    // Each row compares 3000 rays with no mismatch.
    for r in &rows {
        let cols: Vec<&str> = r.split_whitespace().collect();
        assert_eq!((cols[2], cols[3]), ("3000", "0"), "{r}");
    }

    let bvh4 = build(SCENE, "bvh4", "c.bvh4", d);
    let o = dualsplit(&["check", SCENE, "--tree", &bvh4, "--rays", "500"], d);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("  bvh4     primary"), "{out}");
    assert!(!out.contains("  dst "), "{out}");
}

#[test]
fn render_with_a_saved_tree_writes_the_same_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dst = build(SCENE, "dst", "c.dst", d);
    let res = ["--res", "40x30", "--workload", "path"];
    let run = |extra: &[&str], out: &str| {
        let mut args = vec!["render", SCENE];
        args.extend(res);
        args.extend(extra);
        args.extend(["-o", out]);
        let o = dualsplit(&args, d);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        (
            stdout(&o),
            std::fs::read(d.join(out)).expect("image written"),
        )
    };
    let (built_out, built) = run(&["--accel", "dst"], "built.png");
    // Only the DST is built for it.
    assert!(built_out.contains("dst built in"), "{built_out}");
    let (loaded_out, loaded) = run(&["--tree", &dst, "--accel", "dst"], "loaded.png");
    assert!(
        loaded_out.contains("tree c.dst (dst) loaded in"),
        "{loaded_out}"
    );
    assert!(!loaded_out.contains("structures built"), "{loaded_out}");
    assert!(built.len() > 100);
    assert!(built == loaded, "the images differ");
    // Without --accel, the tree's first traversal: dst-sw, the same image again.
    let (default_out, default) = run(&["--tree", &dst], "default.png");
    assert!(default_out.contains(" on dst-sw "), "{default_out}");
    assert!(default == built, "the dst-sw image differs");
    // The image says something: a BVH8 tree gives the same bytes, the sky alone would not.
    let bvh8 = build(SCENE, "bvh8", "c.bvh8", d);
    let (_, b8) = run(&["--tree", &bvh8], "bvh8.png");
    assert!(b8 == built, "the bvh8 image differs");
}

#[test]
fn bench_measures_only_the_saved_structure() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dst = build(SCENE, "dst", "c.dst", d);
    let o = dualsplit(
        &[
            "bench",
            SCENE,
            "--tree",
            &dst,
            "--res",
            "16",
            "--min-seconds",
            "0.01",
            "--json",
        ],
        d,
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("tree c.dst (dst) loaded in"),
        "{}",
        stderr(&o)
    );
    let mut accels = Vec::new();
    let out = stdout(&o);
    let mut lines = out.lines();
    // The first line says what was loaded and how long it took.
    let first: serde_json::Value = serde_json::from_str(lines.next().unwrap()).unwrap();
    assert_eq!(first["kind"], "dst", "{first}");
    assert!(
        first["tree"].as_str().unwrap().ends_with("c.dst"),
        "{first}"
    );
    assert!(first["load_ms"].as_f64().unwrap() > 0.0, "{first}");
    assert!(first.get("build_ms").is_none(), "{first}");
    // The second names the machine.
    let host: serde_json::Value = serde_json::from_str(lines.next().unwrap()).unwrap();
    assert!(host["host"]["cpu"].is_string(), "{host}");
    for line in lines {
        let v: serde_json::Value = serde_json::from_str(line).expect("JSON lines");
        let a = v["accel"].as_str().expect("accel").to_string();
        if v.get("mrays_per_s").is_some() {
            assert!(v["mrays_per_s"].as_f64().unwrap() > 0.0, "{line}");
        }
        if !accels.contains(&a) {
            accels.push(a);
        }
    }
    assert_eq!(accels, ["dst-sw", "dst"]);
}

#[test]
fn simulate_with_a_saved_tree_gives_the_same_results() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dst = build(SCENE, "dst", "c.dst", d);
    let common = [
        "simulate",
        SCENE,
        "--res",
        "8x6",
        "--model",
        "fast",
        "--workload",
        "cast",
        "--json",
    ];
    let run = |extra: &[&str]| {
        let mut args = common.to_vec();
        args.extend(extra);
        let o = dualsplit(&args, d);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        stdout(&o)
    };
    let built = run(&["--accel", "dst-sw,dst"]);
    let loaded = run(&["--tree", &dst, "--accel", "dst-sw,dst"]);
    let v: serde_json::Value = serde_json::from_str(&built).expect("JSON");
    assert_eq!(v["results"].as_array().map(Vec::len), Some(2));
    assert!(v["results"][1]["cycles"].as_u64().unwrap() > 0);
    assert_eq!(built, loaded);
    // Without --accel: every configuration of the tree, the same two.
    assert_eq!(run(&["--tree", &dst]), built);
    // `all` means the tree's configurations too.
    assert_eq!(run(&["--tree", &dst, "--accel", "all"]), built);
}

#[test]
fn a_tree_of_another_scene_is_refused_naming_both() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let other = build("builtin:hairball?triangles=2000", "dst", "hair.dst", d);
    for cmd in [
        &["check", SCENE, "--rays", "10"][..],
        &["render", SCENE, "--res", "4", "-o", "x.png"],
        &["bench", SCENE, "--res", "4", "--min-seconds", "0.01"],
        &["simulate", SCENE, "--res", "4", "--model", "fast"],
    ] {
        let mut args = cmd.to_vec();
        args.extend(["--tree", &other]);
        let e = refused(&args, d);
        assert!(e.contains("hair.dst"), "{args:?}: {e}");
        assert!(e.contains(SCENE), "{args:?}: {e}");
        assert!(e.contains("built from another scene"), "{args:?}: {e}");
    }
    assert!(!d.join("x.png").exists());
}

#[test]
fn a_damaged_tree_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dst = build(SCENE, "dst", "c.dst", d);
    let mut bytes = std::fs::read(d.join(&dst)).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x10;
    std::fs::write(d.join("flipped.dst"), &bytes).unwrap();
    std::fs::write(d.join("short.dst"), &bytes[..bytes.len() - 7]).unwrap();
    for (file, want) in [
        ("flipped.dst", "checksum mismatch"),
        ("short.dst", "truncated"),
        ("missing.dst", "missing.dst"),
    ] {
        for cmd in ["check", "simulate"] {
            let e = refused(&[cmd, SCENE, "--tree", file], d);
            assert!(e.contains(file), "{cmd} {file}: {e}");
            assert!(e.contains(want), "{cmd} {file}: {e}");
            // Once "checksum mismatch: tree file is corrupt: checksum mismatch".
            if want != file {
                assert_eq!(e.matches(want).count(), 1, "{cmd} {file}: {e}");
            }
        }
    }
    #[cfg(unix)]
    {
        // A named pipe once blocked the open forever.
        let ok = std::process::Command::new("mkfifo")
            .arg(d.join("pipe.dst"))
            .status()
            .unwrap()
            .success();
        assert!(ok);
        for cmd in ["check", "simulate"] {
            let e = refused(&[cmd, SCENE, "--tree", "pipe.dst"], d);
            assert!(
                e.contains("pipe.dst: not a regular file (a named pipe)"),
                "{e}"
            );
        }
    }
}

#[test]
fn a_structure_the_tree_does_not_hold_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let dst = build(SCENE, "dst", "c.dst", d);
    for (args, value) in [
        (
            &[
                "render", SCENE, "--accel", "bvh4", "--res", "4", "-o", "x.png",
            ][..],
            "bvh4",
        ),
        (
            &["bench", SCENE, "--accel", "dst,bvh2", "--res", "4"],
            "bvh2",
        ),
        (
            &["simulate", SCENE, "--accel", "bvh8+", "--res", "4"],
            "bvh8+",
        ),
    ] {
        let mut args = args.to_vec();
        args.extend(["--tree", &dst]);
        let e = refused(&args, d);
        assert!(e.contains(&format!("--accel {value}:")), "{args:?}: {e}");
        assert!(e.contains("c.dst holds a dst"), "{args:?}: {e}");
        assert!(e.contains("dst-sw, dst"), "{args:?}: {e}");
    }
    assert!(!d.join("x.png").exists());
}

#[test]
fn build_loads_its_scene_within_the_budgets() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let e = refused(
        &[
            "--max-triangles",
            "10",
            "build",
            SCENE,
            "--accel",
            "dst",
            "-o",
            "c.dst",
        ],
        d,
    );
    assert!(e.contains("10"), "{e}");
    assert!(!d.join("c.dst").exists());
}
