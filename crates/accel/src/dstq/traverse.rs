//! Traversal of the quantized DST: the exact DST's node rules (`dst/traverse.rs`; Lin et al.
//! 2020, §3, Figs. 2–3), with each plane dequantized from its cluster's frame
//! (`plane = p_a + q · 2^(e_a − 127)`) before the same distance, widening and `le_or_nan`
//! tests. A stack entry carries the cluster's word address and the record's bit position
//! beside its interval.
//!
//! Fetch accounting (`docs/dstq-encoding.md`, §6): the frame (16 B at the cluster's start)
//! when the traversal starts working in a cluster other than the one whose frame it holds
//! (descending into a child cluster, or popping an entry of another cluster); then, per
//! node step, the whole 32-bit words that hold the record's bits (a record may straddle a
//! word boundary); 4 B per index entry and 36 B per triangle, as the exact DST.

use super::DstQ;
use super::frame::Frame;
use super::layout::{FRAME_WORDS, ROOT_BIT};
use super::record::{ChildRef, QHeader, read_bits};
use crate::dst::pipeline::{ReturnCode, le_or_nan};
use crate::dst::traverse::{IndexRun, RunResult, dual_carve};
use crate::image::MemoryImage;
use crate::observer::{DstNodeKind, NodeStep, Observer};
use dualsplit_geometry::{Hit, Ray, cull_limit};

/// A traversal-stack entry: a record (its cluster's word address and its bit position in
/// the cluster) and its ray interval.
#[derive(Clone, Copy, Debug)]
struct Entry {
    cluster: u32,
    bit: u32,
    t_min: f32,
    t_max: f32,
}

#[inline(always)]
fn dst_step(kind: DstNodeKind, code: ReturnCode, carving_leaf: bool) -> NodeStep {
    NodeStep::Dst {
        kind,
        code,
        carving_leaf,
    }
}

