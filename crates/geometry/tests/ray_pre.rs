//! `RayPre::new` (branch-free, vector divisions) gives exactly the values of the scalar
//! definition it replaced: `inv_dir = 1 / d` per axis; `kz` the axis of the largest `|d|`
//! (x on ties with y or z, y on a tie of y and z; z when a component is NaN); `kx, ky` the
//! next two axes cyclically, swapped when `d[kz] < 0`; `Sx = d[kx] / d[kz]`,
//! `Sy = d[ky] / d[kz]`, `Sz = 1 / d[kz]`; sign bits of `d`.

use dualsplit_geometry::{Pcg32, Ray, RayPre, Vec3};

/// The scalar definition, as written before `RayPre::new` was made branch-free.
fn reference(ray: &Ray) -> RayPre {
    let d = ray.dir;
    let inv_dir = Vec3::new(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
    let neg = [
        d.x.is_sign_negative(),
        d.y.is_sign_negative(),
        d.z.is_sign_negative(),
    ];
    let a = d.abs();
    let kz = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let shear = Vec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
    RayPre {
        ray: *ray,
        inv_dir,
        neg,
        k: [kx, ky, kz],
        shear,
    }
}

/// Bits of a float, every NaN mapped to one value (NaN payloads are not part of the
/// contract).
fn bits(x: f32) -> u32 {
    if x.is_nan() { u32::MAX } else { x.to_bits() }
}

fn bits3(v: Vec3) -> [u32; 3] {
    [bits(v.x), bits(v.y), bits(v.z)]
}

#[test]
fn ray_pre_equals_the_scalar_definition() {
    let special = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        -0.5,
        1e-30,
        -1e-38,
        1e30,
        f32::MIN_POSITIVE,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
    ];
    let mut rng = Pcg32::new(21, 4);
    let component = |rng: &mut Pcg32| {
        if rng.below(3) == 0 {
            special[rng.below(special.len() as u32) as usize]
        } else {
            rng.range_f32(-2.0, 2.0)
        }
    };
    for case in 0..400_000 {
        let dir = Vec3::new(
            component(&mut rng),
            component(&mut rng),
            component(&mut rng),
        );
        let ray = Ray::new(Vec3::new(0.25, -1.0, 3.0), dir);
        let (got, want) = (RayPre::new(&ray), reference(&ray));
        assert_eq!(got.k, want.k, "case {case}: {dir:?}");
        assert_eq!(got.neg, want.neg, "case {case}: {dir:?}");
        assert_eq!(
            bits3(got.inv_dir),
            bits3(want.inv_dir),
            "case {case}: {dir:?}"
        );
        assert_eq!(bits3(got.shear), bits3(want.shear), "case {case}: {dir:?}");
    }
}
