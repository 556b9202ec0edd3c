//! The traversal of the copy: the node loop, the stack, and the leaf test.

use super::isa::Isa;
use super::lanes::Lanes;
use super::layout::{EMPTY, LANES, LEAF, TriPacket};
use super::ray::RaySimd;
use crate::image::RUN_END;
use crate::wide::simd::Avx2;
use dualsplit_geometry::{Hit, PrimId, Ray, RayPre, Triangle, TriangleHit, Vec3, cull_limit};
use std::cell::RefCell;
use wide::f32x4;

/// The traversal (see the [`super`] module docs) of `nodes` and `packets` with instructions
/// `I`: a closest-hit ray's here, a shadow ray's (`ANY`) in [`any_hit`].
#[inline(always)]
pub(super) fn run<N: Lanes, I: Isa, const ANY: bool>(
    isa: I,
    nodes: &[N],
    packets: &[TriPacket],
    ray: &Ray,
    stack: &mut [Entry],
) -> Option<Hit> {
    if ANY {
        return any_hit(isa, nodes, packets, ray, stack);
    }
    let r = ray_constants(isa, ray);
    let rs = RaySimd::new(&r);
    let mut best: Option<Hit> = None;
    let mut best_t = ray.t_max;
    // Read once: the node loop then keeps it in a register or a stack slot rather than
    // reloading the ray's address for it at every node.
    let t_min = ray.t_min;
    let mut limit = cull_limit(best_t);
    let mut cur = 0u32;
    // Entries in use: `stack[..sp]`, the top last. The caller sizes `stack` to the copy's
    // bound (`stack_len`), so no push goes past its end.
    let mut sp = 0usize;
    loop {
        if cur & LEAF == 0 {
            let node = &nodes[cur as usize];
            let (dv, mask) = node.test(isa, &rs, t_min, limit);
            // Lane i's entry distance.
            let child = |i: usize| node.child(i);
            let d = |i: usize| isa.lane(dv, i);
            if mask != 0 {
                let first = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                if rest == 0 {
                    cur = child(first);
                    continue;
                }
                let second = rest.trailing_zeros() as usize;
                if rest & (rest - 1) == 0 {
                    // Two hits: the nearer next, the other on the stack; at equal
                    // distances the later slot (as `Avx2::sort_hits8`).
                    let (near, far) = if d(second) <= d(first) {
                        (second, first)
                    } else {
                        (first, second)
                    };
                    let c = child(far);
                    prefetch_child(nodes, packets, c);
                    stack[sp] = Entry {
                        t: d(far),
                        child: c,
                    };
                    sp += 1;
                    cur = child(near);
                    continue;
                }
                // Three or more: sorted by the vector unit where there is one (BVH8 with
                // AVX2), without the data-dependent branches of an insertion sort. All
                // eight lanes are written from `sp` on (the stack's bound counts a node's
                // eight, `stack_len`); the hit ones, farthest first, are the first `k`, and
                // the last of them, the nearest, is taken rather than kept. The stacked ones
                // are prefetched.
                if let (Some(avx2), Some(c8)) = (isa.avx2(), node.children8()) {
                    let out: &mut [Entry; 8] = (&mut stack[sp..sp + 8])
                        .try_into()
                        .expect("a window of eight entries");
                    let dist8: [f32; 8] = bytemuck::cast(dv);
                    let (k, near) = avx2.sort_hits8(dist8, c8, mask, bytemuck::cast_mut(out));
                    // The nearest is next; the others stay stacked, it is not.
                    sp += k as usize - 1;
                    let near = near as usize & 7;
                    let mut m = mask & !(1 << near);
                    while m != 0 {
                        let i = m.trailing_zeros() as usize;
                        m &= m - 1;
                        prefetch_child(nodes, packets, child(i));
                    }
                    cur = child(near);
                    continue;
                }
                // Otherwise pushed in slot order, each inserted below the entries
                // already pushed that are nearer (ties by slot, the later nearer the top,
                // as `Avx2::sort_hits8`), so that the nearest ends on top; then it is taken.
                let base = sp;
                let mut m = mask;
                while m != 0 {
                    let i = m.trailing_zeros() as usize;
                    m &= m - 1;
                    let e = Entry {
                        t: d(i),
                        child: child(i),
                    };
                    prefetch_child(nodes, packets, e.child);
                    let mut j = sp;
                    while j > base && stack[j - 1].t < e.t {
                        stack[j] = stack[j - 1];
                        j -= 1;
                    }
                    stack[j] = e;
                    sp += 1;
                }
                // The nearest, just placed on top.
                sp -= 1;
                cur = stack[sp].child;
                continue;
            }
        } else {
            let slot = (cur & !LEAF) as usize;
            test_leaf::<false>(isa.avx2(), packets, slot, &rs, &r, &mut best, &mut best_t);
            limit = cull_limit(best_t);
        }
        // Next: the nearest stacked entry not beyond the limit.
        loop {
            if sp == 0 {
                return best;
            }
            sp -= 1;
            let e = stack[sp];
            if e.t <= limit {
                cur = e.child;
                break;
            }
        }
    }
}

