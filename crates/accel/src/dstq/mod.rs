//! The quantized dual-split tree (`dst-q`): the exact DST's nodes and decisions, grouped
//! into clusters of one fetch each (several DST levels collapsed), every plane stored as a
//! k-bit offset inside its cluster's frame and rounded so that no region shrinks
//! (Lin et al. 2020, §5, future work; layout and measurements in `docs/dstq-encoding.md`).
//!
//! ```text
//!  Dst ──build.rs──▶ exact nodes + exact regions ──▶ clusters (greedy by surface area)
//!                      │                                 │
//!                      └── frame.rs: frame (p, e) per cluster, planes rounded outward
//!                                                        ▼
//!           MemoryImage: lines of clusters | index runs (the DST's) | triangles (shared)
//!                 │
//!   traverse.rs (the DST* rules, planes dequantized)   validate.rs (lockstep with the DST)
//! ```
//!
//! A cluster takes at most `cluster_bytes` inside one aligned line of that size: a 16-byte
//! frame (origin p as 3 × f32, three exponent bytes, a record count), then records, each the
//! DST's 6-bit header code with a child field that is short (7 + W bits) when the child is
//! in the same cluster ([`QHeader`]) and, for an internal node, two k-bit plane offsets.
//! Every quantized region contains its exact region, so closest hits and shadow answers
//! equal the exact DST's (and the BVH2's) on every ray; the price is extra node steps and
//! triangle tests, measured in the doc.
//!
//! ```
//! use dualsplit_accel::{BuildConfig, Bvh2, NoObserver};
//! use dualsplit_accel::dst::{Dst, DstConfig};
//! use dualsplit_accel::dstq::{DstQ, DstQConfig};
//! use dualsplit_geometry::{Aabb, PrimId, Ray, Triangle, Vec3};
//! let tris = vec![
//!     Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0)),
//!     Triangle::new(Vec3::new(-1.0, -1.0, 3.0), Vec3::new(1.0, -1.0, 3.0), Vec3::new(0.0, 1.0, 3.0)),
//! ];
//! let boxes: Vec<Aabb> = tris.iter().map(|t| t.bounds()).collect();
//! let bvh = Bvh2::build(&boxes, &BuildConfig::default());
//! let dst = Dst::from_bvh2(&bvh, &tris[..], &DstConfig::hardware()).unwrap();
//! let q = DstQ::from_dst(&dst, &DstQConfig::default()).unwrap();
//! assert!(q.validate(&dst).is_ok());
//! let hit = q.closest_hit(&Ray::new(Vec3::ZERO, Vec3::Z), &mut NoObserver).unwrap();
//! assert_eq!((hit.t, hit.prim), (2.0, PrimId(0)));
//! ```

mod build;
pub mod frame;
pub mod record;
mod saved;
mod stats;
mod traverse;
mod tree;
pub mod unit;
mod validate;

pub use record::{CHILD_LIMIT, ChildRef, LeftRecord, QHeader, RecordFormat};
pub use stats::DstQStats;
pub use tree::{DstQFields, DstQTree};

use crate::dst::DstError;
use crate::image::MemoryImage;
use crate::validate::ValidationReport;
use dualsplit_geometry::{Aabb, Triangle};
use serde::{Deserialize, Serialize};

/// Fixed positions inside a cluster.
pub mod layout {
    /// Words of the frame at the start of every cluster (origin × 3, exponents + count).
    pub const FRAME_WORDS: usize = 4;
    /// Bit position of a cluster's first root record (right after the frame).
    pub const ROOT_BIT: u32 = 128;
}

/// Errors of [`DstQ::from_dst`].
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DstQError {
    /// Reading the exact DST or encoding a header failed (an offset that does not fit).
    #[error(transparent)]
    Dst(#[from] DstError),
    /// The configuration is outside what the encoding supports.
    #[error(
        "dst-q config bits = {bits}, cluster_bytes = {cluster_bytes}: need 1 ≤ bits ≤ 16 and a \
         multiple of 4 bytes in {min_bytes}..=4096 (a frame and a split's two children)"
    )]
    BadConfig {
        /// Bits per plane offset.
        bits: u32,
        /// Largest cluster / line size in bytes.
        cluster_bytes: u32,
        /// The smallest cluster that holds a frame and two internal records at these bits.
        min_bytes: u32,
    },
}

/// Settings of the quantized DST. The default is the measured choice
/// (`docs/dstq-encoding.md`, §7): 8-bit planes in 64-byte clusters.
///
/// A cluster takes at most `cluster_bytes` and never crosses a `cluster_bytes`-aligned line
/// of the node region (clusters are packed into such lines).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct DstQConfig {
    /// Bits per plane offset k (1–16). The measured table covers 4, 6, 8, 10, 12 and 16.
    pub bits: u32,
    /// Largest cluster and line size in bytes, a multiple of 4: one aligned fetch (64 = one
    /// cache line of the simulated L1).
    pub cluster_bytes: u32,
}

