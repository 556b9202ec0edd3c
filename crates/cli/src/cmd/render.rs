//! `dualsplit render`: one frame of a workload on a structure, written as PNG or EXR.
//!
//! Also holds the scene and structure loading steps with their spinners that `bench`
//! shares.
use crate::args::{View, parse_accel, parse_res, parse_scene, parse_workload};
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
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params
    /// (hairball, forest, atrium, cornell).
    #[arg(value_parser = parse_scene)]
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
    /// Camera and light overrides.
    #[command(flatten)]
    view: View,
    /// Output image: .png (tone-mapped sRGB, 8-bit) or .exr (linear f32).
    #[arg(short, long)]
    output: PathBuf,
}

/// Loads a scene behind a spinner and says how long it took (on stderr when `stdout_is_data`,
/// so that standard output holds only the data, e.g. JSON).
pub(crate) fn load_scene(spec: &str, ctx: &Ctx, stdout_is_data: bool) -> anyhow::Result<Scene> {
    let sp = ctx.spinner(format!("loading {spec}"));
    let t = Instant::now();
    let scene =
        dualsplit_scene::load_with(spec, &ctx.limits).with_context(|| format!("loading {spec}"))?;
    sp.finish_and_clear();
    let line = format!(
        "scene {}: {} triangles, loaded in {:.2} s",
        scene.name,
        scene.triangles.len(),
        t.elapsed().as_secs_f64()
    );
    say(&line, stdout_is_data);
    Ok(scene)
}

/// A progress line: on stdout, or on stderr when stdout carries data.
pub(crate) fn say(line: &str, stdout_is_data: bool) {
    if stdout_is_data {
        eprintln!("{line}");
    } else {
        println!("{line}");
    }
}

/// Builds every structure behind a spinner (the time line goes as in [`load_scene`]).
pub(crate) fn build_structures(
    scene: &Scene,
    ctx: &Ctx,
    stdout_is_data: bool,
) -> anyhow::Result<Structures> {
    let sp = ctx.spinner("building structures");
    let t = Instant::now();
    let s = Structures::try_build(&scene.triangles, &BuildConfig::default())
        .context("building the acceleration structures")?;
    sp.finish_and_clear();
    say(
        &format!("structures built in {:.2} s", t.elapsed().as_secs_f64()),
        stdout_is_data,
    );
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
    crate::output::check_file(&args.output, "-o")?;
    let mut scene = load_scene(&args.scene, ctx, false)?;
    args.view.apply(&mut scene)?;
    let settings = RenderSettings {
        spp: args.spp,
        seed: args.seed,
        ..RenderSettings::new(args.res.0, args.res.1, args.workload)
    };
    dualsplit_render::validate(&scene, &settings)?;
    let structures = build_structures(&scene, ctx, false)?;
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
