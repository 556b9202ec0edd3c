//! File loaders: OBJ, PLY (ASCII and binary), glTF 2.0, each of the first two optionally
//! gzipped.
//!
//! [`load_file`] reads the whole file (a regular file only, within the byte budget),
//! inflates it when it is gzip (by the `.gz` extension or by the gzip magic bytes `1f 8b`),
//! picks the format by the extension under any `.gz`, and hands the bytes to one parser per
//! format. Every parser returns a [`Mesh`]: the triangles
//! in file order plus [`LoadStats`]; [`Scene::from_triangles`] then applies the crate-wide
//! degenerate/non-finite rule (see the crate docs).
//!
//! | extension | parser | notes |
//! |---|---|---|
//! | `.obj`, `.obj.gz` | [`tobj`] | `v` positions and `f` faces only (texture coordinates, normals, materials, points and lines ignored); negative (relative) indices; polygons fan-triangulated |
//! | `.ply`, `.ply.gz` | header: [`ply_rs_bw`]; ASCII body (`nan` and `inf` read as such) and binary body (little- and big-endian): our own readers | element `vertex` with float/double (or integer) `x`, `y`, `z` in any order among other properties; element `face` with a list `vertex_indices` (or `vertex_index`) of any count and index type; polygons fan-triangulated; other elements and properties skipped |
//! | `.gltf`, `.glb` | [`gltf`](::gltf) (JSON and GLB container) plus our own bounds-checked accessor reader | buffers embedded as base64 `data:` URIs, regular files inside the `.gltf`'s folder, or the GLB `BIN` chunk; every `TRIANGLES` primitive of every mesh instanced by the default scene (else scene 0), with node transforms (matrix or TRS) composed down the hierarchy, which must be disjoint trees; other primitive modes are skipped and counted |
//!
//! The binary PLY body has its own decoder because ply-rs-bw builds one `IndexMap` per
//! element, far too slow for the 6.2M-triangle `dragon_sponza.ply.gz` speed bar (3 s);
//! see `docs/performance.md`, "Scene loading".
//!
//! ## Triangle ids
//!
//! Triangles are emitted in file order: faces in the order of the file, each polygon with
//! `n > 3` vertices fan-triangulated into `(v0, v[i], v[i+1])` for `i = 1..n-2`, in that
//! order (counted in [`LoadStats::polygons_triangulated`]). For glTF the order is the
//! depth-first pre-order of the scene's nodes, then each mesh's primitives, then the index
//! buffer. A triangle's id is its position in that sequence; [`Scene::from_triangles`] keeps
//! the order when it drops non-finite triangles, so ids equal file face indices exactly when
//! [`LoadStats::non_finite`] is zero (true of every shipped scene).
//!
//! ## Budgets
//!
//! Every load works within a [`Limits`] (see [`crate::limits`]): only regular files are
//! read (a directory, device, named pipe or socket is [`SceneError::NotAFile`]); reading and
//! inflating stream against [`Limits::max_bytes`], shared with the glTF buffers; and every
//! parser checks [`Limits::max_triangles`] before it emits more triangles. Exceeding a budget
//! is [`SceneError::Limit`].
//!
//! ## Errors
//!
//! Malformed input never panics: every failure is a [`SceneError`] naming the file and, for
//! the line-based formats (OBJ, ASCII PLY, any PLY header), the 1-based line. Counts in
//! headers are checked against the bytes actually present before anything is allocated, so
//! a huge or negative count is an error, not an out-of-memory abort.

mod gltf;
mod obj;
mod ply;

use crate::limits::ByteBudget;
use crate::{Limits, LoadStats, Scene, SceneError};
use dualsplit_geometry::Triangle;
use std::io::Read;
use std::path::Path;

/// A scene file format, chosen by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (text).
    Obj,
    /// Stanford PLY (ASCII or binary).
    Ply,
    /// glTF 2.0, JSON (`.gltf`) or binary container (`.glb`); both parse from the same bytes.
    Gltf,
}

