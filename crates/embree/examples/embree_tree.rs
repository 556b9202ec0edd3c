//! Our CPU traversal on Embree's tree: tells the tree's quality apart from the cost of
//! traversing it.
//!
//! Embree's own SAH builder (`rtcBuildBVH`, [`TreeArgs::bvh8_triangle4`]: the settings of the
//! BVH8 it builds for a triangle scene) builds a BVH8 over the scene's triangle boxes; the
//! tree is encoded as a BVH8 image and given the CPU-side copy our `bvh8` queries use, so
//! the same traversal code runs on three trees: ours (the BVH2 collapsed, Ylitie et al.),
//! Embree's, and Embree's high-quality tree with spatial splits ([`build_tree_split`]: a
//! triangle may sit in several leaves, each under a box of its part there). Every answer of
//! the Embree-tree copies is checked against BVH2's, ray by ray, on
//! the bench's ray sets (a path-traced frame's primary, shadow and diffuse rays); then per ray
//! work (node steps, box and triangle tests, counted on each image's traversal) and single-thread
//! throughput, alternated pass by pass with Embree's `rtcIntersect1`/`rtcOccluded1`
//! (medians of `PASSES` passes).
//!
//! `cargo run --release -p dualsplit-embree --example embree_tree -- SCENE [RES] [PASSES]`
//! (RES: RES×RES frame, 128 by default; PASSES 7). Needs Debian's `libembree-dev`.

use dualsplit_accel::wide::cpu::{CpuBvh, SimdLevel, merge_limit};
use dualsplit_accel::wide::{WideChild, WideNode};
use dualsplit_accel::{BuildConfig, Bvh2, BvhImage, CountingObserver, Structures, WideBvh};
use dualsplit_embree::EmbreeScene;
use dualsplit_embree::tree::{BuiltTree, Child, TreeArgs, build_tree, build_tree_split};
use dualsplit_geometry::Aabb;
use dualsplit_render::bench::{RaySet, ray_sets};
use dualsplit_render::{RayKind, RenderSettings, TraceResult, Workload};
use std::io::Write;
use std::time::{Duration, Instant};

/// Embree's tree as a BVH8 over leaf runs: the wide tree and the primitive ids its leaves
/// index.
fn as_wide(t: &BuiltTree, boxes: &[Aabb]) -> (WideBvh, Vec<u32>) {
    let mut prim_ids = Vec::new();
    let mut leaf = |l: u32| {
        let ids = &t.leaves[l as usize];
        let first = prim_ids.len() as u32;
        prim_ids.extend_from_slice(ids);
        WideChild::Leaf {
            first,
            count: ids.len() as u32,
        }
    };
    let nodes = match t.root {
        Child::Leaf(l) => {
            let b = t.leaves[l as usize]
                .iter()
                .fold(Aabb::EMPTY, |b, &p| b.union(boxes[p as usize]));
            vec![WideNode {
                children: vec![(b, leaf(l))],
            }]
        }
        Child::Node(_) => t
            .nodes
            .iter()
            .map(|n| WideNode {
                children: n
                    .iter()
                    .map(|&(b, c)| {
                        let c = match c {
                            Child::Node(i) => WideChild::Node(i),
                            Child::Leaf(l) => leaf(l),
                        };
                        (b, c)
                    })
                    .collect(),
            })
            .collect(),
    };
    (WideBvh { arity: 8, nodes }, prim_ids)
}

/// One traversal under test.
enum Tracer<'a> {
    Copy(&'a CpuBvh),
    Embree(&'a EmbreeScene),
}

impl Tracer<'_> {
    fn trace(&self, kind: RayKind, r: &dualsplit_geometry::Ray) -> TraceResult {
        match (self, kind) {
            (Tracer::Copy(c), RayKind::Shadow) => {
                TraceResult::Occluded(c.traverse::<true>(r).expect("finite scene").is_some())
            }
            (Tracer::Copy(c), _) => TraceResult::Closest(c.traverse::<false>(r).expect("finite")),
            (Tracer::Embree(e), RayKind::Shadow) => TraceResult::Occluded(e.occluded(r)),
            (Tracer::Embree(e), _) => TraceResult::Closest(e.intersect(r)),
        }
    }
}

