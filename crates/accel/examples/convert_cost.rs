//! The BVH2 → DST conversion's cost against the BVH2 build, by instruction count, and a
//! fingerprint of the converted images.
//!
//! **Cost.** `convert_cost cost MESH BUILDS CONVERTS` loads the shipped mesh `MESH`, builds
//! its BVH2 `BUILDS` times (at least once) and converts the last build `CONVERTS` times
//! (hardware preset), all on a one-thread rayon pool. Under callgrind, one step's
//! instructions are the difference of two whole-program counts:
//!
//! ```sh
//! cargo build --release -p dualsplit-accel --example convert_cost
//! ir() { valgrind --tool=callgrind --callgrind-out-file=/dev/null \
//!     target/release/examples/convert_cost cost "$@" 2>&1 | sed -n 's/.*Collected : //p'; }
//! # BVH2 build: ir M 2 0 − ir M 1 0; conversion: ir M 1 1 − ir M 1 0
//! M=dragon_res2.ply.gz; echo $(ir $M 1 0) $(ir $M 2 0) $(ir $M 1 1)
//! ```
//!
//! **Fingerprint.** `convert_cost hash [MESH…]` prints, for each mesh (default: dragon_res4,
//! bunny, dragon_res2, dragon_box) and each preset (hardware, software, each with identical
//! and similar partitioning), the SHA-256 of the image's node words and index list: a
//! change to the converter that should not change its output must leave every line alone.

use dualsplit_accel::dst::{Dst, DstConfig, Partitioning};
use dualsplit_accel::{BuildConfig, Bvh2, SharedTriangles};
use dualsplit_geometry::Aabb;
use dualsplit_testkit::scenes::shipped_triangles;
use sha2::{Digest, Sha256};
use std::error::Error;
use std::io::{self, Write};

type Res<T> = Result<T, Box<dyn Error + Send + Sync>>;

const USAGE: &str = "usage: convert_cost cost MESH BUILDS CONVERTS | convert_cost hash [MESH…]";

fn load(mesh: &str) -> Res<(SharedTriangles, Vec<Aabb>)> {
    let tris: SharedTriangles = shipped_triangles(mesh)
        .ok_or_else(|| format!("{mesh}: no such shipped mesh"))?
        .into();
    let boxes = tris.iter().map(|t| t.bounds()).collect();
    Ok((tris, boxes))
}

fn cost(mesh: &str, builds: usize, converts: usize) -> Res<()> {
    let (tris, boxes) = load(mesh)?;
    let mut bvh = Bvh2::build(&boxes, &BuildConfig::default());
    for _ in 1..builds {
        bvh = Bvh2::build(std::hint::black_box(&boxes), &BuildConfig::default());
    }
    for _ in 0..converts {
        let dst = Dst::from_bvh2(
            std::hint::black_box(&bvh),
            tris.clone(),
            &DstConfig::hardware(),
        )?;
        std::hint::black_box(dst);
    }
    writeln!(
        io::stdout(),
        "{mesh}: {builds} builds, {converts} conversions"
    )?;
    Ok(())
}

fn hash(meshes: &[String]) -> Res<()> {
    let out = &mut io::stdout().lock();
    let presets = [
        ("hardware", DstConfig::hardware()),
        ("software", DstConfig::software()),
        (
            "hardware-similar",
            DstConfig::hardware().with_partitioning(Partitioning::Similar),
        ),
        (
            "software-similar",
            DstConfig::software().with_partitioning(Partitioning::Similar),
        ),
    ];
    for mesh in meshes {
        let (tris, boxes) = load(mesh)?;
        let bvh = Bvh2::build(&boxes, &BuildConfig::default());
        for (name, cfg) in &presets {
            let dst = Dst::from_bvh2(&bvh, tris.clone(), cfg)?;
            let img = dst.image();
            let mut h = Sha256::new();
            for region in [img.nodes.clone(), img.indices.clone()] {
                h.update((region.end - region.start).to_le_bytes());
                for w in &img.words[region] {
                    h.update(w.to_le_bytes());
                }
            }
            let digest: String = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
            writeln!(out, "{mesh} {name} {digest}")?;
        }
    }
    Ok(())
}

fn run(args: &[String]) -> Res<()> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    match args.first().map(String::as_str) {
        Some("cost") if args.len() == 4 => {
            let n = |s: &str| {
                s.parse::<usize>()
                    .map_err(|e| format!("{s:?} is not a count ({e}); {USAGE}"))
            };
            let (builds, converts) = (n(&args[2])?.max(1), n(&args[3])?);
            pool.install(|| cost(&args[1], builds, converts))
        }
        Some("hash") => {
            let meshes = if args.len() > 1 {
                args[1..].to_vec()
            } else {
                ["dragon_res4", "bunny", "dragon_res2", "dragon_box"]
                    .map(|m| format!("{m}.ply.gz"))
                    .to_vec()
            };
            pool.install(|| hash(&meshes))
        }
        _ => Err(USAGE.into()),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match run(&args) {
        Ok(()) => {}
        // A reader that stopped early (`| head`) is not an error.
        Err(e)
            if e.downcast_ref::<io::Error>().map(io::Error::kind)
                == Some(io::ErrorKind::BrokenPipe) => {}
        Err(e) => {
            eprintln!("convert_cost: {e}");
            std::process::exit(2);
        }
    }
}
