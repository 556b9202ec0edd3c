//! Shared helpers of the DST tests: a brute-force oracle, the BVH2 reference, per-ray
//! comparison of every DST traversal, random scene generators and shipped-mesh loading.
#![allow(dead_code)]

use dualsplit_accel::dst::{Dst, DstConfig, Partitioning};
use dualsplit_accel::{AccelKind, BuildConfig, Bvh2, NoObserver, Structures};
use dualsplit_geometry::{Aabb, Hit, Pcg32, Ray, Triangle, Vec3};

/// A BVH2 over `tris` (default build), its DST and the BVH2 reference traversal.
pub struct Built {
    pub bvh: Bvh2,
    pub dst: Dst,
    pub reference: Structures,
}

pub fn build(tris: &[Triangle], cfg: &DstConfig) -> Built {
    build_with(tris, &BuildConfig::default(), cfg)
}

/// Builds every structure with `bcfg`, then converts the DST from that same BVH2.
pub fn build_with(tris: &[Triangle], bcfg: &BuildConfig, cfg: &DstConfig) -> Built {
    let reference = Structures::try_build(tris, bcfg).expect("structures");
    let bvh = reference.bvh2.clone();
    let dst = Dst::from_bvh2(&bvh, tris, cfg).expect("conversion");
    dst.validate(&bvh).expect("validate");
    Built {
        bvh,
        dst,
        reference,
    }
}

/// Brute-force closest hit: every triangle on `[t_min, t_max]`, ordered by `(t, prim)`.
pub fn oracle_closest(tris: &[Triangle], ray: &Ray) -> Option<Hit> {
    let r = ray.precompute();
    let mut best: Option<Hit> = None;
    for (p, tri) in tris.iter().enumerate() {
        if let Some(h) = tri.intersect(&r, ray.t_min, ray.t_max) {
            let p = p as u32;
            if best.is_none_or(|b| !b.closer_than(h.t, p)) {
                best = Some(Hit {
                    t: h.t,
                    prim: p,
                    u: h.u,
                    v: h.v,
                });
            }
        }
    }
    best
}

fn key(h: Option<Hit>) -> Option<(u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.prim))
}

/// Compares, for one ray, the closest hit (t bits and triangle id) and the shadow answer of
/// the DST software traversal and the pipeline loop against `expected` and each other.
pub fn check_ray(dst: &Dst, ray: &Ray, expected: Option<Hit>, what: &str) {
    let want = key(expected);
    let sw = key(dst.closest_hit(ray, &mut NoObserver));
    assert_eq!(sw, want, "{what}: software closest hit, ray {ray:?}");
    let pipe = key(dst.closest_hit_pipeline(ray, &mut NoObserver));
    assert_eq!(pipe, want, "{what}: pipeline closest hit, ray {ray:?}");
    let occluded = expected.is_some();
    assert_eq!(
        dst.any_hit(ray, &mut NoObserver),
        occluded,
        "{what}: software any hit, ray {ray:?}"
    );
    assert_eq!(
        dst.any_hit_pipeline(ray, &mut NoObserver),
        occluded,
        "{what}: pipeline any hit, ray {ray:?}"
    );
}

/// Brute-force any hit: some triangle on `[t_min, t_max]`.
pub fn oracle_any(tris: &[Triangle], ray: &Ray) -> bool {
    let r = ray.precompute();
    tris.iter()
        .any(|t| t.intersect(&r, ray.t_min, ray.t_max).is_some())
}

/// The BVH kinds checked against the oracle next to the DST.
pub const BVH_KINDS: [AccelKind; 3] = [AccelKind::Bvh2, AccelKind::Bvh4, AccelKind::Bvh8];

