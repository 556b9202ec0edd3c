//! The fast converter decides exactly what the reference DP decides: [`Dst::from_bvh2`] and
//! [`Dst::from_bvh2_reference`] emit their decisions through one encoder, so their images
//! are equal byte for byte exactly when every chain, split axis and child order is. Checked
//! on the shipped scenes under every preset, on random BVHs under random node costs, and on
//! random subtrees of a shipped scene under random node costs.

use dualsplit_accel::dst::{Dst, DstConfig, DstCosts, DstError, Partitioning};
use dualsplit_accel::{BuildConfig, Bvh2, Bvh2Node, SharedTriangles};
use dualsplit_geometry::{Aabb, Pcg32, Triangle, Vec3};
use dualsplit_testkit::scenes::shipped_triangles;
use proptest::prelude::*;
use std::sync::OnceLock;

/// Converts `bvh` with both converters and asserts the same outcome: equal image bytes and
/// stats, or the same error. Returns the fast converter's tree.
fn assert_same(bvh: &Bvh2, tris: &SharedTriangles, cfg: &DstConfig, what: &str) -> Option<Dst> {
    let fast = Dst::from_bvh2(bvh, tris.clone(), cfg);
    let reference = Dst::from_bvh2_reference(bvh, tris.clone(), cfg);
    match (fast, reference) {
        (Ok(fast), Ok(reference)) => {
            assert_eq!(fast.stats(), reference.stats(), "{what}: stats differ");
            assert!(
                fast.image().to_bytes() == reference.image().to_bytes(),
                "{what}: images differ"
            );
            Some(fast)
        }
        (fast, reference) => {
            assert_eq!(fast.err(), reference.err(), "{what}: outcomes differ");
            None
        }
    }
}

/// A mesh committed in the repository's `scenes/` and its BVH2 under the default build.
struct Shipped {
    tris: SharedTriangles,
    bvh: Bvh2,
}

fn shipped(name: &str) -> Shipped {
    let tris: SharedTriangles = shipped_triangles(name)
        .expect("committed in scenes/")
        .into();
    let boxes: Vec<Aabb> = tris.iter().map(|t| t.bounds()).collect();
    let bvh = Bvh2::build(&boxes, &BuildConfig::default());
    Shipped { tris, bvh }
}

fn bunny() -> &'static Shipped {
    static BUNNY: OnceLock<Shipped> = OnceLock::new();
    BUNNY.get_or_init(|| shipped("bunny.ply.gz"))
}

#[test]
fn shipped_scenes_match_reference() {
    let res4 = shipped("dragon_res4.ply.gz");
    for (scene, s) in [("dragon_res4", &res4), ("bunny", bunny())] {
        // Both cost presets, each with identical and with similar partitioning.
        for preset in [DstConfig::hardware(), DstConfig::software()] {
            for p in [Partitioning::Identical, Partitioning::Similar] {
                let cfg = preset.with_partitioning(p);
                let dst = assert_same(&s.bvh, &s.tris, &cfg, &format!("{scene} {cfg:?}"));
                let dst = dst.expect("a shipped scene converts");
                dst.validate(&s.bvh).expect("valid DST");
            }
        }
    }
}

/// The image does not depend on the thread count (the parallel subtrees are written at
/// offsets fixed by the depth-first layout).
#[test]
fn same_image_for_any_thread_count() {
    let s = bunny();
    let cfg = DstConfig::hardware();
    let want = Dst::from_bvh2_reference(&s.bvh, s.tris.clone(), &cfg).expect("conversion");
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        let dst = pool.install(|| Dst::from_bvh2(&s.bvh, s.tris.clone(), &cfg));
        let dst = dst.expect("conversion");
        assert_eq!(
            dst.image().words,
            want.image().words,
            "{threads} threads: image differs"
        );
    }
}

