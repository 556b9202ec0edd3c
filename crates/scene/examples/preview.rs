//! Renders a scene to a PNG with the reference renderer's cast workload (one primary ray and
//! one shadow ray per pixel), to look at builtins and camera presets.
//!
//! ```text
//! cargo run --release -p dualsplit-scene --example preview -- builtin:hairball /tmp/hairball.png [SIZE]
//! ```
//!
//! Optional environment overrides: `EYE=x,y,z`, `TARGET=x,y,z`, `FOV=deg`, `LIGHT=x,y,z`.

use dualsplit_accel::{AccelKind, BuildConfig, NoObserver, Structures};
use dualsplit_render::{PixelJob, RenderSettings, TraceResult, Workload};
use rayon::prelude::*;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: preview SCENE OUT.png [SIZE]");
        std::process::exit(2);
    }
    let size: u32 = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(256);
    let t0 = Instant::now();
    let mut scene = dualsplit_scene::load(&args[1])?;
    let t_load = t0.elapsed();
    let env = |k: &str| std::env::var(k).ok();
    scene.camera = scene.camera.with_overrides(
        env("EYE").as_deref(),
        env("TARGET").as_deref(),
        env("FOV").map(|f| f.parse()).transpose()?,
    )?;
    scene.light = scene
        .light
        .with_overrides(env("LIGHT").as_deref(), None, None)?;
    let t1 = Instant::now();
    let accel = Structures::build(&scene.triangles, &BuildConfig::default());
    let t_build = t1.elapsed();
    let settings = RenderSettings::new(size, size, Workload::Cast);
    let pixels: Vec<f32> = (0..size * size)
        .into_par_iter()
        .map(|i| {
            let mut job = PixelJob::new(&scene, &settings, i % size, i / size);
            while let Some(q) = job.next_ray() {
                let r = match q.kind {
                    dualsplit_render::RayKind::Shadow => TraceResult::Occluded(accel.any_hit(
                        AccelKind::Bvh2,
                        &q.ray,
                        &mut NoObserver,
                    )),
                    _ => TraceResult::Closest(accel.closest_hit(
                        AccelKind::Bvh2,
                        &q.ray,
                        &mut NoObserver,
                    )),
                };
                job.submit(r);
            }
            job.radiance()
        })
        .collect();
    // Simple exposure: scale so the 99th percentile maps to 0.95, then gamma 2.2.
    let mut sorted = pixels.clone();
    sorted.sort_by(f32::total_cmp);
    let p99 = sorted[(sorted.len() * 99 / 100).min(sorted.len() - 1)].max(1e-6);
    let bytes: Vec<u8> = pixels
        .iter()
        .map(|&v| ((v / p99 * 0.95).clamp(0.0, 1.0).powf(1.0 / 2.2) * 255.0).round() as u8)
        .collect();
    let file = std::fs::File::create(&args[2])?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), size, size);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header()?.write_image_data(&bytes)?;
    eprintln!(
        "{}: {} triangles, bounds {:?}..{:?}, load {:.2?}, build {:.2?}, camera {:?}",
        scene.name,
        scene.triangles.len(),
        scene.bounds.min,
        scene.bounds.max,
        t_load,
        t_build,
        scene.camera
    );
    Ok(())
}
