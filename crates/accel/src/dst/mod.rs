//! Dual-split trees (DST): conversion from the BVH2 with identical bounds, the exact
//! header-offset encoding, the software traversal (the paper's DST*) and the hardware
//! dual-split pipeline as a pure step function (Lin et al. 2020, §3, §4.2, Apps. A–C).
//!
//! ```text
//!  Bvh2 ──from_bvh2.rs──▶ per BVH node: carving chain (SAH, DP over faces) + split order
//!                 │        (reference.rs: the same decisions as plain loops, for tests;
//!                 │         both are plan.rs's Planner, and decide in plan.rs's terms)
//!                 └─encode.rs──▶ MemoryImage: node words | index runs | triangles
//!                                 │
//!        traverse.rs (DST*, branchy reference) ◀─┴─▶ pipeline.rs (branch-free step function)
//!                                                    pipeline_traverse.rs (the loop it drives)
//!                  validate.rs (rebuild every BVH box)   stats.rs (sizes, per-ray counts)
//! ```
//!
//! A DST stores no boxes: every internal node holds two axis-aligned planes and one
//! [`HeaderOffset`] word (12 bytes); a plain leaf is one word (4 bytes). The region of a
//! node is the scene box cut by the planes on the path from the root; rays are clipped to
//! the scene box, which is stored beside the tree ([`Dst::scene_box`]).
//!
//! ```
//! use dualsplit_accel::{BuildConfig, Bvh2, NoObserver};
//! use dualsplit_accel::dst::{Dst, DstConfig};
//! use dualsplit_geometry::{Aabb, PrimId, Ray, Triangle, Vec3};
//! let tris = vec![
//!     Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0)),
//!     Triangle::new(Vec3::new(-1.0, -1.0, 3.0), Vec3::new(1.0, -1.0, 3.0), Vec3::new(0.0, 1.0, 3.0)),
//! ];
//! let boxes: Vec<Aabb> = tris.iter().map(|t| t.bounds()).collect();
//! let bvh = Bvh2::build(&boxes, &BuildConfig::default());
//! // The image shares the triangles: pass a `SharedTriangles` (`Arc<[Triangle]>`) to share
//! // one copy between structures, or a slice / Vec to have one made.
//! let dst = Dst::from_bvh2(&bvh, &tris[..], &DstConfig::hardware()).unwrap();
//! dst.validate(&bvh).unwrap();
//! let hit = dst.closest_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut NoObserver).unwrap();
//! assert_eq!((hit.t, hit.prim), (2.0, PrimId(0)));
//! ```

mod encode;
mod fast;
mod from_bvh2;
mod header;
pub mod pipeline;
mod pipeline_traverse;
mod plan;
mod reference;
mod saved;
mod stats;
pub(crate) mod traverse;
mod tree;
mod validate;

pub use fast::DstQuery;
pub use header::{AxisPair, Corner, HeaderOffset, OFFSET_LIMIT};
pub use stats::{DstStats, DstTraceStats, bvh2_size_bytes};
pub use tree::{DstDecoding, DstFields, DstPipeline, DstTree};
pub use validate::DstValidation;

use crate::image::MemoryImage;
use dualsplit_geometry::{Aabb, Triangle};
use serde::{Deserialize, Serialize};

/// Errors of conversion, encoding and validation.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DstError {
    /// An offset does not fit the 26-bit offset field.
    #[error("DST offset {given} does not fit the 26-bit offset field (limit {limit})")]
    OffsetOverflow {
        /// The offset that was needed.
        given: u64,
        /// The limit (2^26).
        limit: u64,
    },
    /// A triangle id does not fit an index entry (bit 31 marks the end of a run).
    #[error("triangle id {given} does not fit a 31-bit index entry (limit {limit})")]
    TriangleIdOverflow {
        /// The id.
        given: u64,
        /// The limit (2^31).
        limit: u64,
    },
    /// The BVH references a triangle that does not exist.
    #[error("BVH leaf {node} references triangle {prim}, but there are only {triangles}")]
    PrimOutOfRange {
        /// BVH node.
        node: u32,
        /// The triangle id.
        prim: u32,
        /// Number of triangles.
        triangles: usize,
    },
    /// A BVH node box is not finite (NaN or infinite coordinates).
    #[error("BVH node {node} has non-finite bounds {bounds:?}")]
    NonFiniteBounds {
        /// BVH node.
        node: u32,
        /// Its box.
        bounds: Aabb,
    },
    /// The BVH's node links are malformed (a child index out of range or a cycle).
    #[error("BVH node {node} has child {child} outside 1..{nodes}")]
    BadBvhLink {
        /// BVH node.
        node: u32,
        /// The child index.
        child: u32,
        /// Number of nodes.
        nodes: usize,
    },
    /// A word is not one of the 37 valid header codes.
    #[error("word {at} = {word:#010x} has an invalid header code")]
    InvalidHeader {
        /// Word index.
        at: u32,
        /// The word.
        word: u32,
    },
    /// A node offset or index run lies outside its region.
    #[error("node at word {at} points at {offset}, outside 0..{limit}")]
    OffsetOutOfRange {
        /// Word index of the node.
        at: u32,
        /// The offset.
        offset: u32,
        /// The region length.
        limit: u32,
    },
    /// A splitting node or leaf is reached with a region that is not its BVH node's box.
    #[error("DST node at word {at} has region {found:?}, BVH node {bvh_node} has box {expected:?}")]
    RegionMismatch {
        /// Word index of the DST node.
        at: u32,
        /// BVH node.
        bvh_node: u32,
        /// The BVH box.
        expected: Aabb,
        /// The region rebuilt from the planes.
        found: Aabb,
    },
    /// The DST's shape differs from the BVH's (a leaf where a split was expected, a leaf
    /// whose triangles differ, ...).
    #[error("DST node at word {at} does not match BVH node {bvh_node}: {what}")]
    ShapeMismatch {
        /// Word index of the DST node.
        at: u32,
        /// BVH node.
        bvh_node: u32,
        /// What differs.
        what: &'static str,
    },
    /// A triangle is referenced other than exactly once.
    #[error("triangle {prim} is referenced {count} times (expected once)")]
    TriangleRefCount {
        /// Triangle id.
        prim: u32,
        /// References found.
        count: u32,
    },
}

