//! The fixture API for shipped meshes: a mesh committed in `scenes/` is found there; a
//! missing one is skipped with the reason printed past the harness's capture, and fails the
//! test when `CI` is set.

use dualsplit_testkit::scenes::{SHARED_ENV, repo_dir, shipped, shipped_path};
use std::process::{Command, Output};

#[test]
fn committed_meshes_are_found_in_the_repository() {
    let path = shipped_path("dragon_res4.ply.gz").expect("committed in scenes/");
    assert_eq!(path.parent(), Some(repo_dir().as_path()));
    let scene = shipped("dragon_res4.ply.gz").expect("committed in scenes/");
    assert_eq!(scene.triangles.len(), 11_102);
    assert_eq!(scene.name, "dragon_res4");
}

/// Asks for a mesh no folder holds; does nothing unless run as the child of
/// [`missing_meshes_skip_locally_and_fail_under_ci`] (so that `CI` in the parent's
/// environment does not fail it).
#[test]
fn probe_missing_mesh() {
    if std::env::var_os("DUALSPLIT_TESTKIT_PROBE").is_none() {
        return;
    }
    assert!(shipped("no_such_mesh.ply.gz").is_none());
    println!("probe returned");
}

/// Runs [`probe_missing_mesh`] in a child process of this test binary, with the large
/// meshes' folder hidden and `CI` set or not, its output captured by the harness as in
/// `cargo test`.
fn probe(ci: bool) -> (Output, String) {
    let mut cmd = Command::new(std::env::current_exe().expect("test binary"));
    cmd.args(["--exact", "probe_missing_mesh", "--test-threads=1"])
        .env("DUALSPLIT_TESTKIT_PROBE", "1")
        .env(SHARED_ENV, "/nonexistent/scenes");
    if ci {
        cmd.env("CI", "1");
    } else {
        cmd.env_remove("CI");
    }
    let out = cmd.output().expect("run the probe");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out, text)
}

#[test]
fn missing_meshes_skip_locally_and_fail_under_ci() {
    let want = format!(
        "no_such_mesh.ply.gz not found in {} or /nonexistent/scenes",
        repo_dir().display()
    );
    let (local, text) = probe(false);
    assert!(local.status.success(), "{text}");
    // The skip shows although the harness captured (and dropped) the passing test's output.
    assert!(text.contains(&format!("skipped scene: {want}")), "{text}");
    assert!(
        !text.contains("probe returned"),
        "the probe's output is captured: {text}"
    );

    let (ci, text) = probe(true);
    assert!(!ci.status.success(), "{text}");
    assert!(
        text.contains(&format!("{want} (required when CI is set)")),
        "{text}"
    );
    assert!(!text.contains("probe returned"), "{text}");
}
