//! Budgets that bound the work and memory of loading one scene.
//!
//! A scene file is untrusted input: a small gzip can inflate to gigabytes, a glTF file can
//! instance one mesh many times or name `/dev/zero` as a buffer. Every loader therefore
//! works against a [`Limits`]: a maximum number of triangles and a maximum number of bytes
//! of file content held in memory. Exceeding either is a typed
//! [`SceneError::Limit`], raised as soon as the loader knows,
//! before the memory is spent.
//!
//! The defaults are sized for a 24 GiB machine: the largest shipped scene
//! (`dragon_sponza.ply.gz`, 6.2M triangles, 117 MB inflated) is well inside them, and
//! building every structure takes about 450 bytes per triangle at peak (`dualsplit stats`
//! on that scene: 2.8 GB), so a scene at the triangle limit needs about 7.5 GB. `docs/robustness.md` lists the budgets and how to raise them (on the command
//! line: `--max-triangles` and `--max-scene-bytes`).

use crate::SceneError;

/// The budgets of one scene load.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Most triangles a scene may have, counted after fan triangulation and glTF instancing
    /// (before non-finite triangles are dropped).
    pub max_triangles: u64,
    /// Most bytes of file content a load may hold: the scene file after inflating it, plus
    /// every external or base64-embedded glTF buffer.
    pub max_bytes: u64,
}

impl Limits {
    /// Default [`Limits::max_triangles`]: 2^24 (16.8M), 2.7× the largest shipped scene.
    pub const DEFAULT_MAX_TRIANGLES: u64 = 1 << 24;
    /// Default [`Limits::max_bytes`]: 2 GiB, 17× the largest shipped scene inflated (117 MB).
    pub const DEFAULT_MAX_BYTES: u64 = 2 << 30;

    /// Checks that `n` triangles fit the budget; `path` names the scene in the error.
    pub fn check_triangles(&self, path: &impl std::fmt::Display, n: u64) -> Result<(), SceneError> {
        if n > self.max_triangles {
            return Err(SceneError::Limit {
                path: path.to_string(),
                what: Budget::Triangles,
                limit: self.max_triangles,
            });
        }
        Ok(())
    }
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_triangles: Self::DEFAULT_MAX_TRIANGLES,
            max_bytes: Self::DEFAULT_MAX_BYTES,
        }
    }
}

/// Which budget an error is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Budget {
    /// [`Limits::max_triangles`].
    Triangles,
    /// [`Limits::max_bytes`].
    Bytes,
}

impl Budget {
    /// What is counted, for messages.
    pub fn unit(self) -> &'static str {
        match self {
            Budget::Triangles => "triangles",
            Budget::Bytes => "bytes of file content (inflated, with glTF buffers)",
        }
    }

    /// The command-line flag that raises it.
    pub fn flag(self) -> &'static str {
        match self {
            Budget::Triangles => "--max-triangles",
            Budget::Bytes => "--max-scene-bytes",
        }
    }
}

/// The bytes of one load still unspent, shared by the scene file and its glTF buffers.
#[derive(Debug)]
pub(crate) struct ByteBudget {
    limit: u64,
    used: u64,
}

impl ByteBudget {
    /// A fresh budget of `limits.max_bytes`.
    pub(crate) fn new(limits: &Limits) -> Self {
        Self {
            limit: limits.max_bytes,
            used: 0,
        }
    }

    /// Bytes that may still be charged.
    pub(crate) fn remaining(&self) -> u64 {
        self.limit - self.used
    }

    /// Charges `n` bytes, or fails naming `path` when they do not fit.
    pub(crate) fn charge(&mut self, path: &std::path::Path, n: u64) -> Result<(), SceneError> {
        if n > self.remaining() {
            return Err(self.exceeded(path));
        }
        self.used += n;
        Ok(())
    }

    /// The error for content that does not fit.
    pub(crate) fn exceeded(&self, path: &std::path::Path) -> SceneError {
        SceneError::Limit {
            path: path.display().to_string(),
            what: Budget::Bytes,
            limit: self.limit,
        }
    }
}
