//! `dualsplit check`: validate every structure of a scene and check that every structure
//! answers every ray exactly like the BVH2 (closest `t` bits and triangle id; any-hit
//! answer), for primary, shadow and diffuse-bounce rays recorded from path-traced pixel
//! jobs on the scene's default camera. BVH2, BVH4, BVH8, the DST software decoder (dst-sw)
//! and the DST pipeline loop (dst) are all compared. Validation includes the DST rebuilding
//! every BVH2 box from its planes. Exits nonzero on any failure.
//!
//! With `--tree FILE` the saved structure is checked instead: validated (a DST against a
//! BVH2 built afresh from the scene with the tree's build settings), and each of its
//! traversals compared ray by ray with that fresh BVH2, which also records the rays. So
//! a saved file that passes answers every ray as a build from the scene would.
use crate::loaded::Loaded;
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::{
    AccelKind, AnyTree, Bvh2Tree, CountingObserver, NoObserver, TraversalSet, ValidationReport,
};
use dualsplit_render::RayKind;
use dualsplit_scene::Scene;
use rayon::prelude::*;
use std::process::ExitCode;

/// Arguments of `dualsplit check`.
#[derive(clap::Args)]
pub struct Args {
    /// Scene: a file (.obj, .ply, .gltf, .glb, optionally .gz) or builtin:NAME?params
    /// (hairball, forest, atrium, cornell).
    #[arg(value_parser = crate::args::parse_scene)]
    scene: String,
    /// Rays of each kind (primary, shadow, diffuse) to compare.
    #[arg(long, default_value_t = 20_000, value_parser = super::rays::parse_count)]
    rays: usize,
    /// Check the tree saved in FILE by `dualsplit build` instead of every structure: it must
    /// come from SCENE (its triangles are checked); it is validated and each of its
    /// traversals is compared ray by ray with a BVH2 built afresh from SCENE.
    #[arg(long, value_name = "FILE")]
    tree: Option<std::path::PathBuf>,
}

/// Most ray mismatches printed per structure and ray kind.
const SHOW: usize = 5;

/// Runs the subcommand.
pub fn run(args: Args, ctx: &Ctx) -> anyhow::Result<ExitCode> {
    let scene = super::load(&args.scene, ctx)?;
    let subject = Loaded::get(&scene, args.tree.as_deref(), ctx)?;
    outln!("{} ({} triangles)", scene.name, scene.triangles.len());
    let failed = match &subject {
        Loaded::Built { structures, .. } => {
            let failed = print_validation(&structures.validate());
            equivalence(&scene, structures, structures, args.rays, ctx) || failed
        }
        // `Loaded::get` builds every structure or loads one tree.
        Loaded::Some { .. } => unreachable!("check never builds a partial set"),
        Loaded::Saved { tree, .. } => {
            outln!("{}", subject.summary());
            // The reference: a BVH2 built afresh from the scene, with the tree's settings.
            let sp = ctx.spinner("building the reference BVH2");
            let fresh = Bvh2Tree::build(&scene.triangles[..], tree.config())
                .with_context(|| format!("building the reference BVH2 of {}", scene.spec))?;
            sp.finish_and_clear();
            outln!(
                "reference: bvh2 built from the scene in {:.1} ms",
                fresh.stats().build_ms
            );
            let report = tree.validate(fresh.logical());
            let failed = print_validation(&[report]);
            let reference = AnyTree::from(fresh.into_tree());
            equivalence(&scene, &reference, tree, args.rays, ctx) || failed
        }
    };
    if failed {
        outln!("check FAILED");
        Ok(ExitCode::FAILURE)
    } else {
        outln!("check passed");
        Ok(ExitCode::SUCCESS)
    }
}

/// Prints the validation reports; true when one failed.
fn print_validation(reports: &[ValidationReport]) -> bool {
    let mut failed = false;
    outln!("validation:");
    for rep in reports {
        outln!(
            "  {:<5} {:<4} internal {:>9} leaves {:>9} triangles {:>9}/{:<9} max depth {:>3} errors {}",
            rep.structure,
            if rep.is_ok() { "ok" } else { "FAIL" },
            rep.internal_nodes,
            rep.leaves,
            rep.triangles_referenced,
            rep.triangles,
            rep.max_depth,
            rep.error_count
        );
        for e in &rep.errors {
            outln!("        {e}");
        }
        failed |= !rep.is_ok();
    }
    failed
}

