//! Building exactly one structure: [`Bvh2Tree`] (the SAH BVH2 every other structure is
//! derived from), [`BvhTree`] (an encoded BVH2, BVH4 or BVH8) and [`DstTree`] (a dual-split
//! tree), each with its [`BuildStats`]. [`AnyTree`] holds whichever one a saved file
//! contains.
//!
//! ```
//! use dualsplit_accel::math::{Ray, Triangle, Vec3};
//! use dualsplit_accel::{BuildConfig, Bvh2Tree, BvhTree, DstConfig, DstTree, RayQuery};
//! let tris = vec![Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0))];
//! let bvh2 = Bvh2Tree::build(tris, &BuildConfig::default()).unwrap();
//! let bvh8 = BvhTree::bvh8_from(&bvh2).unwrap();
//! let dst = DstTree::from_bvh2(&bvh2, &DstConfig::hardware()).unwrap();
//! let ray = Ray::new(Vec3::ZERO, Vec3::Z);
//! assert_eq!(bvh8.intersect(&ray), dst.intersect(&ray));
//! assert_eq!(dst.intersect(&ray), dst.pipeline().intersect(&ray));
//! ```
//!
//! Builds and conversions use rayon; they run on the current pool, so a caller picks the
//! threads with [`rayon::ThreadPool::install`] or the `*_in` constructors.

use crate::cwbvh::Cwbvh;
use crate::dst::{Dst, DstConfig};
use crate::dstq::{DstQ, DstQConfig};
use crate::image::{MemoryImage, SharedTriangles};
use crate::observer::Observer;
use crate::query::{DstPipeline, RayQuery};
use crate::validate::ValidationReport;
use crate::wide::{BvhImage, CollapseConfig, WideBvh};
use crate::{AccelError, AccelKind, BuildConfig, Bvh2, ms_since};
use dualsplit_geometry::{Aabb, Hit, Ray, Triangle};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The six structures a tree can be.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TreeKind {
    /// Binary BVH, 52-byte nodes.
    Bvh2,
    /// 4-wide BVH (Dammertz collapse), 100-byte nodes.
    Bvh4,
    /// 8-wide BVH (Ylitie collapse), 200-byte nodes.
    Bvh8,
    /// Dual-split tree.
    Dst,
    /// Compressed 8-wide BVH (80-byte nodes, quantized child boxes).
    Cwbvh,
    /// Quantized dual-split tree (k-bit planes in collapsed clusters).
    DstQ,
}

impl TreeKind {
    /// All kinds.
    pub const ALL: [TreeKind; 6] = [
        TreeKind::Bvh2,
        TreeKind::Bvh4,
        TreeKind::Bvh8,
        TreeKind::Dst,
        TreeKind::Cwbvh,
        TreeKind::DstQ,
    ];

    /// The command-line name: `bvh2`, `bvh4`, `bvh8`, `dst`, `cwbvh`, `dst-q`.
    pub fn name(self) -> &'static str {
        match self {
            TreeKind::Bvh2 => "bvh2",
            TreeKind::Bvh4 => "bvh4",
            TreeKind::Bvh8 => "bvh8",
            TreeKind::Dst => "dst",
            TreeKind::Cwbvh => "cwbvh",
            TreeKind::DstQ => "dst-q",
        }
    }

    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }

    /// The traversals that read this structure's image: one for a BVH, both decoders
    /// ([`AccelKind::DstSw`] first) for a DST.
    pub fn accel_kinds(self) -> &'static [AccelKind] {
        match self {
            TreeKind::Bvh2 => &[AccelKind::Bvh2],
            TreeKind::Bvh4 => &[AccelKind::Bvh4],
            TreeKind::Bvh8 => &[AccelKind::Bvh8],
            TreeKind::Dst => &[AccelKind::DstSw, AccelKind::Dst],
            TreeKind::Cwbvh => &[AccelKind::Cwbvh],
            TreeKind::DstQ => &[AccelKind::DstQ],
        }
    }

    /// The structure [`AccelKind`] `k` traverses.
    pub fn of_accel(k: AccelKind) -> Self {
        match k {
            AccelKind::Bvh2 => TreeKind::Bvh2,
            AccelKind::Bvh4 => TreeKind::Bvh4,
            AccelKind::Bvh8 => TreeKind::Bvh8,
            AccelKind::DstSw | AccelKind::Dst => TreeKind::Dst,
            AccelKind::Cwbvh => TreeKind::Cwbvh,
            AccelKind::DstQ => TreeKind::DstQ,
        }
    }
}

