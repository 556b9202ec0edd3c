//! `dualsplit stats`: build every structure of a scene and print its sizes like the paper's
//! Table 3 (Lin et al. 2020, §4.2).
//!
//! Sizes count node bytes (internal nodes plus one 4-byte leaf word per leaf) and the
//! triangle-index lists, never the triangles (see `dualsplit_accel::stats`). MiB = 2^20 B.
//!
//! JSON schema (`--json`):
//! `{"scene": str, "triangles": int, "structures": {"bvh2"|"bvh4"|"bvh8": {"name",
//! "nodes", "internal_nodes", "leaves", "bytes_nodes", "bytes_indices", "bytes_total",
//! "percent_of_bvh2", "sah_cost", "build_ms"}}}`.
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::{BuildConfig, Structures, stats::MIB};
use std::process::ExitCode;

/// Arguments of `dualsplit stats`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params.
    scene: String,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let sp = ctx.spinner(format!("loading {}", args.scene));
    let scene = dualsplit_scene::load(&args.scene)
        .with_context(|| format!("loading scene {}", args.scene))?;
    sp.set_message("building BVH2, BVH4, BVH8");
    let s = Structures::try_build(&scene.triangles, &BuildConfig::default())
        .with_context(|| format!("building the structures of {}", args.scene))?;
    sp.finish_and_clear();
    let stats = s.stats();
    if args.json {
        let mut structures = serde_json::Map::new();
        for st in &stats {
            structures.insert(st.name.clone(), serde_json::to_value(st)?);
        }
        let v = serde_json::json!({
            "scene": scene.name,
            "triangles": scene.triangles.len(),
            "structures": structures,
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(ExitCode::SUCCESS);
    }
    println!(
        "{} ({} triangles) — sizes as in Lin et al. 2020, Table 3 (MiB = 2^20 B; nodes + index lists, triangles excluded)",
        scene.name,
        scene.triangles.len()
    );
    println!(
        "{:<6} {:>10} {:>10} {:>11} {:>12} {:>10} {:>8} {:>8} {:>10}",
        "",
        "internal",
        "leaves",
        "nodes MiB",
        "indices MiB",
        "total MiB",
        "% BVH2",
        "SAH",
        "time ms"
    );
    for st in &stats {
        println!(
            "{:<6} {:>10} {:>10} {:>11.2} {:>12.2} {:>10.2} {:>7.1}% {:>8.2} {:>10.1}",
            st.name,
            st.internal_nodes,
            st.leaves,
            st.bytes_nodes as f64 / MIB,
            st.bytes_indices as f64 / MIB,
            st.bytes_total as f64 / MIB,
            st.percent_of_bvh2,
            st.sah_cost,
            st.build_ms
        );
    }
    println!("time: BVH2 build, BVH4/BVH8 collapse from it (wall clock, this machine)");
    Ok(ExitCode::SUCCESS)
}
