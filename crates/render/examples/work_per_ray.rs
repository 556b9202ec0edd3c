//! Work per ray of every structure on the ray sets `dualsplit bench` times (a path-traced
//! frame's primary, shadow and diffuse rays): internal node steps, leaves entered, ray–box,
//! ray–plane and ray–triangle tests, counted by a [`CountingObserver`] on each structure's
//! image traversal (the CPU copies' merged leaves are not counted).
//!
//! `cargo run --release -p dualsplit-render --example work_per_ray -- SCENE [RES]`
//! (RES: the frame is RES×RES, 256 by default.)

use dualsplit_accel::{AccelKind, CountingObserver, Structures};
use dualsplit_render::{RayKind, RenderSettings, Workload, bench::ray_sets};
use std::io::Write;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Written with `?`: a reader that stops early (`| head`) ends the example with an
    // error, not a panic.
    let mut out = std::io::stdout().lock();
    let mut args = std::env::args().skip(1);
    let spec = args.next().ok_or("usage: work_per_ray SCENE [RES]")?;
    let res: u32 = args.next().map_or(Ok(256), |r| r.parse())?;
    let scene = dualsplit_scene::load(&spec)?;
    let s = Structures::try_build(&scene.triangles, &Default::default())?;
    let sets = ray_sets(&scene, &s, &RenderSettings::new(res, res, Workload::Path))?;
    writeln!(out, "{spec}, {res}x{res} path frame; per ray:")?;
    writeln!(
        out,
        "{:8} {:8} {:>8} {:>7} {:>7} {:>7} {:>7}",
        "rays", "accel", "nodes", "leaves", "boxes", "planes", "tris"
    )?;
    for set in &sets {
        for kind in AccelKind::ALL {
            let mut obs = CountingObserver::default();
            for r in &set.rays {
                if set.kind == RayKind::Shadow {
                    s.any_hit(kind, r, &mut obs);
                } else {
                    s.closest_hit(kind, r, &mut obs);
                }
            }
            let n = set.rays.len().max(1) as f64;
            let per = |c: u64| c as f64 / n;
            writeln!(
                out,
                "{:8} {:8} {:8.1} {:7.2} {:7.1} {:7.1} {:7.2}",
                set.kind.name(),
                kind.name(),
                per(obs.nodes),
                per(obs.leaves),
                per(obs.box_tests),
                per(obs.plane_tests),
                per(obs.triangle_tests)
            )?;
        }
    }
    Ok(())
}