impl std::fmt::Display for TreeKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which DST traversal answers queries. The two give identical answers.
///
/// | this | [`AccelKind`] | command line | what it is |
/// |---|---|---|---|
/// | [`DstDecoding::Software`] | [`AccelKind::DstSw`] | `dst-sw` | the software decoder (the paper's DST\*); the fast one on a CPU |
/// | [`DstDecoding::Pipeline`] | [`AccelKind::Dst`] | `dst` | the model of the hardware dual-split pipeline, one step function call per node; for checking and simulating the hardware |
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DstDecoding {
    /// The software decoder (DST\*): what a CPU user wants.
    #[default]
    Software,
    /// The hardware pipeline's step function.
    Pipeline,
}

impl DstDecoding {
    /// The [`AccelKind`] of this traversal.
    pub fn accel_kind(self) -> AccelKind {
        match self {
            DstDecoding::Software => AccelKind::DstSw,
            DstDecoding::Pipeline => AccelKind::Dst,
        }
    }
}

/// Size and time of one structure's build, all times in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct BuildStats {
    /// Which structure.
    pub kind: Option<TreeKind>,
    /// Wall time of this structure's own step, encoding included, in milliseconds: the SAH
    /// build of a BVH2, the collapse of a BVH4 or BVH8 (from a built BVH2), the conversion of
    /// a DST (from a built BVH2). A host measurement; 0 for a loaded tree.
    pub build_ms: f64,
    /// Internal nodes.
    pub internal_nodes: u64,
    /// Leaves (leaf words; for a DST, plain leaves and carving nodes acting as leaves).
    pub leaves: u64,
    /// Bytes of the node region.
    pub node_bytes: u64,
    /// Bytes of the triangle-index region.
    pub index_bytes: u64,
    /// Triangles referenced (the triangle region holds 36 bytes each).
    pub triangles: u64,
}

impl BuildStats {
    pub(crate) fn of_bvh(kind: TreeKind, b: &BvhImage, build_ms: f64) -> Self {
        Self {
            kind: Some(kind),
            build_ms,
            internal_nodes: b.internal_nodes as u64,
            leaves: b.leaves as u64,
            node_bytes: b.image.node_bytes(),
            index_bytes: b.image.index_bytes(),
            triangles: b.image.triangle_slice().len() as u64,
        }
    }

    pub(crate) fn of_dst(d: &Dst, build_ms: f64) -> Self {
        let s = d.stats();
        Self {
            kind: Some(TreeKind::Dst),
            build_ms,
            internal_nodes: s.internal_nodes(),
            leaves: s.leaves + s.carving_leaves,
            node_bytes: d.image().node_bytes(),
            index_bytes: d.image().index_bytes(),
            triangles: d.triangles().len() as u64,
        }
    }

    pub(crate) fn of_cwbvh(c: &Cwbvh, build_ms: f64) -> Self {
        Self {
            kind: Some(TreeKind::Cwbvh),
            build_ms,
            internal_nodes: c.internal_nodes() as u64,
            leaves: c.leaves() as u64,
            node_bytes: c.image().node_bytes(),
            index_bytes: c.image().index_bytes(),
            triangles: c.image().triangle_slice().len() as u64,
        }
    }

    pub(crate) fn of_dstq(q: &DstQ, build_ms: f64) -> Self {
        let s = q.stats();
        Self {
            kind: Some(TreeKind::DstQ),
            build_ms,
            internal_nodes: s.internal_nodes(),
            leaves: s.leaf_count(),
            node_bytes: q.image().node_bytes(),
            index_bytes: q.image().index_bytes(),
            triangles: q.image().triangle_slice().len() as u64,
        }
    }

