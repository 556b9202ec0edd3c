//! PLY: the header through `ply-rs-bw`; the ASCII body ([`ascii`]) and binary bodies (either
//! endianness) through small readers of our own (the binary one for the speed bar, see
//! `docs/performance.md`; the ASCII one to read `nan` and `inf`, which ply-rs-bw's grammar
//! refuses).
//!
//! What is read: element `vertex` with scalar properties `x`, `y`, `z` (any scalar type, any
//! position among other properties) and element `face` with a list property
//! `vertex_indices` (or `vertex_index`) of any count and index type. Faces are
//! fan-triangulated in file order. Every other element and property is skipped, wherever it
//! appears.

mod ascii;

use super::{Mesh, fan, gather, parse_error};
use crate::{Limits, LoadStats, SceneError};
use dualsplit_geometry::{Triangle, Vec3};
use ply_rs_bw::parser::{ParseError, Parser, Reader};
use ply_rs_bw::ply::{DefaultElement, ElementDef, Encoding, Header, PropertyType, ScalarType};
use std::path::Path;

/// Where the loader finds its data in the header.
struct Schema {
    /// Number of vertices (the `vertex` element's count).
    vertex_count: u32,
    /// Index of the `face` list property within the `face` element.
    face_list: usize,
    /// Indices of `x`, `y`, `z` within the `vertex` element.
    xyz: [usize; 3],
}

/// Parses a whole PLY file (already inflated).
pub(super) fn parse(path: &Path, bytes: &[u8], limits: &Limits) -> Result<Mesh, SceneError> {
    let parser = Parser::<DefaultElement>::new();
    let mut reader = Reader::new(bytes);
    let header = parser
        .read_header(&mut reader)
        .map_err(|e| ply_error(path, &e))?;
    // ply-rs-bw's reader is now on the first body line (1-based).
    let first_body_line = reader.line() as u64;
    let schema = schema(path, &header)?;
    let body = reader.into_inner();
    match header.encoding {
        Encoding::Ascii => ascii::parse(path, body, &header, &schema, first_body_line, limits),
        Encoding::BinaryLittleEndian => parse_binary(path, body, &header, &schema, false, limits),
        Encoding::BinaryBigEndian => parse_binary(path, body, &header, &schema, true, limits),
    }
}

/// A ply-rs-bw error as a [`SceneError::Parse`], keeping its line.
fn ply_error(path: &Path, e: &ParseError) -> SceneError {
    let text = e.to_string();
    let message = match e.line() {
        Some(l) => text
            .strip_prefix(&format!("Line {l}: "))
            .unwrap_or(&text)
            .to_string(),
        None => text,
    };
    let message = message.replace("\n\t", "; ");
    parse_error(path, e.line().map(|l| l as u64), message)
}

/// Finds the `vertex` and `face` elements and the properties the loader needs.
fn schema(path: &Path, header: &Header) -> Result<Schema, SceneError> {
    let vertex = header
        .elements
        .get("vertex")
        .ok_or_else(|| parse_error(path, None, "no `vertex` element in the header"))?;
    let face = header.elements.get("face").ok_or_else(|| {
        parse_error(
            path,
            None,
            "no `face` element in the header (a point cloud?)",
        )
    })?;
    let mut xyz = [0; 3];
    for (slot, name) in xyz.iter_mut().zip(["x", "y", "z"]) {
        let (i, _, def) = vertex.properties.get_full(name).ok_or_else(|| {
            parse_error(
                path,
                None,
                format!("element `vertex` has no property `{name}`"),
            )
        })?;
        if !matches!(def.data_type, PropertyType::Scalar(_)) {
            return Err(parse_error(
                path,
                None,
                format!("vertex property `{name}` is a list"),
            ));
        }
        *slot = i;
    }
    let face_list = ["vertex_indices", "vertex_index"]
        .iter()
        .find_map(|n| face.properties.get_full(*n))
        .ok_or_else(|| {
            parse_error(
                path,
                None,
                "element `face` has no property `vertex_indices`",
            )
        })?;
    let (face_list, _, def) = face_list;
    match def.data_type {
        PropertyType::List(_, ScalarType::Float | ScalarType::Double) | PropertyType::Scalar(_) => {
            return Err(parse_error(
                path,
                None,
                format!("face property `{}` must be a list of integers", def.name),
            ));
        }
        PropertyType::List(..) => {}
    }
    let vertex_count = u32::try_from(vertex.count).map_err(|_| {
        parse_error(
            path,
            None,
            format!("{} vertices: more than 2^32 - 1", vertex.count),
        )
    })?;
    Ok(Schema {
        vertex_count,
        face_list,
        xyz,
    })
}

