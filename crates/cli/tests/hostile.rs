//! Hostile input through the command line: each reproducer ends in a clear error (exit 1,
//! a message naming what is wrong and the limit) instead of a read outside the scene's
//! folder, an abort or a hang.

use std::path::Path;
use std::process::{Command, Output};

fn dualsplit(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dualsplit"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the binary runs")
}

/// Expects exit status 1 and `needle` in stderr.
fn fails_with(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "stderr: {err}");
    assert!(err.contains(needle), "`{err}` lacks `{needle}`");
}

#[test]
fn gltf_buffers_outside_the_folder_are_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let json = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
      "buffers":[{"uri":"../../../../etc/passwd","byteLength":36}],
      "bufferViews":[{"buffer":0,"byteLength":36}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
        "min":[0,0,0],"max":[1,1,0]}]}"#;
    std::fs::write(dir.path().join("p.gltf"), json).unwrap();
    let out = dualsplit(&["info", "--json", "p.gltf"], dir.path());
    fails_with(&out, "../../../../etc/passwd");
    assert!(out.stdout.is_empty());
    let zero = json.replace("../../../../etc/passwd", "/dev/zero");
    std::fs::write(dir.path().join("z.gltf"), zero).unwrap();
    fails_with(&dualsplit(&["info", "z.gltf"], dir.path()), "/dev/zero");
}

