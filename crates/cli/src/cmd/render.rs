//! `dualsplit render`: one frame of a workload on a structure, written as PNG or EXR.
//!
//! With `--tree FILE` the structure comes from a saved tree file instead of a build
//! ([`crate::loaded`]); `--accel` then defaults to the tree's own traversal (dst-sw for a
//! DST) and must be one of its traversals.
//!
//! Also holds the scene loading step with its spinner that `bench` shares.
use crate::args::{View, accel_names, parse_res, parse_scene, parse_workload};
use crate::loaded::Loaded;
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::{AccelKind, TraversalSet};
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
    /// Traversal (default: the reference, the BVH2's; with --tree, the saved structure's
    /// first traversal: the software decoder for a DST).
    #[arg(long, value_parser = accel_names())]
    accel: Option<AccelKind>,
    /// Render with the tree saved in FILE by `dualsplit build` instead of building; it must
    /// come from SCENE (its triangles are checked). Only its traversals exist: dst-sw
    /// and dst for a DST, its own kind for a BVH.
    #[arg(long, value_name = "FILE")]
    tree: Option<PathBuf>,
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
        outln!("{line}");
    }
}

/// Builds the structures the traversals `kinds` read (every structure when `kinds` is
/// empty), or loads `--tree`, and says how long it took (the time line goes as in
/// [`load_scene`]).
pub(crate) fn get_structures(
    scene: &Scene,
    tree: Option<&std::path::Path>,
    kinds: &[AccelKind],
    ctx: &Ctx,
    stdout_is_data: bool,
) -> anyhow::Result<Loaded> {
    let s = Loaded::get_for(scene, tree, kinds, ctx)?;
    say(&s.summary(), stdout_is_data);
    Ok(s)
}

/// One line per ray kind: rays, hits, misses.
pub(crate) fn print_counts(c: &RayCounts) {
    for k in RayKind::ALL {
        let n = c.get(k);
        outln!(
            "  {:<8} {:>12} rays {:>12} hits {:>12} misses",
            k.name(),
            n.rays,
            n.hits,
            n.misses()
        );
    }
    outln!(
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
    // Only the structure of the traversal rendered is built.
    let wanted = args.accel.unwrap_or(AccelKind::REFERENCE);
    let structures = get_structures(&scene, args.tree.as_deref(), &[wanted], ctx, false)?;
    let accel = match args.accel {
        Some(k) => {
            structures.require(k.name(), k)?;
            k
        }
        None if args.tree.is_some() => structures.reference(),
        None => AccelKind::REFERENCE,
    };
    let bar = ctx.bar(
        tile_count(&settings),
        format!("{} {}", accel.name(), args.workload.name()),
    );
    let t = Instant::now();
    let frame = render(&scene, &structures, accel, &settings, &|| bar.inc(1))?;
    let secs = t.elapsed().as_secs_f64();
    bar.finish_and_clear();
    outln!(
        "rendered {}x{} {} at {} spp on {} in {:.3} s ({:.2} Mrays/s, {} threads)",
        settings.width,
        settings.height,
        settings.workload.name(),
        settings.spp,
        accel.name(),
        secs,
        frame.counts.rays() as f64 / secs / 1e6,
        rayon::current_num_threads()
    );
    print_counts(&frame.counts);
    frame.image.write(&args.output)?;
    outln!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}
