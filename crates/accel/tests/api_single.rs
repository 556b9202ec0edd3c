//! Every structure built alone through the top-level API ([`Bvh2Tree`], [`BvhTree`],
//! [`DstTree`]) answers every ray exactly as the same structure inside [`Structures`] does:
//! closest hit (`t`, triangle id, barycentrics, all as bits) and shadow answer, ray by ray,
//! plain, batched and observed, on builtin scenes and random rays with edge cases; and a
//! [`Tracer`] reused over every ray answers as the set's plain queries do, on every kind.

use dualsplit_accel::math::{Hit, Ray, Triangle};
use dualsplit_accel::{
    AccelKind, AnyTree, BuildConfig, Bvh2Tree, BvhTree, CountingObserver, DstConfig, DstDecoding,
    DstTree, NoObserver, RayQuery, Structures, Tracer, TraversalSet, TreeKind,
};
use dualsplit_geometry::Pcg32;
use dualsplit_testkit::rays::random_rays;

const RAYS: usize = if cfg!(debug_assertions) { 500 } else { 20_000 };

fn bits(h: Option<Hit>) -> Option<(u32, u32, u32, u32)> {
    h.map(|h| (h.t.to_bits(), h.prim.0, h.u.to_bits(), h.v.to_bits()))
}

fn rays_for(tris: &[Triangle], seed: u64) -> Vec<Ray> {
    let b = tris
        .iter()
        .fold(dualsplit_geometry::Aabb::EMPTY, |b, t| b.union(t.bounds()));
    random_rays(&mut Pcg32::new(seed, 7), tris, &b, RAYS)
}

/// Checks `q` against traversal `kind` of `s` on every ray, in every query form.
fn same_as<Q: RayQuery>(q: &Q, s: &Structures, kind: AccelKind, rays: &[Ray], what: &str) {
    let batch = q.intersect_batch(rays);
    let shadow = q.occluded_batch(rays);
    assert_eq!(batch.len(), rays.len());
    let mut hits = 0;
    for (i, r) in rays.iter().enumerate() {
        let want = s.closest_hit(kind, r, &mut NoObserver);
        let want_any = s.any_hit(kind, r, &mut NoObserver);
        hits += want.is_some() as usize;
        assert_eq!(bits(q.intersect(r)), bits(want), "{what}: ray {i} {r:?}");
        assert_eq!(bits(batch[i]), bits(want), "{what}: batch ray {i}");
        assert_eq!(q.occluded(r), want_any, "{what}: shadow ray {i} {r:?}");
        assert_eq!(shadow[i], want_any, "{what}: batch shadow ray {i}");
        let (mut a, mut b) = (CountingObserver::default(), CountingObserver::default());
        let got = q.intersect_observed(r, &mut a);
        s.closest_hit(kind, r, &mut b);
        assert_eq!(bits(got), bits(want), "{what}: observed ray {i}");
        assert_eq!(a, b, "{what}: observed counters of ray {i}");
        if let Some(h) = want {
            let n = q.hit_normal(&h);
            let tri = s.triangles[h.prim.index()];
            assert_eq!(n, tri.normal().try_normalize(), "{what}: normal of ray {i}");
        }
    }
    assert!(
        hits > rays.len() / 10,
        "{what}: too few hits ({hits}) to compare"
    );
}

/// One [`Tracer`] of `set` over traversal `kind`, reused over every ray, answers as
/// traversal `kind` of `s` does, closest hit and shadow answer, bit for bit: on `rays` and
/// on copies of some of them whose bounds are NaN (which the BVHs' CPU-side copies decline,
/// so the tracer's fallback answers them).
fn tracer_same_as<S: TraversalSet>(
    set: &S,
    s: &Structures,
    kind: AccelKind,
    rays: &[Ray],
    what: &str,
) {
    let mut t: Tracer<'_, S> = set.tracer(kind);
    let nan = rays.iter().take(64).enumerate().map(|(i, r)| match i % 3 {
        0 => Ray {
            t_min: f32::NAN,
            ..*r
        },
        1 => Ray {
            t_max: f32::NAN,
            ..*r
        },
        _ => Ray {
            t_max: f32::INFINITY,
            ..*r
        },
    });
    for (i, r) in rays.iter().copied().chain(nan).enumerate() {
        let want = s.closest_hit(kind, &r, &mut NoObserver);
        assert_eq!(
            bits(t.closest_hit(&r)),
            bits(want),
            "{what}: tracer, ray {i} {r:?}"
        );
        let want_any = s.any_hit(kind, &r, &mut NoObserver);
        assert_eq!(
            t.any_hit(&r),
            want_any,
            "{what}: tracer, shadow ray {i} {r:?}"
        );
    }
}

