//! The hit distance `t` of the watertight test on large triangles, against f64 references.
//!
//! `t` is computed in f64 for the ray the test's constants define (origin, axes `k`, shear
//! `Sx, Sy, Sz`: the ray registers of the simulated hardware), then rounded once. So:
//!
//! * against that ray, it is correct to the final rounding (≤ 2⁻²⁴ relative), on every
//!   triangle and at every angle;
//! * against the f32 ray `(origin, dir)` as given, the only other errors are the roundings
//!   of `Sz = 1/d[kz]` (≤ 2⁻²⁴ relative, it scales `t`) and of `Sx = d[kx]/d[kz]` and `Sy`,
//!   which tilt the ray by ≤ 2⁻²⁴ relative per component: at most
//!   `2⁻²⁴ · (|n[kx]·d[kx]| + |n[ky]·d[ky]|) / |n·d|` more. That is nothing on
//!   axis-aligned floors and walls, and grows as `1/cos` only where a tilted plane is met at
//!   a grazing angle.

use dualsplit_geometry::{Pcg32, Ray, RayPre, Triangle, Vec3};

const ULP: f64 = 1.0 / (1u64 << 24) as f64;

fn f(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// The ray parameter where `o + t·d` meets the triangle's plane, by Cramer's rule on
/// `o + t·d = v0 + b1·(v1 − v0) + b2·(v2 − v0)` in f64 (a formula the tested code does not
/// use).
fn cramer_t(tri: &Triangle, o: [f64; 3], d: [f64; 3]) -> f64 {
    let [v0, v1, v2] = tri.v.map(f);
    let row = |i: usize| [-d[i], v1[i] - v0[i], v2[i] - v0[i], o[i] - v0[i]];
    let r = [row(0), row(1), row(2)];
    let det3 = |c: [usize; 3]| {
        let m = |i: usize, j: usize| r[i][c[j]];
        m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1))
            - m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0))
            + m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0))
    };
    det3([3, 1, 2]) / det3([0, 1, 2])
}

/// `t` of the f32 ray as given.
fn reference_t(tri: &Triangle, ray: &Ray) -> f64 {
    cramer_t(tri, f(ray.origin), f(ray.dir))
}

/// `t` of the ray the test's constants define: direction `(Sx, Sy, 1)` on the axes
/// `(kx, ky, kz)`, which advances `kz` by 1 per unit, so `t = Sz · s`.
fn register_t(tri: &Triangle, pre: &RayPre) -> f64 {
    let [kx, ky, kz] = pre.k;
    let mut d = [0.0; 3];
    d[kx] = pre.shear.x as f64;
    d[ky] = pre.shear.y as f64;
    d[kz] = 1.0;
    cramer_t(tri, f(pre.ray.origin), d) * pre.shear.z as f64
}

/// The extra error the rounded shear allows against the f32 ray (module docs).
fn shear_bound(tri: &Triangle, ray: &Ray, pre: &RayPre) -> f64 {
    let n = f(tri.normal());
    let d = f(ray.dir);
    let [kx, ky, _] = pre.k;
    let nd: f64 = (0..3).map(|i| n[i] * d[i]).sum();
    ULP * ((n[kx] * d[kx]).abs() + (n[ky] * d[ky]).abs()) / nd.abs()
}

fn point_in(rng: &mut Pcg32, tri: &Triangle) -> Vec3 {
    let (mut a, mut b) = (rng.next_f32(), rng.next_f32());
    if a + b > 1.0 {
        (a, b) = (1.0 - a, 1.0 - b);
    }
    tri.v[0] + (tri.v[1] - tri.v[0]) * a + (tri.v[2] - tri.v[0]) * b
}

fn unit(rng: &mut Pcg32) -> Vec3 {
    loop {
        let v = rng.cube_point(-1.0, 1.0);
        let l = v.length();
        if l > 0.1 && l <= 1.0 {
            return v / l;
        }
    }
}

