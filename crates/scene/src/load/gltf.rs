//! glTF 2.0 (`.gltf` JSON or `.glb`), through the `gltf` crate with default features off.
//!
//! The crate parses and validates the document (JSON or GLB container); buffers are resolved
//! here (GLB `BIN` chunk, base64 `data:` URI, or a regular file inside the `.gltf`'s folder,
//! see [`external_file`]) and accessors are read by a small bounds-checked reader, so a lying
//! `byteOffset` or `count` is an error, never a panic. Decoded and external buffers count
//! against the load's byte budget; emitted triangles against its triangle budget.
//!
//! Triangles: the default scene (else scene 0) is walked depth-first in node order, each
//! node's world matrix being `parent × local` (local = `matrix`, or `T × R × S`); every
//! `TRIANGLES` primitive of a node's mesh is emitted in order, its positions transformed to
//! world space. Primitives of any other mode are skipped and counted in
//! [`LoadStats::primitives_skipped`](crate::LoadStats::primitives_skipped). A node reached
//! twice is an error (see [`walk`]); a mesh may still be instanced by many nodes, up to the
//! triangle budget.

use super::{Mesh, parse_error};
use crate::limits::ByteBudget;
use crate::{Limits, SceneError};
use dualsplit_geometry::{Triangle, Vec3};
use glam::Mat4;
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use std::borrow::Cow;
use std::path::{Component, Path, PathBuf};

