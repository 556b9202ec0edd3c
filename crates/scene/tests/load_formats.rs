//! Round trips: a small mesh written in every format and variant loads back to exactly the
//! expected triangles, in file order with fan triangulation.

use dualsplit_geometry::{Triangle, Vec3};
use dualsplit_scene::load::{self, Format};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Vertices of the test mesh (distinct, non-integer coordinates so any mix-up shows).
fn verts() -> Vec<Vec3> {
    vec![
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.5, 0.0, -0.25),
        Vec3::new(0.0, 2.0, 0.5),
        Vec3::new(3.0, 1.0, 1.0),
        Vec3::new(-1.0, 3.5, 2.25),
        Vec3::new(0.75, -2.0, 4.0),
    ]
}

/// Faces of the test mesh: a triangle, a quad and a pentagon.
fn faces() -> Vec<Vec<u32>> {
    vec![vec![0, 1, 2], vec![1, 3, 4, 2], vec![5, 0, 2, 4, 3]]
}

/// The triangles the loaders must produce: fan `(p0, p[i], p[i+1])`, in face order.
fn expected() -> Vec<Triangle> {
    let v = verts();
    let mut out = Vec::new();
    for f in faces() {
        for i in 1..f.len() - 1 {
            out.push(Triangle::new(
                v[f[0] as usize],
                v[f[i] as usize],
                v[f[i + 1] as usize],
            ));
        }
    }
    out
}

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn assert_mesh(path: &Path) {
    let scene = load::load_file(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(scene.triangles, expected(), "{}", path.display());
    assert_eq!(scene.stats.source_triangles, 6);
    assert_eq!(scene.stats.polygons_triangulated, 2);
    assert_eq!(scene.stats.non_finite, 0);
    assert_eq!(scene.stats.degenerate, 0);
}

fn ascii_ply() -> String {
    let mut s = String::from(
        "ply\nformat ascii 1.0\ncomment test\nelement vertex 6\nproperty float x\n\
         property float y\nproperty float z\nelement face 3\n\
         property list uchar int vertex_indices\nend_header\n",
    );
    for v in verts() {
        s += &format!("{} {} {}\n", v.x, v.y, v.z);
    }
    for f in faces() {
        s += &format!("{}", f.len());
        for i in f {
            s += &format!(" {i}");
        }
        s += "\n";
    }
    s
}

#[test]
fn ascii_ply_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    assert_mesh(&write(dir.path(), "m.ply", ascii_ply().as_bytes()));
    assert_mesh(&write(
        dir.path(),
        "m.ply.gz",
        &gzip(ascii_ply().as_bytes()),
    ));
}

