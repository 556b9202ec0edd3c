//! Ray sets shared by `check` and `stats`: rays recorded from path-traced pixel jobs.
use crate::progress::Ctx;
use dualsplit_accel::{NoObserver, TraversalSet};
use dualsplit_geometry::Ray;
use dualsplit_render::{PixelJob, RayKind, RenderSettings, TraceResult, Workload};
use rayon::prelude::*;

/// Most rays of each kind `--rays` may ask for: 2^22. Recording holds each pass's rays of
/// every pixel, then the three sets: peak RSS of `stats builtin:cornell --rays 1000000` is
/// 657 MB, so about 2.7 GB at the limit.
pub const MAX_RAYS: usize = 1 << 22;

/// Parses a `--rays` count: 1 to [`MAX_RAYS`].
pub fn parse_count(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=MAX_RAYS).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{s}` is not a ray count from 1 to {MAX_RAYS} (the limit of recorded rays)"
        )),
    }
}

/// Records `n` rays of each kind (primary, shadow, diffuse) from path-traced pixel jobs
/// (5 bounces), driven by the answers of `s`'s reference traversal (BVH2 for every
/// structure of a scene); more passes with new seeds until each kind has
/// `n` rays (at most 64 passes: a scene the camera barely sees yields fewer).
pub fn record(
    scene: &dualsplit_scene::Scene,
    s: &impl TraversalSet,
    n: usize,
    ctx: &Ctx,
) -> (Vec<Ray>, Vec<Ray>, Vec<Ray>) {
    let reference = s.reference();
    let side = (n as f64).sqrt().ceil().max(1.0) as u32;
    let (mut p, mut sh, mut d) = (Vec::new(), Vec::new(), Vec::new());
    let sp = ctx.spinner("recording rays");
    for pass in 0..64u32 {
        if p.len() >= n && sh.len() >= n && d.len() >= n {
            break;
        }
        let mut settings = RenderSettings::new(side, side, Workload::Path);
        settings.seed = pass;
        let per_pixel: Vec<Vec<(RayKind, Ray)>> = (0..side * side)
            .into_par_iter()
            .map(|i| {
                let mut job = PixelJob::new(scene, &settings, i % side, i / side);
                let mut out = Vec::new();
                while let Some(q) = job.next_ray() {
                    out.push((q.kind, q.ray));
                    let r = if q.kind == RayKind::Shadow {
                        TraceResult::Occluded(s.any_hit(reference, &q.ray, &mut NoObserver))
                    } else {
                        TraceResult::Closest(s.closest_hit(reference, &q.ray, &mut NoObserver))
                    };
                    job.submit(r);
                }
                out
            })
            .collect();
        for (k, r) in per_pixel.into_iter().flatten() {
            match k {
                RayKind::Primary => p.push(r),
                RayKind::Shadow => sh.push(r),
                RayKind::Diffuse => d.push(r),
            }
        }
    }
    sp.finish_and_clear();
    p.truncate(n);
    sh.truncate(n);
    d.truncate(n);
    (p, sh, d)
}