/// Checks one ray strictly against the brute-force oracle: BVH2, BVH4 and BVH8 (closest
/// hit t bits and triangle id, any hit), then the DST's software traversal and pipeline
/// loop ([`check_ray`]), in both partitioning modes. With exits widened by
/// `dualsplit_geometry::EXIT_WIDEN` no structure may round a grazing hit away, so there
/// is no allowance (see `docs/dst-encoding.md` §5).
pub fn check_all(b: &Built, tris: &[Triangle], ray: &Ray) {
    let oracle = oracle_closest(tris, ray);
    let any = oracle_any(tris, ray);
    assert_eq!(
        any,
        oracle.is_some(),
        "oracle any hit vs closest, ray {ray:?}"
    );
    for kind in BVH_KINDS {
        let got = b.reference.closest_hit(kind, ray, &mut NoObserver);
        assert_eq!(
            key(got),
            key(oracle),
            "{kind:?} closest hit vs oracle, ray {ray:?}"
        );
        assert_eq!(
            b.reference.any_hit(kind, ray, &mut NoObserver),
            any,
            "{kind:?} any hit vs oracle, ray {ray:?}"
        );
    }
    let what = match b.dst.config().partitioning {
        Partitioning::Identical => "identical DST vs oracle",
        Partitioning::Similar => "similar DST vs oracle",
    };
    check_ray(&b.dst, ray, oracle, what);
}

/// A point inside (or slightly outside) `b`.
pub fn point_near(rng: &mut Pcg32, b: &Aabb) -> Vec3 {
    let e = b.extent().max(Vec3::splat(1e-3));
    Vec3::new(
        rng.range_f32(b.min.x - 0.2 * e.x, b.max.x + 0.2 * e.x),
        rng.range_f32(b.min.y - 0.2 * e.y, b.max.y + 0.2 * e.y),
        rng.range_f32(b.min.z - 0.2 * e.z, b.max.z + 0.2 * e.z),
    )
}

/// Random rays aimed through the scene box, with edge cases mixed in: zero direction
/// components, origins on triangle planes and box faces, `t_min == t_max`, segments.
pub fn random_rays(rng: &mut Pcg32, tris: &[Triangle], b: &Aabb, n: usize) -> Vec<Ray> {
    let mut rays = Vec::with_capacity(n);
    for i in 0..n {
        let mut o = point_near(rng, b);
        let target = match rng.below(3) {
            0 => {
                let t = &tris[rng.below(tris.len() as u32) as usize];
                let (u, v) = (rng.next_f32(), rng.next_f32());
                let (u, v) = if u + v > 1.0 {
                    (1.0 - u, 1.0 - v)
                } else {
                    (u, v)
                };
                t.v[0] + (t.v[1] - t.v[0]) * u + (t.v[2] - t.v[0]) * v
            }
            1 => tris[rng.below(tris.len() as u32) as usize].v[rng.below(3) as usize],
            _ => point_near(rng, b),
        };
        let mut d = target - o;
        match i % 7 {
            // Zero one or two direction components (axis-parallel rays).
            1 => d[rng.below(3) as usize] = 0.0,
            2 => {
                let k = rng.below(3) as usize;
                d[(k + 1) % 3] = 0.0;
                d[(k + 2) % 3] = -0.0;
            }
            // Origin on a box face / on a vertex's coordinate plane.
            3 => {
                let a = rng.below(3) as usize;
                o[a] = if rng.below(2) == 0 {
                    b.min[a]
                } else {
                    b.max[a]
                };
                d = target - o;
            }
            4 => {
                let a = rng.below(3) as usize;
                o[a] = tris[rng.below(tris.len() as u32) as usize].v[0][a];
                d = target - o;
                if rng.below(2) == 0 {
                    d[a] = 0.0;
                }
            }
            _ => {}
        }
        if d == Vec3::ZERO {
            d = Vec3::new(0.0, 0.0, 1.0);
        }
        let mut ray = Ray::new(o, d);
        match i % 5 {
            1 => {
                ray.t_max = rng.range_f32(0.0, 1.5);
            }
            2 => {
                let t = rng.range_f32(0.0, 1.2);
                ray.t_min = t;
                ray.t_max = t; // t_min == t_max
            }
            3 => {
                ray.t_min = rng.range_f32(0.0, 0.8);
            }
            _ => {}
        }
        rays.push(ray);
    }
    rays
}

/// Loads a shipped mesh (`shared/scenes/NAME`) through the project's scene loader.
pub fn load_shipped(name: &str) -> Vec<Triangle> {
    let path = format!(
        "{}/../../../shared/scenes/{name}",
        env!("CARGO_MANIFEST_DIR")
    );
    dualsplit_scene::load(&path)
        .unwrap_or_else(|e| panic!("{path}: {e}"))
        .triangles
}