/// A binary PLY with shuffled property order, extra properties and elements, doubles for
/// coordinates and the given list types.
fn binary_ply(big_endian: bool, count_ty: &str, index_ty: &str) -> Vec<u8> {
    let enc = if big_endian {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let header = format!(
        "ply\nformat {enc} 1.0\nelement material 2\nproperty uchar red\nproperty list uchar float tags\n\
         element vertex 6\nproperty float confidence\nproperty double z\nproperty float x\n\
         property list ushort short junk\nproperty float y\n\
         element face 3\nproperty int flags\nproperty list {count_ty} {index_ty} vertex_indices\n\
         property uchar tail\nelement edge 1\nproperty int a\nproperty int b\nend_header\n"
    );
    let mut b = header.into_bytes();
    macro_rules! put {
        ($v:expr) => {
            if big_endian {
                b.extend_from_slice(&$v.to_be_bytes())
            } else {
                b.extend_from_slice(&$v.to_le_bytes())
            }
        };
    }
    // material: red, tags list (2 floats), twice
    for k in 0..2u8 {
        put!(k);
        put!(2u8);
        put!(1.0f32);
        put!(2.0f32);
    }
    for (k, v) in verts().iter().enumerate() {
        put!(0.5f32);
        put!(v.z as f64);
        put!(v.x);
        put!(k as u16);
        for j in 0..k {
            put!(j as i16);
        }
        put!(v.y);
    }
    for f in faces() {
        put!(-7i32);
        match count_ty {
            "uchar" => put!(f.len() as u8),
            "ushort" => put!(f.len() as u16),
            "uint" => put!(f.len() as u32),
            "int" => put!(f.len() as i32),
            _ => unreachable!(),
        }
        for i in f {
            match index_ty {
                "int" => put!(i as i32),
                "uint" => put!(i),
                "ushort" => put!(i as u16),
                "short" => put!(i as i16),
                "uchar" => put!(i as u8),
                _ => unreachable!(),
            }
        }
        put!(9u8);
    }
    put!(1i32);
    put!(2i32);
    b
}

#[test]
fn binary_ply_round_trip_both_endians_all_types() {
    let dir = tempfile::tempdir().unwrap();
    for be in [false, true] {
        for (c, i) in [
            ("uchar", "int"),
            ("ushort", "uint"),
            ("int", "ushort"),
            ("uint", "uchar"),
            ("uchar", "short"),
        ] {
            let bytes = binary_ply(be, c, i);
            let name = format!("m_{be}_{c}_{i}.ply");
            assert_mesh(&write(dir.path(), &name, &bytes));
            assert_mesh(&write(dir.path(), &format!("{name}.gz"), &gzip(&bytes)));
        }
    }
}

#[test]
fn plain_binary_ply_fast_path() {
    // The shipped scenes' exact shape: float x y z, list uchar uint.
    let mut b = b"ply\nformat binary_little_endian 1.0\nelement vertex 6\nproperty float x\n\
property float y\nproperty float z\nelement face 3\nproperty list uchar uint vertex_indices\nend_header\n"
        .to_vec();
    for v in verts() {
        for c in v.to_array() {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    for f in faces() {
        b.push(f.len() as u8);
        for i in f {
            b.extend_from_slice(&i.to_le_bytes());
        }
    }
    let dir = tempfile::tempdir().unwrap();
    assert_mesh(&write(dir.path(), "plain.ply", &b));
    // gzip sniffed by magic even without the .gz extension
    assert_mesh(&write(dir.path(), "sniffed.ply", &gzip(&b)));
}

fn obj_text() -> String {
    let mut s = String::from("# test\nmtllib none.mtl\no first\n");
    let v = verts();
    for p in &v[..3] {
        s += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    s += "vt 0 0\nvn 0 0 1\nf 1/1/1 2/1/1 3/1/1\n";
    for p in &v[3..] {
        s += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    // The quad 1 3 4 2 with relative indices (6 vertices so far: -5 is vertex 1).
    s += "g second\nusemtl red\nf -5 -3 -2 -4\n";
    s += "l 1 2\n";
    s += "f 6//1 1//1 3//1 5//1 4//1\n";
    s
}

#[test]
fn obj_round_trip_quads_negative_indices_groups() {
    let dir = tempfile::tempdir().unwrap();
    assert_mesh(&write(dir.path(), "m.obj", obj_text().as_bytes()));
    assert_mesh(&write(dir.path(), "m.OBJ.GZ", &gzip(obj_text().as_bytes())));
}

// ---------------------------------------------------------------------------------------
// glTF
// ---------------------------------------------------------------------------------------

/// Buffer: positions (6 × VEC3 f32) then u16 indices of the triangulated mesh.
fn gltf_buffer() -> (Vec<u8>, usize, usize) {
    let mut b = Vec::new();
    for v in verts() {
        for c in v.to_array() {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    let pos_len = b.len();
    let mut n = 0;
    for f in faces() {
        for i in 1..f.len() - 1 {
            for k in [f[0], f[i], f[i + 1]] {
                b.extend_from_slice(&(k as u16).to_le_bytes());
                n += 1;
            }
        }
    }
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    (b, pos_len, n)
}

/// A document: node 0 (translation) → node 1 (matrix: scale 2) → node 2 (mesh 0, rotation
/// 90° about z + scale), plus node 3 at the root with mesh 0 and no transform; mesh 0 has a
/// TRIANGLES primitive and a LINES primitive (skipped).
fn gltf_json(uri: Option<&str>, buffer_len: usize, pos_len: usize, n_idx: usize) -> String {
    let uri = uri
        .map(|u| format!(r#""uri": "{u}", "#))
        .unwrap_or_default();
    let s = std::f32::consts::FRAC_1_SQRT_2;
    format!(
        r#"{{
  "asset": {{"version": "2.0"}},
  "scene": 0,
  "scenes": [{{"nodes": [0, 3]}}],
  "nodes": [
    {{"children": [1], "translation": [1.0, 2.0, 3.0]}},
    {{"children": [2], "matrix": [2,0,0,0, 0,2,0,0, 0,0,2,0, 0,0,0,1]}},
    {{"mesh": 0, "rotation": [0.0, 0.0, {s}, {s}], "scale": [1.0, 1.0, 0.5]}},
    {{"mesh": 0}}
  ],
  "meshes": [{{"primitives": [
    {{"attributes": {{"POSITION": 0}}, "indices": 1, "mode": 4}},
    {{"attributes": {{"POSITION": 0}}, "mode": 1}}
  ]}}],
  "buffers": [{{{uri}"byteLength": {buffer_len}}}],
  "bufferViews": [
    {{"buffer": 0, "byteOffset": 0, "byteLength": {pos_len}}},
    {{"buffer": 0, "byteOffset": {pos_len}, "byteLength": {idx_len}}}
  ],
  "accessors": [
    {{"bufferView": 0, "componentType": 5126, "count": 6, "type": "VEC3",
      "min": [-1.0, -2.0, -0.25], "max": [3.0, 3.5, 4.0]}},
    {{"bufferView": 1, "componentType": 5123, "count": {n_idx}, "type": "SCALAR"}}
  ]
}}"#,
        idx_len = n_idx * 2
    )
}

/// What the glTF document must load to: the mesh under node 2's world matrix, then the
/// mesh untransformed (node 3), with the same float operations as the loader.
fn gltf_expected() -> Vec<Triangle> {
    use glam::{Mat4, Quat};
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let world = Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0))
        * Mat4::from_scale(Vec3::splat(2.0))
        * Mat4::from_scale_rotation_translation(
            Vec3::new(1.0, 1.0, 0.5),
            Quat::from_xyzw(0.0, 0.0, s, s),
            Vec3::ZERO,
        );
    let mut out: Vec<Triangle> = expected()
        .iter()
        .map(|t| Triangle {
            v: t.v.map(|p| world.transform_point3(p)),
        })
        .collect();
    out.extend(expected());
    out
}

fn check_gltf(path: &Path) {
    let scene = load::load_file(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let want = gltf_expected();
    assert_eq!(scene.triangles.len(), want.len());
    for (k, (got, want)) in scene.triangles.iter().zip(&want).enumerate() {
        for (a, b) in got.v.iter().zip(&want.v) {
            // gltf composes TRS itself; allow one rounding step per component.
            assert!(
                (*a - *b).abs().max_element() <= 1e-5 * b.abs().max_element().max(1.0),
                "triangle {k}: {a} vs {b}"
            );
        }
    }
    // A rotation by 90° about z maps x to y: check one vertex exactly against the hand-made
    // transform p' = t + 2 * R(s * p).
    let p = verts()[1];
    let manual = Vec3::new(1.0, 2.0, 3.0) + 2.0 * Vec3::new(-p.y, p.x, 0.5 * p.z);
    assert!((scene.triangles[0].v[1] - manual).abs().max_element() < 1e-5);
    assert_eq!(scene.stats.primitives_skipped, 2);
    assert_eq!(scene.stats.source_triangles, 12);
}

#[test]
fn gltf_embedded_base64() {
    use base64::Engine;
    let (buf, pos_len, n) = gltf_buffer();
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&buf)
    );
    let json = gltf_json(Some(&uri), buf.len(), pos_len, n);
    let dir = tempfile::tempdir().unwrap();
    check_gltf(&write(dir.path(), "m.gltf", json.as_bytes()));
}

#[test]
fn gltf_external_bin() {
    let (buf, pos_len, n) = gltf_buffer();
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("sub")).unwrap();
    write(&dir.path().join("sub"), "data.bin", &buf);
    let json = gltf_json(Some("sub/data.bin"), buf.len(), pos_len, n);
    check_gltf(&write(dir.path(), "m.gltf", json.as_bytes()));
}

/// A GLB container around `json` and `bin`.
pub fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let total = 12 + 8 + j.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(bin);
    out
}

#[test]
fn glb_round_trip() {
    let (buf, pos_len, n) = gltf_buffer();
    let json = gltf_json(None, buf.len(), pos_len, n);
    let dir = tempfile::tempdir().unwrap();
    check_gltf(&write(dir.path(), "m.glb", &glb(&json, &buf)));
}

#[test]
fn parse_bytes_matches_load_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "m.ply", ascii_ply().as_bytes());
    let mesh = load::parse_bytes(&p, Format::Ply, ascii_ply().as_bytes()).unwrap();
    assert_eq!(mesh.triangles, expected());
    assert_eq!(
        load::format_of(Path::new("a/b.PLY.gz")).unwrap(),
        (Format::Ply, true)
    );
    assert_eq!(
        load::format_of(Path::new("x.glb")).unwrap(),
        (Format::Gltf, false)
    );
}

#[test]
fn shipped_scene_counts() {
    let Some(s) = dualsplit_testkit::scenes::shipped("dragon_res4.ply.gz") else {
        return;
    };
    assert_eq!(s.triangles.len(), 11_102);
    assert_eq!(s.stats.source_triangles, 11_102);
    assert_eq!(s.name, "dragon_res4");
    assert!(s.bounds.extent().min_element() > 0.0);
}