#[test]
fn scene_budgets_are_flags() {
    let dir = tempfile::tempdir().unwrap();
    let spec = "builtin:hairball?triangles=5000";
    let out = dualsplit(&["info", spec, "--max-triangles", "1000"], dir.path());
    fails_with(&out, "more than 1000 triangles");
    fails_with(&out, "--max-triangles");
    let out = dualsplit(&["info", spec, "--max-triangles", "10000"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::write(
        dir.path().join("t.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let out = dualsplit(&["info", "t.obj", "--max-scene-bytes", "10"], dir.path());
    fails_with(&out, "--max-scene-bytes");
}

#[test]
fn simulate_obeys_the_renderer_limits() {
    let dir = tempfile::tempdir().unwrap();
    // Coordinates near 1e38 would put the fitted camera at infinity: loading refuses the
    // scene for its extent, in render and simulate alike.
    std::fs::write(
        dir.path().join("big.obj"),
        "v 1e38 1e38 1e38\nv -1e38 -1e38 -1e38\nv 1e38 -1e38 0\nf 1 2 3\n",
    )
    .unwrap();
    let args = ["big.obj", "--res", "8", "--workload", "cast"];
    let render = [&["render"][..], &args, &["-o", "x.png"]].concat();
    fails_with(&dualsplit(&render, dir.path()), "extent (2e38, 2e38, 2e38)");
    let simulate = [&["simulate"][..], &args, &["--model", "fast"]].concat();
    fails_with(
        &dualsplit(&simulate, dir.path()),
        "extent (2e38, 2e38, 2e38)",
    );
    // A frame far beyond the pixel limit is refused before anything is built or allocated.
    let out = dualsplit(
        &[
            "simulate",
            "builtin:cornell",
            "--res",
            "100000",
            "--model",
            "fast",
        ],
        dir.path(),
    );
    fails_with(&out, "pixels per side");
    let out = dualsplit(
        &[
            "simulate",
            "builtin:cornell",
            "--res",
            "20000",
            "--model",
            "fast",
        ],
        dir.path(),
    );
    fails_with(&out, "268435456");
}

/// The extreme-coordinate reproducer (coordinates at ±3e38, whose extent overflows to +∞)
/// and a scene at the extent limit, 2^60 wide.
#[test]
fn scenes_wider_than_the_extent_limit_are_refused_at_load() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("huge.obj"),
        "v -3e38 -3e38 -3e38\nv 3e38 -3e38 -3e38\nv 0 3e38 3e38\n\
         v -3e38 3e38 -3e38\nv 3e38 3e38 3e38\nv 0 -3e38 3e38\n\
         v 1 2 3\nv 2 3 4\nv 1 3 3\nf 1 2 3\nf 4 5 6\nf 7 8 9\n",
    )
    .unwrap();
    let refused = "huge.obj: the scene's extent (inf, inf, inf) exceeds 1.1529215e18 on some axis";
    for cmd in [
        &["info", "huge.obj"][..],
        &["build", "huge.obj", "--accel", "dst", "-o", "huge.dst"],
        &["check", "huge.obj"],
        &["stats", "huge.obj"],
        &["render", "huge.obj", "--res", "8", "-o", "x.png"],
        &["simulate", "huge.obj", "--res", "8", "--model", "fast"],
    ] {
        fails_with(&dualsplit(cmd, dir.path()), refused);
    }
    assert!(!dir.path().join("huge.dst").exists(), "no tree is saved");
    // At the limit (±2^59, 2^60 wide) every command works, and the saved DST checks.
    let c = (1u64 << 59) as f32;
    let mut obj = String::new();
    for i in 0..24 {
        let s = [c, c / 1e6, 1.0][i % 3] * (1.0 - i as f32 / 48.0);
        obj += &format!(
            "v {} 0 {}\nv 0 {} {}\nv {} {} {}\n",
            -s,
            s,
            s,
            -s,
            s / 2.0,
            -s / 3.0,
            s
        );
        obj += &format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3);
    }
    std::fs::write(dir.path().join("wide.obj"), obj).unwrap();
    for cmd in [
        &["build", "wide.obj", "--accel", "dst", "-o", "wide.dst"][..],
        &["check", "wide.obj", "--tree", "wide.dst", "--rays", "2000"],
        &["check", "wide.obj", "--rays", "2000"],
        &["render", "wide.obj", "--res", "16", "-o", "wide.png"],
        &["simulate", "wide.obj", "--res", "8", "--model", "fast"],
    ] {
        let out = dualsplit(cmd, dir.path());
        let err = String::from_utf8_lossy(&out.stderr);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{cmd:?}: {err}\n{stdout}");
    }
}

#[test]
fn render_states_the_real_limits() {
    let dir = tempfile::tempdir().unwrap();
    for res in ["65535x65535", "65536x65536"] {
        let out = dualsplit(
            &["render", "builtin:cornell", "--res", res, "-o", "x.png"],
            dir.path(),
        );
        fails_with(&out, "at most 268435456 (16384x16384) in a frame");
    }
    let out = dualsplit(
        &[
            "render",
            "builtin:cornell",
            "--spp",
            "4000000000",
            "-o",
            "x.png",
        ],
        dir.path(),
    );
    fails_with(&out, "at most 65536 samples per pixel");
}

/// `simulate builtin:cornell` at 4² on thread model `model` with `--config config`.
fn simulate_with_config(config: &str, model: &str, dir: &Path) -> Output {
    let args = [
        "simulate",
        "builtin:cornell",
        "--res",
        "4",
        "--model",
        model,
    ];
    dualsplit(&[&args[..], &["--config", config]].concat(), dir)
}

#[test]
fn configurations_are_read_only_from_small_regular_files() {
    let dir = tempfile::tempdir().unwrap();
    let sim = |config: &str| simulate_with_config(config, "fast", dir.path());
    fails_with(&sim("/dev/zero"), "not a regular file");
    std::fs::write(dir.path().join("big.toml"), vec![b'#'; 2 << 20]).unwrap();
    fails_with(&sim("big.toml"), "larger than 1048576 bytes");
    #[cfg(unix)]
    {
        let ok = Command::new("mkfifo")
            .arg(dir.path().join("pipe.toml"))
            .status()
            .unwrap()
            .success();
        assert!(ok);
        fails_with(&sim("pipe.toml"), "not a regular file");
    }
    // A TOML error was printed twice (its wrapper shows it, then the cause chain again).
    std::fs::write(dir.path().join("bad.toml"), "tms = \"x\"\n").unwrap();
    let out = sim("bad.toml");
    fails_with(&out, "TOML parse error at line 1");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("TOML parse error").count(), 1, "{err}");
}

