//! Shared helpers of the accel integration tests: a brute-force oracle, scene loading and
//! ray generation through the renderer's `PixelJob`.
#![allow(dead_code)]

use dualsplit_accel::{AccelKind, NoObserver, Structures};
use dualsplit_geometry::{Hit, Ray, Triangle};
use dualsplit_render::{PixelJob, RayKind, RenderSettings, TraceResult, Workload};
use dualsplit_scene::Scene;

/// Closest hit over all triangles in `(t, prim)` order: the reference every structure must
/// match bit for bit.
pub fn oracle_closest(tris: &[Triangle], ray: &Ray) -> Option<Hit> {
    let r = ray.precompute();
    let mut best: Option<Hit> = None;
    for (i, tri) in tris.iter().enumerate() {
        let Some(h) = tri.intersect(&r, ray.t_min, ray.t_max) else {
            continue;
        };
        if best.is_none_or(|b| !b.closer_than(h.t, i as u32)) {
            best = Some(Hit {
                t: h.t,
                prim: i as u32,
                u: h.u,
                v: h.v,
            });
        }
    }
    best
}

/// Whether any triangle is hit on `[t_min, t_max]`.
pub fn oracle_any(tris: &[Triangle], ray: &Ray) -> bool {
    let r = ray.precompute();
    tris.iter()
        .any(|t| t.intersect(&r, ray.t_min, ray.t_max).is_some())
}

/// `(t bits, prim)` of a hit, the quantity compared per ray.
pub fn key(h: Option<Hit>) -> Option<(u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.prim))
}

/// Path of a shipped scene.
pub fn scene_path(name: &str) -> String {
    format!(
        "{}/../../../shared/scenes/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// Loads a shipped scene with `dualsplit_scene::load`.
pub fn load_scene(name: &str) -> Scene {
    let path = scene_path(name);
    dualsplit_scene::load(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

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
