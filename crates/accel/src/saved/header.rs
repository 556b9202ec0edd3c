//! The fixed 512-byte header of a saved tree file (`docs/tree-format.md`): field order,
//! encoding and the checks made on it before anything is allocated.

use super::SavedError;
use crate::BuildConfig;
use crate::dst::{DstConfig, DstCosts, DstStats, Partitioning};
use crate::dstq::DstQConfig;
use crate::tree::TreeKind;
use dualsplit_geometry::{Aabb, Vec3};

/// The first eight bytes of every saved tree file.
pub const MAGIC: [u8; 8] = *b"DSPLTREE";
/// The format version this crate writes and reads.
pub const FORMAT_VERSION: u32 = 1;
/// Bytes of the header, zero-padded.
pub const HEADER_BYTES: usize = 512;
/// Byte offset of the node words: one 4 KiB page, so that the words are page-aligned in the
/// file.
pub const WORDS_OFFSET: u64 = 4096;
/// Bytes of the SHA-256 checksum that ends the file.
pub const CHECKSUM_BYTES: u64 = 32;

/// What the header describes besides the regions' sizes: the structure's own fields.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Extra {
    /// A BVH2, BVH4 or BVH8.
    Bvh {
        internal_nodes: u64,
        leaves: u64,
        sah_cost: f32,
    },
    /// A dual-split tree.
    Dst {
        config: DstConfig,
        scene_box: Aabb,
        stats: DstStats,
    },
    /// A compressed 8-wide BVH.
    Cwbvh { internal_nodes: u64, leaves: u64 },
    /// A quantized dual-split tree (no counts: the tree has none but its walk's).
    DstQ { config: DstQConfig, scene_box: Aabb },
}

/// The decoded header.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Header {
    pub kind: TreeKind,
    pub node_words: u64,
    pub index_words: u64,
    pub triangles: u64,
    pub file_bytes: u64,
    pub triangle_hash: [u8; 32],
    pub build: BuildConfig,
    pub extra: Extra,
}

fn kind_code(k: TreeKind) -> u32 {
    match k {
        TreeKind::Bvh2 => 1,
        TreeKind::Bvh4 => 2,
        TreeKind::Bvh8 => 3,
        TreeKind::Dst => 4,
        TreeKind::Cwbvh => 5,
        TreeKind::DstQ => 6,
    }
}

/// The file size a header with these region sizes implies, or `None` on overflow.
pub(super) fn implied_bytes(node_words: u64, index_words: u64, triangles: u64) -> Option<u64> {
    let words = node_words.checked_add(index_words)?.checked_mul(4)?;
    WORDS_OFFSET
        .checked_add(words)?
        .checked_add(triangles.checked_mul(36)?)?
        .checked_add(CHECKSUM_BYTES)
}

struct Out(Vec<u8>);
impl Out {
    fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }
    fn scene_box(&mut self, b: Aabb) {
        for v in [b.min, b.max] {
            self.f32(v.x);
            self.f32(v.y);
            self.f32(v.z);
        }
    }
}

struct In<'a>(&'a [u8]);
impl In<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        // The header buffer is HEADER_BYTES long and the fields use far fewer bytes.
        let (a, b) = self.0.split_at(N);
        self.0 = b;
        a.try_into().unwrap_or([0; N])
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
    fn scene_box(&mut self) -> Aabb {
        let mut v = [0f32; 6];
        for x in &mut v {
            *x = self.f32();
        }
        Aabb::new(Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]))
    }
    fn f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }
}

/// Checks the build settings a header records: what a build can record (the builder
/// clamps the bins to 2..=256 and takes at least one triangle per leaf, and
/// [`AnyTree::write_to`](crate::AnyTree::write_to) refuses other costs).
pub(super) fn check_build(b: &BuildConfig) -> Result<(), SavedError> {
    if b.max_leaf_size == 0 {
        return Err(SavedError::malformed(
            "build setting max_leaf_size is 0; at least 1".into(),
        ));
    }
    if !(2..=256).contains(&b.bins) {
        return Err(SavedError::malformed(format!(
            "build setting bins is {}; from 2 to 256",
            b.bins
        )));
    }
    check_cost("build setting", "cost_traversal", b.cost_traversal)?;
    check_cost("build setting", "cost_triangle", b.cost_triangle)
}

/// A cost must be a finite number ≥ 0.
pub(super) fn check_cost(what: &str, name: &str, c: f32) -> Result<(), SavedError> {
    if c.is_finite() && c >= 0.0 {
        Ok(())
    } else {
        Err(SavedError::malformed(format!(
            "{what} {name} is {c}; a finite number of at least 0"
        )))
    }
}

