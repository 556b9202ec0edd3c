//! Generation time of the builtin scenes at their default (paper) sizes. Each bench first
//! checks the triangle count, then times `builtin::generate` (which includes
//! `Scene::from_triangles`: the finiteness filter, degenerate count and bounds).
//!
//! ```text
//! cargo bench -p dualsplit-scene --bench builtin
//! ```

use dualsplit_scene::builtin;

fn main() {
    divan::main();
}

#[divan::bench(args = ["hairball", "forest", "atrium"], sample_count = 5, sample_size = 1)]
fn generate_default(name: &str) -> usize {
    let want = match name {
        "hairball" => 2_900_000,
        "forest" => 1_100_000,
        _ => 262_000,
    };
    let n = builtin::generate(name).expect("builtin").triangles.len();
    assert!(n.abs_diff(want) * 20 <= want, "{name}: {n} triangles");
    n
}

/// The hairball's triangles alone, without `Scene::from_triangles`.
#[divan::bench(sample_count = 5, sample_size = 1)]
fn hairball_triangles_only() -> usize {
    builtin::HairballParams::default().triangles().len()
}