    /// Node plus index bytes (the size the paper's Table 3 compares).
    pub fn bytes_total(&self) -> u64 {
        self.node_bytes + self.index_bytes
    }
}

/// The SAH binary BVH over a set of triangles, both as a logical tree (what BVH4, BVH8 and
/// DSTs are derived from) and encoded (what it is traversed through).
#[derive(Clone, Debug)]
pub struct Bvh2Tree {
    logical: Bvh2,
    tree: BvhTree,
}

impl Bvh2Tree {
    /// Builds the BVH2 over `triangles` (ids are indices; a slice, `Vec` or
    /// [`SharedTriangles`], which is shared rather than copied).
    ///
    /// Errors when the image cannot be encoded (an offset field overflows: tens of
    /// millions of triangles).
    pub fn build(
        triangles: impl Into<SharedTriangles>,
        config: &BuildConfig,
    ) -> Result<Self, AccelError> {
        let triangles: SharedTriangles = triangles.into();
        let t0 = Instant::now();
        let boxes: Vec<Aabb> = triangles.iter().map(|t| t.bounds()).collect();
        let logical = Bvh2::build(&boxes, config);
        let build_time = t0.elapsed();
        let wide = WideBvh::from_bvh2(&logical);
        let encoded = BvhImage::encode(&wide, &logical, triangles, config, build_time)?;
        let stats = BuildStats::of_bvh(TreeKind::Bvh2, &encoded, ms_since(t0));
        Ok(Self {
            logical,
            tree: BvhTree {
                encoded,
                config: *config,
                stats,
            },
        })
    }

    /// [`Bvh2Tree::build`] on the threads of `pool`.
    pub fn build_in(
        pool: &rayon::ThreadPool,
        triangles: impl Into<SharedTriangles> + Send,
        config: &BuildConfig,
    ) -> Result<Self, AccelError> {
        pool.install(|| Self::build(triangles, config))
    }

    /// The logical tree.
    pub fn logical(&self) -> &Bvh2 {
        &self.logical
    }

    /// The encoded BVH2 (what [`RayQuery`] traverses and what is saved).
    pub fn tree(&self) -> &BvhTree {
        &self.tree
    }

    /// The encoded BVH2, dropping the logical tree.
    pub fn into_tree(self) -> BvhTree {
        self.tree
    }

    /// The triangles (shared with every structure derived from this one).
    pub fn shared_triangles(&self) -> &SharedTriangles {
        &self.tree.encoded.image.triangle_data
    }

    /// The build settings.
    pub fn config(&self) -> &BuildConfig {
        &self.tree.config
    }

    /// Size and build time of the BVH2.
    pub fn stats(&self) -> &BuildStats {
        &self.tree.stats
    }
}

/// An encoded BVH (2-, 4- or 8-wide) with its build settings and statistics.
#[derive(Clone, Debug)]
pub struct BvhTree {
    pub(crate) encoded: BvhImage,
    pub(crate) config: BuildConfig,
    pub(crate) stats: BuildStats,
}

impl BvhTree {
    /// The BVH4 collapsed from `bvh2` (Dammertz et al. 2008), same leaves.
    pub fn bvh4_from(bvh2: &Bvh2Tree) -> Result<Self, AccelError> {
        let t0 = Instant::now();
        let wide = WideBvh::collapse_bvh4(&bvh2.logical);
        Self::encode(bvh2, &wide, TreeKind::Bvh4, t0)
    }

    /// The BVH8 collapsed from `bvh2` (Ylitie et al. 2017, default collapse costs), same
    /// leaves.
    pub fn bvh8_from(bvh2: &Bvh2Tree) -> Result<Self, AccelError> {
        Self::bvh8_from_with(bvh2, &CollapseConfig::default())
    }

    /// The BVH8 collapsed from `bvh2` with explicit collapse costs.
    pub fn bvh8_from_with(bvh2: &Bvh2Tree, collapse: &CollapseConfig) -> Result<Self, AccelError> {
        let t0 = Instant::now();
        let wide = WideBvh::collapse_bvh8(&bvh2.logical, collapse);
        Self::encode(bvh2, &wide, TreeKind::Bvh8, t0)
    }

