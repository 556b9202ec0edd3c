//! No input panics: random bytes, random truncations and random byte flips of valid files,
//! fed to every parser. Each case must return `Ok` or a `SceneError`. Scenes with
//! coordinates anywhere in the finite f32 range either load with finite cameras and lights
//! or are refused for their extent.

use dualsplit_scene::load::{self, Format};
use dualsplit_scene::{Camera, Light, Scene, SceneError};
use proptest::prelude::*;
use std::path::Path;

/// Small valid files, one per parser path.
fn seeds() -> Vec<(Format, Vec<u8>)> {
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n4 0 1 3 2\n"
        .to_vec();
    let mut bin = b"ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty double z\n\
property float x\nproperty list uchar short extra\nproperty float y\nelement face 2\n\
property list ushort uint vertex_indices\nend_header\n"
        .to_vec();
    for k in 0..4u8 {
        bin.extend_from_slice(&(k as f64).to_be_bytes());
        bin.extend_from_slice(&(k as f32).to_be_bytes());
        bin.push(1);
        bin.extend_from_slice(&7i16.to_be_bytes());
        bin.extend_from_slice(&((k * 2) as f32).to_be_bytes());
    }
    for f in [&[0u32, 1, 2][..], &[0, 1, 3, 2]] {
        bin.extend_from_slice(&(f.len() as u16).to_be_bytes());
        for i in f {
            bin.extend_from_slice(&i.to_be_bytes());
        }
    }
    let mut plain = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
        .to_vec();
    for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        plain.extend_from_slice(&c.to_le_bytes());
    }
    plain.push(3);
    for i in [0u32, 1, 2] {
        plain.extend_from_slice(&i.to_le_bytes());
    }
    let obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf -4 -3 -1 -2\n".to_vec();
    let gltf = br#"{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],
"nodes":[{"mesh":0,"translation":[1,2,3]}],
"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
"buffers":[{"uri":"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAABAAIAAAA=","byteLength":44}],
"bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":6}],
"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},
{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}]}"#
        .to_vec();
    vec![
        (Format::Ply, ascii),
        (Format::Ply, bin),
        (Format::Ply, plain),
        (Format::Obj, obj),
        (Format::Gltf, gltf),
    ]
}

#[test]
fn seeds_are_valid() {
    for (f, bytes) in seeds() {
        let m = load::parse_bytes(Path::new("seed"), f, &bytes).unwrap();
        assert!(!m.triangles.is_empty(), "{f:?}");
    }
}

fn format() -> impl Strategy<Value = Format> {
    prop_oneof![Just(Format::Obj), Just(Format::Ply), Just(Format::Gltf)]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2048, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(f in format(), bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        let _ = load::parse_bytes(Path::new("random"), f, &bytes);
    }

    #[test]
    fn truncations_never_panic(seed in 0usize..5, cut in any::<prop::sample::Index>()) {
        let (f, bytes) = &seeds()[seed];
        let n = cut.index(bytes.len() + 1);
        let _ = load::parse_bytes(Path::new("cut"), *f, &bytes[..n]);
    }

    #[test]
    fn flips_never_panic(
        seed in 0usize..5,
        flips in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
    ) {
        let (f, mut bytes) = seeds().swap_remove(seed);
        for (at, v) in flips {
            let i = at.index(bytes.len());
            bytes[i] = v;
        }
        let _ = load::parse_bytes(Path::new("flip"), f, &bytes);
    }

    #[test]
    fn gzip_garbage_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..256)) {
        let mut b = vec![0x1f, 0x8b];
        b.extend(bytes);
        let _ = load::maybe_gunzip(Path::new("x.ply.gz"), b);
    }
}

