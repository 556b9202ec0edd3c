//! `dualsplit trace SCENE --rays FILE -o FILE [--accel NAME] [--tree FILE] [--occluded]`:
//! answers a file of rays with one traversal, on every core.
//!
//! Both files are raw little-endian records, one per ray, in the rays' order:
//!
//! * rays (32 bytes): `f32` origin x, y, z, direction x, y, z, `t_min`, `t_max`;
//! * closest hits (16 bytes): `f32 t`, `i32 prim`, `f32 u`, `f32 v`; a miss is
//!   `t = +inf`, `prim = -1`, `u = v = 0` (the Python package's `Tree.intersect` arrays);
//! * with `--occluded`, one byte per ray: 1 when it hits any triangle, else 0.
use crate::args::{parse_accel, parse_scene};
use crate::loaded::Loaded;
use crate::progress::Ctx;
use anyhow::{Context, bail};
use dualsplit_accel::{AccelKind, NoObserver, TraversalSet};
use dualsplit_geometry::{Ray, Vec3};
use rayon::prelude::*;
use std::path::PathBuf;
use std::process::ExitCode;

/// Bytes of one ray record.
const RAY_BYTES: usize = 32;

/// Arguments of `dualsplit trace`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params.
    #[arg(value_parser = parse_scene)]
    scene: String,
    /// The rays: 32-byte little-endian records (origin, direction, t_min, t_max as f32).
    #[arg(long, value_name = "FILE")]
    rays: PathBuf,
    /// Traversal: bvh2, bvh4, bvh8, dst-sw, dst, cwbvh or dst-q (default bvh2; with --tree,
    /// the saved structure's first traversal).
    #[arg(long, value_parser = parse_accel)]
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

/// The rays of `bytes`, 32-byte records.
fn parse_rays(bytes: &[u8], file: &std::path::Path) -> anyhow::Result<Vec<Ray>> {
    if !bytes.len().is_multiple_of(RAY_BYTES) {
        bail!(
            "{}: {} bytes is not a whole number of {RAY_BYTES}-byte ray records",
            file.display(),
            bytes.len()
        );
    }
    Ok(bytes
        .chunks_exact(RAY_BYTES)
        .map(|r| {
            let f =
                |i: usize| f32::from_le_bytes([r[4 * i], r[4 * i + 1], r[4 * i + 2], r[4 * i + 3]]);
            Ray {
                origin: Vec3::new(f(0), f(1), f(2)),
                dir: Vec3::new(f(3), f(4), f(5)),
                t_min: f(6),
                t_max: f(7),
            }
        })
        .collect())
}

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    crate::output::check_file(&args.output, "-o")?;
    let bytes = std::fs::read(&args.rays)
        .with_context(|| format!("reading rays {}", args.rays.display()))?;
    let rays = parse_rays(&bytes, &args.rays)?;
    let scene = super::load(&args.scene, ctx)?;
    let structures = Loaded::get(&scene, args.tree.as_deref(), ctx)?;
    let kind = match args.accel {
        Some(k) => {
            structures.require(k.name(), k)?;
            k
        }
        None => match &structures {
            Loaded::Saved { .. } | Loaded::Some { .. } => structures.kinds()[0],
            Loaded::Built { .. } => AccelKind::Bvh2,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_records_are_read_in_order_and_partial_records_refused() {
        let vals: Vec<f32> = (0..16).map(|i| i as f32).collect();
        let bytes: Vec<u8> = vals.iter().flat_map(|v| v.to_le_bytes()).collect();
        let rays = parse_rays(&bytes, std::path::Path::new("r")).unwrap();
        assert_eq!(rays.len(), 2);
        assert_eq!(rays[1].origin, Vec3::new(8.0, 9.0, 10.0));
        assert_eq!((rays[1].t_min, rays[1].t_max), (14.0, 15.0));
        let e = parse_rays(&bytes[..40], std::path::Path::new("r")).unwrap_err();
        assert!(e.to_string().contains("not a whole number"), "{e}");
    }
}
