//! End-to-end tests of the simulator on small scenes and the tiny chip.

use dualsplit_accel::{DstNodeKind, NoObserver, NodeStep, Observer, Structures};
use dualsplit_geometry::{Pcg32, Triangle, Vec3};
use dualsplit_render::{PixelJob, RayKind, RenderSettings, TraceResult, Workload};
use dualsplit_scene::Scene;
use dualsplit_sim::{FrameRequest, SimAccel, SimConfig, SimResult, ThreadModel, simulate};

fn config(name: &str) -> String {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../configs/");
    std::fs::read_to_string(format!("{p}{name}")).unwrap()
}

fn tiny() -> SimConfig {
    SimConfig::from_toml(&config("tiny.toml")).unwrap()
}

/// A seeded soup of 600 small triangles in a unit cube, plus a floor (no builtin scenes
/// needed).
fn scene() -> (Scene, Structures) {
    let mut rng = Pcg32::new(7, 1);
    let mut tris = vec![
        Triangle::new(
            Vec3::new(-1.0, -0.1, -1.0),
            Vec3::new(2.0, -0.1, -1.0),
            Vec3::new(-1.0, -0.1, 2.0),
        ),
        Triangle::new(
            Vec3::new(2.0, -0.1, -1.0),
            Vec3::new(2.0, -0.1, 2.0),
            Vec3::new(-1.0, -0.1, 2.0),
        ),
    ];
    for _ in 0..600 {
        let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        let mut v = || {
            c + Vec3::new(
                rng.range_f32(-0.06, 0.06),
                rng.range_f32(-0.06, 0.06),
                rng.range_f32(-0.06, 0.06),
            )
        };
        let (a, b, d) = (v(), v(), v());
        tris.push(Triangle::new(a, b, d));
    }
    let scene = Scene::from_triangles("soup", "test:soup", tris, Default::default()).unwrap();
    let s = Structures::build(&scene.triangles, &Default::default());
    (scene, s)
}

/// A 24×16 frame on the `fast` thread model (the macro-op replay these tests describe).
fn run(scene: &Scene, s: &Structures, accel: SimAccel, wl: Workload, cfg: &SimConfig) -> SimResult {
    run_model(ThreadModel::Fast, scene, s, accel, wl, cfg)
}

fn run_model(
    model: ThreadModel,
    scene: &Scene,
    s: &Structures,
    accel: SimAccel,
    wl: Workload,
    cfg: &SimConfig,
) -> SimResult {
    let settings = RenderSettings::new(24, 16, wl);
    simulate(
        &FrameRequest::new(scene, s, accel, &settings, cfg).with_model(model),
        &|_, _| {},
    )
    .unwrap()
}

#[test]
fn lin2020_toml_equals_the_builtin_preset() {
    assert_eq!(
        SimConfig::from_toml(&config("lin2020.toml")).unwrap(),
        SimConfig::lin2020()
    );
}

#[test]
fn unknown_key_and_bad_value_are_typed_errors() {
    assert!(SimConfig::from_toml("tmz = 3").is_err());
    let e = SimConfig::from_toml("[dram]\nchannels = 3").unwrap_err();
    assert!(e.to_string().contains("dram.channels"), "{e}");
}

#[test]
fn tiny_config_parses_and_keeps_lin2020_defaults() {
    let t = tiny();
    assert_eq!(t.tms, 2);
    assert_eq!(t.dram.channels, 2);
    assert_eq!(t.dram.t_cas, SimConfig::lin2020().dram.t_cas);
}

#[test]
fn runs_are_bit_identical() {
    let (scene, s) = scene();
    let cfg = tiny();
    for accel in [SimAccel::Bvh4, SimAccel::Dst] {
        let a = run(&scene, &s, accel, Workload::Path, &cfg);
        let b = run(&scene, &s, accel, Workload::Path, &cfg);
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
        assert!(a.cycles > 0);
    }
}

