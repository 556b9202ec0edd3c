//! glTF node graphs and external buffers in a real folder: arbitrary hierarchies (cycles,
//! shared children, deep chains, repeated roots) over a one-triangle mesh whose buffer URI
//! is chosen among files inside the scene's folder, links, folders and escapes.
//!
//! Besides "no panic, abort or hang", two properties are checked: a URI that leaves the
//! scene's folder never loads, and a loaded scene has at most one triangle per node (each
//! node is reached at most once).
#![no_main]

use dualsplit_scene::Limits;
use dualsplit_scene::load;
use libfuzzer_sys::arbitrary::{self, Arbitrary};
use libfuzzer_sys::fuzz_target;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Most nodes in one document.
const MAX_NODES: usize = 64;

/// Budgets small enough that no input takes long or holds much memory.
const LIMITS: Limits = Limits {
    max_triangles: 1 << 12,
    max_bytes: 1 << 20,
};

#[derive(Arbitrary, Debug)]
struct Node {
    children: Vec<u8>,
    mesh: bool,
    translation: Option<[i8; 3]>,
}

#[derive(Arbitrary, Debug)]
enum Uri {
    /// `buf.bin`, next to the scene.
    Inside,
    /// `sub%20dir/buf.bin`.
    Sub,
    /// `inner.bin`, a link to `buf.bin`.
    LinkInside,
    /// `../outside.bin`.
    DotDot,
    /// `%2e%2e/outside.bin`.
    EncodedDotDot,
    /// The absolute path of `outside.bin`.
    Absolute,
    /// `out.bin`, a link to `../outside.bin`.
    LinkOutside,
    /// `zero.bin`, a link to `/dev/zero`.
    Zero,
    /// `folder.bin`, a folder.
    Folder,
    /// Any text.
    Text(String),
}

impl Uri {
    /// The URI as written in the document, and whether it leads out of the folder.
    fn text(&self, outside: &Path) -> (String, bool) {
        match self {
            Uri::Inside => ("buf.bin".into(), false),
            Uri::Sub => ("sub%20dir/buf.bin".into(), false),
            Uri::LinkInside => ("inner.bin".into(), false),
            Uri::DotDot => ("../outside.bin".into(), true),
            Uri::EncodedDotDot => ("%2e%2e/outside.bin".into(), true),
            Uri::Absolute => (outside.display().to_string(), true),
            Uri::LinkOutside => ("out.bin".into(), true),
            Uri::Zero => ("zero.bin".into(), true),
            Uri::Folder => ("folder.bin".into(), false),
            Uri::Text(t) => (t.clone(), false),
        }
    }
}

#[derive(Arbitrary, Debug)]
struct Input {
    nodes: Vec<Node>,
    roots: Vec<u8>,
    uri: Uri,
    /// Extra bytes after the triangle in the buffer files.
    tail: Vec<u8>,
}

/// The folder layout, made once per process: `<tmp>/scene/` holds the buffers and links,
/// `<tmp>/outside.bin` lies next to it.
fn folders() -> &'static (tempfile::TempDir, PathBuf) {
    static DIRS: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    DIRS.get_or_init(|| {
        // Memory-backed where there is one: every input rewrites three files.
        let tmp = tempfile::tempdir_in("/dev/shm")
            .or_else(|_| tempfile::tempdir())
            .expect("a temporary folder");
        let scene = tmp.path().join("scene");
        std::fs::create_dir_all(scene.join("sub dir")).unwrap();
        std::fs::create_dir_all(scene.join("folder.bin")).unwrap();
        std::fs::write(tmp.path().join("outside.bin"), triangle()).unwrap();
        #[cfg(unix)]
        {
            use std::os::unix::fs::symlink;
            symlink("buf.bin", scene.join("inner.bin")).unwrap();
            symlink("../outside.bin", scene.join("out.bin")).unwrap();
            symlink("/dev/zero", scene.join("zero.bin")).unwrap();
        }
        (tmp, scene)
    })
}

/// One triangle's 3 positions, little-endian floats.
fn triangle() -> Vec<u8> {
    [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|c| c.to_le_bytes())
        .collect()
}

fuzz_target!(|input: Input| {
    let (tmp, scene) = folders();
    let n = input.nodes.len().clamp(1, MAX_NODES);
    let mut buffer = triangle();
    buffer.extend_from_slice(&input.tail);
    std::fs::write(scene.join("buf.bin"), &buffer).unwrap();
    std::fs::write(scene.join("sub dir/buf.bin"), &buffer).unwrap();
    let nodes: Vec<String> = (0..n)
        .map(|i| {
            let node = input.nodes.get(i);
            let children: Vec<String> = node
                .map(|d| {
                    d.children
                        .iter()
                        .map(|&c| (c as usize % n).to_string())
                        .collect()
                })
                .unwrap_or_default();
            let mut fields = vec![format!(r#""children":[{}]"#, children.join(","))];
            if node.is_some_and(|d| d.mesh) {
                fields.push(r#""mesh":0"#.into());
            }
            if let Some([x, y, z]) = node.and_then(|d| d.translation) {
                fields.push(format!(r#""translation":[{x},{y},{z}]"#));
            }
            format!("{{{}}}", fields.join(","))
        })
        .collect();
    let roots: Vec<String> = input
        .roots
        .iter()
        .map(|&r| (r as usize % n).to_string())
        .collect();
    let (uri, escapes) = input.uri.text(&tmp.path().join("outside.bin"));
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[{roots}]}}],
        "nodes":[{nodes}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],
        "buffers":[{{"uri":{uri},"byteLength":36}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
          "min":[0,0,0],"max":[1,1,0]}}]}}"#,
        roots = roots.join(","),
        nodes = nodes.join(","),
        uri = serde_json::to_string(&uri).unwrap(),
    );
    let path = scene.join("scene.gltf");
    std::fs::write(&path, &json).unwrap();
    let result = load::read_mesh_with(&path, &LIMITS);
    if escapes {
        assert!(result.is_err(), "{uri} was read");
    }
    if let Ok(mesh) = result {
        // Each node is reached at most once, so at most one triangle per node.
        assert!(
            mesh.triangles.len() <= n,
            "{} triangles",
            mesh.triangles.len()
        );
    }
});
