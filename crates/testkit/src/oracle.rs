//! The brute-force reference: every triangle tested against the ray, the closest hit chosen
//! in `(t, triangle id)` order. Every structure must match it bit for bit, ray by ray.

use dualsplit_accel::{AccelKind, CountingObserver, NoObserver, Structures};
use dualsplit_geometry::{Hit, PrimId, Ray, Triangle};

/// Closest hit over all triangles on `[t_min, t_max]`, ordered by `(t, triangle id)`: equal
/// `t` goes to the smaller id. A ray that is not [traceable](Ray::is_traceable) misses, as
/// in every structure.
pub fn oracle_closest(tris: &[Triangle], ray: &Ray) -> Option<Hit> {
    if !ray.is_traceable() {
        return None;
    }
    let r = ray.precompute();
    let mut best: Option<Hit> = None;
    for (i, tri) in tris.iter().enumerate() {
        let Some(h) = tri.intersect(&r, ray.t_min, ray.t_max) else {
            continue;
        };
        Hit::keep_closest(&mut best, PrimId(i as u32), h);
    }
    best
}

/// Whether any triangle is hit on `[t_min, t_max]` (never for a ray that is not
/// [traceable](Ray::is_traceable)).
pub fn oracle_any(tris: &[Triangle], ray: &Ray) -> bool {
    if !ray.is_traceable() {
        return false;
    }
    let r = ray.precompute();
    tris.iter()
        .any(|t| t.intersect(&r, ray.t_min, ray.t_max).is_some())
}

/// `(t bits, triangle id)` of a hit: the quantity compared per ray.
pub fn key(h: Option<Hit>) -> Option<(u32, PrimId)> {
    h.map(|h| (h.t.to_bits(), h.prim))
}

/// Checks one ray on all seven CPU traversals of `s` ([`AccelKind::ALL`]: BVH2, BVH4, BVH8,
/// the DST software decoder, the DST pipeline loop, the compressed BVH8 and the quantized
/// DST) against the oracle over `tris`: the
/// closest hit's `t` bits and triangle id, and the any-hit answer. `what` names the case in
/// the failure message.
///
/// # Panics
/// On the first structure that disagrees, naming it and the ray.
pub fn check_ray(s: &Structures, tris: &[Triangle], ray: &Ray, what: &str) {
    let want = oracle_closest(tris, ray);
    let want_any = oracle_any(tris, ray);
    assert_eq!(
        want_any,
        want.is_some(),
        "{what}: oracle any hit vs closest hit, ray {ray:?}"
    );
    for kind in AccelKind::ALL {
        let got = s.closest_hit(kind, ray, &mut NoObserver);
        assert_eq!(
            key(got),
            key(want),
            "{what}: {} closest hit vs oracle, ray {ray:?}",
            kind.name()
        );
        assert_eq!(
            s.any_hit(kind, ray, &mut NoObserver),
            want_any,
            "{what}: {} any hit vs oracle, ray {ray:?}",
            kind.name()
        );
        // Observed traversals (what the simulator runs) read the image; plain queries may
        // not (a BVH's CPU-side copy, the DST's plain decoder). Every bit agrees.
        let observed = s.closest_hit(kind, ray, &mut CountingObserver::default());
        assert_eq!(
            hit_bits(observed),
            hit_bits(got),
            "{what}: {} observed vs plain closest hit, ray {ray:?}",
            kind.name()
        );
        assert_eq!(
            s.any_hit(kind, ray, &mut CountingObserver::default()),
            want_any,
            "{what}: {} observed any hit vs oracle, ray {ray:?}",
            kind.name()
        );
        // A BVH answers plain queries from its CPU-side copy; its image traversal (what the
        // simulator and every counting observer read) must give the same hit, bit for bit.
        if let Some(b) = s.encoded(kind) {
            let image = b.closest_hit_image(ray, &mut NoObserver);
            assert_eq!(
                hit_bits(image),
                hit_bits(got),
                "{what}: {} image traversal vs CPU copy, ray {ray:?}",
                kind.name()
            );
            assert_eq!(
                b.any_hit_image(ray, &mut NoObserver),
                want_any,
                "{what}: {} image any hit vs oracle, ray {ray:?}",
                kind.name()
            );
        }
    }
}

/// Every bit of a hit: `t`, triangle id, `u`, `v`.
pub fn hit_bits(h: Option<Hit>) -> Option<[u32; 4]> {
    h.map(|h| [h.t.to_bits(), h.prim.0, h.u.to_bits(), h.v.to_bits()])
}

/// [`check_ray`] for each of `rays`, named by its index.
pub fn check_rays(s: &Structures, tris: &[Triangle], rays: &[Ray]) {
    for (i, ray) in rays.iter().enumerate() {
        check_ray(s, tris, ray, &format!("ray {i}"));
    }
}