/// A leaf naming a triangle the scene does not have, or an id with the index list's run-end
/// bit, is refused with the leaf and the id, by both converters alike, wherever in the
/// leaf's run the bad id is.
#[test]
fn bad_triangle_ids_are_refused() {
    let b = |lo: f32, hi: f32| Aabb {
        min: Vec3::new(lo, 0.0, 0.0),
        max: Vec3::new(hi, 1.0, 1.0),
    };
    let two_leaves = |left: Vec<u32>, right: Vec<u32>| {
        Tree::Inner(
            b(0.0, 2.0),
            Box::new([
                Tree::Leaf(b(0.0, 1.0), left),
                Tree::Leaf(b(1.0, 2.0), right),
            ]),
        )
        .into_bvh2()
    };
    let tris = dummy_triangles(4);
    let cfg = DstConfig::hardware();
    let out_of_range = |node, prim| DstError::PrimOutOfRange {
        node,
        prim,
        triangles: 4,
    };
    // The tree is laid out depth-first: the root is node 0, its leaves nodes 1 and 2.
    for (left, right, want) in [
        (vec![0, 1], vec![2, 4], out_of_range(2, 4)),
        (vec![9, 1], vec![2, 3], out_of_range(1, 9)),
        (vec![0], vec![1 << 31 | 2, 3], out_of_range(2, 1 << 31 | 2)),
    ] {
        let bvh = two_leaves(left.clone(), right.clone());
        assert_same(&bvh, &tris, &cfg, &format!("leaves {left:?} {right:?}"));
        let got = Dst::from_bvh2(&bvh, tris.clone(), &cfg).err();
        assert_eq!(got, Some(want), "leaves {left:?} {right:?}");
    }
}

/// A BVH2 under construction: a leaf's triangle ids, or two children.
enum Tree {
    Leaf(Aabb, Vec<u32>),
    Inner(Aabb, Box<[Tree; 2]>),
}

impl Tree {
    fn bounds(&self) -> Aabb {
        match self {
            Tree::Leaf(b, _) | Tree::Inner(b, _) => *b,
        }
    }

    /// Lays the tree out as a [`Bvh2`]: depth-first, root at 0.
    fn into_bvh2(self) -> Bvh2 {
        fn put(t: &Tree, out: &mut Bvh2) -> u32 {
            let at = out.nodes.len();
            out.nodes.push(Bvh2Node {
                bounds: t.bounds(),
                first: 0,
                count: 0,
                right: 0,
            });
            match t {
                Tree::Leaf(_, ids) => {
                    out.nodes[at].first = out.prim_ids.len() as u32;
                    out.nodes[at].count = ids.len() as u32;
                    out.prim_ids.extend(ids);
                }
                Tree::Inner(_, kids) => {
                    out.nodes[at].first = put(&kids[0], out);
                    out.nodes[at].right = put(&kids[1], out);
                }
            }
            at as u32
        }
        let mut out = Bvh2 {
            nodes: Vec::new(),
            prim_ids: Vec::new(),
            sah_cost: 0.0,
        };
        put(&self, &mut out);
        out
    }
}

/// The subtree of `bvh` below node `n`, as a tree of its own.
fn subtree(bvh: &Bvh2, n: u32) -> Tree {
    let node = &bvh.nodes[n as usize];
    if node.is_leaf() {
        let ids = &bvh.prim_ids[node.first as usize..(node.first + node.count) as usize];
        Tree::Leaf(node.bounds, ids.to_vec())
    } else {
        let [l, r] = node.children().map(|c| subtree(bvh, c));
        Tree::Inner(node.bounds, Box::new([l, r]))
    }
}