/// Checks a vertex index read from face `face` (0-based), returning it as `u32`.
fn check_index(
    path: &Path,
    line: Option<u64>,
    face: usize,
    index: f64,
    vertex_count: u32,
) -> Result<u32, SceneError> {
    if index >= 0.0 && index < vertex_count as f64 && index.fract() == 0.0 {
        Ok(index as u32)
    } else {
        Err(index_error(path, line, face, index, vertex_count))
    }
}

/// The error for a vertex index out of range (or not an integer) in face `face`.
fn index_error(
    path: &Path,
    line: Option<u64>,
    face: usize,
    index: f64,
    vertex_count: u32,
) -> SceneError {
    parse_error(
        path,
        line,
        format!(
            "face {face}: vertex index {index} out of range (the file has {vertex_count} vertices)"
        ),
    )
}

/// A face with fewer than three vertices.
fn short_face(path: &Path, line: Option<u64>, face: usize, n: usize) -> SceneError {
    parse_error(
        path,
        line,
        format!("face {face} has {n} vertices; a polygon needs at least 3"),
    )
}

// ---------------------------------------------------------------------------------------
// Binary
// ---------------------------------------------------------------------------------------

/// A copyable mirror of ply-rs-bw's `ScalarType`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

/// A copyable mirror of ply-rs-bw's `PropertyType`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Prop {
    /// One value.
    One(Scalar),
    /// A list: count type, item type.
    List(Scalar, Scalar),
}

impl From<&ScalarType> for Scalar {
    fn from(t: &ScalarType) -> Self {
        match t {
            ScalarType::Char => Scalar::I8,
            ScalarType::UChar => Scalar::U8,
            ScalarType::Short => Scalar::I16,
            ScalarType::UShort => Scalar::U16,
            ScalarType::Int => Scalar::I32,
            ScalarType::UInt => Scalar::U32,
            ScalarType::Float => Scalar::F32,
            ScalarType::Double => Scalar::F64,
        }
    }
}

impl From<&PropertyType> for Prop {
    fn from(t: &PropertyType) -> Self {
        match t {
            PropertyType::Scalar(s) => Prop::One(s.into()),
            PropertyType::List(c, i) => Prop::List(c.into(), i.into()),
        }
    }
}

/// The properties of an element, in order.
fn props(def: &ElementDef) -> Vec<Prop> {
    def.properties
        .values()
        .map(|p| Prop::from(&p.data_type))
        .collect()
}

/// Size in bytes of a scalar type.
fn size_of(t: Scalar) -> usize {
    match t {
        Scalar::I8 | Scalar::U8 => 1,
        Scalar::I16 | Scalar::U16 => 2,
        Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
        Scalar::F64 => 8,
    }
}

/// A bounds-checked reader over a binary body.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Cursor<'_> {
    /// The next `N` bytes, or `None` at the end of the data.
    #[inline]
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let b = self.bytes.get(self.pos..self.pos + N)?;
        self.pos += N;
        b.try_into().ok()
    }

    /// The next scalar of type `t`, widened to `f64` (exact for every PLY type).
    #[inline]
    fn scalar(&mut self, t: Scalar) -> Option<f64> {
        macro_rules! rd {
            ($ty:ty, $n:literal) => {{
                let b = self.take::<$n>()?;
                if self.big_endian {
                    <$ty>::from_be_bytes(b)
                } else {
                    <$ty>::from_le_bytes(b)
                }
            }};
        }
        Some(match t {
            Scalar::I8 => rd!(i8, 1).into(),
            Scalar::U8 => rd!(u8, 1).into(),
            Scalar::I16 => rd!(i16, 2).into(),
            Scalar::U16 => rd!(u16, 2).into(),
            Scalar::I32 => rd!(i32, 4).into(),
            Scalar::U32 => rd!(u32, 4).into(),
            Scalar::F32 => rd!(f32, 4).into(),
            Scalar::F64 => rd!(f64, 8),
        })
    }

    /// Bytes left.
    fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }
}

/// Smallest record size of an element (lists counted as empty), and whether every record
/// has exactly that size (no list properties).
fn record_size(def: &ElementDef) -> (usize, bool) {
    let mut size = 0;
    let mut fixed = true;
    for p in props(def) {
        match p {
            Prop::One(t) => size += size_of(t),
            Prop::List(c, _) => {
                size += size_of(c);
                fixed = false;
            }
        }
    }
    (size, fixed)
}

