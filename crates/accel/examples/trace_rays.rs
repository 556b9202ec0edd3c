//! Trace your own rays: build a BVH8 over a few triangles and query it, one ray at a time
//! and in a batch, using only `dualsplit-accel`'s documented items.
//!
//! `cargo run --release -p dualsplit-accel --example trace_rays`

use dualsplit_accel::math::{Ray, Triangle, Vec3};
use dualsplit_accel::{BuildConfig, Bvh2Tree, BvhTree, RayQuery};
use std::io::Write;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Written with `?`: a reader that stops early (`| head`) ends the example with an
    // error, not a panic.
    let mut out = std::io::stdout().lock();
    // A floor and a wall.
    let tris = vec![
        Triangle::new(
            Vec3::new(-5.0, 0.0, -5.0),
            Vec3::new(5.0, 0.0, -5.0),
            Vec3::new(0.0, 0.0, 5.0),
        ),
        Triangle::new(
            Vec3::new(-5.0, 0.0, 3.0),
            Vec3::new(5.0, 0.0, 3.0),
            Vec3::new(0.0, 5.0, 3.0),
        ),
    ];
    let bvh2 = Bvh2Tree::build(tris, &BuildConfig::default())?;
    let bvh8 = BvhTree::bvh8_from(&bvh2)?;
    writeln!(out, "BVH8: {:?}", bvh8.stats())?;

    let down = Ray::new(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, -1.0, 0.0));
    let hit = bvh8.intersect(&down).expect("the floor is below");
    writeln!(
        out,
        "down: t = {}, triangle {}, normal {:?}",
        hit.t,
        hit.prim,
        bvh8.hit_normal(&hit)
    )?;
    assert_eq!((hit.t, hit.prim.0), (1.0, 0));

    let rays: Vec<Ray> = (0..8)
        .map(|i| {
            Ray::new(
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(0.0, 0.0, if i % 2 == 0 { 1.0 } else { -1.0 }),
            )
        })
        .collect();
    let hits = bvh8.intersect_batch(&rays);
    let shadows = bvh8.occluded_batch(&rays);
    for (h, s) in hits.iter().zip(&shadows) {
        assert_eq!(h.is_some(), *s);
    }
    writeln!(
        out,
        "batch: {} of {} rays hit the wall",
        hits.iter().flatten().count(),
        rays.len()
    )?;
    assert_eq!(hits.iter().flatten().count(), 4);
    Ok(())
}