    /// The BVH of `kind` derived from `bvh2` (`None` for the kinds that are not an
    /// uncompressed BVH).
    pub fn from_bvh2(bvh2: &Bvh2Tree, kind: TreeKind) -> Option<Result<Self, AccelError>> {
        match kind {
            TreeKind::Bvh2 => Some(Ok(bvh2.tree.clone())),
            TreeKind::Bvh4 => Some(Self::bvh4_from(bvh2)),
            TreeKind::Bvh8 => Some(Self::bvh8_from(bvh2)),
            TreeKind::Dst | TreeKind::Cwbvh | TreeKind::DstQ => None,
        }
    }

    fn encode(
        bvh2: &Bvh2Tree,
        wide: &WideBvh,
        kind: TreeKind,
        t0: Instant,
    ) -> Result<Self, AccelError> {
        let collapse = t0.elapsed();
        let config = *bvh2.config();
        let encoded = BvhImage::encode(
            wide,
            &bvh2.logical,
            bvh2.shared_triangles().clone(),
            &config,
            collapse,
        )?;
        let stats = BuildStats::of_bvh(kind, &encoded, ms_since(t0));
        Ok(Self {
            encoded,
            config,
            stats,
        })
    }

    /// Which BVH: [`TreeKind::Bvh2`], [`TreeKind::Bvh4`] or [`TreeKind::Bvh8`].
    pub fn kind(&self) -> TreeKind {
        match self.encoded.arity {
            2 => TreeKind::Bvh2,
            4 => TreeKind::Bvh4,
            _ => TreeKind::Bvh8,
        }
    }

    /// The encoded structure (image, node counts, SAH cost).
    pub fn encoded(&self) -> &BvhImage {
        &self.encoded
    }

    /// The byte-exact memory image.
    pub fn image(&self) -> &MemoryImage {
        &self.encoded.image
    }

    /// The BVH2 build settings the tree came from.
    pub fn config(&self) -> &BuildConfig {
        &self.config
    }

    /// Size and build time.
    pub fn stats(&self) -> &BuildStats {
        &self.stats
    }
}

/// A dual-split tree with its build settings and statistics. [`RayQuery`] on it uses the
/// software decoder ([`DstDecoding::Software`]); [`DstTree::pipeline`] gives the hardware
/// pipeline model.
#[derive(Clone, Debug)]
pub struct DstTree {
    pub(crate) dst: Dst,
    pub(crate) config: BuildConfig,
    pub(crate) stats: BuildStats,
}

impl DstTree {
    /// Converts `bvh2` into a DST with identical bounds (`preset`:
    /// [`DstConfig::hardware`] for the paper's hardware, [`DstConfig::software`] for DST\*).
    pub fn from_bvh2(bvh2: &Bvh2Tree, preset: &DstConfig) -> Result<Self, AccelError> {
        let t0 = Instant::now();
        let dst = Dst::from_bvh2(&bvh2.logical, bvh2.shared_triangles().clone(), preset)?;
        let stats = BuildStats::of_dst(&dst, ms_since(t0));
        Ok(Self {
            dst,
            config: *bvh2.config(),
            stats,
        })
    }

    /// [`DstTree::from_bvh2`] on the threads of `pool`.
    pub fn from_bvh2_in(
        pool: &rayon::ThreadPool,
        bvh2: &Bvh2Tree,
        preset: &DstConfig,
    ) -> Result<Self, AccelError> {
        pool.install(|| Self::from_bvh2(bvh2, preset))
    }

    /// The tree (image, scene box, node counts, both traversals).
    pub fn dst(&self) -> &Dst {
        &self.dst
    }

    /// The byte-exact memory image.
    pub fn image(&self) -> &MemoryImage {
        self.dst.image()
    }

    /// Queries through the hardware pipeline model ([`DstDecoding::Pipeline`]).
    pub fn pipeline(&self) -> DstPipeline<'_> {
        DstPipeline(&self.dst)
    }

    /// The BVH2 build settings the tree came from.
    pub fn config(&self) -> &BuildConfig {
        &self.config
    }

    /// Size and conversion time.
    pub fn stats(&self) -> &BuildStats {
        &self.stats
    }
}

