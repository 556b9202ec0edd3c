//! Hostile input: glTF buffers outside the scene's folder, node graphs that recurse or
//! explode, files that never end, and budgets. Each case ends in a typed error or a correct
//! result, quickly and within the budgets.

use dualsplit_geometry::{Triangle, Vec3};
use dualsplit_scene::limits::Budget;
use dualsplit_scene::load::{self, Format};
use dualsplit_scene::{Limits, LoadStats, Scene, SceneError};
use std::io::Write;
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// 3 vertices of one triangle, as 36 little-endian bytes.
fn triangle_bytes() -> Vec<u8> {
    [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|c| c.to_le_bytes())
        .collect()
}

/// A glTF document with one triangle mesh read from buffer `uri`, and the given nodes and
/// scene roots (JSON arrays).
fn gltf(uri: &str, nodes: &str, roots: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scenes":[{{"nodes":{roots}}}],"nodes":{nodes},
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "buffers":[{{"uri":"{uri}","byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
          "min":[0,0,0],"max":[1,1,0]}}]}}"#
    )
}

/// A glTF whose only node shows the mesh read from `uri`.
fn gltf_with_uri(uri: &str) -> String {
    gltf(uri, r#"[{"mesh":0}]"#, "[0]")
}

/// Expects an [`SceneError::ExternalUri`] for `uri`, with `reason` in its message.
fn expect_uri_refused(e: SceneError, uri: &str, reason: &str) {
    match &e {
        SceneError::ExternalUri { uri: u, .. } => assert_eq!(u, uri, "{e}"),
        other => panic!("expected ExternalUri for {uri}, got {other:?}"),
    }
    let msg = e.to_string();
    assert!(msg.contains(uri) && msg.contains(reason), "{msg}");
}

#[test]
fn gltf_buffers_inside_the_folder_load() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("sub dir")).unwrap();
    write(dir.path(), "sub dir/tri.bin", &triangle_bytes());
    for uri in [
        "sub%20dir/tri.bin",
        "./sub dir/tri.bin",
        "sub%20dir/./tri.bin",
    ] {
        let p = write(dir.path(), "ok.gltf", gltf_with_uri(uri).as_bytes());
        let s = load::load_file(&p).unwrap_or_else(|e| panic!("{uri}: {e}"));
        assert_eq!(s.triangles.len(), 1, "{uri}");
        assert_eq!(s.triangles[0].v[1].x, 1.0);
    }
}

#[test]
fn gltf_uris_out_of_the_folder_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene_dir = dir.path().join("scene");
    std::fs::create_dir(&scene_dir).unwrap();
    // A file next to the scene's folder, which a `..` would reach.
    write(dir.path(), "secret.bin", &triangle_bytes());
    let cases = [
        ("../../../../etc/passwd", "no `..`"),
        ("../secret.bin", "no `..`"),
        ("%2e%2e/secret.bin", "no `..`"),
        ("sub/../../secret.bin", "no `..`"),
        ("/etc/passwd", "not absolute"),
        ("%2fetc%2fpasswd", "not absolute"),
        ("/dev/zero", "not absolute"),
        ("file:///etc/passwd", "no scheme"),
        ("http://example.invalid/x.bin", "no scheme"),
        ("..\\\\secret.bin", "backslashes"),
        ("a%00b", "NUL"),
        ("%zz", "percent-encoding"),
        ("%ff%fe", "percent-encoding"),
        ("", "empty"),
    ];
    for (uri, reason) in cases {
        let p = write(&scene_dir, "s.gltf", gltf_with_uri(uri).as_bytes());
        let e = load::load_file(&p).unwrap_err();
        let shown = uri.replace("\\\\", "\\");
        expect_uri_refused(e, &shown, reason);
    }
}

#[cfg(unix)]
#[test]
fn gltf_links_out_of_the_folder_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene_dir = dir.path().join("scene");
    std::fs::create_dir(&scene_dir).unwrap();
    let secret = write(dir.path(), "secret.bin", &triangle_bytes());
    std::os::unix::fs::symlink(&secret, scene_dir.join("link.bin")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", scene_dir.join("zero.bin")).unwrap();
    for uri in ["link.bin", "zero.bin"] {
        let p = write(&scene_dir, "s.gltf", gltf_with_uri(uri).as_bytes());
        expect_uri_refused(
            load::load_file(&p).unwrap_err(),
            uri,
            "outside the scene file's folder",
        );
    }
    // A link that stays inside the folder is fine.
    write(&scene_dir, "real.bin", &triangle_bytes());
    std::os::unix::fs::symlink("real.bin", scene_dir.join("inner.bin")).unwrap();
    let p = write(&scene_dir, "s.gltf", gltf_with_uri("inner.bin").as_bytes());
    assert_eq!(load::load_file(&p).unwrap().triangles.len(), 1);
}

