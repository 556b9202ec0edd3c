//! `validate()`: walks the quantized DST's records from the root, alone (the structural
//! check of a loaded image) or in lockstep with its exact DST (conservative planes).
//!
//! Structure: every cluster's frame inside the node region (whole lines), every record
//! inside its cluster's line (at or after bit 128), reached once and overlapping nothing,
//! headers among the exact DST's 37 valid codes, child clusters
//! inside the node region, runs inside the index region and terminated, every index entry
//! in exactly one run, every triangle referenced exactly once, each cluster's record count
//! equal to the records reached in it. Lockstep with the exact DST: the same node kind,
//! axis, corner and run at every node, and every plane conservative: a "≤" plane decodes to
//! at least `min(exact plane, exact region max)`, a "≥" plane to at most
//! `max(exact plane, exact region min)` (the exact region being the one the exact node is
//! entered with), so every quantized region contains its exact region (also checked).
//! Any words give a report, never a panic or an endless walk.

use super::build::{ExactNode, child_region, plane_roles, read_exact};
use super::frame::Frame;
use super::layout::{FRAME_WORDS, ROOT_BIT};
use super::record::{ChildRef, QHeader, read_bits};
use super::{DstQ, DstQStats};
use crate::dst::Dst;
use crate::image::{MemoryImage, RUN_END};
use crate::observer::DstNodeKind;
use crate::validate::{MAX_MESSAGES, ValidationReport};
use dualsplit_geometry::Aabb;

/// A report with nothing reached yet.
pub(super) fn empty_report(img: &MemoryImage) -> ValidationReport {
    ValidationReport {
        structure: "dst-q",
        triangles: img.triangle_slice().len(),
        ..ValidationReport::default()
    }
}

fn error(rep: &mut ValidationReport, msg: String) {
    rep.error_count += 1;
    if rep.errors.len() < MAX_MESSAGES {
        rep.errors.push(msg);
    }
}

const NONE: u32 = u32::MAX;

/// One record to check: where it is, its depth, its exact node (or [`NONE`]) and the
/// quantized region entering it.
struct Visit {
    cluster: u32,
    bit: u32,
    depth: usize,
    exact: u32,
    region: Aabb,
}

impl DstQ {
    /// Checks the tree against `dst`, the exact DST it was converted from: the structure and,
    /// node by node, the same decisions with conservative planes (module docs). Structure
    /// name "dst-q".
    pub fn validate(&self, dst: &Dst) -> ValidationReport {
        match read_exact(dst) {
            Ok(nodes) => self.walk(Some(&nodes)).0,
            Err(e) => {
                let mut rep = empty_report(&self.image);
                error(&mut rep, format!("the exact DST does not read: {e}"));
                rep
            }
        }
    }

    /// The structural check alone (what loading a saved tree runs).
    pub fn validate_structure(&self) -> ValidationReport {
        self.walk(None).0
    }

    /// Node counts and sizes, counted by walking the records.
    pub fn stats(&self) -> DstQStats {
        let mut s = self.walk(None).1;
        s.node_bytes = self.image.node_bytes();
        s.index_bytes = self.image.index_bytes();
        s.total_bytes = self.bytes_total();
        s
    }