/// The compressed 8-wide BVH ([`Cwbvh`]) collapsed from a BVH2, with its build settings
/// and statistics.
#[derive(Clone, Debug)]
pub struct CwbvhTree {
    pub(crate) cwbvh: Cwbvh,
    pub(crate) config: BuildConfig,
    pub(crate) stats: BuildStats,
}

impl CwbvhTree {
    /// The BVH8 collapse of `bvh2` (Ylitie et al. 2017, default collapse costs) encoded with
    /// 80-byte compressed nodes: the BVH8's partitioning, quantized boxes.
    pub fn from_bvh2(bvh2: &Bvh2Tree) -> Result<Self, AccelError> {
        let t0 = Instant::now();
        let wide = WideBvh::collapse_bvh8(&bvh2.logical, &CollapseConfig::default());
        let collapse = t0.elapsed();
        let cwbvh = Cwbvh::from_wide(
            &wide,
            &bvh2.logical,
            bvh2.shared_triangles().clone(),
            collapse,
        )?;
        let stats = BuildStats::of_cwbvh(&cwbvh, ms_since(t0));
        Ok(Self {
            cwbvh,
            config: *bvh2.config(),
            stats,
        })
    }

    /// The structure (image, node counts, traversal).
    pub fn cwbvh(&self) -> &Cwbvh {
        &self.cwbvh
    }

    /// The byte-exact memory image.
    pub fn image(&self) -> &MemoryImage {
        self.cwbvh.image()
    }

    /// The BVH2 build settings the tree came from.
    pub fn config(&self) -> &BuildConfig {
        &self.config
    }

    /// Size and build time.
    pub fn stats(&self) -> &BuildStats {
        &self.stats
    }
}

/// The quantized dual-split tree ([`DstQ`]) encoded from a DST, with its build settings and
/// statistics.
#[derive(Clone, Debug)]
pub struct DstQTree {
    pub(crate) dstq: DstQ,
    pub(crate) config: BuildConfig,
    pub(crate) stats: BuildStats,
}

impl DstQTree {
    /// Quantizes `dst` with `cfg` (the same nodes and decisions; planes rounded outward).
    /// The build time counts the quantization only.
    pub fn from_dst(dst: &DstTree, cfg: &DstQConfig) -> Result<Self, AccelError> {
        let t0 = Instant::now();
        let dstq = DstQ::from_dst(&dst.dst, cfg)?;
        let stats = BuildStats::of_dstq(&dstq, ms_since(t0));
        Ok(Self {
            dstq,
            config: dst.config,
            stats,
        })
    }

    /// Converts `bvh2` into a DST with the hardware preset and quantizes it with `cfg`; the
    /// build time counts both steps.
    pub fn from_bvh2(bvh2: &Bvh2Tree, cfg: &DstQConfig) -> Result<Self, AccelError> {
        let t0 = Instant::now();
        let mut t = Self::from_dst(&DstTree::from_bvh2(bvh2, &DstConfig::hardware())?, cfg)?;
        t.stats.build_ms = ms_since(t0);
        Ok(t)
    }

    /// The structure (image, scene box, traversal).
    pub fn dstq(&self) -> &DstQ {
        &self.dstq
    }

    /// The byte-exact memory image.
    pub fn image(&self) -> &MemoryImage {
        self.dstq.image()
    }

    /// The BVH2 build settings the tree came from.
    pub fn config(&self) -> &BuildConfig {
        &self.config
    }

    /// Size and build time.
    pub fn stats(&self) -> &BuildStats {
        &self.stats
    }
}

/// One structure of any kind: what a saved tree file holds.
#[derive(Clone, Debug)]
pub enum AnyTree {
    /// A BVH2, BVH4 or BVH8.
    Bvh(BvhTree),
    /// A dual-split tree.
    Dst(DstTree),
    /// A compressed 8-wide BVH.
    Cwbvh(CwbvhTree),
    /// A quantized dual-split tree.
    DstQ(DstQTree),
}