#[test]
fn configuration_values_outside_their_ranges_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let sim = |toml: &str, model: &str| {
        std::fs::write(dir.path().join("c.toml"), toml).unwrap();
        simulate_with_config("c.toml", model, dir.path())
    };
    // Each once aborted with "memory allocation of N bytes failed", wrapped, or printed
    // "0 rays" or "NaN J".
    for (toml, says) in [
        (
            "tms = 4294967295",
            "`tms` = 4294967295 is invalid: must be an integer from 1 to 1024 TMs",
        ),
        ("tps_per_tm = 1000000", "`tps_per_tm` = 1000000"),
        (
            "[l2]\nsize_bytes = 68719476736",
            "`l2.size_bytes` = 68719476736",
        ),
        (
            "[units]\nbox_pipes = 4000000000",
            "`units.box_pipes` = 4000000000",
        ),
        (
            "[dram]\nchannels = 1073741824",
            "`dram.channels` = 1073741824",
        ),
        (
            "[l1]\nhit_latency = 1000000000000",
            "`l1.hit_latency` = 1000000000000",
        ),
        ("[dram]\nt_cas = 9223372036854775807", "`dram.t_cas`"),
        ("tms = 65536\ntps_per_tm = 65536", "`tms` = 65536"),
        ("[energy]\nl1_nj = nan", "`energy.l1_nj` = NaN"),
    ] {
        fails_with(&sim(toml, "fast"), says);
    }
    fails_with(
        &sim(
            "tms = 1024\ntps_per_tm = 1024\n[units]\nlocal_store_bytes = 1048576",
            "rv32",
        ),
        "at most 8192 MiB",
    );
}

#[test]
fn ray_counts_are_bounded() {
    let dir = tempfile::tempdir().unwrap();
    for cmd in ["check", "stats"] {
        let out = dualsplit(
            &[cmd, "builtin:cornell", "--rays", "100000000000"],
            dir.path(),
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{cmd}: {err}");
        assert!(err.contains("from 1 to 4194304"), "{cmd}: {err}");
    }
}

/// A study of `builtin:cornell` at 4² with one configuration and workload: (its folder,
/// the result file name of entry 0).
fn small_study(dir: &Path) -> (std::path::PathBuf, String) {
    let out = dualsplit(
        &[
            "plan",
            "builtin:cornell",
            "--res",
            "4",
            "--tms",
            "4",
            "--accel",
            "bvh2",
            "--workload",
            "cast",
            "--out",
            "study",
        ],
        dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let study = dir.join("study");
    let plan: serde_json::Value =
        serde_json::from_slice(&std::fs::read(study.join("plan.json")).unwrap()).unwrap();
    let key = plan["entries"][0]["cache_key"]
        .as_str()
        .unwrap()
        .to_string();
    std::fs::create_dir_all(study.join("cache")).unwrap();
    (study, key)
}

#[cfg(unix)]
#[test]
fn study_files_are_read_only_from_bounded_regular_files() {
    let dir = tempfile::tempdir().unwrap();
    let (study, key) = small_study(dir.path());
    let entry = study.join("cache").join(&key);
    let report = || dualsplit(&["report", "--from", "study"], dir.path());
    // A result linked to /dev/zero once read until killed for memory; a named pipe blocked
    // `report --from` and `run-job` forever; a 300 MB one was read whole.
    std::os::unix::fs::symlink("/dev/zero", &entry).unwrap();
    let out = report();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("not a regular file (a character device)"),
        "{err}"
    );
    std::fs::remove_file(&entry).unwrap();
    let ok = Command::new("mkfifo")
        .arg(&entry)
        .status()
        .unwrap()
        .success();
    assert!(ok);
    let out = report();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("not a regular file (a named pipe)"), "{err}");
    // run-job sees the pipe as an invalid result and replaces it.
    let out = dualsplit(&["run-job", "study", "0"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::metadata(&entry).unwrap().is_file());
    std::fs::remove_file(&entry).unwrap();
    let f = std::fs::File::create(&entry).unwrap();
    f.set_len(300 << 20).unwrap(); // sparse: no disk used
    drop(f);
    let out = report();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("larger than 268435456 bytes"), "{err}");
    // The plan itself.
    let plan = study.join("plan.json");
    std::fs::remove_file(&plan).unwrap();
    std::os::unix::fs::symlink("/dev/zero", &plan).unwrap();
    fails_with(&report(), "not a regular file (a character device)");
    fails_with(
        &dualsplit(&["run-job", "study", "0"], dir.path()),
        "not a regular file (a character device)",
    );
    std::fs::remove_file(&plan).unwrap();
    let ok = Command::new("mkfifo")
        .arg(&plan)
        .status()
        .unwrap()
        .success();
    assert!(ok);
    fails_with(&report(), "not a regular file (a named pipe)");
    fails_with(
        &dualsplit(&["run-job", "study", "0"], dir.path()),
        "not a regular file (a named pipe)",
    );
}