/// Parses a `.gltf` or `.glb` file's bytes; external buffers are read relative to `path`
/// and charged to `budget`, triangles are counted against `limits`.
pub(super) fn parse(
    path: &Path,
    bytes: &[u8],
    limits: &Limits,
    budget: &mut ByteBudget,
) -> Result<Mesh, SceneError> {
    let glerr = |e: gltf::Error| parse_error(path, None, format!("glTF: {e}"));
    // gltf-json's validation indexes `accessors[POSITION]` unchecked (gltf-json 1.4.1,
    // mesh.rs:151), so check the attribute indices first, on the unvalidated document.
    let raw = gltf::Gltf::from_slice_without_validation(bytes).map_err(glerr)?;
    let root = raw.document.as_json();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for index in prim.attributes.values() {
                if index.value() >= root.accessors.len() {
                    return Err(parse_error(
                        path,
                        None,
                        format!(
                            "glTF: mesh {m} primitive {p}: accessor {} does not exist ({} accessors)",
                            index.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    drop(raw);
    let gltf = gltf::Gltf::from_slice(bytes).map_err(glerr)?;
    let doc = &gltf.document;
    let buffers = doc
        .buffers()
        .map(|b| load_buffer(path, &b, gltf.blob.as_deref(), budget))
        .collect::<Result<Vec<_>, _>>()?;
    let mut out = Mesh::default();
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    if let Some(scene) = scene {
        walk(path, doc, scene.nodes(), &buffers, limits, &mut out)?;
    }
    out.stats.source_triangles = out.triangles.len() as u64;
    Ok(out)
}

/// The bytes of one buffer: borrowed from the GLB `BIN` chunk, or decoded from a base64
/// `data:` URI, or read from a file inside the scene's folder (see [`external_file`]). Bytes
/// that are not the scene file's own are charged to `budget` before they are held.
fn load_buffer<'a>(
    path: &Path,
    buffer: &gltf::Buffer<'_>,
    blob: Option<&'a [u8]>,
    budget: &mut ByteBudget,
) -> Result<Cow<'a, [u8]>, SceneError> {
    let data =
        match buffer.source() {
            gltf::buffer::Source::Bin => Cow::Borrowed(blob.ok_or_else(|| {
                parse_error(path, None, "buffer refers to a missing GLB BIN chunk")
            })?),
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let (_, payload) = uri.split_once(";base64,").ok_or_else(|| {
                    parse_error(path, None, "data URI buffer is not base64-encoded")
                })?;
                use base64::Engine;
                let engine = &base64::engine::general_purpose::STANDARD;
                budget.charge(path, base64::decoded_len_estimate(payload.len()) as u64)?;
                Cow::Owned(engine.decode(payload).map_err(|e| {
                    parse_error(
                        path,
                        None,
                        format!("buffer {}: base64: {e}", buffer.index()),
                    )
                })?)
            }
            gltf::buffer::Source::Uri(uri) => {
                let file = external_file(path, buffer.index(), uri)?;
                let bytes = super::read_regular_file(&file, budget).map_err(|e| match e {
                    SceneError::Io { error, .. } => parse_error(
                        path,
                        None,
                        format!(
                            "buffer {}: cannot read {}: {error}",
                            buffer.index(),
                            file.display()
                        ),
                    ),
                    other => other,
                })?;
                budget.charge(&file, bytes.len() as u64)?;
                Cow::Owned(bytes)
            }
        };
    if data.len() < buffer.length() {
        return Err(parse_error(
            path,
            None,
            format!(
                "buffer {} declares {} bytes but has {}",
                buffer.index(),
                buffer.length(),
                data.len()
            ),
        ));
    }
    Ok(data)
}

/// The file an external buffer URI names, which must lie inside the folder of the glTF
/// file `path`.
///
/// The URI is percent-decoded (RFC 3986) and must then be a relative path of plain
/// components: a scheme (`file:`, `http:`), an absolute path, a `..` component, a
/// backslash, or a NUL is refused, naming the URI. The joined path is then resolved
/// (symbolic links followed) and must still lie inside the folder, so a link cannot lead
/// out either.
fn external_file(path: &Path, buffer: usize, uri: &str) -> Result<PathBuf, SceneError> {
    let refuse = |reason: &str| SceneError::ExternalUri {
        path: path.to_path_buf(),
        buffer,
        uri: uri.to_string(),
        reason: reason.to_string(),
    };
    let decoded = percent_decode(uri)
        .ok_or_else(|| refuse("bad percent-encoding (each `%` must start a UTF-8 `%XX` escape)"))?;
    let scheme = decoded
        .split_once(':')
        .is_some_and(|(s, _)| !s.is_empty() && !s.contains('/'));
    if scheme {
        return Err(refuse(
            "only relative file paths are read (no scheme such as file: or http:)",
        ));
    }
    if decoded.contains(['\\', '\0']) {
        return Err(refuse("backslashes and NUL bytes are not allowed"));
    }
    let rel = Path::new(&decoded);
    if decoded.is_empty() || rel.has_root() {
        return Err(refuse(
            "must be a relative path inside the scene file's folder, not absolute or empty",
        ));
    }
    if rel
        .components()
        .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err(refuse(
            "must stay inside the scene file's folder (no `..` components)",
        ));
    }
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let file = folder.join(rel);
    // Both sides resolved: the folder itself may sit behind links.
    let io = |e: std::io::Error, p: &Path| {
        parse_error(
            path,
            None,
            format!("buffer {buffer}: cannot read {}: {e}", p.display()),
        )
    };
    let real_folder = folder.canonicalize().map_err(|e| io(e, folder))?;
    let real_file = file.canonicalize().map_err(|e| io(e, &file))?;
    if !real_file.starts_with(&real_folder) {
        return Err(refuse(&format!(
            "resolves to {}, outside the scene file's folder {}",
            real_file.display(),
            real_folder.display()
        )));
    }
    Ok(real_file)
}

/// `s` with every `%XX` escape decoded, or `None` when an escape is malformed or the result
/// is not UTF-8.
fn percent_decode(s: &str) -> Option<String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = std::str::from_utf8(b.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Emits the triangles of the scene whose root nodes are `roots` and of all their
/// descendants, depth-first in pre-order (children in their listed order).
///
/// The walk keeps its own stack, so a deep hierarchy cannot overflow the thread's, and
/// marks every node it reaches: glTF nodes form disjoint trees (a node has at most one
/// parent, and no cycles), so a node reached a second time (a cycle, a shared child, or a
/// root listed twice or also a child) is an error naming it. Without that rule a few dozen
/// nodes listing their child twice would instance a mesh 2^40 times.
fn walk<'d>(
    path: &Path,
    doc: &'d gltf::Document,
    roots: impl Iterator<Item = gltf::Node<'d>>,
    buffers: &[Cow<'_, [u8]>],
    limits: &Limits,
    out: &mut Mesh,
) -> Result<(), SceneError> {
    let mut seen = vec![false; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node<'d>, Mat4)> = roots.map(|n| (n, Mat4::IDENTITY)).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        let Some(mark) = seen.get_mut(node.index()) else {
            return Err(parse_error(
                path,
                None,
                format!("glTF: node {} does not exist", node.index()),
            ));
        };
        if std::mem::replace(mark, true) {
            return Err(parse_error(
                path,
                None,
                format!(
                    "glTF: node {} is reached twice (a cycle, or a node with two parents); \
                     glTF nodes must form disjoint trees",
                    node.index()
                ),
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            for prim in mesh.primitives() {
                if prim.mode() != Mode::Triangles {
                    out.stats.primitives_skipped += 1;
                    continue;
                }
                let what = format!("mesh {} primitive {}", mesh.index(), prim.index());
                emit(
                    path,
                    &what,
                    &prim,
                    world,
                    buffers,
                    limits,
                    &mut out.triangles,
                )?;
            }
        }
        let first_child = stack.len();
        stack.extend(node.children().map(|c| (c, world)));
        stack[first_child..].reverse();
    }
    Ok(())
}

/// Emits the triangles of one `TRIANGLES` primitive, transformed by `world`.
fn emit(
    path: &Path,
    what: &str,
    prim: &gltf::Primitive<'_>,
    world: Mat4,
    buffers: &[Cow<'_, [u8]>],
    limits: &Limits,
    out: &mut Vec<Triangle>,
) -> Result<(), SceneError> {
    let err = |m: String| parse_error(path, None, format!("{what}: {m}"));
    // The count is known before anything is read: an index accessor's count, else the
    // positions'.
    let vertices = prim.indices().map_or(pos_count(prim), |a| a.count());
    limits.check_triangles(&path.display(), (out.len() + vertices / 3) as u64)?;
    let pos = prim
        .get(&gltf::Semantic::Positions)
        .ok_or_else(|| err("no POSITION attribute".into()))?;
    if pos.data_type() != DataType::F32 || pos.dimensions() != Dimensions::Vec3 {
        return Err(err(format!(
            "POSITION must be FLOAT VEC3, found {:?} {:?}",
            pos.data_type(),
            pos.dimensions()
        )));
    }
    // Positions are read and transformed per index, not all at once: the work of one
    // instance is its triangle count, however large the accessor it draws from.
    let positions = read_accessor(&pos, buffers).map_err(err)?;
    let point = |i: usize| {
        let b = positions.get(i).ok_or_else(|| {
            err(format!(
                "vertex index {i} out of range ({} vertices)",
                positions.count
            ))
        })?;
        let f = |k: usize| f32::from_le_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
        Ok(world.transform_point3(Vec3::new(f(0), f(4), f(8))))
    };
    let triangle = |t: [usize; 3]| -> Result<Triangle, SceneError> {
        Ok(Triangle::new(point(t[0])?, point(t[1])?, point(t[2])?))
    };
    match prim.indices() {
        Some(acc) => {
            let t = acc.data_type();
            if acc.dimensions() != Dimensions::Scalar
                || !matches!(t, DataType::U8 | DataType::U16 | DataType::U32)
            {
                return Err(err(format!("indices must be unsigned SCALAR, found {t:?}")));
            }
            let indices = read_accessor(&acc, buffers).map_err(err)?;
            check_multiple_of_3(indices.count).map_err(err)?;
            let index = |b: &[u8]| match t {
                DataType::U8 => b[0] as usize,
                DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as usize,
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
            };
            let mut it = indices.iter().map(index);
            while let (Some(a), Some(b), Some(c)) = (it.next(), it.next(), it.next()) {
                out.push(triangle([a, b, c])?);
            }
        }
        None => {
            check_multiple_of_3(positions.count).map_err(err)?;
            for k in (0..positions.count).step_by(3) {
                out.push(triangle([k, k + 1, k + 2])?);
            }
        }
    }
    Ok(())
}

/// An error unless `n` vertex indices make whole triangles.
fn check_multiple_of_3(n: usize) -> Result<(), String> {
    if n.is_multiple_of(3) {
        Ok(())
    } else {
        Err(format!("{n} indices, not a multiple of 3"))
    }
}

/// The elements of an accessor: `count` slices of `size` bytes, `stride` apart in `data`.
struct Elements<'b> {
    data: &'b [u8],
    stride: usize,
    size: usize,
    count: usize,
}

impl<'b> Elements<'b> {
    /// Element `i`, or `None` past the end.
    fn get(&self, i: usize) -> Option<&'b [u8]> {
        if i >= self.count {
            return None;
        }
        self.data.get(i * self.stride..i * self.stride + self.size)
    }

    /// Every element in order.
    fn iter(&self) -> impl Iterator<Item = &'b [u8]> + '_ {
        (0..self.count).filter_map(|i| self.get(i))
    }
}

/// The elements of an accessor, bounds-checked against its buffer view and buffer (so every
/// `get` below `count` succeeds). Sparse accessors and accessors without a view are
/// rejected.
fn read_accessor<'b>(
    acc: &gltf::Accessor<'_>,
    buffers: &'b [Cow<'_, [u8]>],
) -> Result<Elements<'b>, String> {
    if acc.sparse().is_some() {
        return Err(format!(
            "accessor {}: sparse accessors are not supported",
            acc.index()
        ));
    }
    let view = acc
        .view()
        .ok_or_else(|| format!("accessor {} has no buffer view", acc.index()))?;
    let buffer = buffers
        .get(view.buffer().index())
        .ok_or_else(|| format!("buffer {} missing", view.buffer().index()))?;
    let size = acc.size();
    let stride = view.stride().unwrap_or(size).max(size);
    let view_end = view.offset().checked_add(view.length());
    let view_bytes = view_end
        .and_then(|end| buffer.get(view.offset()..end))
        .ok_or_else(|| {
            format!(
                "buffer view {} ({} bytes at {}) outside its buffer ({} bytes)",
                view.index(),
                view.length(),
                view.offset(),
                buffer.len()
            )
        })?;
    let count = acc.count();
    let needed = match count {
        0 => Some(0),
        n => (n - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(size))
            .and_then(|x| x.checked_add(acc.offset())),
    };
    let data = needed
        .and_then(|n| view_bytes.get(acc.offset().min(n)..n))
        .ok_or_else(|| {
            format!(
                "accessor {} ({count} elements of {size} bytes, stride {stride}, offset {}) \
                 outside its buffer view ({} bytes)",
                acc.index(),
                acc.offset(),
                view_bytes.len()
            )
        })?;
    Ok(Elements {
        data,
        stride,
        size,
        count,
    })
}

/// The POSITION accessor's element count, 0 without one.
fn pos_count(prim: &gltf::Primitive<'_>) -> usize {
    prim.get(&gltf::Semantic::Positions)
        .map_or(0, |a| a.count())
}