/// How strictly the DST follows the BVH's bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Partitioning {
    /// Identical bounds (the mode of Lin et al. 2020, §4.2): every face that differs from
    /// the incoming region is carved before each splitting node and leaf.
    Identical,
    /// "Similar partitioning" (Lin et al. 2019): above a leaf, a face is left uncarved when
    /// the SAH says the saved carving node costs more than the extra triangle tests.
    /// Splitting nodes still see exactly their BVH box.
    Similar,
}

/// SAH costs of the converter, in units of one ray–triangle test, each multiplied by the
/// surface area of the region in which the node is tested (the recursive SAH of Lin et al.
/// 2019; `docs/dst-encoding.md`, §3).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DstCosts {
    /// A splitting node.
    pub split: f32,
    /// A single-axis carving node.
    pub single_carve: f32,
    /// A dual-axis carving node.
    pub dual_carve: f32,
    /// One ray–triangle test (only used by [`Partitioning::Similar`]).
    pub triangle: f32,
}

/// Conversion settings. Presets: [`DstConfig::hardware`] (default) and
/// [`DstConfig::software`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DstConfig {
    /// Node costs of the SAH model that picks carving chains and split child order.
    pub costs: DstCosts,
    /// Identical (default) or similar partitioning.
    pub partitioning: Partitioning,
}

impl Default for DstConfig {
    fn default() -> Self {
        Self::hardware()
    }
}

impl DstConfig {
    /// The hardware preset (Lin et al. 2020, §4.2): every node type costs the same, because
    /// the dual-split pipeline's latency does not depend on the node type. Relative to a
    /// triangle test a node costs 0.5 (the carving-vs-triangle ratio is not published).
    pub fn hardware() -> Self {
        Self {
            costs: DstCosts {
                split: 0.5,
                single_carve: 0.5,
                dual_carve: 0.5,
                triangle: 1.0,
            },
            partitioning: Partitioning::Identical,
        }
    }

    /// The software preset (Lin et al. 2019, as cited in Lin et al. 2020 §4.2): a dual-axis
    /// carving node, decoded in software, costs more than a single-axis one. Constants are
    /// our guesses (0.3 / 0.3 / 0.5 per node, 1.0 per triangle), not published values.
    pub fn software() -> Self {
        Self {
            costs: DstCosts {
                split: 0.3,
                single_carve: 0.3,
                dual_carve: 0.5,
                triangle: 1.0,
            },
            partitioning: Partitioning::Identical,
        }
    }

    /// This config with `partitioning` replaced.
    pub fn with_partitioning(mut self, partitioning: Partitioning) -> Self {
        self.partitioning = partitioning;
        self
    }
}

/// A dual-split tree: its memory image (node words, then triangle-index runs, then the
/// triangles), the scene box rays are clipped to, and conversion statistics.
#[derive(Clone, Debug)]
pub struct Dst {
    image: MemoryImage,
    scene_box: Aabb,
    config: DstConfig,
    stats: DstStats,
    /// The triangles of the index region in its order, four to a packet, for the plain
    /// queries' decoder (`fast.rs`); made on first use.
    packets: std::sync::OnceLock<std::sync::Arc<crate::image::Pages<crate::wide::cpu::TriPacket>>>,
}

impl Dst {
    /// The byte-exact memory image, read by the CPU traversal and the simulator alike.
    pub fn image(&self) -> &MemoryImage {
        &self.image
    }

    /// The scene box, stored beside the tree; rays are clipped to it before traversal.
    pub fn scene_box(&self) -> Aabb {
        self.scene_box
    }

    /// The config the tree was converted with.
    pub fn config(&self) -> &DstConfig {
        &self.config
    }

    /// Node counts and sizes (conversion time is measured by the caller).
    pub fn stats(&self) -> DstStats {
        self.stats
    }

    /// True for a tree over zero triangles (every ray misses).
    pub fn is_empty(&self) -> bool {
        self.image.nodes.is_empty()
    }

    /// The triangles, read from the image's triangle region.
    #[inline]
    pub fn triangles(&self) -> &[Triangle] {
        self.image.triangle_slice()
    }

    /// A tree from its parts, as a saved tree file stores them ([`crate::saved`]).
    pub(crate) fn from_parts(
        image: MemoryImage,
        scene_box: Aabb,
        config: DstConfig,
        stats: DstStats,
    ) -> Self {
        Self {
            image,
            scene_box,
            config,
            stats,
            packets: Default::default(),
        }
    }
}