#[test]
fn every_request_completes() {
    let (scene, s) = scene();
    let cfg = tiny();
    for (model, accel) in ThreadModel::ALL
        .into_iter()
        .flat_map(|m| SimAccel::ALL.map(|a| (m, a)))
    {
        let r = run_model(model, &scene, &s, accel, Workload::Path, &cfg);
        let c = &r.caches;
        if model == ThreadModel::Fast {
            // One L1 access per recorded load word.
            assert_eq!(c.l1_accesses, r.instructions.loads, "{accel:?}");
        }
        // Every L1 access hit, merged, or went to L2.
        assert_eq!(c.l1_hits + c.l1_merged + c.l2_accesses, c.l1_accesses);
        // Every L2 access hit, merged, or read DRAM.
        assert_eq!(c.l2_hits + c.l2_merged + r.dram.reads, c.l2_accesses);
        assert_eq!(
            r.dram.row_hits + r.dram.row_closed + r.dram.row_conflicts,
            r.dram.reads
        );
        // Every DRAM read returned before the frame ended.
        assert!(r.dram.last_done.get() <= r.cycles);
        // Every pipeline op that was recorded was executed.
        assert_eq!(r.units.box_ops, r.instructions.box_ops);
        assert_eq!(r.units.tri_ops, r.instructions.tri_ops);
        assert_eq!(r.units.dst_ops, r.instructions.dst_ops);
        assert_eq!(r.pixels, 24 * 16);
    }
}

#[test]
fn simulated_pixels_equal_the_renderers() {
    let (scene, s) = scene();
    let cfg = tiny();
    for wl in [Workload::Cast, Workload::Path] {
        let settings = RenderSettings::new(24, 16, wl);
        for accel in SimAccel::ALL {
            let r = simulate(
                &FrameRequest::new(&scene, &s, accel, &settings, &cfg),
                &|_, _| {},
            )
            .unwrap();
            let mut rays = 0;
            for y in 0..16 {
                for x in 0..24 {
                    let mut job = PixelJob::new(&scene, &settings, x, y);
                    while let Some(q) = job.next_ray() {
                        rays += 1;
                        let res = match q.kind {
                            RayKind::Shadow => TraceResult::Occluded(s.any_hit(
                                accel.kind(),
                                &q.ray,
                                &mut NoObserver,
                            )),
                            _ => TraceResult::Closest(s.closest_hit(
                                accel.kind(),
                                &q.ray,
                                &mut NoObserver,
                            )),
                        };
                        job.submit(res);
                    }
                    let i = (y * 24 + x) as usize;
                    assert_eq!(
                        job.radiance().to_bits(),
                        r.radiance[i].to_bits(),
                        "pixel ({x}, {y}) {accel:?} {wl:?}"
                    );
                }
            }
            assert_eq!(rays, r.rays);
        }
    }
}

/// DST (dual-split pipeline) and DST* (software decoder) run the real DST traversals over
/// the DST memory image: their pixels equal the renderer's, both see the same memory stream
/// and triangle tests, DST issues one dual-split op per DST node step (leaf words included)
/// and DST* none, paying the decoder's instructions instead.
#[test]
fn dst_and_dst_sw_pixels_equal_the_renderers_and_use_their_units() {
    let (scene, s) = scene();
    let cfg = tiny();
    for wl in [Workload::Cast, Workload::Path] {
        let settings = RenderSettings::new(24, 16, wl);
        let sim = |m, a| {
            simulate(
                &FrameRequest::new(&scene, &s, a, &settings, &cfg).with_model(m),
                &|_, _| {},
            )
            .unwrap()
        };
        let hw = sim(ThreadModel::Fast, SimAccel::Dst);
        let sw = sim(ThreadModel::Fast, SimAccel::DstSw);
        let (hw_rv32, sw_rv32) = (
            sim(ThreadModel::Rv32, SimAccel::Dst),
            sim(ThreadModel::Rv32, SimAccel::DstSw),
        );
        // Count the DST steps, fetches and triangle tests of the renderer's own rays.
        let mut counter = DstSteps::default();
        for y in 0..16 {
            for x in 0..24 {
                let mut job = PixelJob::new(&scene, &settings, x, y);
                while let Some(q) = job.next_ray() {
                    let res = match q.kind {
                        RayKind::Shadow => TraceResult::Occluded(s.any_hit(
                            SimAccel::Dst.kind(),
                            &q.ray,
                            &mut counter,
                        )),
                        _ => TraceResult::Closest(s.closest_hit(
                            SimAccel::Dst.kind(),
                            &q.ray,
                            &mut counter,
                        )),
                    };
                    job.submit(res);
                }
                let i = (y * 24 + x) as usize;
                let want = job.radiance().to_bits();
                assert_eq!(
                    hw.radiance[i].to_bits(),
                    want,
                    "DST pixel ({x}, {y}) {wl:?}"
                );
                assert_eq!(
                    sw.radiance[i].to_bits(),
                    want,
                    "DST* pixel ({x}, {y}) {wl:?}"
                );
            }
        }
        assert!(counter.nodes > 0, "the DST traversal ran: {counter:?}");
        assert_eq!(hw.units.dst_ops, counter.steps);
        // The compiled DST kernel steps the pipeline exactly as the Rust loop does; the
        // compiled DST* kernel never uses it.
        assert_eq!(hw_rv32.units.dst_ops, counter.steps, "{wl:?}");
        assert_eq!(sw_rv32.units.dst_ops, 0);
        assert_eq!(hw_rv32.radiance, hw.radiance);
        assert_eq!(sw_rv32.radiance, sw.radiance);
        assert_eq!(hw.instructions.node_steps, counter.nodes);
        assert_eq!(sw.instructions.node_steps, counter.nodes);
        assert_eq!(hw.units.box_ops, 0);
        assert_eq!(sw.units.dst_ops, 0);
        assert_eq!(sw.units.box_ops, 0);
        // The two kernels read a step's words differently (measured extra L1 words), but
        // the same lines.
        assert_eq!(hw.units.tri_ops, sw.units.tri_ops);
        assert_eq!(hw.dram_lines, sw.dram_lines);
        assert!(
            sw.instructions.total() > hw.instructions.total(),
            "software decoding issues more instructions"
        );
    }
}

