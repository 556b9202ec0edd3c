//! `validate()`: walks the encoded DST beside its source BVH2 and rebuilds every region from
//! the planes, exactly (Lin et al. 2020, §4.2: identical bounds).
//!
//! Checks: every word on a path has one of the 37 valid header codes; offsets lie inside
//! the node and index regions; each splitting node is entered with exactly its BVH node's
//! box (similar partitioning: leaves may see a larger region containing their box); each
//! leaf's run holds exactly its BVH leaf's triangles and ends with bit 31; every triangle is
//! referenced exactly once.

use super::header::HeaderOffset;
use super::{Dst, DstError, Partitioning};
use crate::build::Bvh2;
use crate::image::RUN_END;
use crate::observer::DstNodeKind;
use dualsplit_geometry::Aabb;
use serde::Serialize;

/// What [`Dst::validate`] found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct DstValidation {
    /// 12-byte nodes reached.
    pub internal_nodes: u64,
    /// Triangle runs reached (plain leaves and carving leaves).
    pub leaves: u64,
    /// Index entries reached through runs.
    pub index_entries: u64,
    /// Longest root-to-leaf path in nodes.
    pub max_depth: u32,
    /// Most splitting nodes on one path: the traversal stack's worst case.
    pub max_stack_depth: u32,
}

impl DstValidation {
    fn merge(self, o: DstValidation) -> DstValidation {
        DstValidation {
            internal_nodes: self.internal_nodes + o.internal_nodes,
            leaves: self.leaves + o.leaves,
            index_entries: self.index_entries + o.index_entries,
            max_depth: self.max_depth.max(o.max_depth),
            max_stack_depth: self.max_stack_depth.max(o.max_stack_depth),
        }
    }
}

struct Walker<'a> {
    dst: &'a Dst,
    bvh: &'a Bvh2,
    similar: bool,
}

impl Walker<'_> {
    fn node_word(&self, at: u32, from: u32) -> Result<HeaderOffset, DstError> {
        let nodes = &self.dst.image.nodes;
        if at as usize >= nodes.len() {
            return Err(DstError::OffsetOutOfRange {
                at: from,
                offset: at,
                limit: nodes.len() as u32,
            });
        }
        let w = HeaderOffset::decode(self.dst.image.words[at as usize], at)?;
        if at as usize + w.size_words() as usize > nodes.len() {
            return Err(DstError::OffsetOutOfRange {
                at,
                offset: at + w.size_words(),
                limit: nodes.len() as u32,
            });
        }
        Ok(w)
    }

    fn plane(&self, at: u32, k: usize) -> f32 {
        f32::from_bits(self.dst.image.words[at as usize + k])
    }

    fn check_region(&self, at: u32, n: u32, region: &Aabb, leaf: bool) -> Result<(), DstError> {
        let b = self.bvh.nodes[n as usize].bounds;
        let ok = if leaf && self.similar {
            region.contains_box(&b)
        } else {
            *region == b
        };
        if ok {
            Ok(())
        } else {
            Err(DstError::RegionMismatch {
                at,
                bvh_node: n,
                expected: b,
                found: *region,
            })
        }
    }

    /// Checks the run at index entry `first` against BVH leaf `n`.
    fn check_run(&self, at: u32, first: u32, n: u32) -> Result<u64, DstError> {
        let img = &self.dst.image;
        let node = &self.bvh.nodes[n as usize];
        if !node.is_leaf() {
            return Err(DstError::ShapeMismatch {
                at,
                bvh_node: n,
                what: "a triangle run where the BVH has an internal node",
            });
        }
        let run = &img.words[img.indices.clone()];
        let start = first as usize;
        let len = run
            .get(start..)
            .and_then(|r| r.iter().position(|&e| e & RUN_END != 0))
            .ok_or(DstError::OffsetOutOfRange {
                at,
                offset: first,
                limit: run.len() as u32,
            })?
            + 1;
        let mut got: Vec<u32> = run[start..start + len]
            .iter()
            .map(|&e| e & !RUN_END)
            .collect();
        let mut want: Vec<u32> =
            self.bvh.prim_ids[node.first as usize..(node.first + node.count) as usize].to_vec();
        got.sort_unstable();
        want.sort_unstable();
        if got != want {
            return Err(DstError::ShapeMismatch {
                at,
                bvh_node: n,
                what: "the leaf's triangle run differs from the BVH leaf",
            });
        }
        Ok(len as u64)
    }

    fn leaf_report(entries: u64, depth: u32, splits: u32) -> DstValidation {
        DstValidation {
            leaves: 1,
            index_entries: entries,
            max_depth: depth,
            max_stack_depth: splits,
            ..DstValidation::default()
        }
    }

    /// Walks the DST node at word `at`, entered with `region`, standing for BVH node `n`.
    fn walk(
        &self,
        at: u32,
        from: u32,
        mut region: Aabb,
        n: u32,
        depth: u32,
        splits: u32,
    ) -> Result<DstValidation, DstError> {
        let w = self.node_word(at, from)?;
        let internal = DstValidation {
            internal_nodes: 1,
            ..DstValidation::default()
        };
        match w.node_kind() {
            DstNodeKind::Leaf => {
                self.check_region(at, n, &region, true)?;
                let e = self.check_run(at, w.offset(), n)?;
                Ok(Self::leaf_report(e, depth + 1, splits))
            }
            DstNodeKind::Split => {
                self.check_region(at, n, &region, false)?;
                let node = &self.bvh.nodes[n as usize];
                if node.is_leaf() {
                    return Err(DstError::ShapeMismatch {
                        at,
                        bvh_node: n,
                        what: "a splitting node where the BVH has a leaf",
                    });
                }
                let a = w.axis();
                let (p0, p1) = (self.plane(at, 1), self.plane(at, 2));
                let mut lr = region;
                lr.max[a] = p0;
                let mut rr = region;
                rr.min[a] = p1;
                let (l, r) = (w.offset(), w.offset() + w.left_size());
                let [x, y] = node.children();
                let try_order = |lo: u32, hi: u32| {
                    let vl = self.walk(l, at, lr, lo, depth + 1, splits + 1)?;
                    let vr = self.walk(r, at, rr, hi, depth + 1, splits + 1)?;
                    // The left size field must match the left child's real size.
                    let real = self.node_word(l, at)?.size_words();
                    if real != w.left_size() {
                        return Err(DstError::ShapeMismatch {
                            at,
                            bvh_node: n,
                            what: "left-size field differs from the left child's size",
                        });
                    }
                    Ok(internal.merge(vl).merge(vr))
                };
                try_order(x, y).or_else(|e| try_order(y, x).map_err(|_| e))
            }
            kind => {
                let (p0, p1) = (self.plane(at, 1), self.plane(at, 2));
                if kind == DstNodeKind::SingleCarve {
                    let a = w.axis();
                    region.max[a] = region.max[a].min(p0);
                    region.min[a] = region.min[a].max(p1);
                } else {
                    let (a0, a1) = w.axis_pair().axes();
                    let c = w.corner();
                    for (a, p, lower) in [(a0, p0, c.first_lower), (a1, p1, c.second_lower)] {
                        if lower {
                            region.min[a] = region.min[a].max(p);
                        } else {
                            region.max[a] = region.max[a].min(p);
                        }
                    }
                }
                if w.is_leaf_flag() {
                    self.check_region(at, n, &region, true)?;
                    let e = self.check_run(at, w.offset(), n)?;
                    Ok(internal.merge(Self::leaf_report(e, depth + 1, splits)))
                } else {
                    Ok(internal.merge(self.walk(w.offset(), at, region, n, depth + 1, splits)?))
                }
            }
        }
    }
}