#[test]
fn plans_are_bounded_before_they_are_made() {
    let dir = tempfile::tempdir().unwrap();
    let values: Vec<String> = (1..=64).map(|i| i.to_string()).collect();
    let values = values.join(",");
    let sweeps: Vec<String> = ["dst_pipes", "box_pipes", "tri_pipes"]
        .iter()
        .map(|k| format!("units.{k}={values}"))
        .collect();
    // Once about 4.2 M entries, past 3.3 GB of memory and still growing.
    let out = dualsplit(
        &[
            "plan",
            "builtin:cornell",
            "--res",
            "4",
            "--vary",
            &sweeps[0],
            "--vary",
            &sweeps[1],
            "--vary",
            &sweeps[2],
            "--out",
            "s",
        ],
        dir.path(),
    );
    fails_with(&out, "the plan would have 11534336 entries");
    fails_with(&out, "at most 65536");
    assert!(!dir.path().join("s/plan.json").exists());
    let many: Vec<String> = (1..=1025).map(|i| i.to_string()).collect();
    let out = dualsplit(
        &[
            "plan",
            "builtin:cornell",
            "--vary",
            &format!("l1.hit_latency={}", many.join(",")),
            "--out",
            "s",
        ],
        dir.path(),
    );
    fails_with(&out, "1025 values; at most 1024 for one key");
}

#[test]
fn ray_files_are_bounded_and_their_rays_checked() {
    let dir = tempfile::tempdir().unwrap();
    let trace = |rays: &str| {
        dualsplit(
            &["trace", "builtin:cornell", "--rays", rays, "-o", "hits.bin"],
            dir.path(),
        )
    };
    let file = |vals: &[f32]| -> Vec<u8> { vals.iter().flat_map(|v| v.to_le_bytes()).collect() };
    let good = [0.0, 0.5, 3.0, 0.0, 0.0, -1.0, 0.0, f32::INFINITY];
    let mut bad = good.to_vec();
    bad.extend_from_slice(&[0.0, 0.5, 3.0, 0.0, 0.0, -1.0, 0.0, f32::NAN]);
    std::fs::write(dir.path().join("good.bin"), file(&good)).unwrap();
    std::fs::write(dir.path().join("nan.bin"), file(&bad)).unwrap();
    let out = trace("good.bin");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // A NaN t_max once gave a hit in five traversals and a miss in two.
    fails_with(&trace("nan.bin"), "ray 1: t_max is NaN");
    bad[9] = f32::INFINITY;
    std::fs::write(dir.path().join("inf.bin"), file(&bad)).unwrap();
    fails_with(&trace("inf.bin"), "ray 1: origin.y is inf");
    // Once read until killed for memory.
    fails_with(
        &trace("/dev/zero"),
        "not a regular file (a character device)",
    );
    let f = std::fs::File::create(dir.path().join("big.bin")).unwrap();
    f.set_len((1 << 30) + 32).unwrap(); // sparse
    drop(f);
    fails_with(&trace("big.bin"), "larger than 1073741824 bytes");
}

/// Runs `args` with standard output closed before the command writes to it.
#[cfg(unix)]
fn with_closed_stdout(args: &[&str], dir: &Path) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_dualsplit"))
        .args(args)
        .current_dir(dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the binary runs");
    drop(child.stdout.take());
    child.wait_with_output().expect("it ends")
}

#[cfg(unix)]
#[test]
fn a_closed_standard_output_ends_quietly_and_files_are_still_written() {
    let dir = tempfile::tempdir().unwrap();
    // `simulate ... | head -1` and `render ... | head -1` once panicked with "failed
    // printing to stdout: Broken pipe", render before it wrote its PNG.
    let runs: [&[&str]; 3] = [
        &[
            "simulate",
            "builtin:cornell",
            "--res",
            "8",
            "--accel",
            "bvh2",
        ],
        &["render", "builtin:cornell", "--res", "8", "-o", "c.png"],
        &["stats", "builtin:cornell"],
    ];
    for args in runs {
        let out = with_closed_stdout(args, dir.path());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
        assert!(
            !err.contains("panicked") && !err.contains("Broken pipe"),
            "{args:?}: {err}"
        );
    }
    let png = std::fs::read(dir.path().join("c.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"), "{} bytes", png.len());
}

