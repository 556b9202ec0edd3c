//! File loaders: OBJ, PLY (ASCII and binary), glTF 2.0, each of the first two optionally
//! gzipped.
//!
//! [`load_file`] reads the whole file, inflates it when it is gzip (by the `.gz` extension or
//! by the gzip magic bytes `1f 8b`), picks the format by the extension under any `.gz`, and
//! hands the bytes to one parser per format. Every parser returns a [`Mesh`]: the triangles
//! in file order plus [`LoadStats`]; [`Scene::from_triangles`] then applies the crate-wide
//! degenerate/non-finite rule (see the crate docs).
//!
//! | extension | parser | notes |
//! |---|---|---|
//! | `.obj`, `.obj.gz` | [`tobj`] | `v` positions and `f` faces only (texture coordinates, normals, materials, points and lines ignored); negative (relative) indices; polygons fan-triangulated |
//! | `.ply`, `.ply.gz` | header: [`ply_rs_bw`]; ASCII body: [`ply_rs_bw`]; binary body (little- and big-endian): our own decoder | element `vertex` with float/double (or integer) `x`, `y`, `z` in any order among other properties; element `face` with a list `vertex_indices` (or `vertex_index`) of any count and index type; polygons fan-triangulated; other elements and properties skipped |
//! | `.gltf`, `.glb` | [`gltf`](::gltf) (JSON and GLB container) plus our own bounds-checked accessor reader | buffers embedded as base64 `data:` URIs, external files relative to the `.gltf`, or the GLB `BIN` chunk; every `TRIANGLES` primitive of every mesh instanced by the default scene (else scene 0), with node transforms (matrix or TRS) composed down the hierarchy; other primitive modes are skipped and counted |
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
//! ## Errors
//!
//! Malformed input never panics: every failure is a [`SceneError`] naming the file and, for
//! the line-based formats (OBJ, ASCII PLY, any PLY header), the 1-based line. Counts in
//! headers are checked against the bytes actually present before anything is allocated, so
//! a huge or negative count is an error, not an out-of-memory abort.

mod gltf;
mod obj;
mod ply;

use crate::{LoadStats, Scene, SceneError};
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

/// Loads a scene file, choosing the format by extension (see the module docs).
///
/// The scene's name is [`file_stem`](crate::file_stem) (the file name without its scene
/// extensions); its spec is the path.
pub fn load_file(path: &Path) -> Result<Scene, SceneError> {
    let mesh = read_mesh(path)?;
    let name = crate::file_stem(path).to_string();
    Scene::from_triangles(
        name,
        path.to_string_lossy().into_owned(),
        mesh.triangles,
        mesh.stats,
    )
}

/// Reads and parses a scene file into a [`Mesh`] (no degenerate/non-finite rule applied).
pub fn read_mesh(path: &Path) -> Result<Mesh, SceneError> {
    let (format, _) = format_of(path)?;
    let raw = std::fs::read(path).map_err(|error| SceneError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    let bytes = maybe_gunzip(path, raw)?;
    parse_bytes(path, format, &bytes)
}

/// Inflates `raw` when it starts with the gzip magic bytes or `path` ends in `.gz`;
/// otherwise returns it unchanged. Concatenated gzip members are all read.
pub fn maybe_gunzip(path: &Path, raw: Vec<u8>) -> Result<Vec<u8>, SceneError> {
    let is_gz_name = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
    if !raw.starts_with(&[0x1f, 0x8b]) && !is_gz_name {
        return Ok(raw);
    }
    // ISIZE (the last 4 bytes) is the inflated size mod 2^32: a good first reservation, but
    // it is untrusted, so cap it at a generous ratio of the compressed size.
    let hint = raw
        .len()
        .checked_sub(4)
        .and_then(|i| raw.get(i..))
        .map_or(0, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize);
    let mut out = Vec::with_capacity(hint.min(raw.len().saturating_mul(16)));
    flate2::read::MultiGzDecoder::new(raw.as_slice())
        .read_to_end(&mut out)
        .map_err(|e| parse_error(path, None, format!("gzip: {e}")))?;
    Ok(out)
}

/// Parses the (already inflated) bytes of a file in `format`. `path` names the file in
/// errors and, for glTF, is where external buffers are looked up relative to.
pub fn parse_bytes(path: &Path, format: Format, bytes: &[u8]) -> Result<Mesh, SceneError> {
    match format {
        Format::Obj => obj::parse(path, bytes),
        Format::Ply => ply::parse(path, bytes),
        Format::Gltf => gltf::parse(path, bytes),
    }
}

/// A [`SceneError::Parse`] for `path`.
fn parse_error(path: &Path, line: Option<u64>, message: impl Into<String>) -> SceneError {
    SceneError::Parse {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

/// Appends the fan triangulation of the polygon `poly` (`n >= 3` vertex indices) to
/// `out` as index triples `(p0, p[i], p[i+1])`, counting polygons with `n > 3`.
fn fan(poly: &[u32], out: &mut Vec<[u32; 3]>, stats: &mut LoadStats) {
    if poly.len() > 3 {
        stats.polygons_triangulated += 1;
    }
    for w in poly.get(1..).unwrap_or_default().windows(2) {
        out.push([poly[0], w[0], w[1]]);
    }
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