impl DstQ {
    /// Closest hit of `ray`, ordered by `(t, prim)`: equal to the exact DST's and the BVH2's
    /// on every ray (conservative planes only add work). Lin et al. 2020, §3, §5.
    pub fn closest_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        self.traverse::<O, false>(ray, obs)
    }

    /// True when `ray` hits any triangle within `[t_min, t_max]`.
    pub fn any_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        self.traverse::<O, true>(ray, obs).is_some()
    }

    /// Where the child `c` of a record in the cluster at word `cluster` lies: (cluster word, bit).
    #[inline(always)]
    fn locate(cluster: u32, c: ChildRef) -> (u32, u32) {
        match c {
            ChildRef::Local(bit) => (cluster, bit),
            ChildRef::Cluster(b) => (b, ROOT_BIT),
        }
    }

    fn traverse<O: Observer, const ANY: bool>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        // Untraceable rays miss (`Ray::is_traceable`), in every structure alike.
        if self.is_empty() || !ray.is_traceable() {
            return None;
        }
        let r = ray.precompute();
        let sb = self.scene_box;
        let (mut t_min, mut t_max) = r.slab(sb.min, sb.max, ray.t_min, cull_limit(ray.t_max));
        if t_min > t_max {
            return None;
        }
        let img = &self.image;
        let words: &[u32] = &img.words;
        let k = self.config.bits;
        let fmt = self.config.record_format();
        let cw = self.config.cluster_words() as usize;
        let runs = IndexRun {
            words,
            index_base: img.indices.start,
            tri_base: img.triangles.start,
            tris: self.triangles(),
        };
        let mut best: Option<Hit> = None;
        let mut best_t = ray.t_max;
        let mut stack: Vec<Entry> = Vec::with_capacity(64);
        let mut frame_at = u32::MAX;
        let mut frame = Frame {
            origin: [0.0; 3],
            exp: [0; 3],
        };
        let (mut cluster, mut bit) = (0u32, ROOT_BIT);
        loop {
            let base = cluster as usize;
            if cluster != frame_at {
                obs.fetch(MemoryImage::addr(base), 4 * FRAME_WORDS as u32);
                let mut fw = [0u32; 4];
                fw.copy_from_slice(&words[base..base + FRAME_WORDS]);
                frame = Frame::from_words(fw);
                frame_at = cluster;
            }
            // A cluster never crosses its line: its records lie before the line's end.
            let cwords = &words[base..(base / cw + 1) * cw];
            let h = QHeader::read(read_bits(cwords, bit as usize, 32), &fmt);
            let (hb, rb) = (h.header_bits(&fmt), h.record_bits(&fmt));
            let (w0, w1) = (bit / 32, (bit + rb - 1) / 32);
            obs.fetch(MemoryImage::addr(base + w0 as usize), 4 * (w1 - w0 + 1));
            let plane = |slot: u32, a: usize| {
                frame.plane(a, read_bits(cwords, (bit + hb + slot * k) as usize, k))
            };
            let run = match h.node_kind() {
                DstNodeKind::Leaf => {
                    obs.step(dst_step(DstNodeKind::Leaf, ReturnCode::Leaf, false));
                    Some(h.run())
                }
                DstNodeKind::Split => {
                    let a = h.exact().axis();
                    let (p0, p1) = (plane(0, a), plane(1, a));
                    let (cb, lbit) = Self::locate(cluster, h.child(&fmt));
                    let lsize = h.left_bits(&fmt);
                    let (left, right) = ((cb, lbit), (cb, lbit + lsize));
                    let (near, far, t1, t2) = if r.neg[a] {
                        (right, left, r.exit_t(a, p1), r.plane_t(a, p0))
                    } else {
                        (left, right, r.exit_t(a, p0), r.plane_t(a, p1))
                    };
                    let near_hit = le_or_nan(t_min, t1);
                    let far_hit = le_or_nan(t2, t_max);
                    obs.step(dst_step(
                        DstNodeKind::Split,
                        ReturnCode::from_bits(near_hit as u8 + far_hit as u8),
                        false,
                    ));
                    match (near_hit, far_hit) {
                        (true, true) => {
                            stack.push(Entry {
                                cluster: far.0,
                                bit: far.1,
                                t_min: t_min.max(t2),
                                t_max,
                            });
                            obs.push();
                            (cluster, bit) = near;
                            t_max = t_max.min(t1);
                            continue;
                        }
                        (true, false) => {
                            (cluster, bit) = near;
                            t_max = t_max.min(t1);
                            continue;
                        }
                        (false, true) => {
                            (cluster, bit) = far;
                            t_min = t_min.max(t2);
                            continue;
                        }
                        (false, false) => None,
                    }
                }
                kind => {
                    let (lo, hi) = if kind == DstNodeKind::SingleCarve {
                        let a = h.exact().axis();
                        let (p0, p1) = (plane(0, a), plane(1, a));
                        let (t1, t2) = if r.neg[a] {
                            (r.exit_t(a, p1), r.plane_t(a, p0))
                        } else {
                            (r.exit_t(a, p0), r.plane_t(a, p1))
                        };
                        (t_min.max(t2), t_max.min(t1))
                    } else {
                        let (a0, a1) = h.exact().axis_pair().axes();
                        let t = (r.plane_t(a0, plane(0, a0)), r.plane_t(a1, plane(1, a1)));
                        dual_carve(&r.neg, h.exact(), t, t_min, t_max)
                    };
                    let hit = le_or_nan(lo, hi);
                    let leaf = h.is_leaf_flag();
                    let code = ReturnCode::from_bits(hit as u8 * (1 + 2 * leaf as u8));
                    obs.step(dst_step(kind, code, leaf));
                    if hit {
                        t_min = lo;
                        t_max = hi;
                        if !leaf {
                            (cluster, bit) = Self::locate(cluster, h.child(&fmt));
                            continue;
                        }
                        Some(h.run())
                    } else {
                        None
                    }
                }
            };
            if let Some(first) = run {
                // The run on the ray's own interval [ray.t_min, best_t], as the exact DST.
                if let RunResult::Occluded =
                    runs.test::<O, ANY>(first, &r, &mut best, &mut best_t, obs)
                {
                    return best;
                }
            }
            // Pop the next entry that can still hold a closer hit, clamping its t_max.
            let limit = cull_limit(best_t);
            loop {
                let Some(e) = stack.pop() else {
                    return best;
                };
                obs.pop();
                if le_or_nan(e.t_min, limit) {
                    (cluster, bit, t_min, t_max) = (e.cluster, e.bit, e.t_min, e.t_max.min(limit));
                    break;
                }
            }
        }
    }
}
