//! The measurement table of `docs/dstq-encoding.md`, §7: for every measured plane width
//! and cluster size, the quantized DST's size against the exact DST and the BVH2, and per
//! ray the bytes, 64-byte lines, node steps and triangle tests on primary and random rays,
//! against the exact DST.
//!
//! `cargo run --release -p dualsplit-accel --example dstq_table` (about 5 s); a scene that
//! is not there is reported, and the run fails when none is.

use dualsplit_accel::dst::Dst;
use dualsplit_accel::dstq::{DstQ, DstQConfig};
use dualsplit_accel::{BuildConfig, ByteAddr, CountingObserver, Observer, Structures};
use dualsplit_geometry::{Pcg32, Ray};
use dualsplit_testkit::rays::{random_rays, record_rays};
use dualsplit_testkit::scenes::shipped;
use std::collections::HashSet;
use std::process::ExitCode;

/// Per-ray work of one structure on one ray set.
#[derive(Default, Clone, Copy)]
struct Work {
    nodes: f64,
    tris: f64,
    bytes: f64,
    lines: f64,
}

/// Counts bytes and the distinct 64-byte lines a ray touches.
#[derive(Default)]
struct Lines {
    c: CountingObserver,
    lines: HashSet<u64>,
}
impl Observer for Lines {
    fn fetch(&mut self, addr: ByteAddr, bytes: u32) {
        self.c.fetch(addr, bytes);
        for l in addr.0 / 64..=(addr.0 + bytes as u64 - 1) / 64 {
            self.lines.insert(l);
        }
    }
    fn step(&mut self, s: dualsplit_accel::NodeStep) {
        self.c.step(s);
    }
    fn triangle_test(&mut self, p: dualsplit_geometry::PrimId, h: bool) {
        self.c.triangle_test(p, h);
    }
}

fn work(rays: &[Ray], mut f: impl FnMut(&Ray, &mut Lines)) -> Work {
    let mut w = Work::default();
    for r in rays {
        let mut o = Lines::default();
        f(r, &mut o);
        w.nodes += o.c.nodes as f64;
        w.tris += o.c.triangle_tests as f64;
        w.bytes += o.c.bytes as f64;
        w.lines += o.lines.len() as f64;
    }
    let n = rays.len().max(1) as f64;
    Work {
        nodes: w.nodes / n,
        tris: w.tris / n,
        bytes: w.bytes / n,
        lines: w.lines / n,
    }
}

fn measure(name: &str, configs: &[DstQConfig]) -> bool {
    let Some(scene) = shipped(name) else {
        println!("\n{name}: skipped, not found (scripts/get-scenes.sh fetches it)");
        return false;
    };
    let s = Structures::build(&scene.triangles, &BuildConfig::default());
    let sets = record_rays(&scene, &s, 128, 16384);
    let b = s.dst().scene_box();
    let random = random_rays(&mut Pcg32::new(5, 5), &scene.triangles, &b, 16384);
    let sets = [("primary", &sets.primary), ("random", &random)];
    let dst: &Dst = s.dst();
    let dst_bytes = dst.stats().total_bytes as f64;
    let bvh2_bytes = s.bvh2_image().bytes_total() as f64;
    let exact: Vec<Work> = sets
        .iter()
        .map(|(_, r)| {
            work(r, |ray, o| {
                dst.closest_hit(ray, o);
            })
        })
        .collect();
    println!(
        "\n{name}: exact DST {:.3} MiB ({:.1} % of BVH2 {:.3} MiB)",
        dst_bytes / 1048576.0,
        100.0 * dst_bytes / bvh2_bytes,
        bvh2_bytes / 1048576.0
    );
    for ((set, rays), e) in sets.iter().zip(&exact) {
        println!(
            "  exact DST, {set} ({} rays): {:.2} nodes, {:.2} triangles, {:.0} B, {:.2} lines per ray",
            rays.len(),
            e.nodes,
            e.tris,
            e.bytes,
            e.lines
        );
    }
    println!(
        "| k | line | MiB | % DST | % BVH2 | B/node | fill | clusters | prim B/ray | prim lines | prim +nodes | prim +tris | rand B/ray | rand lines | rand +nodes | rand +tris |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for cfg in configs {
        let q = DstQ::from_dst(dst, cfg).unwrap();
        assert!(q.validate(dst).is_ok());
        let st = q.stats();
        let tot = q.bytes_total() as f64;
        let mut row = format!(
            "| {} | {} | {:.3} | {:.1} | {:.1} | {:.2} | {:.0} % | {} |",
            cfg.bits,
            cfg.cluster_bytes,
            tot / 1048576.0,
            100.0 * tot / dst_bytes,
            100.0 * tot / bvh2_bytes,
            st.bytes_per_node(),
            100.0 * st.fill(),
            st.clusters
        );
        for ((_, rays), e) in sets.iter().zip(&exact) {
            let w = work(rays, |ray, o| {
                q.closest_hit(ray, o);
            });
            row += &format!(
                " {:.0} | {:.2} | {:+.1} % | {:+.1} % |",
                w.bytes,
                w.lines,
                100.0 * (w.nodes / e.nodes - 1.0),
                100.0 * (w.tris / e.tris - 1.0)
            );
        }
        println!("{row}");
    }
    true
}

fn main() -> ExitCode {
    let mut configs = Vec::new();
    for &cluster_bytes in &DstQConfig::MEASURED_CLUSTER_BYTES {
        for &bits in &DstQConfig::MEASURED_BITS {
            configs.push(DstQConfig {
                bits,
                cluster_bytes,
            });
        }
    }
    let names = ["dragon_res4.ply.gz", "bunny.ply.gz"];
    let measured = names.iter().filter(|n| measure(n, &configs)).count();
    println!("\n{measured} of {} scenes measured", names.len());
    if measured == 0 {
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
