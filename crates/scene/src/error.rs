use std::path::PathBuf;

/// Why a small input file ([`read_limited`](crate::load::read_limited)) was not read.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// The file could not be opened or read.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error (in the message, not a `source()`, so `anyhow` prints it once).
        error: std::io::Error,
    },
    /// The path names a directory, device, named pipe or socket (links followed), which is
    /// never opened: it could block or never end.
    #[error("{}: not a regular file ({kind}); only regular files are read", path.display())]
    NotAFile {
        /// The file.
        path: PathBuf,
        /// What it is instead.
        kind: &'static str,
    },
    /// The file is larger than the limit of what is read.
    #[error("{}: larger than {limit} bytes, the limit ({size} bytes or more)", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size (from its metadata, or the bytes read before stopping).
        size: u64,
        /// The limit.
        limit: u64,
    },
}

impl FileError {
    /// True when the file does not exist.
    pub fn is_not_found(&self) -> bool {
        matches!(self, FileError::Io { error, .. } if error.kind() == std::io::ErrorKind::NotFound)
    }
}

/// Everything that can go wrong while loading or generating a scene.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be opened or read.
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error (shown in the message, deliberately not a `source()`, so that
        /// `anyhow`'s `{:#}` chain does not print it twice).
        error: std::io::Error,
    },
    /// The file's contents are malformed.
    #[error("{path}{}: {message}", line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line, where the format has lines.
        line: Option<u64>,
        /// What is wrong.
        message: String,
    },
    /// The extension is not one of `.obj`, `.ply`, `.gltf`, `.glb` (optionally `.gz`).
    #[error("{path}: unknown scene format (expected .obj, .ply, .obj.gz, .ply.gz, .gltf or .glb)")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
    },
    /// No triangle is left after loading.
    #[error("{spec}: the scene has no triangles")]
    Empty {
        /// The spec.
        spec: String,
    },
    /// A budget of [`Limits`](crate::Limits) would be exceeded.
    #[error("{path}: more than {limit} {} (the limit; raise it with {})", what.unit(), what.flag())]
    Limit {
        /// The file or spec.
        path: String,
        /// Which budget.
        what: crate::limits::Budget,
        /// The budget.
        limit: u64,
    },
    /// The path names something other than a regular file (a directory, a device, a pipe,
    /// a socket), which is never read: it could block or never end.
    #[error("{path}: not a regular file ({kind}); only regular files are read")]
    NotAFile {
        /// The file.
        path: PathBuf,
        /// What it is instead.
        kind: &'static str,
    },
    /// A glTF buffer URI that is not a relative path inside the scene file's folder.
    #[error("{path}: buffer {buffer} URI `{uri}`: {reason}")]
    ExternalUri {
        /// The glTF file.
        path: PathBuf,
        /// The buffer's index.
        buffer: usize,
        /// The URI as written in the file.
        uri: String,
        /// Why it is refused.
        reason: String,
    },
    /// The scene's bounds are wider than [`Scene::MAX_EXTENT`](crate::Scene::MAX_EXTENT) on
    /// some axis (the extent of coordinates near ±3.4e38 overflows to +∞).
    #[error(
        "{spec}: the scene's extent ({:e}, {:e}, {:e}) exceeds {:e} on some axis (bounds ({:e}, {:e}, {:e}) to ({:e}, {:e}, {:e})); f32 areas, cameras and ray tests overflow beyond it: scale the scene down",
        extent[0], extent[1], extent[2], limit, min[0], min[1], min[2], max[0], max[1], max[2]
    )]
    Extent {
        /// The spec.
        spec: String,
        /// Lower corner of the bounds.
        min: [f32; 3],
        /// Upper corner of the bounds.
        max: [f32; 3],
        /// `max − min` per axis (+∞ where the difference overflows).
        extent: [f32; 3],
        /// [`Scene::MAX_EXTENT`](crate::Scene::MAX_EXTENT).
        limit: f32,
    },
    /// The scene lies, at least in part, farther than
    /// [`Scene::MAX_COORDINATE`](crate::Scene::MAX_COORDINATE) from the origin on some axis
    /// (the centre of a scene at 3e38 overflows to +∞, and so do its camera and light).
    #[error(
        "{spec}: the scene's bounds ({:e}, {:e}, {:e}) to ({:e}, {:e}, {:e}) reach beyond ±{:e} on some axis; f32 cameras, lights and ray origins overflow beyond it: move the scene toward the origin",
        min[0], min[1], min[2], max[0], max[1], max[2], limit
    )]
    Far {
        /// The spec.
        spec: String,
        /// Lower corner of the bounds.
        min: [f32; 3],
        /// Upper corner of the bounds.
        max: [f32; 3],
        /// [`Scene::MAX_COORDINATE`](crate::Scene::MAX_COORDINATE).
        limit: f32,
    },
    /// A scene made from another ([`crate::make`]) would be unusable: degenerate
    /// triangles, or bounds the loaders refuse.
    #[error("{spec}: cannot make {what}: {reason}")]
    Make {
        /// The input's spec.
        spec: String,
        /// What was being made (`the Dragon Box`).
        what: &'static str,
        /// Why not.
        reason: String,
    },
    /// A builtin name or parameter is wrong.
    #[error("builtin scene `{spec}`: {message}")]
    Builtin {
        /// The spec after `builtin:`.
        spec: String,
        /// What is wrong.
        message: String,
    },
}
