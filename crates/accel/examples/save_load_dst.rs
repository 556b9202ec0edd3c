//! Build only a DST, save it, load it back (as another process would) and trace a batch of
//! rays through both of its traversals.
//!
//! `cargo run --release -p dualsplit-accel --example save_load_dst`

use dualsplit_accel::math::{Ray, Triangle, Vec3};
use dualsplit_accel::{AnyTree, BuildConfig, Bvh2Tree, DstConfig, DstTree, RayQuery};
use std::io::Write;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Written with `?`: a reader that stops early (`| head`) ends the example with an
    // error, not a panic.
    let mut out = std::io::stdout().lock();
    // A small grid of triangles in the plane z = 4.
    let mut tris = Vec::new();
    for i in 0..16 {
        for j in 0..16 {
            let (x, y) = (i as f32 - 8.0, j as f32 - 8.0);
            tris.push(Triangle::new(
                Vec3::new(x, y, 4.0),
                Vec3::new(x + 1.0, y, 4.0),
                Vec3::new(x, y + 1.0, 4.0),
            ));
        }
    }
    let bvh2 = Bvh2Tree::build(&tris[..], &BuildConfig::default())?;
    let dst = DstTree::from_bvh2(&bvh2, &DstConfig::hardware())?;
    writeln!(out, "DST: {:?}", dst.stats())?;

    let dir = std::env::temp_dir().join(format!("dualsplit-example-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("grid.dstree");
    let dst = AnyTree::from(dst);
    dst.save(&path)?;
    // Passing the scene's triangles checks that the file was built from them.
    let loaded = AnyTree::load(&path, Some(&tris))?;
    std::fs::remove_dir_all(&dir)?;

    let rays: Vec<Ray> = (0..64)
        .map(|k| Ray::new(Vec3::new(k as f32 * 0.2 - 6.3, 0.3, 0.0), Vec3::Z))
        .collect();
    let hits = loaded.intersect_batch(&rays);
    assert_eq!(hits, dst.intersect_batch(&rays));
    let AnyTree::Dst(d) = &loaded else {
        return Err("expected a DST".into());
    };
    assert_eq!(hits, d.pipeline().intersect_batch(&rays));
    writeln!(
        out,
        "{} of {} rays hit; first: {:?}",
        hits.iter().flatten().count(),
        rays.len(),
        hits[0]
    )?;
    Ok(())
}