/// The binary body, either endianness.
fn parse_binary(
    path: &Path,
    body: &[u8],
    header: &Header,
    schema: &Schema,
    big_endian: bool,
    limits: &Limits,
) -> Result<Mesh, SceneError> {
    let mut cur = Cursor {
        bytes: body,
        pos: 0,
        big_endian,
    };
    let mut positions: Vec<Vec3> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    let mut triangles: Vec<Triangle> = Vec::new();
    let mut stats = LoadStats::default();
    for (name, def) in &header.elements {
        let (min_size, fixed) = record_size(def);
        let need = def.count.saturating_mul(min_size);
        if need > cur.remaining() {
            return Err(truncated(path, def, cur.remaining(), need));
        }
        if name == "vertex" {
            positions = read_vertices(path, &mut cur, def, schema)?;
        } else if name == "face" {
            // Every record is a polygon of at least one triangle, or an error.
            limits.check_triangles(&path.display(), def.count as u64)?;
            // The fast path builds triangles straight from the records, so it needs the
            // positions first (the usual order: vertices before faces).
            let fast = match props(def)[..] {
                [Prop::List(count_t, index_t)]
                    if positions.len() == schema.vertex_count as usize =>
                {
                    read_triangles_fast(path, &mut cur, def, &positions, count_t, index_t)?
                }
                _ => None,
            };
            match fast {
                Some(t) => triangles = t,
                None => read_faces(path, &mut cur, def, schema, limits, &mut faces, &mut stats)?,
            }
        } else if fixed {
            cur.pos += need;
        } else {
            let props = props(def);
            for i in 0..def.count {
                for &p in &props {
                    skip_property(path, &mut cur, def, i, p)?;
                }
            }
        }
    }
    if !faces.is_empty() {
        triangles.extend(gather(&positions, &faces));
    }
    stats.source_triangles = triangles.len() as u64;
    Ok(Mesh { triangles, stats })
}

/// The error for a body that ends before `element` does.
fn truncated(path: &Path, def: &ElementDef, remaining: usize, need: usize) -> SceneError {
    parse_error(
        path,
        None,
        format!(
            "truncated: element `{}` declares {} records, needing at least {need} bytes, \
             but only {remaining} bytes are left",
            def.name, def.count
        ),
    )
}

/// The error for a record cut off by the end of the data.
fn cut(path: &Path, def: &ElementDef, record: usize) -> SceneError {
    parse_error(
        path,
        None,
        format!(
            "truncated: the data ends inside record {record} of element `{}` ({} declared)",
            def.name, def.count
        ),
    )
}

/// Reads a list length of type `t`, checking it is a sane non-negative integer that fits
/// in the remaining bytes.
fn list_len(
    path: &Path,
    cur: &mut Cursor<'_>,
    def: &ElementDef,
    record: usize,
    count_t: Scalar,
    item_t: Scalar,
) -> Result<usize, SceneError> {
    let n = cur.scalar(count_t).ok_or_else(|| cut(path, def, record))?;
    if !(n >= 0.0 && n.fract() == 0.0) {
        return Err(parse_error(
            path,
            None,
            format!(
                "record {record} of element `{}`: bad list length {n}",
                def.name
            ),
        ));
    }
    let n = n as usize;
    if n.saturating_mul(size_of(item_t)) > cur.remaining() {
        return Err(cut(path, def, record));
    }
    Ok(n)
}

/// Skips one property of record `record`.
fn skip_property(
    path: &Path,
    cur: &mut Cursor<'_>,
    def: &ElementDef,
    record: usize,
    t: Prop,
) -> Result<(), SceneError> {
    let bytes = match t {
        Prop::One(t) => size_of(t),
        Prop::List(c, i) => list_len(path, cur, def, record, c, i)? * size_of(i),
    };
    if bytes > cur.remaining() {
        return Err(cut(path, def, record));
    }
    cur.pos += bytes;
    Ok(())
}

/// Reads the `vertex` element's positions.
fn read_vertices(
    path: &Path,
    cur: &mut Cursor<'_>,
    def: &ElementDef,
    schema: &Schema,
) -> Result<Vec<Vec3>, SceneError> {
    let props = props(def);
    let mut out = Vec::with_capacity(def.count);
    // Fast path: the common `float x, float y, float z` as the first three properties.
    let plain = props.len() == 3
        && schema.xyz == [0, 1, 2]
        && props.iter().all(|&t| t == Prop::One(Scalar::F32));
    if plain {
        use rayon::prelude::*;
        let bytes = &cur.bytes[cur.pos..cur.pos + def.count * 12];
        let be = cur.big_endian;
        out.par_extend(bytes.par_chunks_exact(12).with_min_len(1 << 14).map(|c| {
            let f = |i: usize| {
                let b = [c[i], c[i + 1], c[i + 2], c[i + 3]];
                if be {
                    f32::from_be_bytes(b)
                } else {
                    f32::from_le_bytes(b)
                }
            };
            Vec3::new(f(0), f(4), f(8))
        }));
        cur.pos += def.count * 12;
        return Ok(out);
    }
    for i in 0..def.count {
        let mut p = [0.0f32; 3];
        for (k, &t) in props.iter().enumerate() {
            match t {
                Prop::One(s) => {
                    let v = cur.scalar(s).ok_or_else(|| cut(path, def, i))?;
                    if let Some(c) = schema.xyz.iter().position(|&x| x == k) {
                        p[c] = v as f32;
                    }
                }
                Prop::List(..) => skip_property(path, cur, def, i, t)?,
            }
        }
        out.push(Vec3::from_array(p));
    }
    Ok(out)
}

