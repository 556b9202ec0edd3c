//! Malformed input: every case ends in a typed [`SceneError`] naming the file (and the line
//! for line-based formats), never a panic. Bad files are generated in a temp dir.

use dualsplit_scene::{SceneError, load};
use std::io::Write;
use std::path::{Path, PathBuf};

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

/// Loads `bytes` as file `name` and returns the error, checking that its message names the
/// file.
fn fail(name: &str, bytes: &[u8]) -> SceneError {
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), name, bytes);
    let e = match load::load_file(&p) {
        Ok(s) => panic!("{name} loaded {} triangles", s.triangles.len()),
        Err(e) => e,
    };
    assert!(
        e.to_string().contains(&p.display().to_string()),
        "message does not name the file: {e}"
    );
    e
}

/// Expects a `Parse` error at `line` whose message contains `needle`.
fn expect_parse(e: &SceneError, line: Option<u64>, needle: &str) {
    match e {
        SceneError::Parse {
            line: l, message, ..
        } => {
            assert_eq!(*l, line, "line of {e}");
            assert!(message.contains(needle), "`{message}` lacks `{needle}`");
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
    if let Some(l) = line {
        assert!(e.to_string().contains(&format!(":{l}: ")), "{e}");
    }
}

const PLY_HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

fn bin_header(nv: &str, nf: &str) -> String {
    format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {nv}\nproperty float x\n\
         property float y\nproperty float z\nelement face {nf}\n\
         property list uchar uint vertex_indices\nend_header\n"
    )
}

fn bin_body() -> Vec<u8> {
    let mut b = Vec::new();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        b.extend_from_slice(&c.to_le_bytes());
    }
    b.push(3);
    for i in [0u32, 1, 2] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

#[test]
fn missing_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("nope.ply");
    let e = load::load_file(&p).unwrap_err();
    assert!(
        matches!(&e, SceneError::Io { path, .. } if path == &p),
        "{e:?}"
    );
    assert!(e.to_string().contains("nope.ply"));
}

#[test]
fn unknown_extension() {
    for name in ["mesh.stl", "mesh", "mesh.gz", "mesh.gltf.gz", "mesh.txt.gz"] {
        let e = fail(name, b"solid x\n");
        assert!(
            matches!(e, SceneError::UnknownFormat { .. }),
            "{name}: {e:?}"
        );
    }
}

#[test]
fn empty_files() {
    for name in ["e.obj", "e.ply", "e.gltf", "e.glb", "e.obj.gz", "e.ply.gz"] {
        let e = fail(name, b"");
        match name {
            // An empty OBJ is valid text with no faces.
            "e.obj" => assert!(matches!(e, SceneError::Empty { .. }), "{name}: {e:?}"),
            _ => assert!(matches!(e, SceneError::Parse { .. }), "{name}: {e:?}"),
        }
    }
    // A gzip of nothing is an empty OBJ / PLY inside.
    assert!(matches!(
        fail("z.obj.gz", &gzip(b"")),
        SceneError::Empty { .. }
    ));
    assert!(matches!(
        fail("z.ply.gz", &gzip(b"")),
        SceneError::Parse { .. }
    ));
}

#[test]
fn ply_wrong_header() {
    expect_parse(&fail("a.ply", b"plx\nformat ascii 1.0\n"), Some(1), "magic");
    let e = fail(
        "b.ply",
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty flot x\nend_header\n",
    );
    expect_parse(&e, Some(4), "parse");
    let e = fail("c.ply", b"ply\nformat ascii 1.0\nelement vertex 3\n");
    assert!(matches!(e, SceneError::Parse { .. }), "{e:?}");
    // No face element (a point cloud).
    let e = fail(
        "d.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n",
    );
    expect_parse(&e, None, "face");
    // Missing z.
    let e = fail(
        "e.ply",
        b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n0 0\n",
    );
    expect_parse(&e, None, "`z`");
}

#[test]
fn ply_negative_and_huge_counts() {
    let e = fail(
        "neg.ply",
        format!("{}{}", bin_header("-3", "1"), "").as_bytes(),
    );
    expect_parse(&e, Some(3), "");
    // Huge counts are checked against the bytes present before anything is allocated.
    let mut b = bin_header("3", "4000000000000").into_bytes();
    b.extend(bin_body());
    expect_parse(&fail("huge.ply", &b), None, "truncated");
    let mut b = bin_header("18446744073709551615", "1").into_bytes();
    b.extend(bin_body());
    assert!(matches!(fail("huge2.ply", &b), SceneError::Parse { .. }));
    // ASCII: a huge count runs out of lines.
    let text = PLY_HEAD.replace("element face 1", "element face 999999999999")
        + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let e = fail("huge.ply", text.as_bytes());
    expect_parse(&e, Some(14), "end of file");
}

