//! The ASCII PLY body: one record per line, values separated by spaces or tabs.
//!
//! Each value is read by Rust's parser for its property's type: an integer type takes an
//! integer in that type's range; `float` and `double` take every spelling `f32::from_str`
//! and `f64::from_str` do, `nan`, `inf` and `infinity` included (any case, optional sign).
//! So a non-finite coordinate reaches the crate-wide rule (the triangle is dropped and
//! counted) exactly as in a binary file. Values past a record's last property are ignored;
//! a line that ends early, a value that does not parse, and a file that ends before the
//! header's counts are errors naming the 1-based line.

use super::{Prop, Scalar, Schema, check_index, props, short_face};
use crate::load::{Mesh, fan, gather, parse_error};
use crate::{Limits, LoadStats, SceneError};
use dualsplit_geometry::Vec3;
use ply_rs_bw::ply::{ElementDef, Header};
use std::path::Path;
use std::str::SplitAsciiWhitespace;

/// The lines of the body, split at `\n` (a `\r` before it is whitespace to the tokenizer).
struct Lines<'a> {
    rest: &'a [u8],
}

impl<'a> Lines<'a> {
    /// The next line, or `None` at the end of the data.
    fn next(&mut self) -> Option<&'a [u8]> {
        if self.rest.is_empty() {
            return None;
        }
        let (line, rest) = match self.rest.iter().position(|&b| b == b'\n') {
            Some(i) => (&self.rest[..i], &self.rest[i + 1..]),
            None => (self.rest, &self.rest[self.rest.len()..]),
        };
        self.rest = rest;
        Some(line)
    }
}

/// One record's values, with what error messages need.
struct Record<'a, 't> {
    path: &'a Path,
    line: u64,
    element: &'a str,
    values: SplitAsciiWhitespace<'t>,
}

impl Record<'_, '_> {
    /// The next value, read as a scalar of type `t` and widened to `f64` (exact for every
    /// PLY type).
    fn scalar(&mut self, t: Scalar, property: &str) -> Result<f64, SceneError> {
        let Some(token) = self.values.next() else {
            return Err(parse_error(
                self.path,
                Some(self.line),
                format!(
                    "the line ends before property `{property}` of element `{}`",
                    self.element
                ),
            ));
        };
        number(token, t).ok_or_else(|| {
            parse_error(
                self.path,
                Some(self.line),
                format!(
                    "`{token}` is not a {} (property `{property}` of element `{}`)",
                    type_name(t),
                    self.element
                ),
            )
        })
    }

    /// The next value as a list length of type `t`: a non-negative integer.
    fn list_len(&mut self, t: Scalar, property: &str) -> Result<usize, SceneError> {
        let n = self.scalar(t, property)?;
        if n >= 0.0 && n.fract() == 0.0 {
            Ok(n as usize)
        } else {
            Err(parse_error(
                self.path,
                Some(self.line),
                format!("bad list length {n} (property `{property}`)"),
            ))
        }
    }

    /// Reads and checks one property whose value is not needed.
    fn skip(&mut self, p: Prop, property: &str) -> Result<(), SceneError> {
        match p {
            Prop::One(t) => {
                self.scalar(t, property)?;
            }
            Prop::List(c, i) => {
                for _ in 0..self.list_len(c, property)? {
                    self.scalar(i, property)?;
                }
            }
        }
        Ok(())
    }
}

/// `token` parsed as type `t`, or `None` when it is not one.
fn number(token: &str, t: Scalar) -> Option<f64> {
    Some(match t {
        Scalar::I8 => token.parse::<i8>().ok()?.into(),
        Scalar::U8 => token.parse::<u8>().ok()?.into(),
        Scalar::I16 => token.parse::<i16>().ok()?.into(),
        Scalar::U16 => token.parse::<u16>().ok()?.into(),
        Scalar::I32 => token.parse::<i32>().ok()?.into(),
        Scalar::U32 => token.parse::<u32>().ok()?.into(),
        Scalar::F32 => token.parse::<f32>().ok()?.into(),
        Scalar::F64 => token.parse::<f64>().ok()?,
    })
}