/// Triangles as read from a file, before the degenerate/non-finite rule is applied.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Triangles in file order (see the module docs for the order); non-finite ones included.
    pub triangles: Vec<Triangle>,
    /// Counts gathered while parsing (`source_triangles`, `polygons_triangulated`,
    /// `primitives_skipped`); `degenerate` and `non_finite` are filled by
    /// [`Scene::from_triangles`].
    pub stats: LoadStats,
}

/// The format of `path` from its extension (case-insensitive), looking under a trailing
/// `.gz`; the flag says whether the name ends in `.gz`.
pub fn format_of(path: &Path) -> Result<(Format, bool), SceneError> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let (inner, gz) = match name.strip_suffix(".gz") {
        Some(inner) => (inner, true),
        None => (name.as_str(), false),
    };
    let format = match inner.rsplit_once('.').map(|(_, ext)| ext) {
        Some("obj") => Format::Obj,
        Some("ply") => Format::Ply,
        Some("gltf" | "glb") if !gz => Format::Gltf,
        _ => {
            return Err(SceneError::UnknownFormat {
                path: path.to_path_buf(),
            });
        }
    };
    Ok((format, gz))
}

/// Loads a scene file, choosing the format by extension (see the module docs), within the
/// default [`Limits`].
///
/// The scene's name is [`file_stem`](crate::file_stem) (the file name without its scene
/// extensions); its spec is the path.
pub fn load_file(path: &Path) -> Result<Scene, SceneError> {
    load_file_with(path, &Limits::default())
}

/// [`load_file`] within `limits`.
pub fn load_file_with(path: &Path, limits: &Limits) -> Result<Scene, SceneError> {
    let mesh = read_mesh_with(path, limits)?;
    let name = crate::file_stem(path).to_string();
    Scene::from_triangles(
        name,
        path.to_string_lossy().into_owned(),
        mesh.triangles,
        mesh.stats,
    )
}

/// Reads and parses a scene file into a [`Mesh`] (no degenerate/non-finite rule applied),
/// within the default [`Limits`].
pub fn read_mesh(path: &Path) -> Result<Mesh, SceneError> {
    read_mesh_with(path, &Limits::default())
}

/// [`read_mesh`] within `limits`: only a regular file is read, at most
/// [`Limits::max_bytes`] of it, inflated to at most what is left of that budget.
pub fn read_mesh_with(path: &Path, limits: &Limits) -> Result<Mesh, SceneError> {
    let (format, _) = format_of(path)?;
    let mut budget = ByteBudget::new(limits);
    let raw = read_regular_file(path, &budget)?;
    let bytes = gunzip_within(path, raw, &budget)?;
    budget.charge(path, bytes.len() as u64)?;
    parse_within(path, format, &bytes, limits, &mut budget)
}

/// What a non-regular file is, for [`SceneError::NotAFile`].
fn kind_of(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a named pipe";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a file"
    }
}

/// Reads `path` whole if it is a regular file (symbolic links followed) of at most `max`
/// bytes: the rule for every small input file (report cache entries, study plans and
/// results, configurations, ray files).
///
/// As in the scene loader, the type is checked before opening (a named pipe is never
/// opened: that would block until a writer appears) and again on the open handle, the size
/// is checked on the handle's metadata, and the read stops one byte past `max`, so a file
/// that grows or a special file that slips through costs at most `max + 1` bytes.
pub fn read_limited(path: &Path, max: u64) -> Result<Vec<u8>, crate::FileError> {
    use crate::FileError;
    let io = |error| FileError::Io {
        path: path.to_path_buf(),
        error,
    };
    let not_a_file = |t| FileError::NotAFile {
        path: path.to_path_buf(),
        kind: kind_of(t),
    };
    let too_large = |size| FileError::TooLarge {
        path: path.to_path_buf(),
        size,
        limit: max,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(not_a_file(meta.file_type()));
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(not_a_file(meta.file_type()));
    }
    if meta.len() > max {
        return Err(too_large(meta.len()));
    }
    let mut out = Vec::with_capacity(meta.len() as usize);
    file.take(max.saturating_add(1))
        .read_to_end(&mut out)
        .map_err(io)?;
    if out.len() as u64 > max {
        return Err(too_large(out.len() as u64));
    }
    Ok(out)
}

