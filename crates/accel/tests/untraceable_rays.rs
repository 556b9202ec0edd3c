//! Rays outside `Ray::is_traceable` (a non-finite origin or direction, a NaN `t_min` or
//! `t_max`) have one defined answer: a miss, in every structure and every query form. A
//! NaN `t_max` once gave a hit in BVH2, BVH4, DST*, DST and DST-Q and a miss in BVH8 and
//! the compressed BVH8. Traceable rays with infinite interval ends still agree everywhere.

use dualsplit_accel::math::{Hit, Ray, Vec3};
use dualsplit_accel::{
    AccelKind, AnyTree, BuildConfig, Bvh2Tree, BvhTree, CountingObserver, CwbvhTree, DstConfig,
    DstQTree, DstTree, NoObserver, RayQuery, Structures, TraversalSet, TreeKind,
};

fn bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.prim.0, h.u.to_bits(), h.v.to_bits()))
}

/// Rays from in front of the Cornell box toward points spread over it: most hit.
fn base_rays(s: &Structures) -> Vec<Ray> {
    let b = s.scene_box();
    let c = b.center();
    let e = b.extent();
    let eye = c + Vec3::new(0.1, 0.2, 2.5) * e.max_element();
    let mut out = Vec::new();
    for i in 0..8 {
        for j in 0..8 {
            let p = b.min + e * Vec3::new((i as f32 + 0.5) / 8.0, (j as f32 + 0.5) / 8.0, 0.5);
            out.push(Ray::new(eye, p - eye));
        }
    }
    out
}

/// `ray` with field `f` (0–7: origin, dir, t_min, t_max) set to `v`.
fn with_field(ray: &Ray, f: usize, v: f32) -> Ray {
    let mut a: [f32; 8] = bytemuck::cast(*ray);
    a[f] = v;
    bytemuck::cast(a)
}

fn trees(tris: &[dualsplit_accel::math::Triangle]) -> Vec<AnyTree> {
    let bvh2 = Bvh2Tree::build(tris, &BuildConfig::default()).expect("bvh2");
    let mut out: Vec<AnyTree> = [TreeKind::Bvh2, TreeKind::Bvh4, TreeKind::Bvh8]
        .into_iter()
        .map(|k| {
            BvhTree::from_bvh2(&bvh2, k)
                .expect("bvh")
                .expect("encode")
                .into()
        })
        .collect();
    out.push(
        DstTree::from_bvh2(&bvh2, &DstConfig::hardware())
            .expect("dst")
            .into(),
    );
    out.push(CwbvhTree::from_bvh2(&bvh2).expect("cwbvh").into());
    out.push(
        DstQTree::from_bvh2(&bvh2, &Default::default())
            .expect("dstq")
            .into(),
    );
    out
}

/// Every answer `set` gives `ray` through traversal `kind`: plain, observed, through a
/// tracer; closest hit and any hit.
fn answers<S: TraversalSet>(
    set: &S,
    kind: AccelKind,
    ray: &Ray,
) -> Vec<Option<(u32, u32, u32, u32)>> {
    let mut obs = CountingObserver::default();
    let mut tracer = set.tracer(kind);
    let any = |b: bool| b.then_some((1, 1, 1, 1));
    vec![
        bits(set.closest_hit(kind, ray, &mut NoObserver)),
        bits(set.closest_hit(kind, ray, &mut obs)),
        bits(tracer.closest_hit(ray)),
        any(set.any_hit(kind, ray, &mut NoObserver)),
        any(set.any_hit(kind, ray, &mut obs)),
        any(tracer.any_hit(ray)),
    ]
}

#[test]
fn untraceable_rays_miss_in_every_structure_and_query_form() {
    let scene = dualsplit_scene::load("builtin:cornell").expect("cornell");
    let s = Structures::build(&scene.triangles, &BuildConfig::default());
    let singles = trees(&scene.triangles);
    let rays = base_rays(&s);
    let hits = rays
        .iter()
        .filter(|r| s.closest_hit(AccelKind::Bvh2, r, &mut NoObserver).is_some())
        .count();
    assert!(
        hits > rays.len() / 2,
        "only {hits} of {} rays hit",
        rays.len()
    );
    let bad = [f32::NAN, -f32::NAN, f32::INFINITY, f32::NEG_INFINITY];
    let mut untraceable = 0;
    for (i, base) in rays.iter().enumerate() {
        for f in 0..8 {
            for v in bad {
                let ray = with_field(base, f, v);
                let traceable = ray.is_traceable();
                assert_eq!(traceable, ray.untraceable_field().is_none(), "{ray:?}");
                // Infinite interval ends are traceable; every other value here is not.
                assert_eq!(traceable, f >= 6 && v.is_infinite(), "{ray:?}");
                let want = answers(&s, AccelKind::Bvh2, &ray);
                if !traceable {
                    untraceable += 1;
                    assert!(
                        want.iter().all(Option::is_none),
                        "ray {i} field {f} = {v}: {want:?}"
                    );
                    assert_eq!(
                        ray.untraceable_field().map(|(_, x)| x.to_bits()),
                        Some(v.to_bits())
                    );
                }
                for kind in AccelKind::ALL {
                    assert_eq!(
                        answers(&s, kind, &ray),
                        want,
                        "{kind:?}: ray {i} field {f} = {v}"
                    );
                }
                for t in &singles {
                    for &kind in t.kinds() {
                        assert_eq!(
                            answers(t, kind, &ray),
                            want,
                            "saved {kind:?}: ray {i}, field {f} = {v}"
                        );
                        if let AnyTree::Bvh(b) = t {
                            assert_eq!(bits(b.intersect(&ray)), want[0], "{kind:?} RayQuery");
                            assert_eq!(b.occluded(&ray), want[3].is_some(), "{kind:?} RayQuery");
                        }
                    }
                }
            }
        }
    }
    assert!(untraceable > 1000, "{untraceable}");
}