#[test]
fn ply_truncated_binary() {
    let mut b = bin_header("3", "1").into_bytes();
    let body = bin_body();
    let full = b.len() + body.len();
    b.extend(body);
    for cut in [full - 1, full - 13, full - 20, full - 48] {
        let e = fail("t.ply", &b[..cut]);
        expect_parse(&e, None, "truncated");
    }
    // A truncated gzip stream.
    let z = gzip(&b);
    let e = fail("t.ply.gz", &z[..z.len() / 2]);
    expect_parse(&e, None, "gzip");
}

#[test]
fn ply_truncated_ascii() {
    let text = format!("{PLY_HEAD}0 0 0\n1 0 0\n");
    expect_parse(&fail("t.ply", text.as_bytes()), Some(12), "end of file");
}

#[test]
fn ply_index_out_of_range() {
    let text = format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
    expect_parse(&fail("o.ply", text.as_bytes()), Some(13), "out of range");
    let text = format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n");
    expect_parse(&fail("n.ply", text.as_bytes()), Some(13), "out of range");
    let mut b = bin_header("3", "1").into_bytes();
    let mut body = bin_body();
    let n = body.len();
    body[n - 4..].copy_from_slice(&7u32.to_le_bytes());
    b.extend(body);
    expect_parse(
        &fail("o.ply", &b),
        None,
        "face 0: vertex index 7 out of range",
    );
}

#[test]
fn ply_short_face_and_bad_tokens() {
    let text = format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n2 0 1\n");
    expect_parse(&fail("s.ply", text.as_bytes()), Some(13), "at least 3");
    let text = format!("{PLY_HEAD}0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n");
    expect_parse(&fail("g.ply", text.as_bytes()), Some(11), "");
}

#[test]
fn ply_garbage_after_header() {
    let mut b = bin_header("3", "1").into_bytes();
    b.extend_from_slice(&[0xff; 20]);
    assert!(matches!(fail("g.ply", &b), SceneError::Parse { .. }));
    // Garbage where the header should be (not UTF-8).
    let e = fail("h.ply", &[0xff, 0xfe, 0x00, 0x01, b'\n', 0x80]);
    assert!(matches!(e, SceneError::Parse { .. }), "{e:?}");
}

#[test]
fn non_finite_vertices_are_dropped_and_counted() {
    // ASCII PLY: `nan`, `inf` and `-Infinity` are read and follow the same rule.
    let head = PLY_HEAD
        .replace("vertex 3", "vertex 6")
        .replace("face 1", "face 4");
    let text = format!(
        "{head}0 0 0\n1 0 0\n0 1 0\nnan 0 0\n0 inf 0\n0 0 -Infinity\n\
         3 0 1 2\n3 0 3 2\n3 4 1 2\n3 5 1 0\n"
    );
    let dir = tempfile::tempdir().unwrap();
    let s = load::load_file(&write(dir.path(), "nan.ply", text.as_bytes())).unwrap();
    assert_eq!(s.stats.source_triangles, 4);
    assert_eq!((s.stats.non_finite, s.triangles.len()), (3, 1));
    // Binary PLY: vertices 3 (NaN) and 4 (inf); faces 1 and 2 use them.
    let mut b = bin_header("5", "4").into_bytes();
    for c in [
        0.0f32,
        0.0,
        0.0,
        1.0,
        0.0,
        0.0,
        0.0,
        1.0,
        0.0,
        f32::NAN,
        0.0,
        0.0,
        0.0,
        f32::INFINITY,
        0.0,
    ] {
        b.extend_from_slice(&c.to_le_bytes());
    }
    for f in [[0u32, 1, 2], [0, 3, 2], [4, 1, 2], [2, 1, 0]] {
        b.push(3);
        for i in f {
            b.extend_from_slice(&i.to_le_bytes());
        }
    }
    let s = load::load_file(&write(dir.path(), "nan.ply", &b)).unwrap();
    assert_eq!(s.stats.source_triangles, 4);
    assert_eq!(s.stats.non_finite, 2);
    assert_eq!(s.triangles.len(), 2);
    // Order kept: faces 0 and 3 survive, as ids 0 and 1.
    assert_eq!(s.triangles[0].v[0].x, 0.0);
    assert_eq!(
        s.triangles[1].v[0],
        dualsplit_geometry::Vec3::new(0.0, 1.0, 0.0)
    );
    // All non-finite: nothing left is an error.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n";
    assert!(matches!(
        fail("allnan.obj", obj.as_bytes()),
        SceneError::Empty { .. }
    ));
    // OBJ too.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv NaN 0 0\nf 1 2 3\nf 1 2 4\n";
    let s = load::load_file(&write(dir.path(), "nan.obj", obj.as_bytes())).unwrap();
    assert_eq!((s.stats.non_finite, s.triangles.len()), (1, 1));
}