impl Header {
    /// The header's `HEADER_BYTES` bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut o = Out(Vec::with_capacity(HEADER_BYTES));
        o.0.extend_from_slice(&MAGIC);
        o.u32(FORMAT_VERSION);
        o.u32(kind_code(self.kind));
        o.u64(self.file_bytes);
        o.u64(WORDS_OFFSET);
        o.u64(self.node_words);
        o.u64(self.index_words);
        o.u64(self.triangles);
        o.0.extend_from_slice(&self.triangle_hash);
        let b = &self.build;
        o.u32(b.max_leaf_size);
        o.f32(b.cost_traversal);
        o.f32(b.cost_triangle);
        o.u32(b.bins);
        o.u32(b.parallel_threshold);
        match self.extra {
            Extra::Bvh {
                internal_nodes,
                leaves,
                sah_cost,
            } => {
                o.u64(internal_nodes);
                o.u64(leaves);
                o.f32(sah_cost);
            }
            Extra::Dst {
                config,
                scene_box,
                stats,
            } => {
                o.f32(config.costs.split);
                o.f32(config.costs.single_carve);
                o.f32(config.costs.dual_carve);
                o.f32(config.costs.triangle);
                o.u32(match config.partitioning {
                    Partitioning::Identical => 0,
                    Partitioning::Similar => 1,
                });
                o.scene_box(scene_box);
                for v in [
                    stats.splitting,
                    stats.single_carving,
                    stats.dual_carving,
                    stats.leaves,
                    stats.carving_leaves,
                    stats.index_entries,
                    stats.node_bytes,
                    stats.index_bytes,
                    stats.total_bytes,
                    stats.bvh2_bytes,
                ] {
                    o.u64(v);
                }
            }
            Extra::Cwbvh {
                internal_nodes,
                leaves,
            } => {
                o.u64(internal_nodes);
                o.u64(leaves);
            }
            Extra::DstQ { config, scene_box } => {
                o.u32(config.bits);
                o.u32(config.cluster_bytes);
                o.scene_box(scene_box);
            }
        }
        o.0.resize(HEADER_BYTES, 0);
        o.0
    }

    /// Decodes and checks a header read from a file of `actual_bytes` bytes: magic,
    /// version, kind, and region sizes that add up to the file's size (so nothing larger
    /// than the file is ever allocated).
    pub fn decode(h: &[u8; HEADER_BYTES], actual_bytes: u64) -> Result<Header, SavedError> {
        let mut i = In(h);
        if i.take::<8>() != MAGIC {
            return Err(SavedError::NotATree);
        }
        let version = i.u32();
        if version != FORMAT_VERSION {
            return Err(SavedError::UnsupportedVersion {
                found: version,
                supported: FORMAT_VERSION,
            });
        }
        let kind = match i.u32() {
            1 => TreeKind::Bvh2,
            2 => TreeKind::Bvh4,
            3 => TreeKind::Bvh8,
            4 => TreeKind::Dst,
            5 => TreeKind::Cwbvh,
            6 => TreeKind::DstQ,
            k => return Err(SavedError::malformed(format!("unknown structure kind {k}"))),
        };
        let file_bytes = i.u64();
        if file_bytes != actual_bytes {
            return Err(SavedError::Length {
                expected: file_bytes,
                found: actual_bytes,
            });
        }
        let words_offset = i.u64();
        if words_offset != WORDS_OFFSET {
            return Err(SavedError::malformed(format!(
                "node words at byte {words_offset}, expected {WORDS_OFFSET}"
            )));
        }
        let node_words = i.u64();
        let index_words = i.u64();
        let triangles = i.u64();
        if implied_bytes(node_words, index_words, triangles) != Some(file_bytes) {
            return Err(SavedError::malformed(format!(
                "{node_words} node words, {index_words} index words and {triangles} triangles \
                 do not make a file of {file_bytes} bytes"
            )));
        }
        let triangle_hash = i.take::<32>();
        let build = BuildConfig {
            max_leaf_size: i.u32(),
            cost_traversal: i.f32(),
            cost_triangle: i.f32(),
            bins: i.u32(),
            parallel_threshold: i.u32(),
        };
        check_build(&build)?;
        let extra = match kind {
            TreeKind::Dst => {
                let costs = DstCosts {
                    split: i.f32(),
                    single_carve: i.f32(),
                    dual_carve: i.f32(),
                    triangle: i.f32(),
                };
                for (name, c) in [
                    ("split", costs.split),
                    ("single_carve", costs.single_carve),
                    ("dual_carve", costs.dual_carve),
                    ("triangle", costs.triangle),
                ] {
                    check_cost("DST cost", name, c)?;
                }
                let partitioning = match i.u32() {
                    0 => Partitioning::Identical,
                    1 => Partitioning::Similar,
                    p => return Err(SavedError::malformed(format!("unknown partitioning {p}"))),
                };
                let scene_box = i.scene_box();
                let mut c = [0u64; 10];
                for x in &mut c {
                    *x = i.u64();
                }
                Extra::Dst {
                    config: DstConfig {
                        costs,
                        partitioning,
                    },
                    scene_box,
                    stats: DstStats {
                        splitting: c[0],
                        single_carving: c[1],
                        dual_carving: c[2],
                        leaves: c[3],
                        carving_leaves: c[4],
                        index_entries: c[5],
                        node_bytes: c[6],
                        index_bytes: c[7],
                        total_bytes: c[8],
                        bvh2_bytes: c[9],
                    },
                }
            }
            TreeKind::Cwbvh => Extra::Cwbvh {
                internal_nodes: i.u64(),
                leaves: i.u64(),
            },
            TreeKind::DstQ => {
                let config = DstQConfig {
                    bits: i.u32(),
                    cluster_bytes: i.u32(),
                };
                config
                    .check()
                    .map_err(|e| SavedError::malformed(e.to_string()))?;
                Extra::DstQ {
                    config,
                    scene_box: i.scene_box(),
                }
            }
            TreeKind::Bvh2 | TreeKind::Bvh4 | TreeKind::Bvh8 => Extra::Bvh {
                internal_nodes: i.u64(),
                leaves: i.u64(),
                sah_cost: i.f32(),
            },
        };
        Ok(Header {
            kind,
            node_words,
            index_words,
            triangles,
            file_bytes,
            triangle_hash,
            build,
            extra,
        })
    }
}