/// A coordinate for the extreme-range scenes. With `wide`: anywhere in the finite f32 range
/// (any sign, exponent and mantissa, zero and subnormals included), the ends of the range,
/// values around the extent limit, or an ordinary small value. Without: the same kinds of
/// values held within ±`Scene::MAX_EXTENT / 2`, so the scene is at most the limit wide.
fn extreme_coordinate(wide: bool) -> BoxedStrategy<f32> {
    let half = Scene::MAX_EXTENT / 2.0;
    // Exponent fields up to 185 give magnitudes below 2^59 = half.
    let top = if wide { 255 } else { 186 };
    let ends = if wide {
        vec![f32::MAX, -f32::MAX, 3e38, -3e38, half, -half]
    } else {
        vec![half, -half, f32::MIN_POSITIVE, 0.0]
    };
    let reach = if wide { 1.01f32 } else { 1.0 };
    prop_oneof![
        (any::<bool>(), 0u32..top, 0u32..1 << 23)
            .prop_map(|(neg, e, m)| f32::from_bits(u32::from(neg) << 31 | e << 23 | m)),
        prop::sample::select(ends),
        (-reach..reach).prop_map(move |f| f * half),
        -4.0f32..4.0,
    ]
    .boxed()
}

/// The extreme-range scene generator: whether it may be wider than the limit, and an OBJ
/// file of 1 to 12 triangles whose vertices come from [`extreme_coordinate`], written in
/// shortest round-trip form.
fn extreme_obj() -> impl Strategy<Value = (bool, String)> {
    any::<bool>().prop_flat_map(|wide| {
        let c = || extreme_coordinate(wide);
        prop::collection::vec([c(), c(), c()], 3..36).prop_map(move |vs| {
            let mut obj = String::new();
            for [x, y, z] in &vs {
                obj += &format!("v {x} {y} {z}\n");
            }
            for i in 0..vs.len() / 3 {
                obj += &format!("f {} {} {}\n", 3 * i + 1, 3 * i + 2, 3 * i + 3);
            }
            (wide, obj)
        })
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    /// A scene at most [`Scene::MAX_EXTENT`] wide and within ±[`Scene::MAX_COORDINATE`]
    /// loads, and every camera and light placed on it (the fit and each file preset) is
    /// finite; a wider one is [`SceneError::Extent`], naming an extent beyond the limit, and
    /// a narrow one reaching farther is [`SceneError::Far`].
    #[test]
    fn extreme_coordinates_load_with_finite_views_or_name_the_extent((may_be_wide, obj) in extreme_obj()) {
        let mesh = load::parse_bytes(Path::new("x.obj"), Format::Obj, obj.as_bytes()).unwrap();
        let bounds = mesh
            .triangles
            .iter()
            .fold(dualsplit_geometry::Aabb::EMPTY, |b, t| b.union(t.bounds()));
        let wide = !(bounds.max - bounds.min).cmple(dualsplit_geometry::Vec3::splat(Scene::MAX_EXTENT)).all();
        let reach = bounds.min.abs().max(bounds.max.abs());
        let far = !reach.cmple(dualsplit_geometry::Vec3::splat(Scene::MAX_COORDINATE)).all();
        prop_assert!(may_be_wide || !(wide || far), "{bounds:?}");
        match Scene::from_triangles("x", "x.obj", mesh.triangles, mesh.stats) {
            Ok(scene) => {
                prop_assert!(!wide && !far, "{:?} loaded", scene.bounds);
                for stem in ["x", "dragon", "bunny", "dragon_box", "sponza_dabrovic", "dragon_sponza"] {
                    let c = Camera::preset_for(stem, &scene.bounds);
                    prop_assert!(c.eye.is_finite() && c.target.is_finite(), "{stem}: {c:?}");
                    prop_assert!((c.target - c.eye).length().is_finite(), "{stem}: {c:?}");
                    let l = Light::preset_for(stem, &scene.bounds);
                    prop_assert!(l.position.is_finite() && l.radius.is_finite(), "{stem}: {l:?}");
                }
            }
            Err(SceneError::Extent { extent, limit, .. }) => {
                prop_assert!(wide);
                prop_assert!(extent.iter().any(|&e| e > limit), "{extent:?}");
            }
            Err(SceneError::Far { min, max, limit, .. }) => {
                prop_assert!(far && !wide);
                prop_assert!(min.iter().chain(&max).any(|&c| c.abs() > limit), "{min:?} {max:?}");
            }
            Err(e) => prop_assert!(false, "{e}"),
        }
    }
}