    fn walk(&self, exact: Option<&[ExactNode]>) -> (ValidationReport, DstQStats) {
        let img = &self.image;
        let mut rep = empty_report(img);
        let mut st = DstQStats::default();
        let k = self.config.bits;
        let fmt = self.config.record_format();
        let cw = self.config.cluster_words() as usize;
        let cbits = self.config.cluster_bytes * 8;
        let words: &[u32] = &img.words;
        let n_tris = rep.triangles;
        if img.nodes.start != 0
            || img.nodes.end != img.indices.start
            || words.len() < img.indices.end
            || !img.nodes.len().is_multiple_of(cw)
        {
            error(
                &mut rep,
                format!(
                    "regions nodes {:?}, indices {:?} over {} words do not fit {}-word lines",
                    img.nodes,
                    img.indices,
                    words.len(),
                    cw
                ),
            );
            return (rep, st);
        }
        let n_words = img.nodes.len();
        let mut index_cover = vec![0u8; img.indices.len()];
        let mut tri_refs = vec![0u32; n_tris];
        if let Some(ex) = exact
            && ex.is_empty() != (n_words == 0)
        {
            error(
                &mut rep,
                "the exact DST and dst-q disagree on emptiness".into(),
            );
            return (rep, st);
        }
        // One bit per node-region bit covered by a frame or a record; records per cluster.
        let mut seen = vec![0u64; (n_words * 32).div_ceil(64)];
        let mut per_cluster: std::collections::BTreeMap<u32, u32> = Default::default();
        let mut stack: Vec<Visit> = Vec::new();
        if n_words > 0 {
            stack.push(Visit {
                cluster: 0,
                bit: ROOT_BIT,
                depth: 0,
                exact: if exact.is_some() { 0 } else { NONE },
                region: self.scene_box,
            });
        }
        while let Some(v) = stack.pop() {
            let at = format!("record {}:{}", v.cluster, v.bit);
            let base = v.cluster as usize;
            // A cluster lies inside one line of `cw` words (the node region is whole lines).
            let line_end = (base / cw + 1) * cw;
            if base + FRAME_WORDS > n_words || line_end > n_words {
                error(
                    &mut rep,
                    format!("{at}: cluster outside the node region 0..{n_words}"),
                );
                continue;
            }
            let avail = ((line_end - base) * 32).min(cbits as usize) as u32;
            if v.bit < ROOT_BIT || v.bit + 32 > avail {
                error(&mut rep, format!("{at}: bit outside {ROOT_BIT}..{avail}"));
                continue;
            }
            let cwords = &words[base..line_end];
            let word = read_bits(cwords, v.bit as usize, 32);
            let h = match QHeader::decode(word, &fmt, v.bit) {
                Ok(h) => h,
                Err(e) => {
                    error(&mut rep, format!("{at}: {e}"));
                    continue;
                }
            };
            let (hb, rb) = (h.header_bits(&fmt), h.record_bits(&fmt));
            if v.bit + rb > avail {
                error(
                    &mut rep,
                    format!("{at}: record of {rb} bits leaves its line"),
                );
                continue;
            }
            let first_visit = !per_cluster.contains_key(&v.cluster);
            if first_visit && !cover(&mut seen, base * 32, ROOT_BIT as usize) {
                error(
                    &mut rep,
                    format!("{at}: the cluster's frame overlaps another record"),
                );
                continue;
            }
            *per_cluster.entry(v.cluster).or_insert(0) += 1;
            if !cover(&mut seen, base * 32 + v.bit as usize, rb as usize) {
                error(
                    &mut rep,
                    format!("{at}: reached twice or overlapping another record"),
                );
                continue;
            }
            st.used_bits += rb as u64 + if first_visit { ROOT_BIT as u64 } else { 0 };
            rep.max_depth = rep.max_depth.max(v.depth);
            let mut fw = [0u32; 4];
            fw.copy_from_slice(&cwords[..FRAME_WORDS]);
            let frame = Frame::from_words(fw);
            let kind = h.node_kind();
            let planes = if kind == DstNodeKind::Leaf {
                [0.0; 2]
            } else {
                let hx = h.exact();
                let mut p = [0.0f32; 2];
                for (a, slot, _) in plane_roles(hx) {
                    let q = read_bits(cwords, (v.bit + hb + slot as u32 * k) as usize, k);
                    p[slot] = frame.plane(a, q);
                }
                p
            };
            // Lockstep with the exact node.
            let ex = exact.and_then(|e| e.get(v.exact as usize));
            if let Some(en) = ex {
                // A split's B field names its left record's size, which differs from the
                // exact DST's left size in words: compare kind and axis for splits.
                let same = if en.hdr.is_split() {
                    h.node_kind() == DstNodeKind::Split && h.exact().axis() == en.hdr.axis()
                } else {
                    en.hdr.header() as u32 == h.code()
                };
                if !same || (h.is_leaf_flag() && en.hdr.offset() != h.run()) {
                    error(
                        &mut rep,
                        format!("{at}: {h:?} differs from the exact node {:?}", en.hdr),
                    );
                    continue;
                }
                if !v.region.contains_box(&en.region) {
                    error(
                        &mut rep,
                        format!(
                            "{at}: region {:?} does not contain the exact region {:?}",
                            v.region, en.region
                        ),
                    );
                }
                if kind != DstNodeKind::Leaf {
                    for (a, slot, lower) in plane_roles(en.hdr) {
                        let (x, got) = (en.planes[slot], planes[slot]);
                        let ok = if lower {
                            got <= x.max(en.region.min[a])
                        } else {
                            got >= x.min(en.region.max[a])
                        };
                        if !ok {
                            error(
                                &mut rep,
                                format!(
                                    "{at}: plane P{slot} = {got} is not conservative \
                                     (exact {x}, {} bound)",
                                    if lower { "lower" } else { "upper" }
                                ),
                            );
                        }
                    }
                }
            }
            let exact_kid = |i: usize| ex.map_or(NONE, |en| en.kids[i]);
            match kind {
                DstNodeKind::Leaf => {
                    st.leaves += 1;
                    rep.leaves += 1;
                }
                DstNodeKind::Split => st.splitting += 1,
                DstNodeKind::SingleCarve => st.single_carving += 1,
                DstNodeKind::DualCarve => st.dual_carving += 1,
            }
            if kind != DstNodeKind::Leaf {
                rep.internal_nodes += 1;
            }
            if h.is_leaf_flag() {
                if kind != DstNodeKind::Leaf {
                    st.carving_leaves += 1;
                    rep.leaves += 1;
                }
                self.check_run(&mut rep, &at, h.run(), &mut index_cover, &mut tri_refs);
                continue;
            }
            let (cb, cbit) = match h.child(&fmt) {
                ChildRef::Local(b) => (v.cluster, b),
                ChildRef::Cluster(c) => (c, ROOT_BIT),
            };
            let hx = h.exact();
            if kind == DstNodeKind::Split {
                let lsize = h.left_bits(&fmt);
                for (side, bit) in [(1, cbit.saturating_add(lsize)), (0, cbit)] {
                    stack.push(Visit {
                        cluster: cb,
                        bit,
                        depth: v.depth + 1,
                        exact: exact_kid(side),
                        region: child_region(hx, planes, v.region, side),
                    });
                }
                // The left size field must name the left record's real size.
                if (cb as usize) < n_words && cbit as usize + 32 <= (n_words - cb as usize) * 32 {
                    let lw = read_bits(&words[cb as usize..n_words], cbit as usize, 32);
                    let real = QHeader::read(lw, &fmt).record_bits(&fmt);
                    if real != lsize {
                        error(&mut rep, format!("{at}: left size {lsize} but {real} bits"));
                    }
                }
            } else {
                stack.push(Visit {
                    cluster: cb,
                    bit: cbit,
                    depth: v.depth + 1,
                    exact: exact_kid(0),
                    region: child_region(hx, planes, v.region, 0),
                });
            }
        }
        // Record counts in the frames, every cluster reached, every entry and triangle once.
        for (&b, &n) in &per_cluster {
            let stored = cluster_count(words, b as usize);
            if n.min(255) != stored as u32 {
                error(
                    &mut rep,
                    format!("cluster at word {b}: frame says {stored} records, {n} reached"),
                );
            }
        }
        st.clusters = per_cluster.len() as u64;
        let unused = index_cover.iter().filter(|&&c| c == 0).count();
        if unused > 0 {
            error(
                &mut rep,
                format!("{unused} index entries in no reached run"),
            );
        }
        rep.triangles_referenced = tri_refs.iter().filter(|&&c| c > 0).count();
        for (p, &c) in tri_refs.iter().enumerate() {
            if c != 1 {
                error(&mut rep, format!("triangle {p} referenced {c} times"));
            }
        }
        st.index_entries = img.indices.len() as u64;
        (rep, st)
    }