#[test]
fn far_lights_and_cameras_are_refused_for_what_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let render = |flag: &str, value: &str| {
        let args = [
            "render",
            "builtin:cornell",
            "--workload",
            "cast",
            "--res",
            "32",
        ];
        dualsplit(
            &[&args[..], &[flag, value, "-o", "x.png"]].concat(),
            dir.path(),
        )
    };
    // Once exit 0 with "shadow 0 rays" and a wrong image.
    fails_with(&render("--light", "1e20,1e20,1e20"), "beyond ±4.611686e18");
    fails_with(&render("--light", "1e19,0,0"), "beyond ±4.611686e18");
    // Once "eye and target coincide".
    fails_with(
        &render("--eye", "0,0,1e30"),
        "--eye `0,0,1e30`: a coordinate lies beyond",
    );
    fails_with(
        &render("--target", "1e30,0,0"),
        "--target `1e30,0,0`: a coordinate lies beyond",
    );
    let args = [
        "render",
        "builtin:cornell",
        "--light-radius=-1",
        "-o",
        "x.png",
    ];
    fails_with(
        &dualsplit(&args, dir.path()),
        "--light-radius -1: must be from 0 to 2^60",
    );
    assert!(!dir.path().join("x.png").exists());
}

#[test]
fn dragon_boxes_that_would_not_load_are_not_written() {
    let dir = tempfile::tempdir().unwrap();
    let make = |input: &str, obj: &str| {
        std::fs::write(dir.path().join(input), obj).unwrap();
        dualsplit(
            &[
                "scene",
                "dragon-box",
                "--reconstruction",
                input,
                "-o",
                "box.ply.gz",
            ],
            dir.path(),
        )
    };
    // Once exit 0 with a box every loader then refused.
    let out = make("wide.obj", "v 0 0 0\nv 1.1e18 0 0\nv 0 1 0\nf 1 2 3\n");
    fails_with(
        &out,
        "wide.obj: cannot make the Dragon Box: the result would not load",
    );
    fails_with(&out, "exceeds");
    // Once 11 triangles of size zero.
    let out = make("point.obj", "v 1 2 3\nv 1 2 3\nv 1 2 3\nf 1 2 3\n");
    fails_with(&out, "box triangle 0 has no area");
    assert!(!dir.path().join("box.ply.gz").exists());
    let out = make("ok.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = dualsplit(&["info", "box.ply.gz"], dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // SimTRaX's box stands at fixed coordinates: a mesh outside it is refused.
    std::fs::remove_file(dir.path().join("box.ply.gz")).unwrap();
    let out = dualsplit(
        &["scene", "dragon-box", "ok.obj", "-o", "box.ply.gz"],
        dir.path(),
    );
    fails_with(&out, "not inside SimTRaX's box");
    assert!(!dir.path().join("box.ply.gz").exists());
}

#[test]
fn outputs_that_name_an_input_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::fs::write(dir.path().join("s.obj"), obj).unwrap();
    // `build S -o S` once overwrote the scene without a word.
    let out = dualsplit(
        &["build", "s.obj", "--accel", "bvh2", "-o", "s.obj"],
        dir.path(),
    );
    fails_with(
        &out,
        "-o s.obj: is the input s.obj; writing it would overwrite it",
    );
    let out = dualsplit(
        &["build", "s.obj", "--accel", "bvh2", "-o", "./s.obj"],
        dir.path(),
    );
    fails_with(&out, "would overwrite it");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("s.obj")).unwrap(),
        obj
    );
    let help = dualsplit(&["build", "--help"], dir.path());
    let help = String::from_utf8_lossy(&help.stdout);
    for kind in ["dst", "bvh2", "bvh4", "bvh8", "cwbvh", "dst-q"] {
        assert!(help.contains(kind), "build --help lacks {kind}: {help}");
    }
}