/// `$body` with `$t` bound to the tree inside `$tree`, whatever its kind (the four tree
/// types share the accessors `image`, `config` and `stats`).
macro_rules! each_tree {
    ($tree:expr, |$t:ident| $body:expr) => {
        match $tree {
            AnyTree::Bvh($t) => $body,
            AnyTree::Dst($t) => $body,
            AnyTree::Cwbvh($t) => $body,
            AnyTree::DstQ($t) => $body,
        }
    };
}

impl AnyTree {
    /// The structure of `kind` derived from `bvh2` with the default settings `dualsplit
    /// build` uses (the DST's hardware preset, the default BVH8 collapse and quantized DST),
    /// or `None` for [`TreeKind::Bvh2`]: the BVH2 is `bvh2` itself
    /// ([`Bvh2Tree::into_tree`]).
    pub fn derive(bvh2: &Bvh2Tree, kind: TreeKind) -> Option<Result<AnyTree, AccelError>> {
        let tree = match kind {
            TreeKind::Bvh2 => return None,
            TreeKind::Bvh4 => BvhTree::bvh4_from(bvh2).map(AnyTree::from),
            TreeKind::Bvh8 => BvhTree::bvh8_from(bvh2).map(AnyTree::from),
            TreeKind::Dst => DstTree::from_bvh2(bvh2, &DstConfig::hardware()).map(AnyTree::from),
            TreeKind::Cwbvh => CwbvhTree::from_bvh2(bvh2).map(AnyTree::from),
            TreeKind::DstQ => DstQTree::from_bvh2(bvh2, &DstQConfig::default()).map(AnyTree::from),
        };
        Some(tree)
    }

    /// Which structure.
    pub fn kind(&self) -> TreeKind {
        match self {
            AnyTree::Bvh(b) => b.kind(),
            AnyTree::Dst(_) => TreeKind::Dst,
            AnyTree::Cwbvh(_) => TreeKind::Cwbvh,
            AnyTree::DstQ(_) => TreeKind::DstQ,
        }
    }

    /// The byte-exact memory image.
    pub fn image(&self) -> &MemoryImage {
        each_tree!(self, |t| t.image())
    }

    /// The BVH2 build settings.
    pub fn config(&self) -> &BuildConfig {
        each_tree!(self, |t| t.config())
    }

    /// Size and build time.
    pub fn stats(&self) -> &BuildStats {
        each_tree!(self, |t| t.stats())
    }

    /// The triangles as one shared allocation.
    pub fn shared_triangles(&self) -> &SharedTriangles {
        &self.image().triangle_data
    }

    /// Checks the tree against `bvh2`, the BVH2 it was derived from (or one built afresh
    /// with the same settings): a BVH image on its own (boxes hold their children), a DST
    /// against `bvh2`'s boxes, a compressed BVH8 for quantized boxes that contain their
    /// children's exact boxes, a quantized DST against the DST converted from `bvh2`
    /// (hardware preset: the same decisions, planes only looser).
    pub fn validate(&self, bvh2: &Bvh2) -> ValidationReport {
        match self {
            AnyTree::Bvh(b) => b.encoded().validate(),
            AnyTree::Dst(d) => ValidationReport::of_dst(&d.dst, bvh2),
            AnyTree::Cwbvh(c) => c.cwbvh.validate(),
            AnyTree::DstQ(q) => {
                let tris = self.shared_triangles().clone();
                match Dst::from_bvh2(bvh2, tris, &DstConfig::hardware()) {
                    Ok(dst) => q.dstq.validate(&dst),
                    Err(e) => {
                        let mut rep = q.dstq.validate_structure();
                        rep.error_count += 1;
                        rep.errors
                            .push(format!("the exact DST of the reference BVH2 fails: {e}"));
                        rep
                    }
                }
            }
        }
    }