/// Reads `path` whole if it is a regular file (symbolic links followed) no larger than what
/// is left of `budget` (not charged here: the caller charges what it keeps).
///
/// The type is checked before opening, so a named pipe is never opened (opening one blocks
/// until a writer appears), and again on the open handle, so a file swapped in between is
/// caught; the read itself stops one byte past the budget, so a file that grows, or a
/// special file that slipped through, cannot exhaust memory.
pub(crate) fn read_regular_file(path: &Path, budget: &ByteBudget) -> Result<Vec<u8>, SceneError> {
    use crate::FileError;
    read_limited(path, budget.remaining()).map_err(|e| match e {
        FileError::Io { path, error } => SceneError::Io { path, error },
        FileError::NotAFile { path, kind } => SceneError::NotAFile { path, kind },
        FileError::TooLarge { path, .. } => budget.exceeded(&path),
    })
}

/// Inflates `raw` when it starts with the gzip magic bytes or `path` ends in `.gz`;
/// otherwise returns it unchanged. Concatenated gzip members are all read. The output is
/// bounded by the default [`Limits::max_bytes`].
pub fn maybe_gunzip(path: &Path, raw: Vec<u8>) -> Result<Vec<u8>, SceneError> {
    gunzip_within(path, raw, &ByteBudget::new(&Limits::default()))
}

/// [`maybe_gunzip`] with the output bounded by `limits.max_bytes`.
pub fn maybe_gunzip_with(
    path: &Path,
    raw: Vec<u8>,
    limits: &Limits,
) -> Result<Vec<u8>, SceneError> {
    gunzip_within(path, raw, &ByteBudget::new(limits))
}

/// [`maybe_gunzip`] with the output bounded by what is left of `budget` (not charged here).
/// Inflating streams into the output and stops one byte past the budget, so a gzip bomb
/// costs at most the budget before it is refused.
pub(crate) fn gunzip_within(
    path: &Path,
    raw: Vec<u8>,
    budget: &ByteBudget,
) -> Result<Vec<u8>, SceneError> {
    let is_gz_name = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
    if !raw.starts_with(&[0x1f, 0x8b]) && !is_gz_name {
        if raw.len() as u64 > budget.remaining() {
            return Err(budget.exceeded(path));
        }
        return Ok(raw);
    }
    let max = budget.remaining();
    // ISIZE (the last 4 bytes) is the inflated size mod 2^32: a good first reservation, but
    // it is untrusted, so cap it at a generous ratio of the compressed size and the budget.
    let hint = raw
        .len()
        .checked_sub(4)
        .and_then(|i| raw.get(i..))
        .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let cap = hint
        .min(raw.len().saturating_mul(16))
        .min(usize::try_from(max).unwrap_or(usize::MAX));
    let mut out = Vec::with_capacity(cap);
    flate2::read::MultiGzDecoder::new(raw.as_slice())
        .take(max.saturating_add(1))
        .read_to_end(&mut out)
        .map_err(|e| parse_error(path, None, format!("gzip: {e}")))?;
    if out.len() as u64 > max {
        return Err(budget.exceeded(path));
    }
    Ok(out)
}

/// Parses the (already inflated) bytes of a file in `format`, within the default
/// [`Limits`]. `path` names the file in errors and, for glTF, is where external buffers are
/// looked up relative to.
pub fn parse_bytes(path: &Path, format: Format, bytes: &[u8]) -> Result<Mesh, SceneError> {
    parse_bytes_with(path, format, bytes, &Limits::default())
}