/// Records `n` rays of each kind on `reference`'s BVH2 and compares every traversal of
/// `subject` with it, ray by ray; prints a table and returns true on any mismatch.
fn equivalence(
    scene: &Scene,
    reference: &impl TraversalSet,
    subject: &impl TraversalSet,
    n: usize,
    ctx: &Ctx,
) -> bool {
    let mut failed = false;
    let sets = super::rays::record(scene, reference, n, ctx);
    outln!("equivalence against BVH2 (per-ray averages from CountingObserver):");
    outln!(
        "  {:<8} {:<8} {:>8} {:>10} {:>8} {:>8} {:>10} {:>10} {:>10} {:>10}",
        "kind",
        "rays",
        "count",
        "mismatch",
        "nodes",
        "leaves",
        "boxes",
        "planes",
        "triangles",
        "bytes"
    );
    for (what, rays) in [
        (RayKind::Primary, &sets.0),
        (RayKind::Shadow, &sets.1),
        (RayKind::Diffuse, &sets.2),
    ] {
        // BVH2's answers (its plain query), computed once per ray set.
        let wants: Vec<Answer> = rays
            .par_iter()
            .map(|r| answer(reference, AccelKind::Bvh2, what, r, &mut NoObserver))
            .collect();
        for &kind in subject.kinds() {
            let bar = ctx.bar(rays.len() as u64, format!("{} {:?}", kind.name(), what));
            let (counts, bad) = rays
                .par_chunks(1024)
                .zip(wants.par_chunks(1024))
                .map(|(chunk, want)| {
                    let mut c = CountingObserver::default();
                    let mut bad = Vec::new();
                    for (ray, want) in chunk.iter().zip(want) {
                        // The observed traversal (the memory image, as the simulator reads
                        // it) and the plain query (a BVH's CPU-side copy, the DST's plain
                        // decoder) must both give the reference's answer.
                        if answer(subject, kind, what, ray, &mut c) != *want
                            || answer(subject, kind, what, ray, &mut NoObserver) != *want
                        {
                            bad.push(*ray);
                        }
                    }
                    bar.inc(chunk.len() as u64);
                    (c, bad)
                })
                .reduce(
                    || (CountingObserver::default(), Vec::new()),
                    |mut a, b| {
                        a.0.add(&b.0);
                        a.1.extend(b.1);
                        a
                    },
                );
            bar.finish_and_clear();
            let n = rays.len().max(1) as f64;
            outln!(
                "  {:<8} {:<8} {:>8} {:>10} {:>8.2} {:>8.2} {:>10.2} {:>10.2} {:>10.2} {:>10.1}",
                kind.name(),
                format!("{what:?}").to_lowercase(),
                rays.len(),
                bad.len(),
                counts.nodes as f64 / n,
                counts.leaves as f64 / n,
                counts.box_tests as f64 / n,
                counts.plane_tests as f64 / n,
                counts.triangle_tests as f64 / n,
                counts.bytes as f64 / n
            );
            for r in bad.iter().take(SHOW) {
                outln!("        mismatch: {r:?}");
            }
            failed |= !bad.is_empty();
        }
    }
    failed
}

/// A ray's answer in comparable form: closest hit as (`t` bits, triangle id), or for shadow
/// rays whether anything blocks the segment.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Answer {
    Closest(Option<(u32, dualsplit_geometry::PrimId)>),
    Occluded(bool),
}

fn answer(
    s: &impl TraversalSet,
    kind: AccelKind,
    what: RayKind,
    ray: &dualsplit_geometry::Ray,
    obs: &mut impl dualsplit_accel::Observer,
) -> Answer {
    if what == RayKind::Shadow {
        Answer::Occluded(s.any_hit(kind, ray, obs))
    } else {
        Answer::Closest(
            s.closest_hit(kind, ray, obs)
                .map(|h| (h.t.to_bits(), h.prim)),
        )
    }
}