/// A shadow ray's step at `node`, whose hit lanes are `mask` (not 0): returns the child to
/// visit next and pushes the other hit children on `stack[*sp..]`. Any hit ends the ray, so
/// the hit children are visited in slot order, which the copy makes the order of their
/// chances of stopping the ray (`order.rs`): the first is next, the others are pushed last
/// slot first, so that they pop in slot order. Their entry distances are not kept: the
/// limit they passed is the one they are popped under (see [`any_hit`]).
#[inline(always)]
fn step_any<N: Lanes>(
    nodes: &[N],
    packets: &[TriPacket],
    node: &N,
    mask: u32,
    stack: &mut [Entry],
    sp: &mut usize,
) -> u32 {
    let mut m = mask & (mask - 1);
    while m != 0 {
        let i = 31 - m.leading_zeros() as usize;
        m &= !(1 << i);
        let c = node.child(i);
        prefetch_child(nodes, packets, c);
        stack[*sp] = Entry { t: 0.0, child: c };
        *sp += 1;
    }
    node.child(mask.trailing_zeros() as usize)
}

/// The ray's constants for the box and triangle tests: by vector instructions where there
/// is AVX2 ([`Avx2::ray_pre`], the same bits as [`Ray::precompute`]).
#[inline(always)]
fn ray_constants<I: Isa>(isa: I, ray: &Ray) -> RayPre {
    match isa.avx2() {
        Some(avx2) => avx2.ray_pre(ray),
        _ => ray.precompute(),
    }
}

/// A shadow ray's traversal. Any hit ends it, and its limit never moves, so every stacked
/// entry passed the limit it is popped under: entries keep no distance, and none is
/// skipped. It reaches its first leaf with the box test's constants alone
/// ([`RaySimd::boxes`]): most shadow rays of some scenes reach none (88 % of Dragon Box's,
/// 36 % of Sponza's) and then never need the watertight test's axes and shear, which are
/// computed there, for the leaves and the node steps after them.
#[inline(always)]
fn any_hit<N: Lanes, I: Isa>(
    isa: I,
    nodes: &[N],
    packets: &[TriPacket],
    ray: &Ray,
    stack: &mut [Entry],
) -> Option<Hit> {
    let (t_min, limit) = (ray.t_min, cull_limit(ray.t_max));
    let mut sp = 0usize;
    let boxes = RaySimd::boxes(ray);
    let mut leaf = descend(isa, nodes, packets, &boxes, t_min, limit, stack, 0, &mut sp)?;
    let r = ray_constants(isa, ray);
    let rs = RaySimd::new(&r);
    let (mut best, mut best_t) = (None, ray.t_max);
    loop {
        let slot = (leaf & !LEAF) as usize;
        if test_leaf::<true>(isa.avx2(), packets, slot, &rs, &r, &mut best, &mut best_t) {
            return best;
        }
        if sp == 0 {
            return None;
        }
        sp -= 1;
        let next = stack[sp].child;
        leaf = descend(isa, nodes, packets, &rs, t_min, limit, stack, next, &mut sp)?;
    }
}

/// A shadow ray's node steps from child word `cur` on `[t_min, limit]` until a leaf, whose
/// child word it returns, popping `stack[..*sp]` at a node whose children the ray all
/// misses; `None` when the stack runs out first (no hit).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn descend<N: Lanes, I: Isa>(
    isa: I,
    nodes: &[N],
    packets: &[TriPacket],
    rs: &RaySimd,
    t_min: f32,
    limit: f32,
    stack: &mut [Entry],
    mut cur: u32,
    sp: &mut usize,
) -> Option<u32> {
    loop {
        if cur & LEAF != 0 {
            return Some(cur);
        }
        let node = &nodes[cur as usize];
        let (_, mask) = node.test(isa, rs, t_min, limit);
        if mask != 0 {
            cur = step_any(nodes, packets, node, mask, stack, sp);
            continue;
        }
        if *sp == 0 {
            return None;
        }
        *sp -= 1;
        cur = stack[*sp].child;
    }
}