#[cfg(unix)]
#[test]
fn gltf_buffers_that_are_not_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("folder.bin")).unwrap();
    mkfifo(&dir.path().join("pipe.bin"));
    for (uri, kind) in [("folder.bin", "directory"), ("pipe.bin", "named pipe")] {
        let p = write(dir.path(), "s.gltf", gltf_with_uri(uri).as_bytes());
        match load::load_file(&p).unwrap_err() {
            SceneError::NotAFile { path, kind: k } => {
                assert!(path.ends_with(uri) && k.contains(kind), "{path:?} {k}");
            }
            other => panic!("{uri}: {other:?}"),
        }
    }
}

#[test]
fn a_deep_node_chain_loads_without_recursion() {
    // 20,000 nodes, each the only child of the one before; the last one shows the mesh,
    // moved by every ancestor's translation.
    let n = 20_000;
    let mut nodes: Vec<String> = (0..n - 1)
        .map(|i| format!(r#"{{"children":[{}],"translation":[1,0,0]}}"#, i + 1))
        .collect();
    nodes.push(r#"{"mesh":0}"#.into());
    let json = gltf(
        &data_uri(&triangle_bytes()),
        &format!("[{}]", nodes.join(",")),
        "[0]",
    );
    let dir = tempfile::tempdir().unwrap();
    let s = load::load_file(&write(dir.path(), "chain.gltf", json.as_bytes())).unwrap();
    assert_eq!(s.triangles.len(), 1);
    assert_eq!(s.triangles[0].v[0].x, (n - 1) as f32);
}

#[test]
fn nodes_reached_twice_are_an_error() {
    let data = data_uri(&triangle_bytes());
    // 40 nodes, each listing its child twice: 2^39 instances if it were walked.
    let n = 40;
    let mut nodes: Vec<String> = (0..n - 1)
        .map(|i| format!(r#"{{"children":[{0},{0}]}}"#, i + 1))
        .collect();
    nodes.push(r#"{"mesh":0}"#.into());
    let twice = gltf(&data, &format!("[{}]", nodes.join(",")), "[0]");
    // A cycle, a root listed twice, a root that is also a child, two parents.
    let cycle = gltf(
        &data,
        r#"[{"children":[1]},{"children":[0],"mesh":0}]"#,
        "[0]",
    );
    let root_twice = gltf(&data, r#"[{"mesh":0}]"#, "[0,0]");
    let root_child = gltf(&data, r#"[{"children":[1]},{"mesh":0}]"#, "[0,1]");
    let two_parents = gltf(
        &data,
        r#"[{"children":[2]},{"children":[2]},{"mesh":0}]"#,
        "[0,1]",
    );
    let dir = tempfile::tempdir().unwrap();
    for (name, json) in [
        ("twice", twice),
        ("cycle", cycle),
        ("root_twice", root_twice),
        ("root_child", root_child),
        ("two_parents", two_parents),
    ] {
        let p = write(dir.path(), &format!("{name}.gltf"), json.as_bytes());
        let e = load::load_file(&p).unwrap_err();
        assert!(
            matches!(&e, SceneError::Parse { message, .. } if message.contains("reached twice")),
            "{name}: {e:?}"
        );
    }
}

#[test]
fn instancing_counts_against_the_triangle_budget() {
    // 1,000 sibling nodes showing the same one-triangle mesh.
    let nodes: Vec<String> = (0..1000)
        .map(|i| format!(r#"{{"mesh":0,"translation":[{i},0,0]}}"#))
        .collect();
    let roots: Vec<String> = (0..1000).map(|i| i.to_string()).collect();
    let json = gltf(
        &data_uri(&triangle_bytes()),
        &format!("[{}]", nodes.join(",")),
        &format!("[{}]", roots.join(",")),
    );
    let p = Path::new("inst.gltf");
    let m = load::parse_bytes(p, Format::Gltf, json.as_bytes()).unwrap();
    assert_eq!(m.triangles.len(), 1000);
    let small = Limits {
        max_triangles: 999,
        ..Limits::default()
    };
    let e = load::parse_bytes_with(p, Format::Gltf, json.as_bytes(), &small).unwrap_err();
    expect_limit(&e, Budget::Triangles, 999);
}

#[test]
fn gzip_bombs_stop_at_the_byte_budget() {
    // 64 MiB of zeros compress to about 64 KiB.
    let mut z = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    let zeros = vec![0u8; 1 << 20];
    for _ in 0..64 {
        z.write_all(&zeros).unwrap();
    }
    let z = z.finish().unwrap();
    assert!(z.len() < 1 << 20);
    let dir = tempfile::tempdir().unwrap();
    let p = write(dir.path(), "bomb.ply.gz", &z);
    let limits = Limits {
        max_bytes: 8 << 20,
        ..Limits::default()
    };
    let e = load::load_file_with(&p, &limits).unwrap_err();
    expect_limit(&e, Budget::Bytes, 8 << 20);
    assert!(e.to_string().contains("--max-scene-bytes"), "{e}");
    // The same file within a big enough budget inflates and fails as PLY.
    let big = Limits {
        max_bytes: 65 << 20,
        ..Limits::default()
    };
    let e = load::load_file_with(&p, &big).unwrap_err();
    assert!(matches!(e, SceneError::Parse { .. }), "{e:?}");
}

#[test]
fn plain_files_count_against_the_byte_budget() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let p = write(dir.path(), "t.obj", obj.as_bytes());
    let exact = Limits {
        max_bytes: obj.len() as u64,
        ..Limits::default()
    };
    assert_eq!(load::load_file_with(&p, &exact).unwrap().triangles.len(), 1);
    let short = Limits {
        max_bytes: obj.len() as u64 - 1,
        ..Limits::default()
    };
    expect_limit(
        &load::load_file_with(&p, &short).unwrap_err(),
        Budget::Bytes,
        obj.len() as u64 - 1,
    );
    // External glTF buffers share the budget with the file.
    write(dir.path(), "tri.bin", &triangle_bytes());
    let json = gltf_with_uri("tri.bin");
    let p = write(dir.path(), "s.gltf", json.as_bytes());
    let exact = Limits {
        max_bytes: json.len() as u64 + 36,
        ..Limits::default()
    };
    assert_eq!(load::load_file_with(&p, &exact).unwrap().triangles.len(), 1);
    let short = Limits {
        max_bytes: json.len() as u64 + 35,
        ..Limits::default()
    };
    expect_limit(
        &load::load_file_with(&p, &short).unwrap_err(),
        Budget::Bytes,
        json.len() as u64 + 35,
    );
}

#[test]
fn every_format_checks_the_triangle_budget() {
    let one = Limits {
        max_triangles: 1,
        ..Limits::default()
    };
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3 4\n";
    let ascii = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0\n1 0 0\n0 1 0\n1 1 0\n4 0 1 3 2\n";
    let mut bin = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\nelement face 2\nproperty list uchar uint vertex_indices\n\
end_header\n"
        .to_vec();
    bin.extend(triangle_bytes());
    let face: Vec<u8> = std::iter::once(3u8)
        .chain([0u32, 1, 2].iter().flat_map(|i| i.to_le_bytes()))
        .collect();
    bin.extend(face.repeat(2));
    for (format, bytes) in [
        (Format::Obj, obj.as_bytes()),
        (Format::Ply, ascii.as_bytes()),
        (Format::Ply, &bin[..]),
    ] {
        let p = Path::new("x");
        assert_eq!(
            load::parse_bytes(p, format, bytes).unwrap().triangles.len(),
            2
        );
        let e = load::parse_bytes_with(p, format, bytes, &one).unwrap_err();
        expect_limit(&e, Budget::Triangles, 1);
    }
    // Builtins are checked before they are generated.
    let e = dualsplit_scene::load_with("builtin:hairball?triangles=5000", &one).unwrap_err();
    expect_limit(&e, Budget::Triangles, 1);
    assert!(e.to_string().contains("--max-triangles"), "{e}");
}

#[cfg(unix)]
#[test]
fn special_files_are_refused_without_reading() {
    let dir = tempfile::tempdir().unwrap();
    let zero = dir.path().join("zero.ply");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let pipe = dir.path().join("pipe.obj");
    mkfifo(&pipe);
    let folder = dir.path().join("folder.ply");
    std::fs::create_dir(&folder).unwrap();
    for (p, kind) in [
        (&zero, "character device"),
        (&pipe, "named pipe"),
        (&folder, "directory"),
    ] {
        match load::load_file(p).unwrap_err() {
            SceneError::NotAFile { path, kind: k } => {
                assert_eq!(&path, p);
                assert!(k.contains(kind), "{k}");
            }
            other => panic!("{}: {other:?}", p.display()),
        }
    }
}

/// Expects a [`SceneError::Limit`] on `what` at `limit`.
fn expect_limit(e: &SceneError, what: Budget, limit: u64) {
    match e {
        SceneError::Limit {
            what: w, limit: l, ..
        } => {
            assert_eq!((*w, *l), (what, limit), "{e}");
        }
        other => panic!("expected a {what:?} limit, got {other:?}"),
    }
    assert!(e.to_string().contains(&limit.to_string()), "{e}");
}

/// A base64 `data:` URI of `bytes`.
fn data_uri(bytes: &[u8]) -> String {
    use base64::Engine;
    format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// Makes a named pipe at `p` (with the system's `mkfifo`).
#[cfg(unix)]
fn mkfifo(p: &Path) {
    let ok = std::process::Command::new("mkfifo")
        .arg(p)
        .status()
        .unwrap()
        .success();
    assert!(ok, "mkfifo {}", p.display());
}

#[test]
fn the_fuzz_seeds_are_valid_scenes() {
    // The seeds in fuzz/seeds start the fuzzers on every parser path; each must parse.
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds");
    let mut n = 0;
    for (dir, format) in [
        ("ply", Format::Ply),
        ("obj", Format::Obj),
        ("gltf", Format::Gltf),
        ("gzip", Format::Ply),
    ] {
        for entry in std::fs::read_dir(seeds.join(dir)).unwrap() {
            let p = entry.unwrap().path();
            if p.file_name().is_some_and(|f| f == "external.gltf") {
                continue; // its buffer file is out of reach: it seeds the error path
            }
            let raw = std::fs::read(&p).unwrap();
            let bytes = load::maybe_gunzip(&p, raw).unwrap();
            let m = load::parse_bytes(&p, format, &bytes)
                .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            assert!(!m.triangles.is_empty(), "{}", p.display());
            n += 1;
        }
    }
    assert_eq!(n, 12);
}

#[test]
fn the_extreme_coordinate_seeds_load_or_name_their_extent() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz/seeds/obj");
    // Coordinates at ±3e38: the extent overflows to +∞.
    let e = dualsplit_scene::load(seeds.join("extreme.obj").to_str().unwrap()).unwrap_err();
    assert!(
        matches!(&e, SceneError::Extent { extent, .. } if extent.iter().all(|x| x.is_infinite())),
        "{e:?}"
    );
    assert!(
        e.to_string()
            .contains("extent (inf, inf, inf) exceeds 1.1529215e18"),
        "{e}"
    );
    // ±5.7e17: just under the limit, with a finite fitted camera.
    let s = dualsplit_scene::load(seeds.join("at_extent_limit.obj").to_str().unwrap()).unwrap();
    assert!((s.bounds.max - s.bounds.min).max_element() <= dualsplit_scene::Scene::MAX_EXTENT);
    assert!(s.camera.eye.is_finite() && s.light.position.is_finite());
    // A single point at (3e38, −3e38, −3e38): no extent, but its centre would overflow.
    let e = dualsplit_scene::load(seeds.join("far_point.obj").to_str().unwrap()).unwrap_err();
    assert!(matches!(&e, SceneError::Far { .. }), "{e:?}");
    assert!(e.to_string().contains("reach beyond ±1.1529215e18"), "{e}");
}

#[test]
fn a_small_scene_far_from_the_origin_is_refused_by_its_reach() {
    let at = |x: f32| {
        Triangle::new(
            Vec3::new(x, 0.0, 0.0),
            Vec3::new(x, 1.0, 0.0),
            Vec3::new(x, 0.0, 1.0),
        )
    };
    let limit = dualsplit_scene::Scene::MAX_COORDINATE;
    for x in [limit * 2.0, -1e30, 3e38] {
        let e =
            Scene::from_triangles("far", "far.obj", vec![at(x)], LoadStats::default()).unwrap_err();
        assert!(
            matches!(&e, SceneError::Far { limit: l, .. } if *l == limit),
            "{x}: {e:?}"
        );
    }
    // At the limit itself it loads, with a finite camera and light.
    let s =
        Scene::from_triangles("near", "near.obj", vec![at(-limit)], LoadStats::default()).unwrap();
    assert!(
        s.camera.eye.is_finite() && s.camera.target.is_finite() && s.light.position.is_finite()
    );
}
