//! The observer sees exactly what the kernel reads and does (contract 2): exact event
//! sequences on a tiny scene, and fetch addresses inside the image regions on a larger one.

use dualsplit_accel::{
    AccelKind, BuildConfig, ByteAddr, MemoryImage, NodeStep, Observer, Structures,
};
use dualsplit_geometry::{Pcg32, PrimId, Ray, Triangle, Vec3};

#[derive(Debug, PartialEq, Clone)]
enum Ev {
    Fetch(ByteAddr, u32),
    FetchBox(ByteAddr, u32),
    Step(NodeStep),
    Tri(PrimId, bool),
    Push,
    Pop,
}

#[derive(Default)]
struct Rec(Vec<Ev>);

impl Observer for Rec {
    fn fetch(&mut self, addr: ByteAddr, bytes: u32) {
        self.0.push(Ev::Fetch(addr, bytes));
    }
    fn fetch_box(&mut self, addr: ByteAddr, bytes: u32) {
        self.0.push(Ev::FetchBox(addr, bytes));
    }
    fn step(&mut self, s: NodeStep) {
        self.0.push(Ev::Step(s));
    }
    fn triangle_test(&mut self, prim: PrimId, hit: bool) {
        self.0.push(Ev::Tri(prim, hit));
    }
    fn push(&mut self) {
        self.0.push(Ev::Push);
    }
    fn pop(&mut self) {
        self.0.push(Ev::Pop);
    }
}

#[test]
fn single_triangle_event_sequence() {
    let tri = Triangle::new(
        Vec3::new(-1.0, -1.0, 2.0),
        Vec3::new(1.0, -1.0, 2.0),
        Vec3::new(0.0, 1.0, 2.0),
    );
    let s = Structures::build(&[tri], &BuildConfig::default());
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    for (kind, node_bytes, arity) in [
        (AccelKind::Bvh2, 52u32, 2u8),
        (AccelKind::Bvh4, 100, 4),
        (AccelKind::Bvh8, 200, 8),
    ] {
        let img = s.image(kind);
        // Root node, then its one leaf word right after it, then the index run, then the
        // triangle.
        let leaf_word = (node_bytes / 4) as usize;
        assert_eq!(img.nodes, 0..leaf_word + 1);
        assert_eq!(img.words[leaf_word] as usize, img.indices.start);
        assert_eq!(img.words[img.indices.start], 1 << 31);
        let mut rec = Rec::default();
        let hit = s.closest_hit(kind, &ray, &mut rec).unwrap();
        assert_eq!((hit.t, hit.prim), (2.0, PrimId(0)));
        // The node's header (after its boxes), then the one present child's box.
        let boxes = 24 * arity as u32;
        assert_eq!(
            rec.0,
            vec![
                Ev::Fetch(ByteAddr(boxes as u64), node_bytes - boxes),
                Ev::FetchBox(ByteAddr(0), 24),
                Ev::Step(NodeStep::Bvh {
                    arity,
                    valid: 1,
                    hits: 1
                }),
                Ev::Fetch(MemoryImage::addr(leaf_word), 4),
                Ev::Fetch(MemoryImage::addr(img.indices.start), 4),
                Ev::Step(NodeStep::Leaf { count: 1 }),
                Ev::Fetch(MemoryImage::addr(img.triangles.start), 36),
                Ev::Tri(PrimId(0), true),
            ],
            "{kind:?}"
        );
    }
}

#[test]
fn fetches_stay_inside_regions_and_match_node_sizes() {
    let mut rng = Pcg32::new(7, 3);
    let tris: Vec<Triangle> = (0..3000)
        .map(|_| {
            let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0;
            let d = |r: &mut Pcg32| Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) - 0.5;
            Triangle::new(p, p + d(&mut rng), p + d(&mut rng))
        })
        .collect();
    let s = Structures::build(&tris, &BuildConfig::default());
    for kind in [AccelKind::Bvh2, AccelKind::Bvh4, AccelKind::Bvh8] {
        let img = s.image(kind);
        let arity = s.encoded(kind).expect("a BVH kind").arity as u64;
        let header_bytes = if kind == AccelKind::Bvh8 { 8 } else { 4 };
        for i in 0..200 {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0;
            let d = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5;
            let mut rec = Rec::default();
            let hit = s.closest_hit(kind, &Ray::new(o, d), &mut rec);
            let (mut pushes, mut pops) = (0, 0);
            // The node whose header was fetched last (its byte address) and the slots of
            // the boxes fetched since.
            let (mut node, mut slots) = (None, Vec::new());
            for e in &rec.0 {
                match *e {
                    Ev::Fetch(ByteAddr(a), b) => {
                        let w = (a / 4) as usize;
                        let end = w + (b / 4) as usize;
                        let inside = |r: &std::ops::Range<usize>| r.start <= w && end <= r.end;
                        assert!(
                            (inside(&img.nodes) && (b == header_bytes || b == 4))
                                || inside(&img.indices)
                                || (inside(&img.triangles) && b == 36),
                            "{kind:?} ray {i}: fetch {a}+{b}"
                        );
                        node = (b == header_bytes && inside(&img.nodes)).then(|| a - 24 * arity);
                        slots.clear();
                    }
                    Ev::FetchBox(ByteAddr(a), b) => {
                        let n = node.expect("a box is fetched after its node's header");
                        assert!(b == 24 && a >= n && (a - n) % 24 == 0, "{kind:?} ray {i}");
                        let k = (a - n) / 24;
                        assert!(k < arity && slots.last().is_none_or(|&j| j < k));
                        slots.push(k);
                    }
                    Ev::Step(NodeStep::Bvh { valid, .. }) => {
                        // Every present child's box, each once, in slot order.
                        assert_eq!(slots.len(), valid as usize, "{kind:?} ray {i}");
                    }
                    Ev::Push => pushes += 1,
                    Ev::Pop => pops += 1,
                    _ => {}
                }
            }
            // Every pushed entry is popped once the closest-hit traversal ends.
            assert_eq!(pushes, pops, "{kind:?} ray {i}");
            let last_accept = rec.0.iter().rev().find_map(|e| match e {
                Ev::Tri(p, true) => Some(*p),
                _ => None,
            });
            assert_eq!(hit.map(|h| h.prim), last_accept, "{kind:?} ray {i}");
        }
    }
}
