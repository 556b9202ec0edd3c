//! The dual-split pipeline step function against a node-by-node reference written from the
//! paper's rules (Lin et al. 2020, Figs. 2–3, App. A–C), and the per-ray counters of the
//! software traversal and the pipeline loop.

use dualsplit_accel::dst::pipeline::{PipelineInput, ReturnCode, step};
use dualsplit_accel::dst::{AxisPair, Corner, DstConfig, HeaderOffset};
use dualsplit_accel::{CountingObserver, DstNodeKind};
use dualsplit_geometry::{Aabb, Pcg32, Triangle, widen_exit};
use dualsplit_testkit::dst::build;
use dualsplit_testkit::rays::random_rays;
use proptest::prelude::*;
use std::cmp::Ordering;

fn input(word: HeaderOffset, p0: f32, p1: f32, o: [f32; 3], d: [f32; 3]) -> PipelineInput {
    PipelineInput {
        word,
        p0,
        p1,
        origin: o,
        inv_dir: d.map(|x| 1.0 / x),
        t_min: 0.0,
        t_max: 100.0,
    }
}

#[test]
fn split_cases_of_fig3() {
    // Split on x: left child below x = 4 (P0), right child above x = 6 (P1); left child is a
    // 3-word node at word 30, so the right child is at 33.
    let w = HeaderOffset::split(0, 3, 30).unwrap();
    // +x ray from x = 0: near = left (t1 = 4), far = right (t2 = 6): both.
    let out = step(&input(w, 4.0, 6.0, [0.0; 3], [1.0, 0.0, 0.0]));
    assert_eq!(out.code, ReturnCode::BothChildren);
    assert_eq!((out.offset, out.offset_stack), (30, 33));
    // t1 is the near child's exit: widened by 1 + 2γ₃ (Ize 2013); t2 (entry) is exact.
    assert_eq!((out.t_min_out, out.t_max_out), (6.0, widen_exit(4.0)));
    // −x ray from x = 10: near = right (t1 = (6 − 10)/−1 = 4), far = left (t2 = 6).
    let out = step(&input(w, 4.0, 6.0, [10.0, 0.0, 0.0], [-1.0, 0.0, 0.0]));
    assert_eq!(out.code, ReturnCode::BothChildren);
    assert_eq!((out.offset, out.offset_stack), (33, 30));
    assert_eq!((out.t_min_out, out.t_max_out), (6.0, widen_exit(4.0)));
    // +x ray from x = 5 (in the gap, moving right): only the far (right) child.
    let out = step(&input(w, 4.0, 6.0, [5.0, 0.0, 0.0], [1.0, 0.0, 0.0]));
    assert_eq!(out.code, ReturnCode::OneChild);
    assert_eq!(out.offset, 33);
    assert_eq!((out.t_min_out, out.t_max_out), (1.0, 100.0));
    // +x ray from x = 0 with t_max = 5: only the near child, interval [0, 4].
    let mut i = input(w, 4.0, 6.0, [0.0; 3], [1.0, 0.0, 0.0]);
    i.t_max = 5.0;
    let out = step(&i);
    assert_eq!(out.code, ReturnCode::OneChild);
    assert_eq!(out.offset, 30);
    assert_eq!((out.t_min_out, out.t_max_out), (0.0, widen_exit(4.0)));
    // t_min = 4.5, t_max = 5.5: the ray segment lies in the gap: miss.
    i.t_min = 4.5;
    i.t_max = 5.5;
    assert_eq!(step(&i).code, ReturnCode::Miss);
    // A ray lying in the plane x = 4 (zero x direction): NaN distance, the near child stays.
    let out = step(&input(w, 4.0, 6.0, [4.0, 0.0, 0.0], [0.0, 1.0, 0.0]));
    assert_eq!(out.code, ReturnCode::OneChild);
    assert_eq!((out.offset, out.t_min_out, out.t_max_out), (30, 0.0, 100.0));
}

