//! Simulator speed. `cargo bench -p dualsplit-sim`.
//!
//! `frame_dragon_rv32`: the compiled kernels (thread model `rv32`) on a 64×64 path-traced
//! frame of the shipped `dragon_box.ply.gz`, BVH2 and DST, counted in simulated
//! instructions (the bar: ≥ 10 M per host second per core). The other benches time the
//! `fast` thread model (the macro-op replay), counted in simulated node visits:
//!
//! `engine_node_visits`: the lin2020 chip (64 TMs × 32 threads) replaying a synthetic
//! BVH2-like stream: per node visit one 13-word (52-byte) node load at a random node of a
//! 16 MB depth-first region (so L1, L2 and DRAM all see traffic), 2 serial box ops and 17
//! instructions; every 8th visit a 9-word triangle load and a triangle op. The counter is
//! node visits. `frame_soup`: a whole 128×128 path-traced frame (functional traversal +
//! timing) on a seeded 20 000-triangle soup, counted in simulated node visits.
//! `frame_atrium`: a whole 64×64 path-traced frame of the builtin architectural scene
//! (`builtin:atrium`) in each of the eight configurations, counted the same way (a BVH8
//! visit loads a 200-byte node and tests 8 boxes, a DST visit one 8–20-byte node).
//! `frame_dragon`: a 128×128 path-traced frame of the shipped `dragon_box.ply.gz` (found by
//! `dualsplit_testkit::scenes::shipped`; skipped with a note when the file is absent),
//! every configuration.
//!
//! The synthetic stream is a stress case, not a typical frame: 1.54 DRAM reads per visit
//! and 100-visit programs, where the dragon_box 512² BVH2 path frame makes 0.20 DRAM reads
//! per visit and 11.7 visits per ray.

use divan::counter::ItemsCount;
use dualsplit_geometry::{Pcg32, Triangle, Vec3};
use dualsplit_sim::hw::atomic::AtomicUnit;
use dualsplit_sim::hw::{Chip, Stalls, pipe::Pipe};
use dualsplit_sim::model::fast::op::Op;
use dualsplit_sim::model::fast::replay::{WorkSource, run as run_chip};
use dualsplit_sim::model::fast::thread::Thread;
use dualsplit_sim::{FrameRequest, SimAccel, SimConfig, SimResult, ThreadModel, simulate};
use std::sync::OnceLock;

fn main() {
    divan::main();
}

struct Synthetic {
    rng: Pcg32,
    programs_left: u64,
    visits_per_program: u32,
}

impl WorkSource for Synthetic {
    /// Reuses the thread's finished program buffer, as the real workload does, sized for
    /// the whole program (3 ops per visit, 2 more every 8th), so the generator does not
    /// reallocate and copy inside the measured replay.
    fn next(
        &mut self,
        _id: usize,
        t: &mut Thread,
        _a: &mut AtomicUnit,
        _s: &mut Stalls,
    ) -> Option<Vec<Op>> {
        if self.programs_left == 0 {
            return None;
        }
        self.programs_left -= 1;
        let v = self.visits_per_program as usize;
        let mut ops = t.take_ops();
        ops.clear();
        ops.reserve_exact(3 * v + 2 * (v / 8));
        for v in 0..self.visits_per_program {
            let node = self.rng.below(16 * 1024 * 1024 / 52) as u64;
            ops.push(Op::Load {
                word: (node * 13) as u32,
                words: 13,
            });
            ops.push(Op::Pipe {
                pipe: Pipe::Box,
                n: 2,
                parallel: false,
            });
            ops.push(Op::Issue { n: 17, fpinv: 0 });
            if v % 8 == 7 {
                let tri = self.rng.below(1 << 20) as u64;
                ops.push(Op::Load {
                    word: ((1 << 24) + tri * 9) as u32,
                    words: 9,
                });
                ops.push(Op::Pipe {
                    pipe: Pipe::Triangle,
                    n: 1,
                    parallel: false,
                });
            }
        }
        Some(ops)
    }
}

#[divan::bench(sample_count = 5)]
fn engine_node_visits(b: divan::Bencher) {
    let cfg = SimConfig::lin2020();
    let threads = cfg.tms * cfg.tps_per_tm;
    let programs = threads as u64 * 2;
    let visits = 100u32;
    b.counter(ItemsCount::new(programs * visits as u64))
        .bench(|| {
            let mut chip = Chip::new(&cfg, 1);
            let mut th: Vec<Thread> = (0..threads)
                .map(|i| Thread::new((i / cfg.tps_per_tm) as usize))
                .collect();
            let mut w = Synthetic {
                rng: Pcg32::new(1, 2),
                programs_left: programs,
                visits_per_program: visits,
            };
            run_chip(&mut chip, &mut th, &mut w)
        });
}

