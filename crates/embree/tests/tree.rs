//! Embree's builder wrapper (`tree::build_tree`): the tree it hands back holds every box
//! once, in boxes that contain their subtrees, within the arguments' limits; with spatial
//! splits (`tree::build_tree_split`) every part of every triangle lies in a box of a leaf
//! that holds it, as `tree::clipped_bounds` makes the parts' boxes. Tests that need the
//! library pass with a note when the crate was built without it (never under CI).

use dualsplit_embree::tree::{
    BuiltTree, Child, TreeArgs, build_tree, build_tree_split, clipped_bounds,
};
use dualsplit_embree::{EmbreeError, available};
use dualsplit_geometry::{Aabb, Pcg32, Triangle, Vec3};
use dualsplit_testkit::scenes::shipped_triangles;

fn build(boxes: &[Aabb], args: &TreeArgs) -> Option<BuiltTree> {
    skip_if_missing(build_tree(boxes, args))
}

/// The tree, or `None` (with a note) when the crate was built without Embree.
fn skip_if_missing(built: Result<BuiltTree, EmbreeError>) -> Option<BuiltTree> {
    match built {
        Ok(t) => Some(t),
        Err(EmbreeError::Missing(why)) => {
            assert!(!available());
            assert!(
                std::env::var_os("CI").is_none(),
                "Embree is missing under CI ({why})"
            );
            eprintln!("note: Embree is missing ({why}); test skipped");
            None
        }
        Err(e) => panic!("{e}"),
    }
}

/// The primitives below `c`, checking every node on the way: at most `args.branching`
/// children, each child's box containing its primitives' boxes, leaves of 1 to
/// `args.max_leaf` primitives.
fn check(t: &BuiltTree, c: Child, boxes: &[Aabb], args: &TreeArgs, out: &mut Vec<u32>) -> Aabb {
    match c {
        Child::Leaf(l) => {
            let ids = &t.leaves[l as usize];
            assert!(
                (1..=args.max_leaf as usize).contains(&ids.len()),
                "leaf {l}: {ids:?}"
            );
            out.extend(ids);
            ids.iter()
                .fold(Aabb::EMPTY, |b, &p| b.union(boxes[p as usize]))
        }
        Child::Node(n) => {
            let node = &t.nodes[n as usize];
            assert!(
                (1..=args.branching as usize).contains(&node.len()),
                "node {n}"
            );
            let mut all = Aabb::EMPTY;
            for &(b, child) in node {
                let below = check(t, child, boxes, args, out);
                assert!(
                    b.contains_box(&below),
                    "node {n}: {b:?} does not hold {below:?}"
                );
                all = all.union(below);
            }
            all
        }
    }
}

#[test]
fn embree_tree_holds_every_triangle_once_in_containing_boxes() {
    let tris = shipped_triangles("dragon_res4.ply.gz").expect("dragon_res4 is committed");
    let boxes: Vec<Aabb> = tris.iter().map(|t| t.bounds()).collect();
    for args in [
        TreeArgs::bvh8_triangle4(),
        TreeArgs {
            branching: 2,
            sah_block: 1,
            min_leaf: 1,
            max_leaf: 4,
            ..TreeArgs::bvh8_triangle4()
        },
    ] {
        let Some(t) = build(&boxes, &args) else {
            return;
        };
        let mut prims = Vec::new();
        check(&t, t.root, &boxes, &args, &mut prims);
        prims.sort_unstable();
        let want: Vec<u32> = (0..boxes.len() as u32).collect();
        assert_eq!(prims, want, "{args:?}: every box once");
        assert!(
            t.nodes.len() > boxes.len() / (8 * args.max_leaf as usize),
            "{args:?}: a real tree"
        );
    }
}

#[test]
fn one_box_is_a_leaf_root_and_bad_arguments_are_refused() {
    let b = Aabb {
        min: Vec3::splat(0.0),
        max: Vec3::splat(1.0),
    };
    if let Some(t) = build(&[b], &TreeArgs::bvh8_triangle4()) {
        let mut prims = Vec::new();
        check(&t, t.root, &[b], &TreeArgs::bvh8_triangle4(), &mut prims);
        assert_eq!(prims, vec![0]);
    }
    for args in [
        TreeArgs {
            branching: 9,
            ..TreeArgs::bvh8_triangle4()
        },
        TreeArgs {
            max_leaf: 33,
            ..TreeArgs::bvh8_triangle4()
        },
    ] {
        let e = build_tree(&[b], &args).expect_err("out of range");
        assert!(matches!(e, EmbreeError::Unsupported(_)), "{e}");
    }
    let e = build_tree(&[], &TreeArgs::bvh8_triangle4()).expect_err("no boxes");
    assert!(matches!(e, EmbreeError::Unsupported(_)), "{e}");
}

/// Every leaf's box (as its parent gives it) and triangles, below `c` in box `b`, checking
/// that each node's boxes lie within its own.
fn leaves(t: &BuiltTree, c: Child, b: Aabb, out: &mut Vec<(Aabb, Vec<u32>)>) {
    match c {
        Child::Leaf(l) => out.push((b, t.leaves[l as usize].clone())),
        Child::Node(n) => {
            for &(cb, child) in &t.nodes[n as usize] {
                assert!(b.contains_box(&cb), "node {n}: {cb:?} outside {b:?}");
                leaves(t, child, cb, out);
            }
        }
    }
}

