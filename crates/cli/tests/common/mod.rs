//! Running the `dualsplit` binary from the CLI's integration tests.
use std::path::Path;
use std::process::{Command, Output};

/// `dualsplit ARGS` in `cwd`, without a scenes folder from the environment.
pub fn dualsplit(args: &[&str], cwd: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dualsplit"))
        .args(args)
        .current_dir(cwd)
        .env_remove("DUALSPLIT_SCENES")
        .output()
        .expect("run dualsplit")
}

/// Its standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Its standard output as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}
