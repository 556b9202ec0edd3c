//! Rays for tests and benchmarks: the rays the renderer's path-tracing jobs generate, and
//! random rays aimed through a scene with its edge cases mixed in.

use dualsplit_accel::{AccelKind, NoObserver, Structures};
use dualsplit_geometry::{Aabb, Pcg32, Ray, Triangle, Vec3};
use dualsplit_render::{PixelJob, RayKind, RenderSettings, TraceResult, Workload};
use dualsplit_scene::Scene;

/// Rays of each kind recorded from path-traced pixel jobs (5 bounces, a shadow ray at every
/// hit), driven by the BVH2's answers.
#[derive(Default)]
pub struct RaySets {
    /// Camera rays.
    pub primary: Vec<Ray>,
    /// Shadow rays (any hit).
    pub shadow: Vec<Ray>,
    /// Diffuse bounce rays.
    pub diffuse: Vec<Ray>,
}

/// Records at least `n` rays of each kind (up to a cap of passes), `side × side` pixels per
/// pass, a new seed each pass.
pub fn record_rays(scene: &Scene, s: &Structures, side: u32, n: usize) -> RaySets {
    let mut out = RaySets::default();
    for pass in 0..16u32 {
        if out.primary.len() >= n && out.shadow.len() >= n && out.diffuse.len() >= n {
            break;
        }
        let mut settings = RenderSettings::new(side, side, Workload::Path);
        settings.seed = pass;
        for y in 0..side {
            for x in 0..side {
                let mut job = PixelJob::new(scene, &settings, x, y);
                while let Some(q) = job.next_ray() {
                    let res = match q.kind {
                        RayKind::Shadow => {
                            out.shadow.push(q.ray);
                            TraceResult::Occluded(s.any_hit(
                                AccelKind::Bvh2,
                                &q.ray,
                                &mut NoObserver,
                            ))
                        }
                        k => {
                            if k == RayKind::Primary {
                                out.primary.push(q.ray);
                            } else {
                                out.diffuse.push(q.ray);
                            }
                            TraceResult::Closest(s.closest_hit(
                                AccelKind::Bvh2,
                                &q.ray,
                                &mut NoObserver,
                            ))
                        }
                    };
                    job.submit(res);
                }
            }
        }
    }
    out
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