/// [`parse_bytes`] within `limits`: `bytes` count against [`Limits::max_bytes`], and so do
/// glTF buffers.
pub fn parse_bytes_with(
    path: &Path,
    format: Format,
    bytes: &[u8],
    limits: &Limits,
) -> Result<Mesh, SceneError> {
    let mut budget = ByteBudget::new(limits);
    budget.charge(path, bytes.len() as u64)?;
    parse_within(path, format, bytes, limits, &mut budget)
}

/// Dispatches to the format's parser; `budget` has been charged for `bytes` already.
fn parse_within(
    path: &Path,
    format: Format,
    bytes: &[u8],
    limits: &Limits,
    budget: &mut ByteBudget,
) -> Result<Mesh, SceneError> {
    match format {
        Format::Obj => obj::parse(path, bytes, limits),
        Format::Ply => ply::parse(path, bytes, limits),
        Format::Gltf => gltf::parse(path, bytes, limits, budget),
    }
}

/// A [`SceneError::Parse`] for `path`.
fn parse_error(path: &Path, line: Option<u64>, message: impl Into<String>) -> SceneError {
    SceneError::Parse {
        path: path.to_path_buf(),
        line,
        message: clip_message(message.into()),
    }
}

/// Longest parse error message kept whole, in bytes: a parser may quote the bad line, and
/// a 200 KB line must not make a 200 KB message (a longer one keeps its first 160 and
/// last 80 bytes).
pub const MAX_MESSAGE_BYTES: usize = 240;

/// `message` cut to about [`MAX_MESSAGE_BYTES`]: its first 160 and last 80 bytes (at
/// character boundaries) around `…(N bytes)…`, so both a quoted line's start and the
/// explanation after it remain; control characters are shown as spaces.
fn clip_message(message: String) -> String {
    let clean = |s: &str| -> String {
        s.chars()
            .map(|c| if c.is_control() { ' ' } else { c })
            .collect()
    };
    if message.len() <= MAX_MESSAGE_BYTES {
        return clean(&message);
    }
    let mut head = 160;
    while !message.is_char_boundary(head) {
        head -= 1;
    }
    let mut tail = message.len() - 80;
    while !message.is_char_boundary(tail) {
        tail += 1;
    }
    format!(
        "{}…({} bytes)…{}",
        clean(&message[..head]),
        tail - head,
        clean(&message[tail..])
    )
}

/// Appends the fan triangulation of the polygon `poly` (`n >= 3` vertex indices) to
/// `out` as index triples `(p0, p[i], p[i+1])`, counting polygons with `n > 3`; fails when
/// `out` would then hold more than [`Limits::max_triangles`].
fn fan(
    path: &Path,
    limits: &Limits,
    poly: &[u32],
    out: &mut Vec<[u32; 3]>,
    stats: &mut LoadStats,
) -> Result<(), SceneError> {
    let added = poly.len().saturating_sub(2);
    limits.check_triangles(&path.display(), (out.len() + added) as u64)?;
    if poly.len() > 3 {
        stats.polygons_triangulated += 1;
    }
    for w in poly.get(1..).unwrap_or_default().windows(2) {
        out.push([poly[0], w[0], w[1]]);
    }
    Ok(())
}

/// Builds triangles from vertex positions and index triples (indices already checked to be
/// in range), in parallel.
fn gather(positions: &[dualsplit_geometry::Vec3], faces: &[[u32; 3]]) -> Vec<Triangle> {
    use rayon::prelude::*;
    faces
        .par_iter()
        .with_min_len(1 << 14)
        .map(|f| {
            Triangle::new(
                positions[f[0] as usize],
                positions[f[1] as usize],
                positions[f[2] as usize],
            )
        })
        .collect()
}
