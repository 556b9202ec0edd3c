//! No input panics: random bytes, random truncations and random byte flips of valid files,
//! fed to every parser. Each case must return `Ok` or a `SceneError`.

use dualsplit_scene::load::{self, Format};
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
