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

use crate::dst::{Dst, DstConfig};
use crate::image::{MemoryImage, SharedTriangles};
use crate::observer::Observer;
use crate::query::{DstPipeline, RayQuery};
use crate::wide::{BvhImage, CollapseConfig, WideBvh};
use crate::{AccelError, AccelKind, BuildConfig, Bvh2};
use dualsplit_geometry::{Aabb, Hit, Ray, Triangle};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The four structures a tree can be.
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
}

impl TreeKind {
    /// All kinds.
    pub const ALL: [TreeKind; 4] = [
        TreeKind::Bvh2,
        TreeKind::Bvh4,
        TreeKind::Bvh8,
        TreeKind::Dst,
    ];

    /// The command-line name: `bvh2`, `bvh4`, `bvh8`, `dst`.
    pub fn name(self) -> &'static str {
        match self {
            TreeKind::Bvh2 => "bvh2",
            TreeKind::Bvh4 => "bvh4",
            TreeKind::Bvh8 => "bvh8",
            TreeKind::Dst => "dst",
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
        }
    }

    /// The structure [`AccelKind`] `k` traverses.
    pub fn of_accel(k: AccelKind) -> Self {
        match k {
            AccelKind::Bvh2 => TreeKind::Bvh2,
            AccelKind::Bvh4 => TreeKind::Bvh4,
            AccelKind::Bvh8 => TreeKind::Bvh8,
            AccelKind::DstSw | AccelKind::Dst => TreeKind::Dst,
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

    /// Node plus index bytes (the size the paper's Table 3 compares).
    pub fn bytes_total(&self) -> u64 {
        self.node_bytes + self.index_bytes
    }
}

fn ms_since(t0: Instant) -> f64 {
    t0.elapsed().as_secs_f64() * 1e3
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

    /// The BVH of `kind` derived from `bvh2` (`None` for [`TreeKind::Dst`]).
    pub fn from_bvh2(bvh2: &Bvh2Tree, kind: TreeKind) -> Option<Result<Self, AccelError>> {
        match kind {
            TreeKind::Bvh2 => Some(Ok(bvh2.tree.clone())),
            TreeKind::Bvh4 => Some(Self::bvh4_from(bvh2)),
            TreeKind::Bvh8 => Some(Self::bvh8_from(bvh2)),
            TreeKind::Dst => None,
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

/// One structure of any kind: what a saved tree file holds.
#[derive(Clone, Debug)]
pub enum AnyTree {
    /// A BVH2, BVH4 or BVH8.
    Bvh(BvhTree),
    /// A dual-split tree.
    Dst(DstTree),
}

impl AnyTree {
    /// Which structure.
    pub fn kind(&self) -> TreeKind {
        match self {
            AnyTree::Bvh(b) => b.kind(),
            AnyTree::Dst(_) => TreeKind::Dst,
        }
    }

    /// The byte-exact memory image.
    pub fn image(&self) -> &MemoryImage {
        match self {
            AnyTree::Bvh(b) => b.image(),
            AnyTree::Dst(d) => d.image(),
        }
    }

    /// The BVH2 build settings.
    pub fn config(&self) -> &BuildConfig {
        match self {
            AnyTree::Bvh(b) => b.config(),
            AnyTree::Dst(d) => d.config(),
        }
    }

    /// Size and build time.
    pub fn stats(&self) -> &BuildStats {
        match self {
            AnyTree::Bvh(b) => b.stats(),
            AnyTree::Dst(d) => d.stats(),
        }
    }

    /// The triangles as one shared allocation.
    pub fn shared_triangles(&self) -> &SharedTriangles {
        &self.image().triangle_data
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
        }
    };
}

query_via!(Bvh2Tree, |s| &s.tree.encoded);
query_via!(BvhTree, |s| &s.encoded);
query_via!(DstTree, |s| &s.dst);

/// Queries an [`AnyTree`] through its default traversal (the software decoder for a DST).
impl RayQuery for AnyTree {
    #[inline]
    fn intersect_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        match self {
            AnyTree::Bvh(b) => b.intersect_observed(ray, obs),
            AnyTree::Dst(d) => d.intersect_observed(ray, obs),
        }
    }
    #[inline]
    fn occluded_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        match self {
            AnyTree::Bvh(b) => b.occluded_observed(ray, obs),
            AnyTree::Dst(d) => d.occluded_observed(ray, obs),
        }
    }
    fn triangles(&self) -> &[Triangle] {
        self.image().triangle_slice()
    }
}