/// A frame bench's scene with its structures, built once per bench function: divan calls
/// the function once per configuration, and every configuration reads the same structures
/// (dragon_box takes ≈ 2 s to load and build).
type Built = (dualsplit_scene::Scene, dualsplit_accel::Structures);

/// `None` when the scene could not be had.
type Prepared = Option<Built>;

/// Builds `cell`'s scene on first use (`None`: the scene could not be had; said once).
fn prepared(
    cell: &'static OnceLock<Prepared>,
    scene: impl FnOnce() -> Result<dualsplit_scene::Scene, String>,
) -> Option<&'static Built> {
    cell.get_or_init(|| match scene() {
        Ok(scene) => {
            let s = dualsplit_accel::Structures::build(&scene.triangles, &Default::default());
            Some((scene, s))
        }
        Err(e) => {
            eprintln!("frame bench skipped: {e}");
            None
        }
    })
    .as_ref()
}

/// Simulates a `res`² path-traced frame of the prepared scene with the `fast` thread model
/// once to count its node visits, then times it.
fn bench_frame(b: divan::Bencher, prepared: Option<&'static Built>, accel: SimAccel, res: u32) {
    bench_model(b, prepared, ThreadModel::Fast, accel, res, |r| {
        r.instructions.node_steps
    });
}

/// Simulates a `res`² path-traced frame once with thread model `model` to count `items`,
/// then times it.
fn bench_model(
    b: divan::Bencher,
    prepared: Option<&'static Built>,
    model: ThreadModel,
    accel: SimAccel,
    res: u32,
    items: fn(&SimResult) -> u64,
) {
    let Some((scene, s)) = prepared else {
        return;
    };
    let settings =
        dualsplit_render::RenderSettings::new(res, res, dualsplit_render::Workload::Path);
    let cfg = SimConfig::lin2020();
    let sim = || {
        simulate(
            &FrameRequest::new(scene, s, accel, &settings, &cfg).with_model(model),
            &|_, _| {},
        )
        .unwrap()
    };
    b.counter(ItemsCount::new(items(&sim()))).bench(sim);
}

#[divan::bench(args = [SimAccel::Bvh2, SimAccel::Dst], sample_count = 3)]
fn frame_soup(b: divan::Bencher, accel: SimAccel) {
    static SOUP: OnceLock<Prepared> = OnceLock::new();
    let soup = prepared(&SOUP, || {
        let mut rng = Pcg32::new(7, 1);
        let tris: Vec<Triangle> = (0..20_000)
            .map(|_| {
                let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
                let mut v = || {
                    c + Vec3::new(
                        rng.range_f32(-0.02, 0.02),
                        rng.range_f32(-0.02, 0.02),
                        rng.range_f32(-0.02, 0.02),
                    )
                };
                let (a, b, d) = (v(), v(), v());
                Triangle::new(a, b, d)
            })
            .collect();
        dualsplit_scene::Scene::from_triangles("soup", "bench:soup", tris, Default::default())
            .map_err(|e| e.to_string())
    });
    bench_frame(b, soup, accel, 128);
}

#[divan::bench(args = SimAccel::ALL, sample_count = 3)]
fn frame_atrium(b: divan::Bencher, accel: SimAccel) {
    static ATRIUM: OnceLock<Prepared> = OnceLock::new();
    let atrium = prepared(&ATRIUM, || {
        dualsplit_scene::builtin::generate("atrium").map_err(|e| e.to_string())
    });
    bench_frame(b, atrium, accel, 64);
}

#[divan::bench(args = SimAccel::ALL, sample_count = 3)]
fn frame_dragon(b: divan::Bencher, accel: SimAccel) {
    bench_frame(b, dragon(), accel, 128);
}

#[divan::bench(args = [SimAccel::Bvh2, SimAccel::Dst], sample_count = 3)]
fn frame_dragon_rv32(b: divan::Bencher, accel: SimAccel) {
    bench_model(b, dragon(), ThreadModel::Rv32, accel, 64, |r| {
        r.instructions.total()
    });
}

/// The shipped Dragon Box, built once.
fn dragon() -> Option<&'static Built> {
    static DRAGON: OnceLock<Prepared> = OnceLock::new();
    prepared(&DRAGON, || {
        dualsplit_testkit::scenes::shipped("dragon_box.ply.gz")
            .ok_or_else(|| "dragon_box.ply.gz not found".to_string())
    })
}
