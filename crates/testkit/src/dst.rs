//! A BVH2 and the DST converted from it, built together, and the per-ray check of both DST
//! traversals (the software decoder, DST*, and the pipeline loop).

use crate::oracle::{check_ray as check_structures, key};
use dualsplit_accel::dst::{Dst, DstConfig, Partitioning};
use dualsplit_accel::{BuildConfig, Bvh2, CountingObserver, NoObserver, Structures};
use dualsplit_geometry::{Hit, Ray, Triangle};

/// The DST presets every DST test loops over: the hardware and software cost presets with
/// identical bounds, and the hardware preset with similar bounds.
pub fn dst_presets() -> [DstConfig; 3] {
    [
        DstConfig::hardware(),
        DstConfig::software(),
        DstConfig::hardware().with_partitioning(Partitioning::Similar),
    ]
}

/// Every structure of a scene, with its DST converted under a chosen [`DstConfig`].
pub struct Built {
    /// The source BVH2.
    pub bvh: Bvh2,
    /// The DST converted from [`Built::bvh`] (the same tree as `reference.dst`).
    pub dst: Dst,
    /// BVH2, BVH4, BVH8 and the DST, for traversal through [`Structures`].
    pub reference: Structures,
}

/// [`build_with`] under the default BVH2 build.
pub fn build(tris: &[Triangle], cfg: &DstConfig) -> Built {
    build_with(tris, &BuildConfig::default(), cfg)
}

/// Builds every structure with `bcfg`, the DST under `cfg`, and validates the DST against
/// its BVH2.
///
/// # Panics
/// When an image cannot be encoded or the DST does not validate.
pub fn build_with(tris: &[Triangle], bcfg: &BuildConfig, cfg: &DstConfig) -> Built {
    let reference = Structures::try_build_with(tris, bcfg, cfg).expect("structures");
    reference
        .dst()
        .validate(&reference.bvh2)
        .expect("DST validates against its BVH2");
    Built {
        bvh: reference.bvh2.clone(),
        dst: reference.dst().clone(),
        reference,
    }
}

/// Compares, for one ray, the closest hit (`t` bits and triangle id) and the any-hit
/// answer of the DST software decoder and the pipeline loop with `expected`.
///
/// # Panics
/// On the first disagreement, naming the traversal, `what` and the ray.
pub fn check_dst_ray(dst: &Dst, ray: &Ray, expected: Option<Hit>, what: &str) {
    let want = key(expected);
    let sw = dst.closest_hit(ray, &mut NoObserver);
    assert_eq!(key(sw), want, "{what}: software closest hit, ray {ray:?}");
    // Observed, the software decoder reads the image (traverse.rs); plain queries run the
    // plain decoder (fast.rs). Every bit of their hits agrees.
    let observed = dst.closest_hit(ray, &mut CountingObserver::default());
    assert_eq!(
        crate::oracle::hit_bits(observed),
        crate::oracle::hit_bits(sw),
        "{what}: observed vs plain software closest hit, ray {ray:?}"
    );
    assert_eq!(
        dst.any_hit(ray, &mut CountingObserver::default()),
        expected.is_some(),
        "{what}: observed software any hit, ray {ray:?}"
    );
    let pipe = key(dst.closest_hit_pipeline(ray, &mut NoObserver));
    assert_eq!(pipe, want, "{what}: pipeline closest hit, ray {ray:?}");
    let occluded = expected.is_some();
    assert_eq!(
        dst.any_hit(ray, &mut NoObserver),
        occluded,
        "{what}: software any hit, ray {ray:?}"
    );
    assert_eq!(
        dst.any_hit_pipeline(ray, &mut NoObserver),
        occluded,
        "{what}: pipeline any hit, ray {ray:?}"
    );
}

/// Checks one ray on all seven traversals of `b` against the oracle
/// ([`crate::oracle::check_ray`]), naming the DST's partitioning mode. With exits widened by
/// `dualsplit_geometry::EXIT_WIDEN` no structure may round a grazing hit away, so there is
/// no allowance.
pub fn check_all(b: &Built, tris: &[Triangle], ray: &Ray) {
    let what = match b.dst.config().partitioning {
        Partitioning::Identical => "identical DST",
        Partitioning::Similar => "similar DST",
    };
    check_structures(&b.reference, tris, ray, what);
}
