//! Wavefront OBJ through `tobj`: positions (`v`) and faces (`f`) only.
//!
//! tobj is called without its own triangulation, so every face keeps its arity and is
//! fan-triangulated here like PLY polygons. Points and lines are ignored. tobj reports no
//! line numbers, so the reader handed to it counts the lines it consumes (errors raised
//! while a line is parsed get that line); an index out of range is only noticed by tobj when
//! an object ends, so its line is found by a second, light scan ([`locate_bad_index`]).

use super::{Mesh, fan, gather, parse_error};
use crate::{Limits, LoadStats, SceneError};
use dualsplit_geometry::Vec3;
use std::io::BufRead;
use std::path::Path;

/// A `BufRead` that counts the newlines consumed through it.
struct LineCounter<'a> {
    inner: &'a [u8],
    newlines: u64,
    last_was_newline: bool,
}

impl std::io::Read for LineCounter<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = buf.len().min(self.inner.len());
        buf[..n].copy_from_slice(&self.inner[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl BufRead for LineCounter<'_> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        Ok(self.inner)
    }
    fn consume(&mut self, amt: usize) {
        let amt = amt.min(self.inner.len());
        let (done, rest) = self.inner.split_at(amt);
        self.newlines += done.iter().filter(|&&b| b == b'\n').count() as u64;
        if let Some(&b) = done.last() {
            self.last_was_newline = b == b'\n';
        }
        self.inner = rest;
    }
}

/// Parses a whole OBJ file (already inflated).
pub(super) fn parse(path: &Path, bytes: &[u8], limits: &Limits) -> Result<Mesh, SceneError> {
    let mut reader = LineCounter {
        inner: bytes,
        newlines: 0,
        last_was_newline: true,
    };
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let result = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    });
    let models = match result {
        Ok((models, _materials)) => models,
        Err(e) => {
            let line = match e {
                tobj::LoadError::FaceVertexOutOfBounds => locate_bad_index(bytes),
                // The failing line was the last one consumed (it ended in '\n' unless it
                // was the file's last line).
                _ => Some(reader.newlines + u64::from(!reader.last_was_newline)),
            };
            let what = match e {
                tobj::LoadError::FaceVertexOutOfBounds => {
                    "face vertex index out of range (or 0)".to_string()
                }
                tobj::LoadError::ReadError => "read error (not UTF-8 text?)".to_string(),
                other => other.to_string(),
            };
            return Err(parse_error(path, line, what));
        }
    };
    let mut positions: Vec<Vec3> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    let mut stats = LoadStats::default();
    let mut poly: Vec<u32> = Vec::new();
    for m in &models {
        let mesh = &m.mesh;
        let base = positions.len() as u64;
        positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        let local = mesh.positions.len() / 3;
        let to_global = |i: u32| -> Result<u32, SceneError> {
            if (i as usize) < local {
                u32::try_from(base + u64::from(i))
                    .map_err(|_| parse_error(path, None, "more than 2^32 - 1 vertices"))
            } else {
                Err(parse_error(
                    path,
                    None,
                    format!("face vertex {i} out of range"),
                ))
            }
        };
        if mesh.face_arities.is_empty() {
            limits.check_triangles(
                &path.display(),
                (faces.len() + mesh.indices.len() / 3) as u64,
            )?;
            for t in mesh.indices.chunks_exact(3) {
                faces.push([to_global(t[0])?, to_global(t[1])?, to_global(t[2])?]);
            }
        } else {
            let mut start = 0usize;
            for &n in &mesh.face_arities {
                let end = start + n as usize;
                let idx = mesh.indices.get(start..end).unwrap_or_default();
                poly.clear();
                for &i in idx {
                    poly.push(to_global(i)?);
                }
                if poly.len() >= 3 {
                    fan(path, limits, &poly, &mut faces, &mut stats)?;
                }
                start = end;
            }
        }
    }
    stats.source_triangles = faces.len() as u64;
    Ok(Mesh {
        triangles: gather(&positions, &faces),
        stats,
    })
}

/// Finds the first `f` line with a vertex index that is 0 or out of range, counting the
/// `v` lines of the whole file (tobj checks indices against all positions read so far when
/// an object ends). Returns the 1-based line, if one is found.
fn locate_bad_index(bytes: &[u8]) -> Option<u64> {
    let text = String::from_utf8_lossy(bytes);
    let total = text
        .lines()
        .filter(|l| l.trim_start().starts_with("v ") || l.trim_start().starts_with("v\t"))
        .count() as i64;
    let mut seen = 0i64;
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => seen += 1,
            Some("f") => {
                for w in words {
                    let Some(Ok(i)) = w.split('/').next().map(str::parse::<i64>) else {
                        continue;
                    };
                    let resolved = if i < 0 { seen + i } else { i - 1 };
                    if resolved < 0 || resolved >= total {
                        return Some(n as u64 + 1);
                    }
                }
            }
            _ => {}
        }
    }
    None
}