impl Dst {
    /// Walks the tree beside `bvh` (the BVH2 it is converted from) and checks it; see the
    /// module docs for what is checked. Lin et al. 2020, §4.2.
    pub fn validate(&self, bvh: &Bvh2) -> Result<DstValidation, DstError> {
        let img = &self.image;
        if self.is_empty() {
            return if bvh.prim_ids.is_empty() {
                Ok(DstValidation::default())
            } else {
                Err(DstError::ShapeMismatch {
                    at: 0,
                    bvh_node: 0,
                    what: "empty DST for a non-empty BVH",
                })
            };
        }
        let walker = Walker {
            dst: self,
            bvh,
            similar: self.config.partitioning == Partitioning::Similar,
        };
        let report = walker.walk(0, 0, self.scene_box, 0, 0, 0)?;
        // Every triangle referenced exactly once, and every index entry reached.
        let n_tris = self.triangles().len();
        let mut count = vec![0u32; n_tris];
        for &e in &img.words[img.indices.clone()] {
            let p = e & !RUN_END;
            match count.get_mut(p as usize) {
                Some(c) => *c += 1,
                None => {
                    return Err(DstError::PrimOutOfRange {
                        node: 0,
                        prim: p,
                        triangles: n_tris,
                    });
                }
            }
        }
        let mut referenced: Vec<bool> = vec![false; n_tris];
        for &p in &bvh.prim_ids {
            if let Some(r) = referenced.get_mut(p as usize) {
                *r = true;
            }
        }
        for (p, &c) in count.iter().enumerate() {
            if c != referenced[p] as u32 {
                return Err(DstError::TriangleRefCount {
                    prim: p as u32,
                    count: c,
                });
            }
        }
        if report.index_entries != img.indices.len() as u64 {
            return Err(DstError::ShapeMismatch {
                at: 0,
                bvh_node: 0,
                what: "some index entries are not reachable from the root",
            });
        }
        Ok(report)
    }
}