/// Counts DST node steps.
#[derive(Debug, Default)]
struct DstSteps {
    steps: u64,
    nodes: u64,
}

impl Observer for DstSteps {
    fn step(&mut self, step: NodeStep) {
        if let NodeStep::Dst { kind, .. } = step {
            self.steps += 1;
            self.nodes += u64::from(kind != DstNodeKind::Leaf);
        }
    }
}

#[test]
fn parallel_box_pipelines_issue_once_per_node() {
    let (scene, s) = scene();
    let cfg = tiny();
    for model in ThreadModel::ALL {
        let serial = run_model(model, &scene, &s, SimAccel::Bvh4, Workload::Cast, &cfg);
        let plus = run_model(model, &scene, &s, SimAccel::Bvh4Plus, Workload::Cast, &cfg);
        // Same rays; the "+" kernel issues one box instruction per node. (Frame times are
        // not compared: the two kernels differ in their other instructions too, and the
        // `fast` model charges each its own measured costs. The compiled "+" kernel tests
        // a node's empty child slots too, so only the `fast` model's box ops are equal.)
        if model == ThreadModel::Fast {
            assert_eq!(serial.units.box_ops, plus.units.box_ops);
        }
        assert!(
            plus.instructions.box_issues * 2 <= serial.instructions.box_issues,
            "{model:?}: {} vs {}",
            plus.instructions.box_issues,
            serial.instructions.box_issues
        );
    }
}

#[test]
fn empty_frame_is_an_error() {
    let (scene, s) = scene();
    let settings = RenderSettings::new(0, 16, Workload::Cast);
    assert!(
        simulate(
            &FrameRequest::new(&scene, &s, SimAccel::Dst, &settings, &tiny()),
            &|_, _| {}
        )
        .is_err()
    );
}

/// A memory-heavy synthetic stream through the engine directly (the placeholder traversal
/// reports no fetches, so this is where the hierarchy's bookkeeping is exercised).
mod synthetic {
    use dualsplit_geometry::Pcg32;
    use dualsplit_sim::SimConfig;
    use dualsplit_sim::hw::atomic::AtomicUnit;
    use dualsplit_sim::hw::{Chip, Stalls, pipe::Pipe};
    use dualsplit_sim::model::fast::op::Op;
    use dualsplit_sim::model::fast::replay::{WorkSource, run as run_chip};
    use dualsplit_sim::model::fast::thread::Thread;