#[test]
fn carving_and_leaf_codes() {
    // Single-axis carving on y to [2, 3] (P0 = max, P1 = min), child at word 9.
    let w = HeaderOffset::single_carve(1, false, 9).unwrap();
    let out = step(&input(w, 3.0, 2.0, [0.0; 3], [0.0, 1.0, 0.0]));
    assert_eq!(out.code, ReturnCode::OneChild);
    assert_eq!(
        (out.offset, out.t_min_out, out.t_max_out),
        (9, 2.0, widen_exit(3.0))
    );
    let out = step(&input(w, 3.0, 2.0, [0.0, 5.0, 0.0], [0.0, -1.0, 0.0]));
    assert_eq!(
        (out.code, out.t_min_out, out.t_max_out),
        (ReturnCode::OneChild, 2.0, widen_exit(3.0))
    );
    assert_eq!(
        step(&input(w, 3.0, 2.0, [0.0, 5.0, 0.0], [0.0, 1.0, 0.0])).code,
        ReturnCode::Miss
    );
    // Carving leaf: same planes with L = 1 → code 3 with the run offset.
    let wl = HeaderOffset::single_carve(1, true, 77).unwrap();
    let out = step(&input(wl, 3.0, 2.0, [0.0; 3], [0.0, 1.0, 0.0]));
    assert_eq!((out.code, out.offset), (ReturnCode::Leaf, 77));
    // Plain leaf: always code 3.
    let out = step(&input(
        HeaderOffset::leaf(5).unwrap(),
        0.0,
        0.0,
        [0.0; 3],
        [1.0; 3],
    ));
    assert_eq!((out.code, out.offset), (ReturnCode::Leaf, 5));
    // Dual-axis (x, z): x ≥ 1 (lower), z ≤ 2 (upper). Ray +x +z from the origin:
    // x plane is an entry at t = 1, z plane an exit at t = 2.
    let wd = HeaderOffset::dual_carve(
        AxisPair::Xz,
        Corner {
            first_lower: true,
            second_lower: false,
        },
        false,
        12,
    )
    .unwrap();
    let out = step(&input(wd, 1.0, 2.0, [0.0; 3], [1.0, 0.0, 1.0]));
    assert_eq!((out.code, out.offset), (ReturnCode::OneChild, 12));
    assert_eq!((out.t_min_out, out.t_max_out), (1.0, widen_exit(2.0)));
    // Ray −x: x ≥ 1 is now an exit plane, hit only if starting beyond it.
    let out = step(&input(wd, 1.0, 2.0, [3.0, 0.0, 0.0], [-1.0, 0.0, 1.0]));
    assert_eq!((out.t_min_out, out.t_max_out), (0.0, widen_exit(2.0)));
    assert_eq!(
        step(&input(wd, 1.0, 2.0, [0.5, 0.0, 0.0], [-1.0, 0.0, 1.0])).code,
        ReturnCode::Miss
    );
}

/// The paper's per-node rules written as plainly as possible (a `match` per node type),
/// with exit-role distances widened by `widen_exit` (Ize 2013; the robustness rule of
/// `dualsplit-geometry`): a splitting node's t1 and every carving plane that clamps `hi`.
fn reference(i: &PipelineInput) -> (u8, u32, f32, f32, Option<(u32, f32)>) {
    let w = i.word;
    let t = |a: usize, p: f32| (p - i.origin[a]) * i.inv_dir[a];
    let neg = |a: usize| i.inv_dir[a].is_sign_negative();
    match w.node_kind() {
        DstNodeKind::Leaf => (3, w.offset(), i.t_min, i.t_max, None),
        DstNodeKind::Split => {
            let a = w.axis();
            let (l, r) = (w.offset(), w.offset() + w.left_size());
            let (near, far, t1, t2) = if neg(a) {
                (r, l, widen_exit(t(a, i.p1)), t(a, i.p0))
            } else {
                (l, r, widen_exit(t(a, i.p0)), t(a, i.p1))
            };
            let near_hit = i.t_min.partial_cmp(&t1) != Some(Ordering::Greater);
            let far_hit = i.t_max.partial_cmp(&t2) != Some(Ordering::Less);
            match (near_hit, far_hit) {
                (true, true) => (
                    2,
                    near,
                    i.t_min,
                    i.t_max.min(t1),
                    Some((far, i.t_min.max(t2))),
                ),
                (true, false) => (1, near, i.t_min, i.t_max.min(t1), None),
                (false, true) => (1, far, i.t_min.max(t2), i.t_max, None),
                (false, false) => (0, 0, 0.0, 0.0, None),
            }
        }
        kind => {
            let (mut lo, mut hi) = (i.t_min, i.t_max);
            let planes = if kind == DstNodeKind::SingleCarve {
                let a = w.axis();
                [(a, i.p0, false), (a, i.p1, true)]
            } else {
                let (a0, a1) = w.axis_pair().axes();
                let c = w.corner();
                [(a0, i.p0, c.first_lower), (a1, i.p1, c.second_lower)]
            };
            for (a, p, lower) in planes {
                if neg(a) == lower {
                    hi = hi.min(widen_exit(t(a, p)));
                } else {
                    lo = lo.max(t(a, p));
                }
            }
            if lo > hi {
                (0, 0, 0.0, 0.0, None)
            } else {
                let code = if w.is_leaf_flag() { 3 } else { 1 };
                (code, w.offset(), lo, hi, None)
            }
        }
    }
}

fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        (-4i32..=4).prop_map(|v| v as f32),
        -4.0f32..4.0,
        Just(f32::INFINITY),
        Just(f32::NEG_INFINITY),
    ]
}

fn dir() -> impl Strategy<Value = f32> {
    prop_oneof![
        Just(0.0f32),
        Just(-0.0f32),
        -2.0f32..2.0,
        (-2i32..=2).prop_map(|v| v as f32)
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4096, ..ProptestConfig::default() })]

    #[test]
    fn step_matches_reference(
        code in 0usize..37,
        offset in 0u32..1000,
        p0 in coord(), p1 in coord(),
        o in prop::array::uniform3((-4i32..=4).prop_map(|v| v as f32)),
        d in prop::array::uniform3(dir()),
        t_min in prop_oneof![Just(0.0f32), 0.0f32..3.0],
        len in prop_oneof![Just(0.0f32), 0.0f32..5.0, Just(f32::INFINITY)],
    ) {
        let h = HeaderOffset::ALL_VALID_HEADERS[code] as u32;
        let word = HeaderOffset::decode(h << 26 | offset, 0).unwrap();
        let i = PipelineInput {
            word, p0, p1, origin: o, inv_dir: d.map(|x| 1.0 / x), t_min, t_max: t_min + len,
        };
        let out = step(&i);
        let (code, off, lo, hi, push) = reference(&i);
        prop_assert_eq!(out.code as u8, code);
        if code != 0 {
            prop_assert_eq!(out.offset, off);
        }
        if code == 1 || code == 2 {
            prop_assert_eq!(out.t_max_out.to_bits(), hi.to_bits());
        }
        if code == 1 {
            prop_assert_eq!(out.t_min_out.to_bits(), lo.to_bits());
        }
        if let Some((far, far_min)) = push {
            prop_assert_eq!(out.offset_stack, far);
            prop_assert_eq!(out.t_min_out.to_bits(), far_min.to_bits());
        }
    }
}

/// Per ray, the software traversal and the pipeline loop report the same steps, and the
/// byte count is exactly 12 per internal node, 4 per plain leaf word, 4 per index entry
/// and 36 per triangle tested.
#[test]
fn counters_agree_per_ray() {
    let mut rng = Pcg32::new(99, 1);
    let tris: Vec<Triangle> = (0..300)
        .map(|_| {
            let a = rng.cube_point(-5.0, 5.0);
            let e = |rng: &mut Pcg32| rng.cube_point(-0.5, 0.5);
            Triangle::new(a, a + e(&mut rng), a + e(&mut rng))
        })
        .collect();
    let scene_box = tris.iter().fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
    for cfg in [DstConfig::hardware(), DstConfig::software()] {
        let b = build(&tris, &cfg);
        for ray in random_rays(&mut rng, &tris, &scene_box, 400) {
            for any in [false, true] {
                let (mut sw, mut pipe) = (CountingObserver::default(), CountingObserver::default());
                if any {
                    b.dst.any_hit(&ray, &mut sw);
                    b.dst.any_hit_pipeline(&ray, &mut pipe);
                } else {
                    b.dst.closest_hit(&ray, &mut sw);
                    b.dst.closest_hit_pipeline(&ray, &mut pipe);
                }
                assert_eq!(sw, pipe, "ray {ray:?}");
                // Every internal node tests two planes; every code-3 step enters one run.
                assert_eq!(sw.plane_tests, 2 * sw.nodes);
                let steps: u64 = sw.dst_codes.iter().sum();
                let plain_leaf_steps = steps - sw.nodes;
                // Any-hit stops inside a run; closest hit enters exactly one run per code 3.
                if !any {
                    assert_eq!(sw.leaves, sw.dst_codes[3]);
                }
                // Each triangle test reads one index entry (4 B) and one triangle (36 B).
                assert_eq!(
                    sw.bytes,
                    12 * sw.nodes + 4 * plain_leaf_steps + 40 * sw.triangle_tests,
                    "ray {ray:?}"
                );
            }
        }
    }
}