/// Reads the `face` element, fan-triangulating into `faces`.
fn read_faces(
    path: &Path,
    cur: &mut Cursor<'_>,
    def: &ElementDef,
    schema: &Schema,
    limits: &Limits,
    faces: &mut Vec<[u32; 3]>,
    stats: &mut LoadStats,
) -> Result<(), SceneError> {
    let props = props(def);
    // Most files have triangles only, so one triangle per record is a good guess (the count
    // was checked against the bytes present).
    faces.reserve(def.count.min(limits.max_triangles as usize));
    let mut poly: Vec<u32> = Vec::with_capacity(16);
    for i in 0..def.count {
        for (k, &t) in props.iter().enumerate() {
            match t {
                Prop::List(c, it) if k == schema.face_list => {
                    let n = list_len(path, cur, def, i, c, it)?;
                    poly.clear();
                    for _ in 0..n {
                        let x = cur.scalar(it).ok_or_else(|| cut(path, def, i))?;
                        poly.push(check_index(path, None, i, x, schema.vertex_count)?);
                    }
                    if n < 3 {
                        return Err(short_face(path, None, i, n));
                    }
                    fan(path, limits, &poly, faces, stats)?;
                }
                _ => skip_property(path, cur, def, i, t)?,
            }
        }
    }
    Ok(())
}

/// The fast path for a `face` element whose only property is the index list with an 8-bit
/// count and 32-bit indices (the shipped scenes): when every record's count is 3, the
/// records are a fixed 13-byte stride, so triangles are built from them in parallel, straight
/// from `positions`. Returns `None` (nothing consumed) when the element does not have that
/// shape; [`read_faces`] then runs.
///
/// The shape test is sound: if the record at offset 0 has count 3 it is 13 bytes long, so
/// the next record starts at 13, and so on; checking every 13th byte for 3 is exactly what
/// the sequential reader would see.
fn read_triangles_fast(
    path: &Path,
    cur: &mut Cursor<'_>,
    def: &ElementDef,
    positions: &[Vec3],
    count_t: Scalar,
    index_t: Scalar,
) -> Result<Option<Vec<Triangle>>, SceneError> {
    use rayon::prelude::*;
    const REC: usize = 13;
    if !matches!(count_t, Scalar::U8 | Scalar::I8) || !matches!(index_t, Scalar::U32 | Scalar::I32)
    {
        return Ok(None);
    }
    let Some(bytes) = def
        .count
        .checked_mul(REC)
        .and_then(|n| cur.bytes.get(cur.pos..cur.pos.checked_add(n)?))
    else {
        return Ok(None);
    };
    if !bytes
        .par_chunks_exact(REC)
        .with_min_len(1 << 14)
        .all(|r| r[0] == 3)
    {
        return Ok(None);
    }
    let be = cur.big_endian;
    // A negative i32 reads as a u32 >= 2^31 > any vertex count, so one range test covers
    // both index types.
    let decode = |r: &[u8], k: usize| {
        let b = [r[k], r[k + 1], r[k + 2], r[k + 3]];
        let i = if be {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        };
        i as usize
    };
    let n = positions.len();
    let in_range = |r: &[u8]| decode(r, 1) < n && decode(r, 5) < n && decode(r, 9) < n;
    if !bytes
        .par_chunks_exact(REC)
        .with_min_len(1 << 14)
        .all(in_range)
    {
        // Find the first bad index for the message.
        for (i, r) in bytes.chunks_exact(REC).enumerate() {
            if let Some(bad) = [1, 5, 9]
                .map(|k| decode(r, k))
                .into_iter()
                .find(|&v| v >= n)
            {
                let shown = if index_t == Scalar::I32 {
                    f64::from(bad as u32 as i32)
                } else {
                    bad as f64
                };
                return Err(index_error(path, None, i, shown, n as u32));
            }
        }
        return Err(parse_error(path, None, "vertex index out of range"));
    }
    // Every index was checked above, so the indexing below cannot fail; an indexed parallel
    // iterator collects straight into the output vector.
    let triangles: Vec<Triangle> = bytes
        .par_chunks_exact(REC)
        .with_min_len(1 << 14)
        .map(|r| {
            Triangle::new(
                positions[decode(r, 1)],
                positions[decode(r, 5)],
                positions[decode(r, 9)],
            )
        })
        .collect();
    cur.pos += bytes.len();
    Ok(Some(triangles))
}
