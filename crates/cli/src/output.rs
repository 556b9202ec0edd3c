//! Output paths, checked before any long work starts (a frame is not rendered or simulated
//! only to fail at writing it), and the JSON destination of `--json[=FILE]`.
use anyhow::{Context, bail};
use std::path::{Path, PathBuf};

/// The folder a file path writes into (`.` for a bare file name).
fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Checks that a file can be created in `dir` by creating and removing a probe file there.
fn probe_dir(dir: &Path, what: &str) -> anyhow::Result<()> {
    tempfile::Builder::new()
        .prefix(".dualsplit-probe-")
        .tempfile_in(dir)
        .map(drop)
        .with_context(|| format!("{what}: cannot write in {}", dir.display()))
}

/// Checks that `path` can be written as a file: its folder exists and is writable, and it
/// is not itself a folder. `what` names the option in messages (`-o`, `--json`).
pub fn check_file(path: &Path, what: &str) -> anyhow::Result<()> {
    if path.is_dir() {
        bail!("{what} {}: is a directory, not a file", path.display());
    }
    let dir = parent_dir(path);
    if !dir.is_dir() {
        bail!(
            "{what} {}: no such directory {} (create it first)",
            path.display(),
            dir.display()
        );
    }
    probe_dir(&dir, &format!("{what} {}", path.display()))
}

/// Refuses an output `path` that names one of `inputs` (the same file, through any path or
/// link): `build scene.ply -o scene.ply` would overwrite the scene.
pub fn check_not_an_input(path: &Path, what: &str, inputs: &[&Path]) -> anyhow::Result<()> {
    let Ok(out) = std::fs::canonicalize(path) else {
        return Ok(()); // not there yet: it names no existing input
    };
    for input in inputs {
        if std::fs::canonicalize(input).is_ok_and(|i| i == out) {
            bail!(
                "{what} {}: is the input {}; writing it would overwrite it",
                path.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// Creates the output folder `dir` (and its parents) and checks that it is writable.
pub fn prepare_dir(dir: &Path, what: &str) -> anyhow::Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("{what} {}: exists and is not a directory", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{what} {}: cannot create the directory", dir.display()))?;
    probe_dir(dir, &format!("{what} {}", dir.display()))
}

/// Where `--json` output goes: standard output (`--json`) or a file (`--json=FILE`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum JsonOut {
    /// Print it.
    Stdout,
    /// Write it to this file.
    File(PathBuf),
}

impl JsonOut {
    /// The destination of a `--json` option's value (`-` is standard output), with a file
    /// destination checked.
    pub fn from_arg(arg: Option<&Path>) -> anyhow::Result<Option<Self>> {
        Ok(match arg {
            None => None,
            Some(p) if p.as_os_str() == "-" => Some(JsonOut::Stdout),
            Some(p) => {
                check_file(p, "--json")?;
                Some(JsonOut::File(p.to_path_buf()))
            }
        })
    }

    /// Writes `text` (a newline is added) to the destination.
    pub fn emit(&self, text: &str) -> anyhow::Result<()> {
        match self {
            JsonOut::Stdout => outln!("{text}"),
            JsonOut::File(p) => {
                std::fs::write(p, format!("{text}\n"))
                    .with_context(|| format!("writing {}", p.display()))?;
                eprintln!("wrote {}", p.display());
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_folders_and_folders_as_files_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let e = check_file(&dir.path().join("no/x.png"), "-o").unwrap_err();
        assert!(format!("{e:#}").contains("no such directory"), "{e:#}");
        let e = check_file(dir.path(), "-o").unwrap_err();
        assert!(format!("{e:#}").contains("is a directory"), "{e:#}");
        check_file(&dir.path().join("x.png"), "-o").unwrap();
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "probe left behind"
        );
        let file = dir.path().join("f");
        std::fs::write(&file, "").unwrap();
        let e = prepare_dir(&file, "--out").unwrap_err();
        assert!(format!("{e:#}").contains("not a directory"), "{e:#}");
        prepare_dir(&dir.path().join("a/b"), "--out").unwrap();
        assert!(dir.path().join("a/b").is_dir());
    }
}
