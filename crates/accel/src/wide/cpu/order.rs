//! The order of a node's children in the copy: the child a shadow ray most likely ends in
//! first.
//!
//! A shadow ray visits its hit children in slot order (it needs any hit, not the nearest),
//! so the copy puts first the child most likely to stop a ray that crosses the node: the
//! order of Ize and Hansen's RTSAH for occlusion rays ("RTSAH Traversal Order for Occlusion
//! Rays", Eurographics 2011), by probability alone. For rays of uniformly random
//! directions, a line that meets a convex box `B` inside its parent `P` does so with
//! probability `SA(B) / SA(P)` (Cauchy: a convex body's mean projected area is a quarter of
//! its surface area), and a line that meets `B` meets a flat triangle of area `a` inside it
//! with probability `2a / SA(B)` (a triangle's mean projected area is `a / 2`), at most 1
//! for all of them. So a ray crossing the parent ends in child `B`, holding triangles of
//! total area `A`, with probability about `min(SA(B), 2A) / SA(P)`: children are ordered by
//! [`key`], `min(SA(B), 2A)`, largest first.
//!
//! Closest-hit rays visit children nearest first whatever their slots (ties excepted, see
//! the traversal), and every answer is independent of the order (see the [`super`] module
//! docs): this changes speed only. Figures: `docs/cpu-traversal.md`, "Shadow rays: the
//! likeliest occluder first".

use super::lanes::Lanes;
use super::layout::{LANES, LEAF, TriPacket};
use super::traverse::lane_triangle;
use crate::image::{RUN_END, words_box};
use dualsplit_geometry::Triangle;

/// Puts the children of every node of a finished copy (`nodes`, whose children have larger
/// indices than their parent, as [`copy`](super::copy::copy) makes them, over `packets`)
/// in its lanes by [`key`], largest first, ties in lane order. The boxes and child words
/// move together, so the tree is the same; empty lanes (key 0) stay last.
pub(super) fn order_lanes<N: Lanes>(nodes: &mut [N], packets: &[TriPacket]) {
    // Triangle area under each node, filled from the last node back, so that a node's
    // children are done before it.
    let mut area = vec![0.0f64; nodes.len()];
    for i in (0..nodes.len()).rev() {
        let n = &mut nodes[i];
        let mut lanes = [(0.0f64, [0.0f32; 6], 0u32); 8];
        let lanes = &mut lanes[..N::W];
        let mut sum = 0.0;
        for (l, lane) in lanes.iter_mut().enumerate() {
            let c = n.child(l);
            let a = if c & LEAF != 0 {
                leaf_area(packets, (c & !LEAF) as usize)
            } else {
                area.get(c as usize).copied().unwrap_or(0.0)
            };
            sum += a;
            let b = n.lane_box(l);
            *lane = (key(&b, a), b, c);
        }
        area[i] = sum;
        lanes.sort_by(|x, y| y.0.total_cmp(&x.0));
        for (l, &(_, b, c)) in lanes.iter().enumerate() {
            n.set(l, b, c);
        }
    }
}

/// The total area of the triangles of the leaf whose first triangle is at `slot` of
/// `packets` (it ends at the first id from there with [`RUN_END`]).
fn leaf_area(packets: &[TriPacket], mut slot: usize) -> f64 {
    let mut a = 0.0;
    while let Some(pk) = packets.get(slot / LANES) {
        let l = slot % LANES;
        a += triangle_area(&lane_triangle(pk, l));
        if pk.prim[l] & RUN_END != 0 {
            break;
        }
        slot += 1;
    }
    a
}

/// The area of `t`, in f64 (finite for any finite f32 vertices); 0 if it is not finite.
fn triangle_area(t: &Triangle) -> f64 {
    let [a, b, c] = t.v.map(|p| p.as_dvec3());
    let area = 0.5 * (b - a).cross(c - a).length();
    if area.is_finite() { area } else { 0.0 }
}

/// The ordering key of a child with box words `b` (min.xyz, max.xyz) over triangles of
/// total area `area`: `min(SA(B), 2A)`, in f64 (an f32 box area overflows near f32's range,
/// which would tie every large child).
fn key(b: &[f32; 6], area: f64) -> f64 {
    (2.0 * words_box(b).half_area64()).min(2.0 * area)
}

