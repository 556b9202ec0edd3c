//! The grazing-ray regression cases of the slab test, shared by the geometry tests (the
//! premise) and the DST tests (every structure finds the hit).

use dualsplit_geometry::{Ray, Triangle, Vec3};

/// Rays aimed exactly at a triangle vertex that is a corner of the triangle's box (found by
/// a seeded search): without widened exits the slab test's computed entry lands one ulp
/// above its exit while the watertight test accepts the hit (Ize 2013).
pub const GRAZING_CASES: [([[f32; 3]; 3], [u32; 3], usize); 4] = [
    (
        [[4.0, -0.0, 2.0], [4.0, 2.0, 2.0], [1.0, -1.0, 1.0]],
        [1057123824, 3226476036, 1077493544],
        2,
    ),
    (
        [[-3.0, 3.0, -0.0], [-4.0, 2.0, -1.0], [2.0, 1.0, -2.0]],
        [3217441944, 3222153514, 3228377840],
        2,
    ),
    (
        [[3.0, 2.0, -2.0], [-3.0, -1.0, -2.0], [-1.0, 0.0, -3.0]],
        [3207833408, 1076492226, 3213691328],
        1,
    ),
    (
        [[-3.0, 3.0, -1.0], [-0.0, -2.0, 2.0], [4.0, -3.0, -0.0]],
        [3227753434, 1077816614, 3173895040],
        0,
    ),
];

/// Case `i`: its triangle and the ray from its origin at the chosen vertex.
pub fn grazing_case(i: usize) -> (Triangle, Ray) {
    let (v, o, k) = GRAZING_CASES[i];
    let tri = Triangle::new(Vec3::from(v[0]), Vec3::from(v[1]), Vec3::from(v[2]));
    let o = Vec3::new(
        f32::from_bits(o[0]),
        f32::from_bits(o[1]),
        f32::from_bits(o[2]),
    );
    (tri, Ray::new(o, tri.v[k] - o))
}
