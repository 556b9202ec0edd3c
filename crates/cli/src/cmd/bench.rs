//! `dualsplit bench`: CPU traversal throughput per structure and ray type, and full-frame
//! render times. Every structure's answers are checked against BVH2, ray by ray, before
//! anything is timed (see `dualsplit_render::bench`).
use super::render::{build_structures, load_scene};
use crate::args::{parse_accel, parse_res, parse_workload};
use crate::output::JsonOut;
use crate::progress::Ctx;
use dualsplit_accel::AccelKind;
use dualsplit_render::bench::{MeasureConfig, Throughput, measure, ray_sets};
use dualsplit_render::{RenderSettings, Workload, render, tile_count};
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `dualsplit bench`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params
    /// (hairball, forest, atrium, cornell).
    #[arg(value_parser = crate::args::parse_scene)]
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
    /// Print the results as JSON lines instead of a table; `--json=FILE` writes them to FILE.
    #[arg(long, value_name = "FILE", num_args = 0..=1, require_equals = true, default_missing_value = "-")]
    json: Option<std::path::PathBuf>,
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let json = JsonOut::from_arg(args.json.as_deref())?;
    // JSON lines go out as they are measured on standard output, and all at the end to a
    // file.
    let mut lines: Vec<String> = Vec::new();
    let mut json_line = |v: String| {
        if json == Some(JsonOut::Stdout) {
            println!("{v}");
        } else {
            lines.push(v);
        }
    };
    let accels = if args.accel.is_empty() {
        AccelKind::ALL.to_vec()
    } else {
        args.accel.clone()
    };
    let scene = load_scene(&args.scene, ctx, json.is_some())?;
    let settings = RenderSettings {
        seed: args.seed,
        ..RenderSettings::new(args.res.0, args.res.1, args.workload)
    };
    dualsplit_render::validate(&scene, &settings)?;
    let structures = build_structures(&scene, ctx, json.is_some())?;
    let sp = ctx.spinner("generating rays on bvh2");
    let t = Instant::now();
    let sets = ray_sets(&scene, &structures, &settings)?;
    sp.finish_and_clear();
    let line = format!(
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
    super::render::say(&line, json.is_some());
    let cfg = MeasureConfig {
        min_seconds: args.min_seconds,
        ..MeasureConfig::default()
    };
    if json.is_none() {
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
        if json.is_some() {
            for r in &row {
                json_line(serde_json::to_string(r)?);
            }
            if let Some(s) = frame_s {
                json_line(
                    serde_json::json!({
                        "accel": kind, "frame_seconds": s, "width": settings.width,
                        "height": settings.height, "workload": settings.workload,
                    })
                    .to_string(),
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
    if let Some(out @ JsonOut::File(_)) = &json {
        out.emit(&lines.join("\n"))?;
    }
    Ok(ExitCode::SUCCESS)
}
