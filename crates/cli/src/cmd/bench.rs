//! `dualsplit bench`: CPU traversal throughput per structure and ray type, and full-frame
//! render times. Every structure's answers are checked against BVH2, ray by ray, before
//! anything is timed (see `dualsplit_render::bench`).
use super::render::{build_structures, load_scene, parse_accel, parse_res, parse_workload};
use crate::progress::Ctx;
use dualsplit_accel::AccelKind;
use dualsplit_render::bench::{MeasureConfig, Throughput, measure, ray_sets};
use dualsplit_render::{RenderSettings, Workload, render, tile_count};
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `dualsplit bench`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params.
    scene: String,
    /// Structures to measure, comma-separated (bvh2, bvh4, bvh8, dst-sw, dst); default all.
    #[arg(long, value_delimiter = ',', value_parser = parse_accel)]
    accel: Vec<AccelKind>,
    /// Workload whose rays are measured: cast (primary, shadow) or path (primary, shadow, diffuse).
    #[arg(long, default_value = "path", value_parser = parse_workload)]
    workload: Workload,
    /// Frame resolution the rays come from, WIDTHxHEIGHT or N for N×N.
    #[arg(long, default_value = "512", value_parser = parse_res)]
    res: (u32, u32),
    /// Seed of the per-pixel random numbers.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Minimum seconds of timing per structure and ray type.
    #[arg(long, default_value_t = 1.0)]
    min_seconds: f64,
    /// Skip the full-frame render timing.
    #[arg(long)]
    no_frame: bool,
    /// Print the results as JSON lines instead of a table.
    #[arg(long)]
    json: bool,
}

/// Most pixels in a benchmark frame: 2^24 (4096 × 4096). The ray sets hold every ray of the
/// frame with BVH2's answer, about 450 bytes per pixel on the path workload (peak RSS of
/// `bench builtin:cornell --res 1024 --accel bvh2`: 459 MB), so about 7.5 GB at the limit.
pub const MAX_BENCH_PIXELS: u64 = 1 << 24;

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let accels = if args.accel.is_empty() {
        AccelKind::ALL.to_vec()
    } else {
        args.accel.clone()
    };
    let scene = load_scene(&args.scene, ctx)?;
    let settings = RenderSettings {
        seed: args.seed,
        ..RenderSettings::new(args.res.0, args.res.1, args.workload)
    };
    dualsplit_render::validate(&scene, &settings)?;
    let pixels = u64::from(settings.width) * u64::from(settings.height);
    if pixels > MAX_BENCH_PIXELS {
        anyhow::bail!(
            "--res {}x{}: {pixels} pixels; bench holds every ray of its frame (about 450 bytes \
             per pixel), so at most {MAX_BENCH_PIXELS} (4096x4096)",
            settings.width,
            settings.height
        );
    }
    let structures = build_structures(&scene, ctx)?;
    let sp = ctx.spinner("generating rays on bvh2");
    let t = Instant::now();
    let sets = ray_sets(&scene, &structures, &settings)?;
    sp.finish_and_clear();
    println!(
        "ray sets of a {}x{} {} frame: {} in {:.2} s; {} threads",
        settings.width,
        settings.height,
        settings.workload.name(),
        sets.iter()
            .map(|s| format!("{} {}", s.rays.len(), s.kind.name()))
            .collect::<Vec<_>>()
            .join(", "),
        t.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    let cfg = MeasureConfig {
        min_seconds: args.min_seconds,
        ..MeasureConfig::default()
    };
    if !args.json {
        println!(
            "{:<8} {:>16} {:>16} {:>16} {:>14}",
            "accel", "primary Mrays/s", "shadow Mrays/s", "diffuse Mrays/s", "frame s"
        );
    }
    for &kind in &accels {
        let mut row: Vec<Throughput> = Vec::new();
        for set in sets.iter().filter(|s| !s.rays.is_empty()) {
            let sp = ctx.spinner(format!("{} {} rays", kind.name(), set.kind.name()));
            row.push(measure(&structures, kind, set, &cfg)?);
            sp.finish_and_clear();
        }
        let frame_s = if args.no_frame {
            None
        } else {
            let bar = ctx.bar(tile_count(&settings), format!("{} frame", kind.name()));
            let t = Instant::now();
            render(&scene, &structures, kind, &settings, &|| bar.inc(1))?;
            bar.finish_and_clear();
            Some(t.elapsed().as_secs_f64())
        };
        if args.json {
            for r in &row {
                println!("{}", serde_json::to_string(r)?);
            }
            if let Some(s) = frame_s {
                println!(
                    "{}",
                    serde_json::json!({
                        "accel": kind, "frame_seconds": s, "width": settings.width,
                        "height": settings.height, "workload": settings.workload,
                    })
                );
            }
        } else {
            let cell = |k: dualsplit_render::RayKind| {
                row.iter()
                    .find(|r| r.ray_kind == k)
                    .map(|r| format!("{:.2}", r.mrays_per_s))
                    .unwrap_or_else(|| "-".into())
            };
            println!(
                "{:<8} {:>16} {:>16} {:>16} {:>14}",
                kind.name(),
                cell(dualsplit_render::RayKind::Primary),
                cell(dualsplit_render::RayKind::Shadow),
                cell(dualsplit_render::RayKind::Diffuse),
                frame_s
                    .map(|s| format!("{s:.3}"))
                    .unwrap_or_else(|| "-".into())
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
