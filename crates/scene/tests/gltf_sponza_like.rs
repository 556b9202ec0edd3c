//! A glTF with the structure of the Khronos sample Crytek Sponza (the paper's Crytek Sponza
//! as distributed): an external `.bin`, textured primitives (TEXCOORD_0, NORMAL, materials
//! whose base colour is an image), several meshes, one instanced twice, and node transforms
//! under a scaling root. The fixture (`tests/fixtures/sponza_like`, written by its
//! `make.py`) uses transforms exact in f32, so the triangles are compared bit for bit.
use dualsplit_geometry::{Triangle, Vec3};

fn fixture() -> String {
    format!(
        "{}/tests/fixtures/sponza_like/sponza_like.gltf",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// The fixture's triangles in world space, computed here from its local coordinates and
/// node transforms, in the loader's order (nodes depth-first, primitives in order).
fn expected() -> Vec<Triangle> {
    let v = |p: [f32; 3]| Vec3::from_array(p);
    let quad = |q: [[f32; 3]; 4], f: &dyn Fn(Vec3) -> Vec3| {
        let q = q.map(|p| f(v(p)));
        [[0, 2, 1], [0, 3, 2]].map(|[a, b, c]| Triangle::new(q[a], q[b], q[c]))
    };
    let wall = |f: &dyn Fn(Vec3) -> Vec3| {
        let q = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 8.0, 0.0],
            [0.0, 8.0, 0.0],
        ]
        .map(|p| f(v(p)));
        [[0, 1, 2], [0, 2, 3]].map(|[a, b, c]| Triangle::new(q[a], q[b], q[c]))
    };
    // The root scales by 0.5; each child's local transform comes first.
    let floor = |p: Vec3| 0.5 * (p + Vec3::new(-2.0, 0.0, 0.0));
    let east = |p: Vec3| 0.5 * (Vec3::new(p.z, p.y, -p.x) + Vec3::new(3.0, 0.0, 1.0));
    let west = |p: Vec3| 0.5 * (p + Vec3::new(-3.0, 0.0, 1.0));
    let mut out = Vec::new();
    out.extend(quad(
        [
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [4.0, 0.0, 2.0],
            [0.0, 0.0, 2.0],
        ],
        &floor,
    ));
    out.extend(quad(
        [
            [0.0, 0.0, 2.0],
            [4.0, 0.0, 2.0],
            [4.0, 0.0, 4.0],
            [0.0, 0.0, 4.0],
        ],
        &floor,
    ));
    out.extend(wall(&east));
    out.extend(wall(&west));
    out
}

#[test]
fn a_sponza_like_gltf_loads_every_mesh_with_its_node_transform() {
    let scene = dualsplit_scene::load(&fixture()).unwrap();
    let want = expected();
    assert_eq!(scene.triangles.len(), 8);
    for (i, (got, want)) in scene.triangles.iter().zip(&want).enumerate() {
        let bits = |t: &Triangle| t.v.map(|p| p.to_array().map(f32::to_bits));
        assert_eq!(bits(got), bits(want), "triangle {i}");
    }
    assert_eq!(scene.stats.primitives_skipped, 0);
    assert_eq!(scene.stats.non_finite, 0);
    assert_eq!(scene.name, "sponza_like");
    // The root's scale applies to every instance: the bounds are half the local ones.
    assert_eq!(scene.bounds.min, Vec3::new(-1.5, 0.0, 0.0));
    assert_eq!(scene.bounds.max, Vec3::new(1.5, 4.0, 2.0));
}

#[test]
fn the_fixture_is_textured_and_its_image_is_not_needed_to_load() {
    let text = std::fs::read_to_string(fixture()).unwrap();
    for key in [
        "\"TEXCOORD_0\"",
        "\"baseColorTexture\"",
        "\"images\"",
        "brick.png",
    ] {
        assert!(text.contains(key), "the fixture lost {key}");
    }
    // Only geometry is read: a copy without the image still loads the same triangles.
    let dir = tempfile::tempdir().unwrap();
    let src = std::path::Path::new(&fixture())
        .parent()
        .unwrap()
        .to_path_buf();
    for f in ["sponza_like.gltf", "sponza_like.bin"] {
        std::fs::copy(src.join(f), dir.path().join(f)).unwrap();
    }
    let copy =
        dualsplit_scene::load(dir.path().join("sponza_like.gltf").to_str().unwrap()).unwrap();
    assert_eq!(
        copy.triangles,
        dualsplit_scene::load(&fixture()).unwrap().triangles
    );
    // Without its .bin it is an error naming the buffer's file.
    std::fs::remove_file(dir.path().join("sponza_like.bin")).unwrap();
    let e = dualsplit_scene::load(dir.path().join("sponza_like.gltf").to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("sponza_like.bin"), "{e}");
}