/// Rays aimed at points of large, randomly oriented triangles (sizes 10 to 10⁴), from
/// origins all around, low above the triangle's plane (a camera over a floor) and on another
/// large surface nearby (a bounce off a wall). Returns each hit's triangle, ray and `t`.
fn random_hits(seed: u64) -> Vec<(Triangle, Ray, f32)> {
    let mut rng = Pcg32::new(seed, 7);
    let mut out = Vec::new();
    for _ in 0..20_000 {
        let size = 10f32.powf(rng.range_f32(1.0, 4.0));
        let centre = unit(&mut rng) * size * rng.range_f32(0.0, 2.0);
        let tri = Triangle::new(
            centre + unit(&mut rng) * size,
            centre + unit(&mut rng) * size,
            centre + unit(&mut rng) * size,
        );
        let n = tri.normal().normalize();
        let target = point_in(&mut rng, &tri);
        let origin = match rng.below(3) {
            0 => target + unit(&mut rng) * size * rng.range_f32(0.01, 4.0),
            1 => {
                let along = (unit(&mut rng) - n * unit(&mut rng).dot(n)).normalize_or_zero();
                let height = size * 10f32.powf(rng.range_f32(-3.0, -1.0));
                target + along * size * rng.range_f32(0.1, 2.0) + n * height
            }
            _ => {
                let other =
                    point_in(&mut rng, &tri) + unit(&mut rng) * size * rng.range_f32(0.2, 1.0);
                other + n * size * 2e-5
            }
        };
        let ray = Ray::new(origin, target - origin);
        if let Some(h) = tri.intersect(&ray.precompute(), 0.0, f32::INFINITY) {
            out.push((tri, ray, h.t));
        }
    }
    out
}

fn rel(t: f32, want: f64) -> f64 {
    ((t as f64 - want) / want).abs()
}

fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

#[test]
fn t_is_the_rounded_f64_crossing_of_the_registers_ray() {
    for seed in 0..3 {
        let hits = random_hits(seed);
        assert!(hits.len() > 15_000, "seed {seed}: only {} hits", hits.len());
        for (tri, ray, t) in &hits {
            let want = register_t(tri, &ray.precompute());
            // One rounding to f32, and a little for the reference's own f64 arithmetic.
            assert!(
                rel(*t, want) <= ULP * 1.001,
                "seed {seed}: {tri:?} {ray:?}: t {t}, f64 {want}"
            );
        }
    }
}

#[test]
fn t_on_large_triangles_against_f64_is_within_the_shear_rounding() {
    for seed in 0..3 {
        let hits = random_hits(seed);
        let mut e = Vec::new();
        for (tri, ray, t) in &hits {
            let pre = ray.precompute();
            let err = rel(*t, reference_t(tri, ray));
            // The final rounding, the rounding of `Sz = 1/d[kz]` (which scales `t`), and the
            // tilt of the rounded `Sx, Sy`.
            let bound = (2.0 * ULP + shear_bound(tri, ray, &pre)) * 1.001;
            assert!(
                err <= bound,
                "seed {seed}: {tri:?} {ray:?}: {err:e} > {bound:e}"
            );
            e.push(err);
        }
        let p99 = quantile(&mut e, 0.99);
        let p999 = quantile(&mut e, 0.999);
        eprintln!(
            "seed {seed}: {} hits, p99 {p99:.2e}, p99.9 {p999:.2e}, max {:.2e}",
            e.len(),
            e.last().unwrap()
        );
        // Randomly oriented planes met at all angles, a third of them grazing on purpose:
        // the rounded shear keeps 99 % of the hits within 1e-6.
        assert!(p99 <= 1e-6, "seed {seed}: p99 {p99:e}");
    }
}

#[test]
fn t_of_large_floors_and_walls_seen_at_grazing_angles_matches_f64() {
    // A 20 000-unit room of axis-aligned floor and walls (two triangles each), eyes 1.7
    // above the floor, rays to points all over it: where the f32 formula was least accurate.
    let l = 1e4;
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let quads = [
        [p(-l, 0.0, -l), p(l, 0.0, -l), p(l, 0.0, l), p(-l, 0.0, l)],
        [
            p(-l, 0.0, -l),
            p(-l, 50.0, -l),
            p(l, 50.0, -l),
            p(l, 0.0, -l),
        ],
        [p(l, 0.0, -l), p(l, 50.0, -l), p(l, 50.0, l), p(l, 0.0, l)],
    ];
    let tris: Vec<Triangle> = quads
        .iter()
        .flat_map(|[a, b, c, d]| [Triangle::new(*a, *b, *c), Triangle::new(*a, *c, *d)])
        .collect();
    let mut rng = Pcg32::new(11, 3);
    let mut e = Vec::new();
    for _ in 0..30_000 {
        let eye = p(rng.range_f32(-l, l), 1.7, rng.range_f32(-l, l));
        let tri = &tris[rng.below(tris.len() as u32) as usize];
        let ray = Ray::new(eye, point_in(&mut rng, tri) - eye);
        if let Some(h) = tri.intersect(&ray.precompute(), 0.0, f32::INFINITY) {
            e.push(rel(h.t, reference_t(tri, &ray)));
        }
    }
    assert!(e.len() > 25_000, "{} hits", e.len());
    let p999 = quantile(&mut e, 0.999);
    let max = *e.last().unwrap();
    eprintln!("room: {} hits, p99.9 {p999:.2e}, max {max:.2e}", e.len());
    assert!(p999 <= 1e-6 && max <= 1e-6, "p99.9 {p999:e}, max {max:e}");
}
