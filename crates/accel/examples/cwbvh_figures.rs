//! The figures of `docs/cwbvh-encoding.md`: the compressed BVH8's size against the BVH8
//! and the BVH2, its quantization growth, and per ray the child boxes hit, nodes visited
//! and triangles tested against the BVH8 (same tree, exact boxes) on recorded rays.
//!
//! `cargo run --release -p dualsplit-accel --example cwbvh_figures`; a scene that is not
//! there is reported, and the run fails when none is.

use dualsplit_accel::cwbvh::Cwbvh;
use dualsplit_accel::{BuildConfig, BvhImage, NodeStep, Observer, Structures};
use dualsplit_geometry::Triangle;
use dualsplit_testkit::rays::record_rays;
use dualsplit_testkit::scenes::shipped;
use std::process::ExitCode;

/// The structures compared, all with leaves of at most 4 triangles.
struct Built<'a> {
    tris: &'a [Triangle],
    bvh2: &'a BvhImage,
    bvh8: &'a BvhImage,
    cw: &'a Cwbvh,
}

/// Counts the child boxes hit (`NodeStep::Bvh` hits), nodes and triangle tests.
#[derive(Default, Clone, Copy)]
struct BoxHits {
    hits: u64,
    nodes: u64,
    tris: u64,
}
impl Observer for BoxHits {
    fn step(&mut self, s: NodeStep) {
        if let NodeStep::Bvh { hits, .. } = s {
            self.hits += hits as u64;
            self.nodes += 1;
        }
    }
    fn triangle_test(&mut self, _: dualsplit_geometry::PrimId, _: bool) {
        self.tris += 1;
    }
}

/// The figures of `docs/cwbvh-encoding.md`: sizes against BVH8 and BVH2, quantization
/// growth, and per ray the child boxes hit, nodes visited and triangles tested by the
/// compressed BVH8 against the BVH8 (same tree, exact boxes) on recorded rays.
fn figures(name: &str) -> bool {
    let Some(scene) = shipped(name) else {
        println!("{name}: skipped, not found (scripts/get-scenes.sh fetches it)");
        return false;
    };
    let cfg = BuildConfig {
        max_leaf_size: 4,
        ..BuildConfig::default()
    };
    let s = Structures::build(&scene.triangles, &cfg);
    let rays = record_rays(&scene, &s, 200, 40_000);
    let b = Built {
        tris: &scene.triangles,
        bvh2: s.bvh2_image(),
        bvh8: s.bvh8(),
        cw: s.cwbvh(),
    };
    {
        println!(
            "{name}: {} triangles; bytes cwbvh {} bvh8 {} bvh2 {} ({:.1} % of BVH8, {:.1} % of BVH2); {} nodes, {} leaves",
            b.tris.len(),
            b.cw.bytes_total(),
            b.bvh8.bytes_total(),
            b.bvh2.bytes_total(),
            100.0 * b.cw.bytes_total() as f64 / b.bvh8.bytes_total() as f64,
            100.0 * b.cw.bytes_total() as f64 / b.bvh2.bytes_total() as f64,
            b.cw.internal_nodes(),
            b.cw.leaves(),
        );
        println!("  {:?}", b.cw.quantization_stats());
        for (what, set, any) in [
            ("primary", &rays.primary, false),
            ("diffuse", &rays.diffuse, false),
            ("shadow", &rays.shadow, true),
        ] {
            let (mut q, mut x) = (BoxHits::default(), BoxHits::default());
            for ray in set.iter() {
                if any {
                    b.cw.any_hit_image(ray, &mut q);
                    b.bvh8.any_hit_image(ray, &mut x);
                } else {
                    b.cw.closest_hit_image(ray, &mut q);
                    b.bvh8.closest_hit_image(ray, &mut x);
                }
            }
            let n = set.len() as f64;
            println!(
                "  {what} ({} rays): box hits/ray cwbvh {:.3} bvh8 {:.3} (+{:.3}, +{:.2} %); nodes/ray {:.3} vs {:.3}; triangle tests/ray {:.3} vs {:.3}",
                set.len(),
                q.hits as f64 / n,
                x.hits as f64 / n,
                (q.hits as f64 - x.hits as f64) / n,
                100.0 * (q.hits as f64 / x.hits as f64 - 1.0),
                q.nodes as f64 / n,
                x.nodes as f64 / n,
                q.tris as f64 / n,
                x.tris as f64 / n,
            );
        }
    }
    true
}

fn main() -> ExitCode {
    let names = ["dragon_res4.ply.gz", "bunny.ply.gz"];
    let measured = names.iter().filter(|n| figures(n)).count();
    println!("{measured} of {} scenes measured", names.len());
    if measured == 0 {
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