fn scene_case(spec: &str, cfg: &BuildConfig) {
    let scene = dualsplit_scene::load(spec).expect("builtin scene");
    let tris: &[Triangle] = &scene.triangles;
    let s = Structures::build(tris, cfg);
    let rays = rays_for(tris, 11);
    for kind in AccelKind::ALL {
        tracer_same_as(&s, &s, kind, &rays, &format!("{spec} {kind:?}"));
    }

    let bvh2 = Bvh2Tree::build(tris, cfg).expect("bvh2");
    assert_eq!(
        bvh2.logical().nodes,
        s.bvh2.nodes,
        "{spec}: same logical BVH2"
    );
    same_as(&bvh2, &s, AccelKind::Bvh2, &rays, &format!("{spec} bvh2"));
    for kind in [TreeKind::Bvh2, TreeKind::Bvh4, TreeKind::Bvh8] {
        let t = BvhTree::from_bvh2(&bvh2, kind)
            .expect("a BVH kind")
            .expect("encode");
        assert_eq!(t.kind(), kind);
        let accel = kind.accel_kinds()[0];
        assert_eq!(
            t.image().words,
            s.image(accel).words,
            "{spec} {kind}: same image"
        );
        assert_eq!(t.stats().node_bytes, s.image(accel).node_bytes());
        same_as(&t, &s, accel, &rays, &format!("{spec} {kind}"));
        let any = AnyTree::from(t);
        tracer_same_as(&any, &s, accel, &rays, &format!("{spec} AnyTree {kind}"));
        let mut other = any.tracer(if accel == AccelKind::Bvh8 {
            AccelKind::Bvh2
        } else {
            AccelKind::Bvh8
        });
        assert!(
            rays.iter()
                .all(|r| other.closest_hit(r).is_none() && !other.any_hit(r)),
            "{spec} {kind}: a tracer of a kind the tree lacks misses"
        );
        for &k in AccelKind::ALL.iter() {
            let r = &rays[0];
            let got = any.closest_hit(k, r, &mut NoObserver);
            assert_eq!(
                got.is_some(),
                k == accel,
                "{spec} {kind}: AnyTree serves {k:?}"
            );
        }
    }

    let dst = DstTree::from_bvh2(&bvh2, &DstConfig::hardware()).expect("dst");
    assert_eq!(
        dst.image().words,
        s.dst().image().words,
        "{spec} dst: same image"
    );
    assert_eq!(dst.stats().kind, Some(TreeKind::Dst));
    same_as(
        &dst,
        &s,
        DstDecoding::Software.accel_kind(),
        &rays,
        &format!("{spec} dst-sw"),
    );
    same_as(
        &dst.pipeline(),
        &s,
        DstDecoding::Pipeline.accel_kind(),
        &rays,
        &format!("{spec} dst pipeline"),
    );
    let any = AnyTree::from(dst);
    for kind in [AccelKind::DstSw, AccelKind::Dst] {
        tracer_same_as(&any, &s, kind, &rays, &format!("{spec} AnyTree {kind:?}"));
    }
    same_as(
        &any,
        &s,
        AccelKind::DST_SOFTWARE,
        &rays,
        &format!("{spec} AnyTree dst"),
    );
}

#[test]
fn single_structures_answer_like_structures_on_builtins() {
    for spec in [
        "builtin:cornell",
        "builtin:atrium?triangles=15000",
        "builtin:forest?triangles=6000",
        "builtin:hairball?triangles=6000",
    ] {
        scene_case(spec, &BuildConfig::default());
    }
    scene_case(
        "builtin:forest?triangles=3000",
        &BuildConfig::single_triangle_leaves(),
    );
}

#[test]
fn a_caller_pool_builds_the_same_trees() {
    let scene = dualsplit_scene::load("builtin:forest?triangles=20000").expect("builtin");
    let cfg = BuildConfig::default();
    let pool = dualsplit_accel::rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let a = Bvh2Tree::build_in(&pool, &scene.triangles[..], &cfg).expect("bvh2");
    let b = Bvh2Tree::build(&scene.triangles[..], &cfg).expect("bvh2");
    assert_eq!(a.logical().nodes, b.logical().nodes);
    let da = DstTree::from_bvh2_in(&pool, &a, &DstConfig::hardware()).expect("dst");
    let db = DstTree::from_bvh2(&b, &DstConfig::hardware()).expect("dst");
    assert_eq!(da.image().words, db.image().words);
}

#[test]
fn kinds_and_decodings_have_unambiguous_names() {
    assert_eq!(AccelKind::DST_SOFTWARE, AccelKind::DstSw);
    assert_eq!(AccelKind::DST_SOFTWARE.name(), "dst-sw");
    assert_eq!(AccelKind::DST_PIPELINE.name(), "dst");
    assert_eq!(DstDecoding::default(), DstDecoding::Software);
    for k in TreeKind::ALL {
        assert_eq!(TreeKind::parse(k.name()), Some(k));
        for &a in k.accel_kinds() {
            assert_eq!(TreeKind::of_accel(a), k);
        }
    }
    assert_eq!(TreeKind::parse("dst-sw"), None);
}

#[test]
fn rays_and_hits_are_plain_data() {
    let rays = [Ray::new(
        dualsplit_accel::math::Vec3::X,
        dualsplit_accel::math::Vec3::Y,
    ); 3];
    let bytes: &[u8] = bytemuck::cast_slice(&rays);
    assert_eq!(bytes.len(), 3 * 32);
    let back: Vec<Ray> = bytes.chunks(32).map(bytemuck::pod_read_unaligned).collect();
    assert_eq!(back, rays);
    assert_eq!(&bytes[..4], &1.0f32.to_le_bytes());
    assert_eq!(std::mem::size_of::<Hit>(), 16);
}
