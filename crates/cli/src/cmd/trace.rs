//! `dualsplit trace SCENE --rays FILE -o FILE [--accel NAME] [--tree FILE] [--occluded]`:
//! answers a file of rays with one traversal, on every core.
//!
//! Both files are raw little-endian records, one per ray, in the rays' order:
//!
//! * rays (32 bytes): `f32` origin x, y, z, direction x, y, z, `t_min`, `t_max`
//!   ([`dualsplit_accel::ray_file`]: at most 2^25 rays, each with a finite origin and
//!   direction and no NaN `t_min` or `t_max`; a ray breaking that is an error naming it);
//! * closest hits (16 bytes): `f32 t`, `i32 prim`, `f32 u`, `f32 v`; a miss is
//!   `t = +inf`, `prim = -1`, `u = v = 0` (the Python package's `Tree.intersect` arrays);
//! * with `--occluded`, one byte per ray: 1 when it hits any triangle, else 0.
use crate::args::{accel_names, parse_scene};
use crate::loaded::Loaded;
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::{AccelKind, NoObserver, TraversalSet, ray_file};
use rayon::prelude::*;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `dualsplit trace`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params.
    #[arg(value_parser = parse_scene)]
    scene: String,
    /// The rays: 32-byte little-endian records (origin, direction, t_min, t_max as f32).
    #[arg(long, value_name = "FILE")]
    rays: PathBuf,
    /// Traversal (default: the reference, the BVH2's; with --tree, the saved structure's
    /// first traversal).
    #[arg(long, value_parser = accel_names())]
    accel: Option<AccelKind>,
    /// Trace with the tree saved in FILE by `dualsplit build` instead of building.
    #[arg(long, value_name = "FILE")]
    tree: Option<PathBuf>,
    /// Shadow rays: write one byte per ray (1 = occluded) instead of closest hits.
    #[arg(long)]
    occluded: bool,
    /// The answers' file.
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    crate::output::check_file(&args.output, "-o")?;
    let mut inputs = vec![args.rays.as_path(), std::path::Path::new(&args.scene)];
    inputs.extend(args.tree.as_deref());
    crate::output::check_not_an_input(&args.output, "-o", &inputs)?;
    let bytes = dualsplit_scene::load::read_limited(&args.rays, ray_file::MAX_BYTES)?;
    let rays =
        ray_file::parse_rays(&bytes).with_context(|| format!("rays {}", args.rays.display()))?;
    drop(bytes);
    let scene = super::load(&args.scene, ctx)?;
    let structures = Loaded::get(&scene, args.tree.as_deref(), ctx)?;
    let kind = match args.accel {
        Some(k) => {
            structures.require(k.name(), k)?;
            k
        }
        None => match &structures {
            Loaded::Saved { .. } | Loaded::Some { .. } => structures.kinds()[0],
            Loaded::Built { .. } => AccelKind::REFERENCE,
        },
    };
    let out: Vec<u8> = if args.occluded {
        rays.par_iter()
            .map(|r| u8::from(structures.any_hit(kind, r, &mut NoObserver)))
            .collect()
    } else {
        let hits: Vec<[u8; 16]> = rays
            .par_iter()
            .map(|r| {
                let (t, prim, u, v) = match structures.closest_hit(kind, r, &mut NoObserver) {
                    Some(h) => (h.t, h.prim.0 as i32, h.u, h.v),
                    None => (f32::INFINITY, -1, 0.0, 0.0),
                };
                let mut rec = [0u8; 16];
                rec[0..4].copy_from_slice(&t.to_le_bytes());
                rec[4..8].copy_from_slice(&prim.to_le_bytes());
                rec[8..12].copy_from_slice(&u.to_le_bytes());
                rec[12..16].copy_from_slice(&v.to_le_bytes());
                rec
            })
            .collect();
        hits.concat()
    };
    std::fs::write(&args.output, &out)
        .with_context(|| format!("writing {}", args.output.display()))?;
    eprintln!(
        "{} rays traced with {} ({}), answers in {}",
        rays.len(),
        kind.name(),
        structures.summary(),
        args.output.display()
    );
    Ok(ExitCode::SUCCESS)
}
