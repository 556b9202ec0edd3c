//! One pass of one of `bench`'s ray sets through our BVH8 copy, then through Embree: the
//! program to run under callgrind for instructions, branches and mispredictions per ray.
//!
//! `cpu_cost SCENE RES SET` builds the structures of `SCENE`, records the ray sets of a
//! RES×RES path-traced frame (as `dualsplit bench` does), and traces set `SET` (`primary`,
//! `shadow` or `diffuse`) once with `bvh8`'s plain queries through one [`Tracer`] (the calls
//! `bench` times) and once with `rtcIntersect1` / `rtcOccluded1`. Each side's per-ray call is
//! one function of its own here (`cpu_cost::ours`, `cpu_cost::embree_query`: everything a
//! ray costs, the entry into the library included); collecting only inside one of them, or
//! only inside the traversal proper, gives that side's counts:
//!
//! ```sh
//! cargo build --release -p dualsplit-embree --example cpu_cost
//! run() { valgrind --tool=callgrind --branch-sim=yes --callgrind-out-file=/dev/null \
//!     --toggle-collect="$1" target/release/examples/cpu_cost "${@:2}" 2>&1 | grep Collected; }
//! S=sponza_dabrovic.ply.gz   # a shipped mesh's path, or builtin:NAME
//! run 'cpu_cost::ours' $S 64 primary      # our whole query
//! run 'cpu_cost::embree_query' $S 64 primary   # Embree's whole query
//! run rtcIntersect1 $S 64 primary   # Embree's (rtcOccluded1 for the shadow set)
//! ```
//!
//! "Collected" lists Ir, conditional branches and mispredicted ones; the program prints the
//! set's ray count to divide by. Our copy's traversal proper runs inside the AVX2 function
//! `dualsplit_accel::wide::simd::Avx2::vectorize::with_avx2` when the CPU has AVX2: its
//! inclusive cost inside our whole query (`--callgrind-out-file=F` with the first toggle,
//! then `callgrind_annotate --inclusive=yes F`). Collecting with that function as the
//! toggle would count the structures' builds too, which run other kernels through it.
//!
//! `cpu_cost SCENE RES SET away` traces the set's rays moved to start beyond the scene's box
//! and point away from it, so that every query ends at the root's box test: what a ray costs
//! whatever it meets (entry into the library, set-up, one node test, return).

use dualsplit_accel::{AccelKind, Structures, Tracer, TraversalSet};
use dualsplit_embree::EmbreeScene;
use dualsplit_geometry::{Ray, Vec3};
use dualsplit_render::bench::ray_sets;
use dualsplit_render::{RayKind, RenderSettings, Workload};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let usage = "usage: cpu_cost SCENE RES primary|shadow|diffuse [away]";
    let mut args = std::env::args().skip(1);
    let spec = args.next().ok_or(usage)?;
    let res: u32 = args.next().ok_or(usage)?.parse()?;
    let kind = args.next().ok_or(usage)?;
    let away = match args.next().as_deref() {
        None => false,
        Some("away") => true,
        Some(_) => return Err(usage.into()),
    };
    let scene = dualsplit_scene::load(&spec)?;
    let s = Structures::try_build(&scene.triangles, &Default::default())?;
    let sets = ray_sets(&scene, &s, &RenderSettings::new(res, res, Workload::Path))?;
    let set = sets
        .iter()
        .find(|set| set.kind.name() == kind)
        .ok_or(usage)?;
    // Made here, not by the first query, so that no side's counts include building.
    s.bvh8().cpu();
    let embree = EmbreeScene::new(&scene.triangles)?;
    let shadow = set.kind == RayKind::Shadow;
    // The root's box is the scene's.
    let moved = away.then(|| moved_away(&set.rays, s.bvh2.nodes[0].bounds.max));
    let rays = moved.as_deref().unwrap_or(&set.rays);
    let mut hits = [0usize; 2];
    let mut tracer = s.tracer(AccelKind::Bvh8);
    for r in rays {
        hits[0] += ours(&mut tracer, r, shadow) as usize;
    }
    for r in rays {
        hits[1] += embree_query(&embree, r, shadow) as usize;
    }
    println!(
        "{spec}, {res}x{res} path frame, {} {kind} rays: {} hits (ours), {} (Embree)",
        set.rays.len(),
        hits[0],
        hits[1]
    );
    Ok(())
}

/// `rays` moved to start beyond `corner`, the scene box's maximum, and to point away from it
/// on every axis (their interval kept), so that none meets the scene's box.
fn moved_away(rays: &[Ray], corner: Vec3) -> Vec<Ray> {
    let beyond = |c: f32| c + c.abs() + 1.0;
    let origin = Vec3::new(beyond(corner.x), beyond(corner.y), beyond(corner.z));
    rays.iter()
        .map(|r| Ray {
            origin,
            dir: Vec3::new(
                r.dir.x.abs() + 0.1,
                r.dir.y.abs() + 0.1,
                r.dir.z.abs() + 0.1,
            ),
            ..*r
        })
        .collect()
}

/// Our plain query of `r` on BVH8, as `bench` makes it: through a [`Tracer`] made once for
/// the whole set. A hit or, for a shadow ray, an occluder.
#[inline(never)]
fn ours(t: &mut Tracer<'_, Structures>, r: &Ray, shadow: bool) -> bool {
    if shadow {
        t.any_hit(r)
    } else {
        t.closest_hit(r).is_some()
    }
}

/// Embree's query of `r`, as `bench` makes it.
#[inline(never)]
fn embree_query(e: &EmbreeScene, r: &Ray, shadow: bool) -> bool {
    if shadow {
        e.occluded(r)
    } else {
        e.intersect(r).is_some()
    }
}
