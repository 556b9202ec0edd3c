//! Small input files (hardware configurations), read defensively: only a regular file, and
//! at most a bounded number of bytes, so a path naming `/dev/zero` or a named pipe is an
//! error instead of a hang or an out-of-memory abort.

use anyhow::{Context, bail};
use std::io::Read;
use std::path::Path;

/// Largest configuration file read: 1 MiB (the shipped ones are under 8 KiB).
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// The text of `path`, a regular file (links followed) of at most `max` bytes in UTF-8.
pub fn read_text(path: &Path, max: u64) -> anyhow::Result<String> {
    let meta = std::fs::metadata(path).with_context(|| format!("reading {}", path.display()))?;
    if !meta.is_file() {
        bail!(
            "{}: not a regular file; only regular files are read",
            path.display()
        );
    }
    let file = std::fs::File::open(path).with_context(|| format!("reading {}", path.display()))?;
    let mut text = String::new();
    file.take(max + 1)
        .read_to_string(&mut text)
        .with_context(|| format!("reading {}", path.display()))?;
    if text.len() as u64 > max {
        bail!("{}: larger than {max} bytes", path.display());
    }
    Ok(text)
}
