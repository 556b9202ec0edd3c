//! glTF 2.0 (`.gltf` JSON or `.glb`), through the `gltf` crate with default features off.
//!
//! The crate parses and validates the document (JSON or GLB container); buffers are resolved
//! here (GLB `BIN` chunk, base64 `data:` URI, or a file relative to the `.gltf`) and
//! accessors are read by a small bounds-checked reader, so a lying `byteOffset` or `count`
//! is an error, never a panic.
//!
//! Triangles: the default scene (else scene 0) is walked depth-first in node order, each
//! node's world matrix being `parent × local` (local = `matrix`, or `T × R × S`); every
//! `TRIANGLES` primitive of a node's mesh is emitted in order, its positions transformed to
//! world space. Primitives of any other mode are skipped and counted in
//! [`LoadStats::primitives_skipped`](crate::LoadStats::primitives_skipped).

use super::{Mesh, parse_error};
use crate::SceneError;
use dualsplit_geometry::{Triangle, Vec3};
use glam::Mat4;
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use std::path::Path;

/// Parses a `.gltf` or `.glb` file's bytes; external buffers are read relative to `path`.
pub(super) fn parse(path: &Path, bytes: &[u8]) -> Result<Mesh, SceneError> {
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
        .map(|b| load_buffer(path, &b, gltf.blob.as_deref()))
        .collect::<Result<Vec<_>, _>>()?;
    let mut out = Mesh::default();
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    if let Some(scene) = scene {
        let max_depth = doc.nodes().len();
        for node in scene.nodes() {
            walk(
                path,
                &node,
                Mat4::IDENTITY,
                0,
                max_depth,
                &buffers,
                &mut out,
            )?;
        }
    }
    out.stats.source_triangles = out.triangles.len() as u64;
    Ok(out)
}

/// The bytes of one buffer.
fn load_buffer(
    path: &Path,
    buffer: &gltf::Buffer<'_>,
    blob: Option<&[u8]>,
) -> Result<Vec<u8>, SceneError> {
    let data = match buffer.source() {
        gltf::buffer::Source::Bin => blob
            .ok_or_else(|| parse_error(path, None, "buffer refers to a missing GLB BIN chunk"))?
            .to_vec(),
        gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
            let (_, payload) = uri
                .split_once(";base64,")
                .ok_or_else(|| parse_error(path, None, "data URI buffer is not base64-encoded"))?;
            use base64::Engine;
            base64::engine::general_purpose::STANDARD
                .decode(payload)
                .map_err(|e| {
                    parse_error(
                        path,
                        None,
                        format!("buffer {}: base64: {e}", buffer.index()),
                    )
                })?
        }
        gltf::buffer::Source::Uri(uri) => {
            let file = path
                .parent()
                .unwrap_or(Path::new("."))
                .join(uri.replace("%20", " "));
            std::fs::read(&file).map_err(|e| {
                parse_error(
                    path,
                    None,
                    format!(
                        "buffer {}: cannot read {}: {e}",
                        buffer.index(),
                        file.display()
                    ),
                )
            })?
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

/// Emits the triangles of `node` and its descendants.
fn walk(
    path: &Path,
    node: &gltf::Node<'_>,
    parent: Mat4,
    depth: usize,
    max_depth: usize,
    buffers: &[Vec<u8>],
    out: &mut Mesh,
) -> Result<(), SceneError> {
    if depth > max_depth {
        return Err(parse_error(
            path,
            None,
            format!("node {} is part of a cycle", node.index()),
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
            emit(path, &what, &prim, world, buffers, &mut out.triangles)?;
        }
    }
    for child in node.children() {
        walk(path, &child, world, depth + 1, max_depth, buffers, out)?;
    }
    Ok(())
}

/// Emits the triangles of one `TRIANGLES` primitive, transformed by `world`.
fn emit(
    path: &Path,
    what: &str,
    prim: &gltf::Primitive<'_>,
    world: Mat4,
    buffers: &[Vec<u8>],
    out: &mut Vec<Triangle>,
) -> Result<(), SceneError> {
    let err = |m: String| parse_error(path, None, format!("{what}: {m}"));
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
    let positions: Vec<Vec3> = read_accessor(&pos, buffers)
        .map_err(err)?
        .map(|b| {
            let f = |i: usize| f32::from_le_bytes([b[i], b[i + 1], b[i + 2], b[i + 3]]);
            world.transform_point3(Vec3::new(f(0), f(4), f(8)))
        })
        .collect();
    let indices: Vec<usize> = match prim.indices() {
        Some(acc) => {
            let t = acc.data_type();
            if acc.dimensions() != Dimensions::Scalar
                || !matches!(t, DataType::U8 | DataType::U16 | DataType::U32)
            {
                return Err(err(format!("indices must be unsigned SCALAR, found {t:?}")));
            }
            read_accessor(&acc, buffers)
                .map_err(err)?
                .map(|b| match t {
                    DataType::U8 => b[0] as usize,
                    DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as usize,
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
                })
                .collect()
        }
        None => (0..positions.len()).collect(),
    };
    if !indices.len().is_multiple_of(3) {
        return Err(err(format!(
            "{} indices, not a multiple of 3",
            indices.len()
        )));
    }
    for t in indices.chunks_exact(3) {
        let get = |i: usize| {
            positions.get(i).copied().ok_or_else(|| {
                err(format!(
                    "vertex index {i} out of range ({} vertices)",
                    positions.len()
                ))
            })
        };
        out.push(Triangle::new(get(t[0])?, get(t[1])?, get(t[2])?));
    }
    Ok(())
}

/// The elements of an accessor as byte slices of the element size, bounds-checked against
/// its buffer view and buffer. Sparse accessors and accessors without a view are rejected.
fn read_accessor<'b>(
    acc: &gltf::Accessor<'_>,
    buffers: &'b [Vec<u8>],
) -> Result<impl Iterator<Item = &'b [u8]>, String> {
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
    Ok((0..count).map(move |i| &data[i * stride..i * stride + size]))
}
