//! Small input files (hardware configurations), read defensively: only a regular file, and
//! at most a bounded number of bytes, so a path naming `/dev/zero` or a named pipe is an
//! error instead of a hang or an out-of-memory abort.

use std::path::Path;

/// Largest configuration file read: 1 MiB (the shipped ones are under 8 KiB).
pub const MAX_CONFIG_BYTES: u64 = 1 << 20;

/// The text of `path`, a regular file (links followed) of at most `max` bytes in UTF-8
/// ([`dualsplit_scene::load::read_limited`]).
pub fn read_text(path: &Path, max: u64) -> anyhow::Result<String> {
    let bytes = dualsplit_scene::load::read_limited(path, max)?;
    String::from_utf8(bytes).map_err(|e| {
        anyhow::anyhow!(
            "{}: not UTF-8 text (byte {})",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })
}