    fn check_run(
        &self,
        rep: &mut ValidationReport,
        at: &str,
        first: u32,
        cover: &mut [u8],
        tri_refs: &mut [u32],
    ) {
        let img = &self.image;
        let run = &img.words[img.indices.clone()];
        let mut j = first as usize;
        loop {
            if j >= run.len() {
                error(
                    rep,
                    format!("{at}: run from {first} leaves the index region"),
                );
                return;
            }
            cover[j] = cover[j].saturating_add(1);
            if cover[j] > 1 {
                error(rep, format!("{at}: index entry {j} in two runs"));
                return;
            }
            let p = (run[j] & !RUN_END) as usize;
            match tri_refs.get_mut(p) {
                Some(c) => *c += 1,
                None => error(rep, format!("{at}: triangle {p} out of range")),
            }
            if run[j] & RUN_END != 0 {
                return;
            }
            j += 1;
        }
    }
}

/// Marks bits `at..at + n` of `seen`; false when one of them already was.
fn cover(seen: &mut [u64], at: usize, n: usize) -> bool {
    let mut fresh = true;
    for b in at..at + n {
        fresh &= seen[b / 64] & (1 << (b % 64)) == 0;
        seen[b / 64] |= 1 << (b % 64);
    }
    fresh
}

/// The record count stored in byte 3 of a cluster's frame word 3.
fn cluster_count(words: &[u32], base: usize) -> u8 {
    (words[base + 3] >> 24) as u8
}