/// Prefetches child word `c`'s node or the first packet of its leaf (every line of it).
/// The address is computed without a bounds check: a prefetch hint reads nothing for the
/// program and cannot fault.
#[inline(always)]
fn prefetch_child<N>(nodes: &[N], packets: &[TriPacket], c: u32) {
    if c & LEAF == 0 {
        crate::wide::simd::prefetch(nodes.as_ptr().wrapping_add(c as usize));
    } else {
        crate::wide::simd::prefetch(packets.as_ptr().wrapping_add((c & !LEAF) as usize / LANES));
    }
}

/// Tests the leaf whose first triangle is at `slot` of `packets` (it ends at the first id
/// from there with [`RUN_END`]) on `[ray.t_min, best_t]`, keeping the closest hit by
/// [`Hit::closer_than`] in `best` and `best_t`. Returns true when `ANY` and a hit was
/// accepted. `avx2`: the token when the caller runs compiled for AVX2.
#[inline(always)]
pub(crate) fn test_leaf<const ANY: bool>(
    avx2: Option<Avx2>,
    packets: &[TriPacket],
    slot: usize,
    rs: &RaySimd,
    r: &RayPre,
    best: &mut Option<Hit>,
    best_t: &mut f32,
) -> bool {
    let mut i = slot / LANES;
    // Lanes at or after the leaf's first.
    let mut from = (0b1111 << (slot % LANES)) & 0b1111;
    loop {
        let pk = &packets[i];
        // Lanes up to the leaf's last (the first id from `from` on with bit 31 set:
        // RUN_END or padding).
        let ends = f32x4::new(bytemuck::cast(pk.prim)).move_mask() as u32 & from;
        let lanes = if ends == 0 {
            from
        } else {
            from & ((ends & ends.wrapping_neg()) << 1).wrapping_sub(1)
        };
        // Lanes the scalar test could accept. With AVX2 the rest of the test runs on all
        // four lanes at once, and only the lanes it keeps and those with an edge function
        // equal to zero (which the scalar test recomputes in f64) are visited; otherwise
        // the scalar test decides each candidate from the edge functions computed here.
        let e = rs.triangle_edges(pk);
        let mut m = e.candidates & lanes;
        let done = match avx2 {
            Some(avx2) if m & !e.zero != 0 => {
                let c = rs.complete(avx2, pk, &e, r, r.ray.t_min);
                m &= c.ok | e.zero;
                Some(c)
            }
            _ => None,
        };
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            let p = PrimId(pk.prim[l] & !RUN_END);
            let h = if e.zero & (1 << l) != 0 {
                intersect_lane(pk, l, r, *best_t)
            } else if let Some(c) = &done {
                // `t > t_hi` rejects, as in the scalar test (a NaN end rejects nothing).
                if c.t[l] > *best_t {
                    None
                } else {
                    Some(TriangleHit {
                        t: c.t[l],
                        u: c.u[l],
                        v: c.v[l],
                    })
                }
            } else {
                lane_triangle(pk, l).intersect_from_edges(
                    r,
                    [e.u[l], e.v[l], e.w[l]],
                    r.ray.t_min,
                    *best_t,
                )
            };
            if let Some(h) = h
                && Hit::keep_closest(best, p, h)
            {
                if ANY {
                    return true;
                }
                *best_t = h.t;
            }
        }
        if ends != 0 {
            return false;
        }
        i += 1;
        from = 0b1111;
    }
}

/// Lane `l`'s triangle of `pk`: its own words, from the packet (already in cache).
#[inline(always)]
pub(super) fn lane_triangle(pk: &TriPacket, l: usize) -> Triangle {
    let vertex = |k: usize| Vec3::new(pk.v[3 * k][l], pk.v[3 * k + 1][l], pk.v[3 * k + 2][l]);
    Triangle::new(vertex(0), vertex(1), vertex(2))
}

/// [`Triangle::intersect`] of lane `l` of `pk` on `[ray.t_min, t_hi]`, for the rare lanes
/// with an edge function equal to zero: out of line, so that the common path keeps the
/// triangle in registers rather than in memory for this call.
#[cold]
#[inline(never)]
fn intersect_lane(pk: &TriPacket, l: usize, r: &RayPre, t_hi: f32) -> Option<TriangleHit> {
    lane_triangle(pk, l).intersect(r, r.ray.t_min, t_hi)
}

/// A stacked child: its entry distance and child word.
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub(super) struct Entry {
    pub(super) t: f32,
    pub(super) child: u32,
}

impl Entry {
    /// What fills a stack slot before its first use.
    pub(super) const UNUSED: Self = Self {
        t: 0.0,
        child: EMPTY,
    };
}

thread_local! {
    /// The traversal stack's buffer, one per thread, reused from ray to ray (borrowed in
    /// place: one thread-local access per ray, where taking the buffer out and putting it
    /// back took two and moved it twice).
    pub(super) static STACK: RefCell<Vec<Entry>> = const { RefCell::new(Vec::new()) };
}
