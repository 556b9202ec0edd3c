//! `dualsplit stats`: build every structure of a scene and print its sizes like the paper's
//! Table 3 (Lin et al. 2020, §4.2).
//!
//! Sizes count node bytes (internal nodes plus one 4-byte leaf word per leaf) and the
//! triangle-index lists, never the triangles (see `dualsplit_accel::stats`). MiB = 2^20 B.
//!
//! The DST rows add node counts by kind and the conversion time, and a second table compares
//! DST variants (hardware and software cost presets, identical and similar partitioning) by
//! size and by per-ray work on rays recorded from the scene's path-traced pixels.
//!
//! JSON schema (`--json`):
//! `{"scene": str, "triangles": int, "structures": {"bvh2"|"bvh4"|"bvh8"|"dst": {"name",
//! "nodes", "internal_nodes", "leaves", "bytes_nodes", "bytes_indices", "bytes_total",
//! "percent_of_bvh2", "sah_cost" (null for dst), "build_ms", and for "dst" also
//! "convert_ms" and "dst": {"splitting", "single_carving", "dual_carving", "leaves",
//! "carving_leaves", "index_entries", "node_bytes", "index_bytes", "total_bytes",
//! "bvh2_bytes"}}}, "dst_variants": [{"name", "bytes_total", "percent_of_bvh2", "rays",
//! "nodes", "leaves", "plane_tests", "triangle_tests", "bytes"}], "bvh2_per_ray": {"rays",
//! "nodes", "box_tests", "triangle_tests", "bytes"}}`.
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::dst::{Dst, DstConfig, Partitioning};
use dualsplit_accel::{AccelKind, CountingObserver, stats::MIB};
use std::process::ExitCode;

/// Arguments of `dualsplit stats`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params
    /// (hairball, forest, atrium, cornell).
    #[arg(value_parser = crate::args::parse_scene)]
    scene: String,
    /// Print JSON instead of a table; `--json=FILE` writes it to FILE.
    #[arg(long, value_name = "FILE", num_args = 0..=1, require_equals = true, default_missing_value = "-")]
    json: Option<std::path::PathBuf>,
    /// Rays of each kind used for the per-ray comparison of DST variants.
    #[arg(long, default_value_t = 4096, value_parser = super::rays::parse_count)]
    rays: usize,
}

/// One DST variant's size and per-ray work.
#[derive(serde::Serialize)]
struct Variant {
    name: &'static str,
    bytes_total: u64,
    percent_of_bvh2: f64,
    rays: u64,
    nodes: f64,
    leaves: f64,
    plane_tests: f64,
    triangle_tests: f64,
    bytes: f64,
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let json = crate::output::JsonOut::from_arg(args.json.as_deref())?;
    let (scene, s) = super::load_and_build(&args.scene, ctx)?;
    let stats = s.stats();
    let (primary, _, diffuse) = super::rays::record(&scene, &s, args.rays, ctx);
    let rays: Vec<_> = primary.into_iter().chain(diffuse).collect();
    let base = s.bvh2_image().bytes_total();
    let sp = ctx.spinner("converting DST variants");
    let mut variants = Vec::new();
    for (name, cfg) in [
        ("hardware, identical", DstConfig::hardware()),
        (
            "hardware, similar",
            DstConfig::hardware().with_partitioning(Partitioning::Similar),
        ),
        ("software, identical", DstConfig::software()),
        (
            "software, similar",
            DstConfig::software().with_partitioning(Partitioning::Similar),
        ),
    ] {
        // The hardware/identical tree is the one `Structures` already built.
        let converted;
        let d = if cfg == *s.dst().config() {
            s.dst()
        } else {
            converted = Dst::from_bvh2(&s.bvh2, s.triangles.clone(), &cfg)
                .with_context(|| format!("converting the DST ({name})"))?;
            &converted
        };
        let t = d.trace_stats(&rays);
        let bytes_total = d.stats().total_bytes;
        variants.push(Variant {
            name,
            bytes_total,
            percent_of_bvh2: 100.0 * bytes_total as f64 / base.max(1) as f64,
            rays: t.rays,
            nodes: t.nodes,
            leaves: t.leaves,
            plane_tests: t.plane_tests,
            triangle_tests: t.triangle_tests,
            bytes: t.bytes,
        });
    }
    let mut bvh = CountingObserver::default();
    for r in &rays {
        s.closest_hit(AccelKind::Bvh2, r, &mut bvh);
    }
    sp.finish_and_clear();
    let n = rays.len().max(1) as f64;
    if let Some(out) = json {
        let mut structures = serde_json::Map::new();
        for st in &stats {
            structures.insert(st.name.clone(), serde_json::to_value(st)?);
        }
        let v = serde_json::json!({
            "scene": scene.name,
            "triangles": scene.triangles.len(),
            "structures": structures,
            "dst_variants": variants,
            "bvh2_per_ray": {
                "rays": rays.len(),
                "nodes": bvh.nodes as f64 / n,
                "box_tests": bvh.box_tests as f64 / n,
                "triangle_tests": bvh.triangle_tests as f64 / n,
                "bytes": bvh.bytes as f64 / n,
            },
        });
        out.emit(&serde_json::to_string_pretty(&v)?)?;
        return Ok(ExitCode::SUCCESS);
    }
    outln!(
        "{} ({} triangles) — sizes as in Lin et al. 2020, Table 3 (MiB = 2^20 B; nodes + index lists, triangles excluded)",
        scene.name,
        scene.triangles.len()
    );
    outln!(
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
        outln!(
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
    outln!(
        "time: BVH2 build, BVH4/BVH8 collapse, DST conversion from the BVH2, CWBVH collapse and encoding, DST-Q quantization of the DST (wall clock, this machine)"
    );
    if let Some(d) = stats.iter().find_map(|st| st.dst) {
        outln!(
            "dst nodes: {} splitting, {} single-axis carving, {} dual-axis carving, {} leaves, {} carving leaves (hardware preset, identical bounds)",
            d.splitting,
            d.single_carving,
            d.dual_carving,
            d.leaves,
            d.carving_leaves
        );
    }
    outln!();
    outln!(
        "per-ray work, closest hit on {} primary + diffuse rays (averages):",
        rays.len()
    );
    outln!(
        "{:<32} {:>10} {:>8} {:>8} {:>8} {:>10} {:>10} {:>9}",
        "",
        "total MiB",
        "% BVH2",
        "nodes",
        "leaves",
        "tests",
        "triangles",
        "bytes"
    );
    outln!(
        "{:<32} {:>10.2} {:>7.1}% {:>8.2} {:>8} {:>10.2} {:>10.2} {:>9.1}",
        "bvh2 (boxes)",
        base as f64 / MIB,
        100.0,
        bvh.nodes as f64 / n,
        "",
        bvh.box_tests as f64 / n,
        bvh.triangle_tests as f64 / n,
        bvh.bytes as f64 / n
    );
    for v in &variants {
        outln!(
            "{:<32} {:>10.2} {:>7.1}% {:>8.2} {:>8.2} {:>10.2} {:>10.2} {:>9.1}",
            format!("dst {} (planes)", v.name),
            v.bytes_total as f64 / MIB,
            v.percent_of_bvh2,
            v.nodes,
            v.leaves,
            v.plane_tests,
            v.triangle_tests,
            v.bytes
        );
    }
    Ok(ExitCode::SUCCESS)
}