/// A random BVH2 of `leaves` leaves (1–4 triangles each, ids `0..`): random leaf boxes,
/// merged two at a time in random order. Coordinates lie on a grid of `grid` cells per unit
/// (0: free), so that faces and areas often coincide and ties are common. A parent box is
/// the union of its children's; when `loose`, some of its faces are moved, mostly outward
/// (a refitted or hand-made BVH), sometimes inward (children poking out, regions that
/// invert: inputs the converter must still decide on deterministically).
fn random_bvh(seed: u64, leaves: usize, grid: u32, loose: bool) -> (Bvh2, usize) {
    let mut rng = Pcg32::new(seed, 3);
    let coord = |rng: &mut Pcg32| {
        let x = rng.range_f32(-4.0, 4.0);
        if grid == 0 {
            x
        } else {
            (x * grid as f32).round() / grid as f32
        }
    };
    let mut pool = Vec::new();
    let mut next_id = 0;
    for _ in 0..leaves {
        let (a, b) = (
            Vec3::new(coord(&mut rng), coord(&mut rng), coord(&mut rng)),
            Vec3::new(coord(&mut rng), coord(&mut rng), coord(&mut rng)),
        );
        let count = 1 + rng.below(4);
        pool.push(Tree::Leaf(
            Aabb::new(a.min(b), a.max(b)),
            (next_id..next_id + count).collect(),
        ));
        next_id += count;
    }
    while pool.len() > 1 {
        let x = pool.swap_remove(rng.below(pool.len() as u32) as usize);
        let y = pool.swap_remove(rng.below(pool.len() as u32) as usize);
        let mut b = x.bounds().union(y.bounds());
        if loose {
            for f in 0..6 {
                if rng.below(4) == 0 {
                    let d = rng.range_f32(-0.25, 0.5);
                    if f % 2 == 1 {
                        b.max[f / 2] += d;
                    } else {
                        b.min[f / 2] -= d;
                    }
                }
            }
        }
        pool.push(Tree::Inner(b, Box::new([x, y])));
    }
    let root = pool.pop().expect("at least one leaf");
    (root.into_bvh2(), next_id as usize)
}

/// Node costs that make every regime of the DP likely: the presets' values, equal costs,
/// single-axis nodes dearer or cheaper than dual-axis ones, and free-form values.
fn costs() -> impl Strategy<Value = DstCosts> {
    let c = || prop_oneof![Just(0.3f32), Just(0.5f32), Just(1.0f32), (0.05f32..2.0f32)];
    (c(), c(), c(), c()).prop_map(|(split, single_carve, dual_carve, triangle)| DstCosts {
        split,
        single_carve,
        dual_carve,
        triangle,
    })
}

fn partitioning() -> impl Strategy<Value = Partitioning> {
    prop_oneof![Just(Partitioning::Identical), Just(Partitioning::Similar)]
}

/// Dummy triangles for `n` ids (the converter reads only their count).
fn dummy_triangles(n: usize) -> SharedTriangles {
    vec![Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y); n].into()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_bvhs_match_reference(
        seed in any::<u64>(),
        leaves in 1usize..64,
        grid in prop::sample::select(vec![0u32, 1, 2, 8]),
        loose in any::<bool>(),
        costs in costs(),
        partitioning in partitioning(),
    ) {
        let (bvh, n) = random_bvh(seed, leaves, grid, loose);
        let cfg = DstConfig { costs, partitioning };
        assert_same(&bvh, &dummy_triangles(n), &cfg, &format!("random BVH, {cfg:?}"));
    }

    #[test]
    fn bunny_subtrees_match_reference(
        path in any::<u32>(),
        depth in 3u32..24,
        costs in costs(),
        partitioning in partitioning(),
    ) {
        let s = bunny();
        // The node `depth` levels down (or the leaf above it), bit i of `path` choosing
        // the child at level i.
        let mut n = 0;
        for i in 0..depth {
            let node = &s.bvh.nodes[n as usize];
            if node.is_leaf() {
                break;
            }
            n = node.children()[(path >> i & 1) as usize];
        }
        let bvh = subtree(&s.bvh, n).into_bvh2();
        let cfg = DstConfig { costs, partitioning };
        assert_same(&bvh, &s.tris, &cfg, &format!("bunny node {n}, {cfg:?}"));
    }
}
