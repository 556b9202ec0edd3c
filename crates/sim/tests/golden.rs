//! Golden runs: the simulated results that define "the model did not change".
//!
//! Both TRaX thread models ([`ThreadModel::ALL`]: the compiled kernels and the macro-op
//! replay), every configuration of [`SimAccel::ALL`] on the `tiny` chip (`configs/tiny.toml`),
//! and the `simt` model's configurations ([`rt_accels`]) on `configs/rtx2060.toml`, both
//! workloads, on `builtin:cornell` and on the shipped `dragon_res4.ply.gz` (11 K triangles,
//! committed in the repository's `scenes/`), at small resolutions. For each run
//! the test compares exact cycles, instructions, DRAM reads and activations, L1 and L2 hits
//! and the three energy terms (as `f64` bits) with `tests/golden/expected.toml`, which
//! records the [`MODEL_VERSION`] it was taken with.
//!
//! A refactor must leave this file untouched. A change that alters simulated results bumps
//! `MODEL_VERSION` (`crates/sim/src/lib.rs`), adds the version to "Model versions" in
//! `docs/simulator.md`, and re-records the file:
//!
//! ```text
//! DUALSPLIT_BLESS=1 cargo test --release -p dualsplit-sim --test golden
//! ```
//!
//! Without the shipped mesh the test skips the `dragon_res4` runs with a note, and fails
//! when the `CI` environment variable is set ([`dualsplit_testkit::scenes::shipped`]).

use dualsplit_accel::Structures;
use dualsplit_render::{RenderSettings, Workload};
use dualsplit_sim::model::simt::rt_accels;
use dualsplit_sim::{
    FrameRequest, MODEL_VERSION, SimAccel, SimConfig, SimResult, ThreadModel, simulate,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The scenes: name as given to the loader (relative to the shipped folder for files),
/// and whether it is a shipped file.
const SCENES: [(&str, bool); 2] = [("builtin:cornell", false), ("dragon_res4.ply.gz", true)];

/// Workloads and their resolutions (width, height): small, so all 32 runs per scene take
/// seconds in a release build.
const WORKLOADS: [(Workload, &str, u32, u32); 2] = [
    (Workload::Cast, "cast", 96, 64),
    (Workload::Path, "path", 48, 32),
];

/// The compared quantities of one run.
#[derive(Clone, Debug, PartialEq)]
struct Golden {
    key: String,
    cycles: u64,
    instructions: u64,
    dram_reads: u64,
    dram_activations: u64,
    l1_hits: u64,
    l2_hits: u64,
    /// DRAM, caches, compute (`EnergySplit`), as `f64::to_bits`.
    energy_bits: [u64; 3],
}

impl Golden {
    fn of(key: String, r: &SimResult) -> Self {
        Self {
            key,
            cycles: r.cycles,
            instructions: r.instructions.total(),
            dram_reads: r.dram.reads,
            dram_activations: r.dram.activations,
            l1_hits: r.caches.l1_hits,
            l2_hits: r.caches.l2_hits,
            energy_bits: [
                r.energy.dram_j.to_bits(),
                r.energy.caches_j.to_bits(),
                r.energy.compute_j.to_bits(),
            ],
        }
    }

    fn write(&self, out: &mut String) {
        let e = self.energy_bits.map(f64::from_bits);
        let _ = writeln!(out, "\n[[run]]");
        let _ = writeln!(out, "key = \"{}\"", self.key);
        let _ = writeln!(out, "cycles = {}", self.cycles);
        let _ = writeln!(out, "instructions = {}", self.instructions);
        let _ = writeln!(out, "dram_reads = {}", self.dram_reads);
        let _ = writeln!(out, "dram_activations = {}", self.dram_activations);
        let _ = writeln!(out, "l1_hits = {}", self.l1_hits);
        let _ = writeln!(out, "l2_hits = {}", self.l2_hits);
        let _ = writeln!(
            out,
            "energy_bits = [\"{:#018x}\", \"{:#018x}\", \"{:#018x}\"]",
            self.energy_bits[0], self.energy_bits[1], self.energy_bits[2]
        );
        let _ = writeln!(
            out,
            "# energy (J): dram {:e}, caches {:e}, compute {:e}",
            e[0], e[1], e[2]
        );
    }

    fn read(t: &toml::Table) -> Self {
        let int = |k: &str| {
            t.get(k)
                .and_then(toml::Value::as_integer)
                .unwrap_or_else(|| panic!("expected.toml: run without integer `{k}`"))
                as u64
        };
        let bits: Vec<u64> = t
            .get("energy_bits")
            .and_then(toml::Value::as_array)
            .expect("expected.toml: run without `energy_bits`")
            .iter()
            .map(|v| {
                let s = v.as_str().expect("energy bits are hex strings");
                u64::from_str_radix(s.trim_start_matches("0x"), 16).expect("hex energy bits")
            })
            .collect();
        Self {
            key: t["key"].as_str().expect("run key").to_string(),
            cycles: int("cycles"),
            instructions: int("instructions"),
            dram_reads: int("dram_reads"),
            dram_activations: int("dram_activations"),
            l1_hits: int("l1_hits"),
            l2_hits: int("l2_hits"),
            energy_bits: bits.try_into().expect("three energy terms"),
        }
    }
}

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn expected_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/expected.toml")
}

fn tiny() -> SimConfig {
    let text = std::fs::read_to_string(repo().join("configs/tiny.toml")).unwrap();
    SimConfig::from_toml(&text).unwrap()
}