/// Per-ray work on an image's traversal: node steps, box tests, triangle tests.
fn work(img: &BvhImage, set: &RaySet) -> [f64; 3] {
    let mut obs = CountingObserver::default();
    for r in &set.rays {
        if set.kind == RayKind::Shadow {
            img.any_hit_image(r, &mut obs);
        } else {
            img.closest_hit_image(r, &mut obs);
        }
    }
    let n = set.rays.len().max(1) as f64;
    [obs.nodes, obs.box_tests, obs.triangle_tests].map(|c| c as f64 / n)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Written with `?`: a reader that stops early (`| head`) ends the example with an
    // error, not a panic.
    let mut out = std::io::stdout().lock();
    let mut args = std::env::args().skip(1);
    let spec = args
        .next()
        .ok_or("usage: embree_tree SCENE [RES] [PASSES]")?;
    let res: u32 = args.next().map_or(Ok(128), |r| r.parse())?;
    let passes: usize = args.next().map_or(Ok(7), |r| r.parse())?;
    let scene = dualsplit_scene::load(&spec)?;
    let cfg = BuildConfig::default();
    let s = Structures::try_build(&scene.triangles, &cfg)?;
    let sets = ray_sets(&scene, &s, &RenderSettings::new(res, res, Workload::Path))?;

    let boxes: Vec<_> = scene.triangles.iter().map(|t| t.bounds()).collect();
    let t0 = Instant::now();
    let tree = build_tree(&boxes, &TreeArgs::bvh8_triangle4())?;
    let build = t0.elapsed();
    let (wide, prim_ids) = as_wide(&tree, &boxes);
    let fake = Bvh2 {
        nodes: Vec::new(),
        prim_ids,
        sah_cost: 0.0,
    };
    let theirs = BvhImage::encode(&wide, &fake, s.triangles.clone(), &cfg, build)?;
    let report = theirs.validate();
    if !report.is_ok() {
        return Err(format!("Embree's tree encodes to an invalid image: {report:?}").into());
    }
    // Leaves share triangles, which the image's checks refuse (each triangle once); every
    // answer of its copy is checked against BVH2's below instead.
    let t0 = Instant::now();
    let split = build_tree_split(&scene.triangles, &TreeArgs::bvh8_triangle4())?;
    let split_build = t0.elapsed();
    let (split_wide, split_ids) = as_wide(&split, &boxes);
    let refs = split_ids.len();
    let split_ids = Bvh2 {
        nodes: Vec::new(),
        prim_ids: split_ids,
        sah_cost: 0.0,
    };
    let split_img = BvhImage::encode(
        &split_wide,
        &split_ids,
        s.triangles.clone(),
        &cfg,
        split_build,
    )?;
    let leaves = tree.leaves.len().max(1) as f64;
    let tris: usize = tree.leaves.iter().map(Vec::len).sum();
    writeln!(
        out,
        "{spec}: {} triangles; Embree's BVH8 ({:?}): {} nodes, {} leaves of {:.2} triangles, built in {:.0} ms; ours: {} nodes, {} leaves",
        scene.triangles.len(),
        TreeArgs::bvh8_triangle4(),
        tree.nodes.len(),
        tree.leaves.len(),
        tris as f64 / leaves,
        build.as_secs_f64() * 1e3,
        s.bvh8().internal_nodes,
        s.bvh8().leaves,
    )?;
    writeln!(
        out,
        "Embree's BVH8 with spatial splits: {} nodes, {} leaves, {refs} triangle references (+{:.0} %), built in {:.0} ms",
        split.nodes.len(),
        split.leaves.len(),
        100.0 * (refs as f64 / scene.triangles.len() as f64 - 1.0),
        split_build.as_secs_f64() * 1e3,
    )?;

    let level = SimdLevel::detect();
    let merge = merge_limit();
    let copies = [
        ("ours", s.bvh8().cpu_copy_with(level, merge)),
        ("ours, no merge", s.bvh8().cpu_copy_with(level, 0)),
        ("Embree's tree", theirs.cpu_copy_with(level, merge)),
        ("Embree's tree, no merge", theirs.cpu_copy_with(level, 0)),
        ("Embree's split tree", split_img.cpu_copy_with(level, merge)),
    ];
    let embree = EmbreeScene::new(&scene.triangles)?;
    let mut tracers: Vec<(&str, Tracer)> =
        copies.iter().map(|(n, c)| (*n, Tracer::Copy(c))).collect();
    tracers.push(("Embree rtcIntersect1", Tracer::Embree(&embree)));

    // Every copy's answers against BVH2's, ray by ray (Embree is not held to them).
    for (name, t) in tracers.iter().filter(|t| matches!(t.1, Tracer::Copy(_))) {
        for set in &sets {
            for (i, (r, want)) in set.rays.iter().zip(&set.expected).enumerate() {
                let got = t.trace(set.kind, r);
                if !got.bit_eq(want) {
                    return Err(format!(
                        "{name}: {} ray {i} answers {got:?}, BVH2 {want:?}",
                        set.kind.name()
                    )
                    .into());
                }
            }
        }
    }
    let mib = |c: &CpuBvh| c.bytes() as f64 / 1048576.0;
    writeln!(
        out,
        "copies: ours {:.2} MiB ({:.2} without merging), Embree's tree {:.2} MiB, with spatial splits {:.2} MiB",
        mib(&copies[0].1),
        mib(&copies[1].1),
        mib(&copies[2].1),
        mib(&copies[4].1)
    )?;
    writeln!(
        out,
        "every answer of the five copies equals BVH2's ({} rays); {level:?}, merge limit {merge}, 1 thread, {passes} alternated passes",
        sets.iter().map(|s| s.rays.len()).sum::<usize>()
    )?;

    writeln!(
        out,
        "{:8} {:>8} {:>8} {:>8} | {:>8} {:>8} {:>8} | {:>8} {:>8} {:>8}  (per ray: BVH8 node steps, box tests, triangle tests on each image)",
        "rays", "ours", "", "", "Embree's", "", "", "splits", "", ""
    )?;
    for set in &sets {
        write!(out, "{:8}", set.kind.name())?;
        for img in [s.bvh8(), &theirs, &split_img] {
            let w = work(img, set);
            write!(out, " {:8.2} {:8.1} {:8.2} |", w[0], w[1], w[2])?;
        }
        writeln!(out)?;
    }

    writeln!(out, "Mrays/s, medians:")?;
    print!("{:8}", "rays");
    for (name, _) in &tracers {
        print!(" {name:>24}");
    }
    writeln!(out)?;
    for set in &sets {
        let mut times = vec![Vec::new(); tracers.len()];
        for _ in 0..passes {
            for (k, (_, t)) in tracers.iter().enumerate() {
                let t0 = Instant::now();
                for r in &set.rays {
                    std::hint::black_box(t.trace(set.kind, std::hint::black_box(r)));
                }
                times[k].push(t0.elapsed());
            }
        }
        print!("{:8}", set.kind.name());
        for ts in &mut times {
            ts.sort();
            let med: Duration = ts[ts.len() / 2];
            print!(" {:>24.2}", set.rays.len() as f64 / med.as_secs_f64() / 1e6);
        }
        writeln!(out)?;
    }
    Ok(())
}
