//! Loading a saved Dragon Box DST against building it: `build_dst` is the whole build
//! (BVH2 + conversion), `load_dst` reads and checks the saved file (page cache warm);
//! `load_bvh8` the same for a BVH8. `check_dst` and `check_bvh8` time the structural check
//! alone ([`AnyTree::check_structure`], part of every load).
//!
//! `cargo bench -p dualsplit-accel --bench saved_tree`
//! (under `cargo test --benches` the small `dragon_res4` is used).

use dualsplit_accel::{
    AnyTree, BuildConfig, Bvh2Tree, BvhTree, DstConfig, DstTree, SharedTriangles, TreeKind,
};
use dualsplit_testkit::scenes::shipped_triangles;
use std::path::PathBuf;
use std::sync::OnceLock;

struct Input {
    tris: SharedTriangles,
    file: PathBuf,
    bvh8_file: PathBuf,
    dst: AnyTree,
    bvh8: AnyTree,
    _dir: tempfile::TempDir,
}

fn scene_name() -> String {
    std::env::var("DST_BENCH_SCENE").unwrap_or_else(|_| {
        if !std::env::args().any(|a| a == "--bench") {
            "dragon_res4.ply.gz".into()
        } else {
            "dragon_box.ply.gz".into()
        }
    })
}

fn build(tris: &SharedTriangles) -> DstTree {
    let bvh2 = Bvh2Tree::build(tris.clone(), &BuildConfig::default()).expect("bvh2");
    DstTree::from_bvh2(&bvh2, &DstConfig::hardware()).expect("dst")
}

fn input() -> &'static Input {
    static INPUT: OnceLock<Input> = OnceLock::new();
    INPUT.get_or_init(|| {
        let tris: SharedTriangles = shipped_triangles(&scene_name())
            .expect("the benchmark needs this mesh")
            .into();
        let dir = tempfile::tempdir().expect("tempdir");
        let file = dir.path().join("dst.dstree");
        let dst = AnyTree::from(build(&tris));
        dst.save(&file).expect("save");
        let bvh2 = Bvh2Tree::build(tris.clone(), &BuildConfig::default()).expect("bvh2");
        let bvh8 = AnyTree::from(
            BvhTree::from_bvh2(&bvh2, TreeKind::Bvh8)
                .expect("bvh8")
                .expect("encode"),
        );
        let bvh8_file = dir.path().join("bvh8.dstree");
        bvh8.save(&bvh8_file).expect("save");
        Input {
            tris,
            file,
            bvh8_file,
            dst,
            bvh8,
            _dir: dir,
        }
    })
}

fn main() {
    let i = input();
    // The loaded tree is the built one.
    let loaded = AnyTree::load(&i.file, Some(&i.tris)).expect("load");
    assert_eq!(loaded.image().words, build(&i.tris).image().words);
    eprintln!(
        "{}: {} triangles, DST file {} bytes, BVH8 file {} bytes",
        scene_name(),
        i.tris.len(),
        std::fs::metadata(&i.file).expect("file").len(),
        std::fs::metadata(&i.bvh8_file).expect("file").len()
    );
    divan::main();
}

#[divan::bench(sample_count = 5, sample_size = 1)]
fn build_dst() -> DstTree {
    build(&input().tris)
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn load_dst() -> AnyTree {
    let i = input();
    AnyTree::load(&i.file, Some(&i.tris)).expect("load")
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn load_dst_unchecked_scene() -> AnyTree {
    AnyTree::load(&input().file, None).expect("load")
}

#[divan::bench(sample_count = 10, sample_size = 1)]
fn load_bvh8() -> AnyTree {
    let i = input();
    AnyTree::load(&i.bvh8_file, Some(&i.tris)).expect("load")
}

#[divan::bench(sample_count = 20, sample_size = 1)]
fn check_dst() {
    input().dst.check_structure().expect("a clean DST");
}

#[divan::bench(sample_count = 20, sample_size = 1)]
fn check_bvh8() {
    input().bvh8.check_structure().expect("a clean BVH8");
}