#[test]
fn split_tree_puts_every_part_of_a_triangle_in_a_leaf_box_that_holds_it() {
    let tris = shipped_triangles("dragon_res4.ply.gz").expect("dragon_res4 is committed");
    let args = TreeArgs::bvh8_triangle4();
    let Some(t) = skip_if_missing(build_tree_split(&tris, &args)) else {
        return;
    };
    let scene = tris.iter().fold(Aabb::EMPTY, |b, t| b.union(t.bounds()));
    let mut all = Vec::new();
    leaves(&t, t.root, scene, &mut all);
    let mut boxes_of = vec![Vec::new(); tris.len()];
    for (b, ids) in &all {
        assert!((1..=args.max_leaf as usize).contains(&ids.len()), "{ids:?}");
        let mut once = ids.clone();
        once.sort_unstable();
        once.dedup();
        assert_eq!(
            once.len(),
            ids.len(),
            "a triangle twice in one leaf: {ids:?}"
        );
        for &p in ids {
            boxes_of[p as usize].push(*b);
        }
    }
    let refs: usize = boxes_of.iter().map(Vec::len).sum();
    assert!(
        refs > tris.len(),
        "spatial splits made no reference: {refs}"
    );
    assert!(refs <= 2 * tris.len(), "{refs} references");
    // Each triangle's points on a grid of barycentric weights (f64): each lies in a box
    // of a leaf holding the triangle.
    for (i, tri) in tris.iter().enumerate() {
        for p in points(tri, 8) {
            let held = boxes_of[i].iter().any(|b| holds(b, &p));
            assert!(held, "triangle {i}: {p:?} in none of {:?}", boxes_of[i]);
        }
    }
}

/// Points of `t` by barycentric weights on a grid of `n` steps, in f64.
fn points(t: &Triangle, n: u32) -> Vec<[f64; 3]> {
    let v = t.v.map(|p| p.to_array().map(f64::from));
    let mut out = Vec::new();
    for i in 0..=n {
        for j in 0..=n - i {
            let (a, b) = (i as f64 / n as f64, j as f64 / n as f64);
            out.push(
                [0, 1, 2].map(|k| v[0][k] + a * (v[1][k] - v[0][k]) + b * (v[2][k] - v[0][k])),
            );
        }
    }
    out
}

/// Whether box `b` holds point `p` (compared in f64, so no rounding of `p`).
fn holds(b: &Aabb, p: &[f64; 3]) -> bool {
    (0..3).all(|a| b.min[a] as f64 <= p[a] && p[a] <= b.max[a] as f64)
}

#[test]
fn clipped_bounds_hold_the_triangle_on_each_side_of_a_plane() {
    let mut rng = Pcg32::new(7, 3);
    let mut split = 0;
    for _ in 0..2000 {
        let mut v = || rng.cube_point(-8.0, 8.0);
        let t = Triangle::new(v(), v(), v());
        let b = t.bounds();
        assert_eq!(clipped_bounds(&t, &b), Some(b), "a triangle's own box");
        let d = rng.below(3) as usize;
        let pos = rng.range_f32(b.min[d], b.max[d]);
        let (mut l, mut r) = (b, b);
        l.max[d] = pos;
        r.min[d] = pos;
        let (lc, rc) = (clipped_bounds(&t, &l), clipped_bounds(&t, &r));
        // The grid, and where the edges cross the plane (the parts' corners there).
        let v = t.v.map(|p| p.to_array().map(f64::from));
        let mut pts = points(&t, 24);
        for (p, q) in [(v[0], v[1]), (v[1], v[2]), (v[2], v[0])] {
            let s = (pos as f64 - p[d]) / (q[d] - p[d]);
            if (0.0..=1.0).contains(&s) {
                pts.push([0, 1, 2].map(|k| {
                    if k == d {
                        pos as f64
                    } else {
                        p[k] + (q[k] - p[k]) * s
                    }
                }));
            }
        }
        for p in pts {
            let (pl, pr) = (p[d] <= pos as f64, p[d] >= pos as f64);
            if pl {
                let lc = lc.expect("a point on the left");
                assert!(
                    holds(&lc, &p) && l.contains_box(&lc),
                    "{t:?} {d} {pos}: {lc:?}"
                );
            }
            if pr {
                let rc = rc.expect("a point on the right");
                assert!(
                    holds(&rc, &p) && r.contains_box(&rc),
                    "{t:?} {d} {pos}: {rc:?}"
                );
            }
        }
        if let (Some(lc), Some(rc)) = (lc, rc) {
            split += (lc.half_area() < b.half_area() && rc.half_area() < b.half_area()) as u32;
        }
    }
    assert!(split > 1000, "the parts' boxes are smaller: {split}");
}

#[test]
fn clipped_bounds_of_a_box_beside_the_triangle_are_none() {
    let t = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y);
    let above = Aabb::new(Vec3::new(0.0, 0.0, 1.0), Vec3::splat(2.0));
    assert_eq!(clipped_bounds(&t, &above), None);
    // Beyond the hypotenuse, inside the triangle's box.
    let corner = Aabb::new(Vec3::new(0.75, 0.75, 0.0), Vec3::new(1.0, 1.0, 0.0));
    assert_eq!(clipped_bounds(&t, &corner), None);
}