impl Default for DstQConfig {
    /// k = 8 in 64-byte clusters, measured (`docs/dstq-encoding.md`, §7): of the settings
    /// smaller than the exact DST and within 5 % of its traversal work, the one whose rays
    /// touch the fewest 64-byte lines (31–38 % fewer than the exact DST) and read the fewest
    /// bytes, at 78 % of its size for about +2.5 % node steps and +3.5 % triangle tests;
    /// one cluster is one L1 line and a node whose child shares its cluster one word.
    fn default() -> Self {
        Self {
            bits: 8,
            cluster_bytes: 64,
        }
    }
}

impl DstQConfig {
    /// The k values and cluster sizes of the measurement table.
    pub const MEASURED_BITS: [u32; 6] = [4, 6, 8, 10, 12, 16];
    /// The cluster sizes of the measurement table.
    pub const MEASURED_CLUSTER_BYTES: [u32; 2] = [64, 128];

    /// Words per line (the largest cluster).
    pub fn cluster_words(&self) -> u32 {
        self.cluster_bytes / 4
    }

    /// The record geometry: k and the local child-field width W.
    pub fn record_format(&self) -> RecordFormat {
        RecordFormat::new(self.bits, self.cluster_bytes)
    }

    /// Bits of an internal-node record with a 32-bit header: 32 + 2k.
    pub fn internal_record_bits(&self) -> u32 {
        32 + 2 * self.bits
    }

    fn min_bytes(bits: u32) -> u32 {
        // Frame + two internal records (a split's children), rounded up to a word.
        (layout::ROOT_BIT + 2 * (32 + 2 * bits)).div_ceil(32) * 4
    }

    /// Checks the config against the encoding's limits.
    pub fn check(&self) -> Result<(), DstQError> {
        let ok_bits = (1..=16).contains(&self.bits);
        let min_bytes = Self::min_bytes(self.bits.min(16));
        let ok_bytes = self.cluster_bytes.is_multiple_of(4)
            && self.cluster_bytes >= min_bytes
            && self.cluster_bytes <= 4096;
        if ok_bits && ok_bytes {
            Ok(())
        } else {
            Err(DstQError::BadConfig {
                bits: self.bits,
                cluster_bytes: self.cluster_bytes,
                min_bytes,
            })
        }
    }
}

/// A quantized dual-split tree: its memory image (lines of clusters, the DST's index runs, the
/// shared triangles), the scene box rays are clipped to, and its config.
#[derive(Clone, Debug)]
pub struct DstQ {
    image: MemoryImage,
    scene_box: Aabb,
    config: DstQConfig,
}

impl DstQ {
    fn assemble(image: MemoryImage, scene_box: Aabb, config: DstQConfig) -> Self {
        Self {
            image,
            scene_box,
            config,
        }
    }

    /// A tree from a saved image: checks its structure (valid headers, records inside their
    /// lines, offsets and runs in range, nothing reached twice, every triangle referenced
    /// once) before traversal may read it; the report when it fails.
    pub fn from_image(
        image: MemoryImage,
        scene_box: Aabb,
        config: DstQConfig,
    ) -> Result<Self, ValidationReport> {
        if let Err(e) = config.check() {
            let mut rep = validate::empty_report(&image);
            rep.error_count = 1;
            rep.errors.push(e.to_string());
            return Err(rep);
        }
        let q = Self::assemble(image, scene_box, config);
        let rep = q.validate_structure();
        if rep.is_ok() { Ok(q) } else { Err(rep) }
    }

    /// The byte-exact memory image.
    pub fn image(&self) -> &MemoryImage {
        &self.image
    }

    /// The scene box, stored beside the tree (24 B); rays are clipped to it.
    pub fn scene_box(&self) -> Aabb {
        self.scene_box
    }

    /// The config the tree was built with.
    pub fn config(&self) -> &DstQConfig {
        &self.config
    }

    /// True for a tree over zero triangles.
    pub fn is_empty(&self) -> bool {
        self.image.nodes.is_empty()
    }

    /// The triangles, read from the image's triangle region.
    pub fn triangles(&self) -> &[Triangle] {
        self.image.triangle_slice()
    }

    /// Node bytes (whole lines, padding included) + index bytes + the 24-byte
    /// scene box: the quantity of Lin et al. 2020, Table 3, defined as
    /// [`crate::dst::DstStats::total_bytes`].
    pub fn bytes_total(&self) -> u64 {
        self.image.node_bytes() + self.image.index_bytes() + 24
    }
}
