//! The `trace --rays` file reader (`dualsplit_accel::ray_file::parse_rays`) on arbitrary
//! bytes: a typed error, or one ray per 32-byte record, each traceable. The same bytes read
//! as raw rays go through every traversal of a small scene: an untraceable ray misses in
//! each, closest hit and any hit alike (`Ray::is_traceable`), and no ray panics.
#![no_main]

use dualsplit_accel::math::Ray;
use dualsplit_accel::ray_file::{RAY_BYTES, parse_rays};
use dualsplit_accel::{AccelKind, BuildConfig, NoObserver, Structures};
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

fn structures() -> &'static Structures {
    static S: OnceLock<Structures> = OnceLock::new();
    S.get_or_init(|| {
        let scene = dualsplit_scene::load("builtin:cornell").expect("cornell");
        Structures::build(&scene.triangles, &BuildConfig::default())
    })
}

fuzz_target!(|data: &[u8]| {
    if let Ok(rays) = parse_rays(data) {
        assert_eq!(rays.len() * RAY_BYTES, data.len());
        assert!(rays.iter().all(Ray::is_traceable));
    }
    let s = structures();
    for chunk in data.chunks_exact(RAY_BYTES).take(8) {
        let ray: Ray = bytemuck::pod_read_unaligned(chunk);
        for kind in AccelKind::ALL {
            let hit = s.closest_hit(kind, &ray, &mut NoObserver);
            let any = s.any_hit(kind, &ray, &mut NoObserver);
            if !ray.is_traceable() {
                assert!(hit.is_none() && !any, "{kind:?}: untraceable {ray:?} hit");
            }
        }
    }
});