/// The `simt` model's GPU chip.
fn rtx2060() -> SimConfig {
    let text = std::fs::read_to_string(repo().join("configs/rtx2060.toml")).unwrap();
    SimConfig::from_toml(&text).unwrap()
}

/// Runs every golden configuration; scenes that cannot be found are skipped (the caller
/// decides whether that is allowed).
fn run_all(missing: &mut Vec<String>) -> Vec<Golden> {
    run_each(&tiny(), 1, missing)
        .into_iter()
        .map(|(key, r)| Golden::of(key, &r))
        .collect()
}

/// Runs every golden configuration on chip `cfg` and `threads` host threads: each run's
/// key and result.
fn run_each(
    cfg: &SimConfig,
    threads: usize,
    missing: &mut Vec<String>,
) -> Vec<(String, SimResult)> {
    let mut out = Vec::new();
    for (name, is_file) in SCENES {
        let scene = if is_file {
            let Some(scene) = dualsplit_testkit::scenes::shipped(name) else {
                missing.push(name.to_string());
                continue;
            };
            scene
        } else {
            dualsplit_scene::load(name).unwrap_or_else(|e| panic!("{name}: {e}"))
        };
        let structures = Structures::build(&scene.triangles, &Default::default());
        let short = name
            .trim_start_matches("builtin:")
            .trim_end_matches(".ply.gz");
        for (wl, wl_name, w, h) in WORKLOADS {
            let settings = RenderSettings::new(w, h, wl);
            for model in ThreadModel::ALL {
                for accel in SimAccel::ALL {
                    let r = simulate(
                        &FrameRequest::new(&scene, &structures, accel, &settings, cfg)
                            .with_model(model)
                            .with_threads(threads),
                        &|_, _| {},
                    )
                    .unwrap_or_else(|e| panic!("{short} {wl_name} {}: {e}", accel.name()));
                    let key = format!(
                        "{} {short} {wl_name} {w}x{h} {}",
                        model.name(),
                        accel.name()
                    );
                    out.push((key, r));
                }
            }
            for accel in rt_accels() {
                let r = simulate(
                    &FrameRequest::new(&scene, &structures, accel, &settings, &rtx2060())
                        .with_model(ThreadModel::Simt),
                    &|_, _| {},
                )
                .unwrap_or_else(|e| panic!("simt {short} {wl_name} {}: {e}", accel.name()));
                out.push((
                    format!("simt {short} {wl_name} {w}x{h} {}", accel.name()),
                    r,
                ));
            }
        }
    }
    out
}

fn render_file(runs: &[Golden]) -> String {
    let mut s = String::new();
    s.push_str(
        "# Golden runs of crates/sim/tests/golden.rs: the tiny chip (configs/tiny.toml), every\n\
         # configuration, cast and path, both TRaX thread models; the simt model on\n\
         # configs/rtx2060.toml. Re-record only together with a MODEL_VERSION bump\n\
         # (listed in docs/simulator.md, \"Model versions\"):\n\
         #   DUALSPLIT_BLESS=1 cargo test --release -p dualsplit-sim --test golden\n\n",
    );
    let _ = writeln!(s, "model_version = {MODEL_VERSION}");
    for r in runs {
        r.write(&mut s);
    }
    s
}

#[test]
fn golden_runs_are_unchanged() {
    let mut missing = Vec::new();
    let runs = run_all(&mut missing);
    if !missing.is_empty() {
        eprintln!("note: skipping the golden runs of {}", missing.join(", "));
    }
    if std::env::var_os("DUALSPLIT_BLESS").is_some() {
        assert!(
            missing.is_empty(),
            "re-recording needs every scene of the golden runs"
        );
        std::fs::create_dir_all(expected_path().parent().unwrap()).unwrap();
        std::fs::write(expected_path(), render_file(&runs)).unwrap();
        eprintln!(
            "recorded {} golden runs for model version {MODEL_VERSION}",
            runs.len()
        );
        return;
    }
    let text = std::fs::read_to_string(expected_path()).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (record with DUALSPLIT_BLESS=1)",
            expected_path().display()
        )
    });
    let table: toml::Table = text.parse().expect("expected.toml parses");
    let version = table
        .get("model_version")
        .and_then(toml::Value::as_integer)
        .expect("expected.toml: model_version");
    assert_eq!(
        version, MODEL_VERSION as i64,
        "expected.toml was recorded with model version {version}, the crate is version \
         {MODEL_VERSION}: re-record it (DUALSPLIT_BLESS=1) and list the version in \
         docs/simulator.md, \"Model versions\""
    );
    let expected: Vec<Golden> = table["run"]
        .as_array()
        .expect("expected.toml: [[run]]")
        .iter()
        .map(|v| Golden::read(v.as_table().expect("a run is a table")))
        .collect();
    let mut diffs = Vec::new();
    for r in &runs {
        match expected.iter().find(|e| e.key == r.key) {
            None => diffs.push(format!("{}: not in expected.toml", r.key)),
            Some(e) if e != r => {
                diffs.push(format!("{}:\n  expected {e:?}\n  got      {r:?}", r.key))
            }
            Some(_) => {}
        }
    }
    let skipped = expected.len() - runs.len();
    assert!(
        diffs.is_empty(),
        "{} of {} golden runs differ (a change to simulated results needs a MODEL_VERSION \
         bump and a re-record):\n{}",
        diffs.len(),
        runs.len(),
        diffs.join("\n")
    );
    assert!(
        missing.is_empty() || skipped > 0,
        "runs were skipped but expected.toml has no more runs than were compared"
    );
    assert!(!runs.is_empty());
}