    struct Random {
        rng: Pcg32,
        left: u32,
        loads: u64,
    }
    impl WorkSource for Random {
        fn next(
            &mut self,
            _id: usize,
            _t: &mut Thread,
            _a: &mut AtomicUnit,
            _s: &mut Stalls,
        ) -> Option<Vec<Op>> {
            if self.left == 0 {
                return None;
            }
            self.left -= 1;
            let mut ops = Vec::new();
            for _ in 0..20 {
                let node = self.rng.below(1 << 16) as u64;
                ops.push(Op::Load {
                    word: (node * 13) as u32,
                    words: 13,
                });
                self.loads += 13;
                ops.push(Op::Pipe {
                    pipe: Pipe::Box,
                    n: 2,
                    parallel: false,
                });
                ops.push(Op::Issue { n: 5, fpinv: 0 });
            }
            Some(ops)
        }
    }

    fn run(cfg: &SimConfig) -> (u64, Chip, u64) {
        let mut chip = Chip::new(cfg, 1);
        let n = cfg.tms * cfg.tps_per_tm;
        let mut th: Vec<Thread> = (0..n)
            .map(|i| Thread::new((i / cfg.tps_per_tm) as usize))
            .collect();
        let mut w = Random {
            rng: Pcg32::new(3, 4),
            left: 200,
            loads: 0,
        };
        let end = run_chip(&mut chip, &mut th, &mut w);
        (end.get(), chip, w.loads)
    }

    #[test]
    fn every_load_is_served_and_deterministic() {
        let cfg = SimConfig::from_toml(&super::config("tiny.toml")).unwrap();
        let (end, chip, loads) = run(&cfg);
        let stats = chip.stats();
        let c = stats.caches;
        assert_eq!(c.l1_accesses, loads);
        assert_eq!(c.l1_hits + c.l1_merged + c.l2_accesses, c.l1_accesses);
        let d = stats.dram;
        assert_eq!(c.l2_hits + c.l2_merged + d.reads, c.l2_accesses);
        assert!(d.reads > 100, "the stream must reach DRAM: {}", d.reads);
        assert!(d.last_done.get() <= end);
        assert_eq!(stats.units.box_ops, 200 * 20 * 2);
        let (end2, chip2, _) = run(&cfg);
        assert_eq!(end, end2);
        assert_eq!(stats, chip2.stats());
        // Bandwidth never above the configured peak.
        let bytes = d.reads as f64 * 64.0;
        assert!(bytes / end as f64 <= cfg.dram_peak_bytes_per_cycle());
    }
}

/// One saved-or-built tree (`AnyTree`, what `--tree` gives) simulates exactly as the same
/// structure among every structure, on both thread models; a configuration whose
/// traversal the tree lacks is refused.
#[test]
fn one_tree_simulates_as_every_structure() {
    use dualsplit_accel::{AnyTree, Bvh2Tree, DstConfig, DstTree};
    let (scene, s) = scene();
    let bvh2 = Bvh2Tree::build(&scene.triangles[..], &Default::default()).unwrap();
    let dst = AnyTree::from(DstTree::from_bvh2(&bvh2, &DstConfig::hardware()).unwrap());
    let cfg = tiny();
    let settings = RenderSettings::new(12, 8, Workload::Path);
    for model in [ThreadModel::Fast, ThreadModel::Rv32] {
        for accel in [SimAccel::DstSw, SimAccel::Dst] {
            let go = |set: &dyn Fn() -> Result<SimResult, dualsplit_sim::SimError>| {
                let r = set().unwrap();
                assert!(r.cycles > 0 && r.rays > 0);
                format!("{r:?}")
            };
            let want = go(&|| {
                simulate(
                    &FrameRequest::new(&scene, &s, accel, &settings, &cfg).with_model(model),
                    &|_, _| {},
                )
            });
            let got = go(&|| {
                simulate(
                    &FrameRequest::new(&scene, &dst, accel, &settings, &cfg).with_model(model),
                    &|_, _| {},
                )
            });
            assert!(got == want, "{model:?} {accel:?}: the results differ");
        }
    }
    let e = simulate(
        &FrameRequest::new(&scene, &dst, SimAccel::Bvh4Plus, &settings, &cfg),
        &|_, _| {},
    )
    .unwrap_err();
    assert!(
        matches!(&e, dualsplit_sim::SimError::Unsupported { accel: "BVH4+", available } if available == "dst-sw, dst"),
        "{e}"
    );
}