#[cfg(test)]
mod tests {
    use super::super::CpuNodes;
    use super::*;
    use crate::Structures;
    use dualsplit_geometry::{Pcg32, Vec3};

    /// The triangle area under child word `c` of a copy, walking the copy from `c` down.
    fn copy_area<N: Lanes>(nodes: &[N], packets: &[TriPacket], c: u32) -> f64 {
        if c & LEAF != 0 {
            return leaf_area(packets, (c & !LEAF) as usize);
        }
        let n = &nodes[c as usize];
        (0..N::W)
            .map(|l| copy_area(nodes, packets, n.child(l)))
            .sum()
    }

    /// Every node of `nodes` holds its children by key, largest first, each key
    /// recomputed from the copy (lane boxes and the triangles below them). Sums in
    /// another order may differ in their last bits, hence the relative margin.
    fn check_order<N: Lanes>(nodes: &[N], packets: &[TriPacket]) {
        let mut ordered_pairs = 0;
        for (i, n) in nodes.iter().enumerate() {
            let keys: Vec<f64> = (0..N::W)
                .map(|l| key(&n.lane_box(l), copy_area(nodes, packets, n.child(l))))
                .collect();
            for l in 1..N::W {
                assert!(
                    keys[l] <= keys[l - 1] * (1.0 + 1e-9),
                    "node {i}: lane {l}'s key {} above lane {}'s {}",
                    keys[l],
                    l - 1,
                    keys[l - 1]
                );
                ordered_pairs += (keys[l] < keys[l - 1]) as usize;
            }
        }
        // The scene's sizes vary, so the order is not the trivial one of equal keys.
        assert!(
            ordered_pairs > nodes.len(),
            "{ordered_pairs} strictly ordered pairs"
        );
    }

    /// Copies of BVH2, BVH4 and BVH8 images of triangles of many sizes put every node's
    /// children in key order.
    #[test]
    fn copies_hold_children_by_key() {
        let mut rng = Pcg32::new(31, 7);
        let tris: Vec<Triangle> = (0..3000)
            .map(|_| {
                let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 100.0;
                let s = 0.05 + 20.0 * rng.next_f32().powi(4);
                let mut p = || c + Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * s;
                Triangle::new(p(), p(), p())
            })
            .collect();
        let s = Structures::try_build(&tris, &Default::default()).expect("structures");
        for img in [s.bvh2_image(), s.bvh4(), s.bvh8()] {
            let cpu = img.cpu();
            match &cpu.nodes {
                CpuNodes::Four(n) => check_order(n, &cpu.packets),
                CpuNodes::Eight(n) => check_order(n, &cpu.packets),
            }
        }
    }

    #[test]
    fn key_is_the_smaller_of_box_area_and_twice_the_triangles() {
        // A unit cube: surface area 6.
        let cube = [0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
        assert_eq!(key(&cube, 1.0), 2.0);
        assert_eq!(key(&cube, 5.0), 6.0);
        // A flat box (a wall): surface area twice its face, which one triangle pair fills.
        let wall = [0.0, 0.0, 0.0, 2.0, 3.0, 0.0];
        assert_eq!(key(&wall, 6.0), 12.0);
        assert_eq!(key(&wall, 1.0), 2.0);
        // An inverted (empty) box has no area.
        let empty = [1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
        assert_eq!(key(&empty, 1.0), 0.0);
    }

    #[test]
    fn triangle_area_is_exact_where_it_can_be_and_finite_at_the_range_ends() {
        let t = Triangle::new(
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        );
        assert_eq!(triangle_area(&t), 3.0);
        let big = Triangle::new(
            Vec3::new(-3e38, -3e38, 0.0),
            Vec3::new(3e38, -3e38, 0.0),
            Vec3::new(-3e38, 3e38, 0.0),
        );
        let a = triangle_area(&big);
        assert!(a.is_finite() && a > 1e77, "{a}");
        let nan = Triangle::new(Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::ONE);
        assert_eq!(triangle_area(&nan), 0.0);
    }
}