/// The PLY name of a scalar type, for messages.
fn type_name(t: Scalar) -> &'static str {
    match t {
        Scalar::I8 => "char",
        Scalar::U8 => "uchar",
        Scalar::I16 => "short",
        Scalar::U16 => "ushort",
        Scalar::I32 => "int",
        Scalar::U32 => "uint",
        Scalar::F32 => "float",
        Scalar::F64 => "double",
    }
}

/// What the loader does with an element's records.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Role {
    Vertex,
    Face,
    Other,
}

/// Parses the ASCII body `body`, whose first line is line `first_line` of the file.
pub(super) fn parse(
    path: &Path,
    body: &[u8],
    header: &Header,
    schema: &Schema,
    first_line: u64,
    limits: &Limits,
) -> Result<Mesh, SceneError> {
    let mut lines = Lines { rest: body };
    let mut line = first_line;
    let mut positions: Vec<Vec3> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    let mut poly: Vec<u32> = Vec::new();
    let mut stats = LoadStats::default();
    for (name, def) in &header.elements {
        let role = match name.as_str() {
            "vertex" => Role::Vertex,
            "face" => Role::Face,
            _ => Role::Other,
        };
        let props = props(def);
        let names: Vec<&str> = def.properties.keys().map(String::as_str).collect();
        // A record takes at least two bytes ("0\n"), so the body bounds any reservation.
        let cap = def.count.min(body.len() / 2);
        match role {
            Role::Vertex => positions.reserve(cap),
            Role::Face => faces.reserve(cap.min(limits.max_triangles as usize)),
            Role::Other => {}
        }
        for i in 0..def.count {
            let Some(bytes) = lines.next() else {
                return Err(end_of_file(path, line, def, i));
            };
            let text = std::str::from_utf8(bytes)
                .map_err(|_| parse_error(path, Some(line), "not UTF-8 text"))?;
            let mut rec = Record {
                path,
                line,
                element: name,
                values: text.split_ascii_whitespace(),
            };
            match role {
                Role::Vertex => {
                    let mut p = [0.0f32; 3];
                    for (k, (&t, &n)) in props.iter().zip(&names).enumerate() {
                        match (t, schema.xyz.iter().position(|&x| x == k)) {
                            (Prop::One(s), Some(c)) => p[c] = rec.scalar(s, n)? as f32,
                            _ => rec.skip(t, n)?,
                        }
                    }
                    positions.push(Vec3::from_array(p));
                }
                Role::Face => {
                    for (k, (&t, &n)) in props.iter().zip(&names).enumerate() {
                        match t {
                            Prop::List(c, it) if k == schema.face_list => {
                                let count = rec.list_len(c, n)?;
                                poly.clear();
                                for _ in 0..count {
                                    let x = rec.scalar(it, n)?;
                                    poly.push(check_index(
                                        path,
                                        Some(line),
                                        i,
                                        x,
                                        schema.vertex_count,
                                    )?);
                                }
                                if poly.len() < 3 {
                                    return Err(short_face(path, Some(line), i, poly.len()));
                                }
                                fan(path, limits, &poly, &mut faces, &mut stats)?;
                            }
                            _ => rec.skip(t, n)?,
                        }
                    }
                }
                Role::Other => {
                    for (&t, &n) in props.iter().zip(&names) {
                        rec.skip(t, n)?;
                    }
                }
            }
            line += 1;
        }
    }
    stats.source_triangles = faces.len() as u64;
    Ok(Mesh {
        triangles: gather(&positions, &faces),
        stats,
    })
}

/// The error for a body that ends before record `record` of `def`.
fn end_of_file(path: &Path, line: u64, def: &ElementDef, record: usize) -> SceneError {
    parse_error(
        path,
        Some(line),
        format!(
            "unexpected end of file: element `{}` declares {} records, the file holds {record}",
            def.name, def.count
        ),
    )
}
