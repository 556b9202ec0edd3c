//! `dualsplit render`: one frame of a workload on a structure, written as PNG or EXR.
//!
//! Also holds the argument parsers `bench` shares (resolution, structure and workload names) and the scene/structure loading steps with their spinners.
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::{AccelKind, BuildConfig, Structures};
use dualsplit_render::{RayCounts, RayKind, RenderSettings, Workload, render, tile_count};
use dualsplit_scene::Scene;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `dualsplit render`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params.
    scene: String,
    /// Structure: bvh2, bvh4, bvh8, dst-sw or dst.
    #[arg(long, default_value = "bvh2", value_parser = parse_accel)]
    accel: AccelKind,
    /// Workload: cast (primary + shadow ray) or path (5 diffuse bounces with a shadow ray at each hit).
    #[arg(long, default_value = "path", value_parser = parse_workload)]
    workload: Workload,
    /// Resolution, WIDTHxHEIGHT or N for N×N.
    #[arg(long, default_value = "1024x1024", value_parser = parse_res)]
    res: (u32, u32),
    /// Samples per pixel.
    #[arg(long, default_value_t = 1)]
    spp: u32,
    /// Seed of the per-pixel random numbers.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Camera position x,y,z (default: the scene's camera).
    #[arg(long, allow_hyphen_values = true)]
    eye: Option<String>,
    /// Point the camera looks at, x,y,z.
    #[arg(long, allow_hyphen_values = true)]
    target: Option<String>,
    /// Vertical field of view in degrees, in (0, 180).
    #[arg(long)]
    fov: Option<f32>,
    /// Light centre x,y,z (default: the scene's light).
    #[arg(long, allow_hyphen_values = true)]
    light: Option<String>,
    /// Light radius (0 = point light, hard shadows).
    #[arg(long)]
    light_radius: Option<f32>,
    /// Output image: .png (tone-mapped sRGB, 8-bit) or .exr (linear f32).
    #[arg(short, long)]
    output: PathBuf,
}

/// Parses a structure name.
pub(crate) fn parse_accel(s: &str) -> Result<AccelKind, String> {
    AccelKind::parse(s).ok_or_else(|| {
        let names: Vec<_> = AccelKind::ALL.iter().map(|k| k.name()).collect();
        format!(
            "unknown structure `{s}` (expected one of {})",
            names.join(", ")
        )
    })
}

/// Parses a workload name.
pub(crate) fn parse_workload(s: &str) -> Result<Workload, String> {
    Workload::parse(s).ok_or_else(|| format!("unknown workload `{s}` (expected cast or path)"))
}

/// Parses `WxH` or `N`.
pub(crate) fn parse_res(s: &str) -> Result<(u32, u32), String> {
    let num = |t: &str| {
        t.trim()
            .parse::<u32>()
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| format!("bad resolution `{s}` (expected WIDTHxHEIGHT or N, positive)"))
    };
    match s.split_once(['x', 'X']) {
        Some((w, h)) => Ok((num(w)?, num(h)?)),
        None => num(s).map(|n| (n, n)),
    }
}

/// Loads a scene behind a spinner.
pub(crate) fn load_scene(spec: &str, ctx: &Ctx) -> anyhow::Result<Scene> {
    let sp = ctx.spinner(format!("loading {spec}"));
    let t = Instant::now();
    let scene =
        dualsplit_scene::load_with(spec, &ctx.limits).with_context(|| format!("loading {spec}"))?;
    sp.finish_and_clear();
    println!(
        "scene {}: {} triangles, loaded in {:.2} s",
        scene.name,
        scene.triangles.len(),
        t.elapsed().as_secs_f64()
    );
    Ok(scene)
}

/// Builds every structure behind a spinner.
pub(crate) fn build_structures(scene: &Scene, ctx: &Ctx) -> anyhow::Result<Structures> {
    let sp = ctx.spinner("building structures");
    let t = Instant::now();
    let s = Structures::try_build(&scene.triangles, &BuildConfig::default())
        .context("building the acceleration structures")?;
    sp.finish_and_clear();
    println!("structures built in {:.2} s", t.elapsed().as_secs_f64());
    Ok(s)
}

/// One line per ray kind: rays, hits, misses.
pub(crate) fn print_counts(c: &RayCounts) {
    for k in RayKind::ALL {
        let n = c.get(k);
        println!(
            "  {:<8} {:>12} rays {:>12} hits {:>12} misses",
            k.name(),
            n.rays,
            n.hits,
            n.misses()
        );
    }
    println!(
        "  {:<8} {:>12} rays {:>12} hits {:>12} misses",
        "total",
        c.rays(),
        c.hits(),
        c.misses()
    );
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    dualsplit_render::ImageFormat::from_path(&args.output)?;
    let mut scene = load_scene(&args.scene, ctx)?;
    scene.camera =
        scene
            .camera
            .with_overrides(args.eye.as_deref(), args.target.as_deref(), args.fov)?;
    scene.light = scene
        .light
        .with_overrides(args.light.as_deref(), args.light_radius, None)?;
    let settings = RenderSettings {
        spp: args.spp,
        seed: args.seed,
        ..RenderSettings::new(args.res.0, args.res.1, args.workload)
    };
    dualsplit_render::validate(&scene, &settings)?;
    let structures = build_structures(&scene, ctx)?;
    let bar = ctx.bar(
        tile_count(&settings),
        format!("{} {}", args.accel.name(), args.workload.name()),
    );
    let t = Instant::now();
    let frame = render(&scene, &structures, args.accel, &settings, &|| bar.inc(1))?;
    let secs = t.elapsed().as_secs_f64();
    bar.finish_and_clear();
    println!(
        "rendered {}x{} {} at {} spp on {} in {:.3} s ({:.2} Mrays/s, {} threads)",
        settings.width,
        settings.height,
        settings.workload.name(),
        settings.spp,
        args.accel.name(),
        secs,
        frame.counts.rays() as f64 / secs / 1e6,
        rayon::current_num_threads()
    );
    print_counts(&frame.counts);
    frame.image.write(&args.output)?;
    println!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}