#[test]
fn degenerate_triangles_are_kept_and_counted() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 1 1 1\n";
    let dir = tempfile::tempdir().unwrap();
    let s = load::load_file(&write(dir.path(), "deg.obj", obj.as_bytes())).unwrap();
    assert_eq!(s.triangles.len(), 3);
    assert_eq!(s.stats.degenerate, 2);
}

#[test]
fn obj_errors_name_the_line() {
    expect_parse(
        &fail("i.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n# ok\nf 1 2 4\n"),
        Some(5),
        "out of range",
    );
    expect_parse(
        &fail("z.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
        Some(4),
        "out of range",
    );
    expect_parse(
        &fail("n.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n"),
        Some(4),
        "out of range",
    );
    expect_parse(
        &fail("p.obj", b"v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n"),
        Some(2),
        "position",
    );
    expect_parse(
        &fail("f.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n"),
        Some(4),
        "face",
    );
    // Last line without a newline.
    expect_parse(
        &fail("l.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x"),
        Some(4),
        "face",
    );
    // Not UTF-8 on line 2.
    expect_parse(
        &fail("u.obj", b"v 0 0 0\nv \xff\xfe 0 0\nf 1 2 3\n"),
        Some(2),
        "UTF-8",
    );
    // The same inside gzip.
    expect_parse(
        &fail("g.obj.gz", &gzip(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")),
        Some(4),
        "out of range",
    );
}

#[test]
fn gltf_errors() {
    let e = fail("g.gltf", b"{ not json");
    expect_parse(&e, None, "glTF");
    let e = fail("g.glb", b"glTF\x02\x00\x00\x00\xff\xff\xff\xff");
    expect_parse(&e, None, "glTF");
    // An accessor that claims more data than its view holds.
    let json = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
      "buffers":[{"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAA","byteLength":12}],
      "bufferViews":[{"buffer":0,"byteLength":12}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":3000,"type":"VEC3","min":[0,0,0],"max":[0,0,0]}]}"#;
    expect_parse(
        &fail("big.gltf", json.as_bytes()),
        None,
        "outside its buffer view",
    );
    // A missing external buffer file.
    let json = json.replace(
        "data:application/octet-stream;base64,AAAAAAAAAAAAAAAA",
        "missing.bin",
    );
    let e = fail("ext.gltf", json.as_bytes());
    expect_parse(&e, None, "missing.bin");
    // Index out of range.
    let json = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
      "buffers":[{"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAABAAkA","byteLength":42}],
      "bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[0,0,0]},
                   {"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]}"#;
    expect_parse(
        &fail("idx.gltf", json.as_bytes()),
        None,
        "vertex index 9 out of range",
    );
    // POSITION names an accessor that does not exist (gltf-json's validator would index
    // out of bounds here; found by the proptest in load_fuzz.rs).
    let json = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]}"#;
    expect_parse(
        &fail("noacc.gltf", json.as_bytes()),
        None,
        "accessor 0 does not exist",
    );
    // A node cycle.
    let json = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],
      "nodes":[{"children":[1]},{"children":[0]}]}"#;
    let e = fail("cycle.gltf", json.as_bytes());
    assert!(matches!(e, SceneError::Parse { .. }), "{e:?}");
    // No triangles at all.
    let json = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[]}]}"#;
    assert!(matches!(
        fail("none.gltf", json.as_bytes()),
        SceneError::Empty { .. }
    ));
}

#[test]
fn long_bad_lines_give_short_messages() {
    // A 200 KB first line once gave a 200 KB message with a Rust Debug dump.
    let long = "x".repeat(200_000);
    let ascii_body = format!(
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 {long}\n"
    );
    for (name, bytes) in [
        ("first.ply", format!("{long}\n")),
        (
            "header.ply",
            format!("ply\nformat ascii 1.0\n{long}\nend_header\n"),
        ),
        ("body.ply", ascii_body),
        (
            "bad.obj",
            format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 {long}\n"),
        ),
    ] {
        let e = fail(name, bytes.as_bytes()).to_string();
        assert!(
            e.len() < 400,
            "{name}: a message of {} bytes: {}",
            e.len(),
            e.chars().take(400).collect::<String>()
        );
        assert!(e.contains(name), "{name}: {e}");
    }
}