    /// Closest hit through traversal `kind`, or `None` when this tree is not the structure
    /// `kind` reads ([`TreeKind::accel_kinds`]).
    pub fn closest_hit<O: Observer>(
        &self,
        kind: AccelKind,
        ray: &Ray,
        obs: &mut O,
    ) -> Option<Option<Hit>> {
        match (self, kind) {
            (AnyTree::Dst(d), AccelKind::DstSw) => Some(d.dst.closest_hit(ray, obs)),
            (AnyTree::Dst(d), AccelKind::Dst) => Some(d.dst.closest_hit_pipeline(ray, obs)),
            (AnyTree::Cwbvh(c), AccelKind::Cwbvh) => Some(c.cwbvh.closest_hit(ray, obs)),
            (AnyTree::DstQ(q), AccelKind::DstQ) => Some(q.dstq.closest_hit(ray, obs)),
            (AnyTree::Bvh(b), k) if TreeKind::of_accel(k) == b.kind() => {
                Some(b.encoded.closest_hit(ray, obs))
            }
            _ => None,
        }
    }

    /// Any hit through traversal `kind`, or `None` when this tree is not the structure
    /// `kind` reads.
    pub fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<bool> {
        match (self, kind) {
            (AnyTree::Dst(d), AccelKind::DstSw) => Some(d.dst.any_hit(ray, obs)),
            (AnyTree::Dst(d), AccelKind::Dst) => Some(d.dst.any_hit_pipeline(ray, obs)),
            (AnyTree::Cwbvh(c), AccelKind::Cwbvh) => Some(c.cwbvh.any_hit(ray, obs)),
            (AnyTree::DstQ(q), AccelKind::DstQ) => Some(q.dstq.any_hit(ray, obs)),
            (AnyTree::Bvh(b), k) if TreeKind::of_accel(k) == b.kind() => {
                Some(b.encoded.any_hit(ray, obs))
            }
            _ => None,
        }
    }
}

impl From<BvhTree> for AnyTree {
    fn from(b: BvhTree) -> Self {
        AnyTree::Bvh(b)
    }
}

impl From<DstTree> for AnyTree {
    fn from(d: DstTree) -> Self {
        AnyTree::Dst(d)
    }
}

impl From<CwbvhTree> for AnyTree {
    fn from(c: CwbvhTree) -> Self {
        AnyTree::Cwbvh(c)
    }
}

impl From<DstQTree> for AnyTree {
    fn from(q: DstQTree) -> Self {
        AnyTree::DstQ(q)
    }
}

macro_rules! query_via {
    ($ty:ty, |$s:ident| $inner:expr) => {
        impl RayQuery for $ty {
            #[inline]
            fn intersect_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
                let $s = self;
                $inner.intersect_observed(ray, obs)
            }
            #[inline]
            fn occluded_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
                let $s = self;
                $inner.occluded_observed(ray, obs)
            }
            fn triangles(&self) -> &[Triangle] {
                let $s = self;
                RayQuery::triangles($inner)
            }
            fn intersect_batch(&self, rays: &[Ray]) -> Vec<Option<Hit>> {
                let $s = self;
                $inner.intersect_batch(rays)
            }
            fn occluded_batch(&self, rays: &[Ray]) -> Vec<bool> {
                let $s = self;
                $inner.occluded_batch(rays)
            }
        }
    };
}

query_via!(Bvh2Tree, |s| &s.tree.encoded);
query_via!(BvhTree, |s| &s.encoded);
query_via!(DstTree, |s| &s.dst);
query_via!(CwbvhTree, |s| &s.cwbvh);
query_via!(DstQTree, |s| &s.dstq);

/// Queries an [`AnyTree`] through its default traversal (the software decoder for a DST).
impl RayQuery for AnyTree {
    #[inline]
    fn intersect_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        each_tree!(self, |t| t.intersect_observed(ray, obs))
    }
    #[inline]
    fn occluded_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        each_tree!(self, |t| t.occluded_observed(ray, obs))
    }
    fn triangles(&self) -> &[Triangle] {
        self.image().triangle_slice()
    }
    fn intersect_batch(&self, rays: &[Ray]) -> Vec<Option<Hit>> {
        each_tree!(self, |t| t.intersect_batch(rays))
    }
    fn occluded_batch(&self, rays: &[Ray]) -> Vec<bool> {
        each_tree!(self, |t| t.occluded_batch(rays))
    }
}
