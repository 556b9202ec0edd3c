//! `dualsplit build SCENE --accel dst|bvh2|bvh4|bvh8|cwbvh|dst-q -o FILE [--json]`: builds
//! exactly one structure (every kind but the BVH2 is derived from the scene's BVH2) and saves it in the
//! saved-tree format (`docs/tree-format.md`), so later runs can load it instead of
//! building. The structure is validated before it is written (a DST against its BVH2, as
//! `check --tree` does): one that does not validate is an error and no file is written.
//!
//! JSON schema (`--json`), one object: `{"scene", "spec", "triangles", "accel", "file",
//! "file_bytes", "bvh2_ms", "build_ms", "save_ms", "stats"}`: `build_ms` is the wall time of
//! every step that makes the structure (the BVH2 build, plus the collapse or conversion),
//! `bvh2_ms` the BVH2 build alone, `save_ms` the write, and `stats` the structure's
//! [`dualsplit_accel::BuildStats`] (its own `build_ms` is the last step alone). Times are
//! host measurements.
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::{AnyTree, BuildConfig, BuildStats, Bvh2Tree, TreeKind};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

/// Arguments of `dualsplit build`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params.
    #[arg(value_parser = crate::args::parse_scene)]
    scene: String,
    /// The structure to build (with the default presets: the DST's hardware preset, the
    /// default BVH8 collapse and quantized DST).
    #[arg(long, value_parser = tree_kind_names())]
    accel: TreeKind,
    /// The tree file to write.
    #[arg(short, long)]
    output: PathBuf,
    /// Print one JSON object instead of a table; `--json=FILE` writes it to FILE.
    #[arg(long, value_name = "FILE", num_args = 0..=1, require_equals = true, default_missing_value = "-")]
    json: Option<PathBuf>,
}

/// Parses a [`TreeKind`] name (one of [`TreeKind::names`]).
pub fn parse_tree_kind(s: &str) -> Result<TreeKind, String> {
    TreeKind::parse(s).ok_or_else(|| format!("unknown structure `{s}` ({})", TreeKind::names()))
}

/// `--accel` of `build`: [`TreeKind`]'s names.
fn tree_kind_names() -> crate::args::Names<TreeKind> {
    crate::args::Names::new(parse_tree_kind, || {
        TreeKind::ALL.map(TreeKind::name).to_vec()
    })
}

/// What `build` reports, also its JSON form.
#[derive(serde::Serialize)]
struct Built<'a> {
    scene: &'a str,
    spec: &'a str,
    triangles: u64,
    accel: TreeKind,
    file: String,
    file_bytes: u64,
    bvh2_ms: f64,
    build_ms: f64,
    save_ms: f64,
    stats: BuildStats,
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let json = crate::output::JsonOut::from_arg(args.json.as_deref())?;
    crate::output::check_file(&args.output, "-o")?;
    crate::output::check_not_an_input(&args.output, "-o", &[std::path::Path::new(&args.scene)])?;
    let sp = ctx.spinner(format!("loading {}", args.scene));
    let scene = dualsplit_scene::load_with(&args.scene, &ctx.limits)
        .with_context(|| format!("loading scene {}", args.scene))?;
    sp.set_message(format!("building {}", args.accel));
    let t0 = Instant::now();
    let bvh2 = Bvh2Tree::build(&scene.triangles[..], &BuildConfig::default())
        .with_context(|| format!("building the BVH2 of {}", args.scene))?;
    let bvh2_ms = bvh2.stats().build_ms;
    let tree: Option<AnyTree> = AnyTree::derive(&bvh2, args.accel).transpose()?;
    let build_ms = t0.elapsed().as_secs_f64() * 1e3;
    sp.set_message(format!("validating {}", args.accel));
    let report = match &tree {
        None => bvh2.tree().encoded().validate(),
        Some(t) => t.validate(bvh2.logical()),
    };
    let tree = tree.unwrap_or_else(|| bvh2.into_tree().into());
    if !report.is_ok() {
        anyhow::bail!(
            "the {} built from {} does not validate ({} errors: {}); {} was not written",
            args.accel,
            args.scene,
            report.error_count,
            report.errors.join("; "),
            args.output.display()
        );
    }
    sp.set_message(format!("saving {}", args.output.display()));
    let t0 = Instant::now();
    tree.save(&args.output)?;
    let save_ms = t0.elapsed().as_secs_f64() * 1e3;
    sp.finish_and_clear();
    let file_bytes = std::fs::metadata(&args.output)
        .with_context(|| format!("reading back {}", args.output.display()))?
        .len();
    let out = Built {
        scene: &scene.name,
        spec: &scene.spec,
        triangles: scene.triangles.len() as u64,
        accel: args.accel,
        file: args.output.display().to_string(),
        file_bytes,
        bvh2_ms,
        build_ms,
        save_ms,
        stats: *tree.stats(),
    };
    if let Some(j) = json {
        j.emit(&serde_json::to_string_pretty(&out)?)?;
    } else {
        outln!(
            "{} {}: {} triangles, {} node + {} index bytes, built in {:.1} ms (BVH2 {:.1} ms), \
             saved {} bytes to {} in {:.1} ms",
            out.scene,
            out.accel,
            out.triangles,
            out.stats.node_bytes,
            out.stats.index_bytes,
            out.build_ms,
            out.bvh2_ms,
            out.file_bytes,
            out.file,
            out.save_ms
        );
    }
    Ok(ExitCode::SUCCESS)
}
