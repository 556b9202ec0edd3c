//! The quantized dual-split pipeline (`dstq::unit::unit_step`, what the simulator's
//! `rt.dstqp` computes) drives a traversal that answers every ray as the quantized DST's own
//! traversal does: the same closest hit (t bits, triangle id) and shadow answer, visiting
//! the same records in the same order. The loop is the compiled kernel's (`kernels/dstq.h`):
//! the frame and three record words per step, a stack of (record name, interval).

use dualsplit_accel::dst::pipeline::{ReturnCode, le_or_nan};
use dualsplit_accel::dstq::unit::{POS_BITS, UNIT_BITS, unit_step};
use dualsplit_accel::dstq::{DstQ, layout::ROOT_BIT};
use dualsplit_accel::image::RUN_END;
use dualsplit_accel::{BuildConfig, CountingObserver, Structures};
use dualsplit_geometry::{Hit, Pcg32, PrimId, Ray, Triangle, cull_limit};
use dualsplit_testkit::oracle::hit_bits;
use dualsplit_testkit::rays::random_rays;
use dualsplit_testkit::scenes::{room, shipped};

/// The kernel's loop over `unit_step`; also counts the records stepped.
fn unit_traverse(q: &DstQ, ray: &Ray, any: bool) -> (Option<Hit>, u64) {
    let img = q.image();
    let words: &[u32] = &img.words;
    let tris = q.triangles();
    if q.is_empty() {
        return (None, 0);
    }
    let r = ray.precompute();
    let sb = q.scene_box();
    let (mut t_min, mut t_max) = r.slab(sb.min, sb.max, ray.t_min, cull_limit(ray.t_max));
    if t_min > t_max {
        return (None, 0);
    }
    let mut best: Option<Hit> = None;
    let mut best_t = ray.t_max;
    let mut stack: Vec<(u32, f32, f32)> = Vec::new();
    let mut node = ROOT_BIT;
    let mut steps = 0;
    let word = |i: usize| words.get(i).copied().unwrap_or(0);
    loop {
        steps += 1;
        let cluster = (node >> POS_BITS) as usize;
        let frame = [0, 1, 2, 3].map(|i| word(cluster + i));
        let w0 = cluster + ((node & ((1 << POS_BITS) - 1)) / 32) as usize;
        let rec = [0, 1, 2].map(|i| word(w0 + i));
        let out = unit_step(
            frame,
            rec,
            node,
            ray.origin.to_array(),
            r.inv_dir.to_array(),
            t_min,
            t_max,
        );
        match out.code {
            ReturnCode::OneChild => {
                (node, t_min, t_max) = (out.next, out.t_min_out, out.t_max_out);
                continue;
            }
            ReturnCode::BothChildren => {
                stack.push((out.stack, out.t_min_out, t_max));
                (node, t_max) = (out.next, out.t_max_out);
                continue;
            }
            ReturnCode::Leaf => {
                let mut i = img.indices.start + out.next as usize;
                loop {
                    let e = words[i];
                    let p = PrimId(e & !RUN_END);
                    if let Some(h) = tris[p.index()].intersect(&r, ray.t_min, best_t) {
                        if any {
                            return (Some(Hit::on(p, h)), steps);
                        }
                        if Hit::keep_closest(&mut best, p, h) {
                            best_t = h.t;
                        }
                    }
                    if e & RUN_END != 0 {
                        break;
                    }
                    i += 1;
                }
            }
            ReturnCode::Miss => {}
        }
        let limit = cull_limit(best_t);
        loop {
            let Some((n, lo, hi)) = stack.pop() else {
                return (best, steps);
            };
            if le_or_nan(lo, limit) {
                (node, t_min, t_max) = (n, lo, hi.min(limit));
                break;
            }
        }
    }
}

fn check(name: &str, tris: &[Triangle], rays: &[Ray]) {
    let s = Structures::build(tris, &BuildConfig::default());
    let q = s.dstq();
    assert_eq!(q.config().bits, UNIT_BITS);
    for (i, ray) in rays.iter().enumerate() {
        let mut obs = CountingObserver::default();
        let want = q.closest_hit(ray, &mut obs);
        let (got, steps) = unit_traverse(q, ray, false);
        assert_eq!(hit_bits(got), hit_bits(want), "{name} ray {i}");
        let records: u64 = obs.dst_codes.iter().sum();
        assert_eq!(steps, records, "{name} ray {i}: records stepped");
        assert_eq!(
            unit_traverse(q, ray, true).0.is_some(),
            q.any_hit(ray, &mut CountingObserver::default()),
            "{name} shadow ray {i}"
        );
    }
}

#[test]
fn the_unit_loop_answers_every_ray_as_the_quantized_dst() {
    let n = if cfg!(debug_assertions) { 500 } else { 20_000 };
    for name in ["dragon_res4.ply.gz", "bunny.ply.gz"] {
        let Some(scene) = shipped(name) else {
            panic!("{name} is shipped with the repository");
        };
        let rays = random_rays(&mut Pcg32::new(9, 1), &scene.triangles, &scene.bounds, n);
        check(name, &scene.triangles, &rays);
    }
    let scene = room(true, 8);
    let rays = random_rays(&mut Pcg32::new(9, 2), &scene.triangles, &scene.bounds, n);
    check("closed room", &scene.triangles, &rays);
}
