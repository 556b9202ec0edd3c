//! The tree types of the BVH family: [`Bvh2Tree`] (the SAH BVH2 every structure is
//! derived from, logical and encoded) and [`BvhTree`] (an encoded BVH2, BVH4 or BVH8), and
//! what the registry needs of them ([`Structure`]).

use super::{BvhImage, BvhQuery, CollapseConfig, Node4, Node8, WideBvh};
use crate::bvh2::Node2;
use crate::image::{MemoryImage, SharedTriangles};
use crate::observer::Observer;
use crate::saved::{FieldReader, FieldWriter, SavedError, Violation};
use crate::stats::StructureStats;
use crate::structure::{PlainQuery, SavedFields, Structure};
use crate::tree::{BuildStats, query_via};
use crate::validate::ValidationReport;
use crate::{
    AccelError, AccelKind, AnyTree, BuildConfig, Bvh2, Presets, Structures, TreeKind, ms_since,
};
use dualsplit_geometry::{Aabb, Hit, Ray};
use std::time::{Duration, Instant};

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
        let stats = BvhTree::build_stats(TreeKind::Bvh2, &encoded, ms_since(t0));
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

    /// The encoded BVH2 (what [`crate::RayQuery`] traverses and what is saved).
    pub fn tree(&self) -> &BvhTree {
        &self.tree
    }

    /// The logical tree, dropping the encoded one.
    pub fn into_logical(self) -> Bvh2 {
        self.logical
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
            _ => None,
        }
    }

    /// The statistics of `encoded`, a BVH of `kind`.
    fn build_stats(kind: TreeKind, encoded: &BvhImage, build_ms: f64) -> BuildStats {
        BuildStats::of_image(
            kind,
            &encoded.image,
            encoded.internal_nodes as u64,
            encoded.leaves as u64,
            build_ms,
        )
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
        let stats = BvhTree::build_stats(kind, &encoded, ms_since(t0));
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

/// The header fields a saved BVH records: its node counts and SAH cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhFields {
    internal_nodes: u64,
    leaves: u64,
    sah_cost: f32,
}

impl SavedFields for BvhFields {
    fn write(&self, out: &mut FieldWriter) {
        out.u64(self.internal_nodes);
        out.u64(self.leaves);
        out.f32(self.sah_cost);
    }

    fn read(_: TreeKind, input: &mut FieldReader) -> Result<Self, SavedError> {
        Ok(Self {
            internal_nodes: input.u64(),
            leaves: input.u64(),
            sah_cost: input.f32(),
        })
    }
}

impl PlainQuery for BvhQuery<'_> {
    #[inline]
    fn closest_hit(&mut self, ray: &Ray) -> Option<Hit> {
        BvhQuery::closest_hit(self, ray)
    }
    #[inline]
    fn any_hit(&mut self, ray: &Ray) -> bool {
        BvhQuery::any_hit(self, ray)
    }
}

impl Structure for BvhTree {
    type Fields = BvhFields;
    type Query<'a> = BvhQuery<'a>;

    fn derive(
        bvh2: &Bvh2Tree,
        kind: TreeKind,
        presets: &Presets,
        _built: &[AnyTree],
    ) -> Result<Self, AccelError> {
        match kind {
            TreeKind::Bvh4 => Self::bvh4_from(bvh2),
            TreeKind::Bvh8 => Self::bvh8_from_with(bvh2, &presets.collapse),
            _ => Ok(bvh2.tree.clone()),
        }
    }

    fn kind(&self) -> TreeKind {
        BvhTree::kind(self)
    }

    fn image(&self) -> &MemoryImage {
        &self.encoded.image
    }

    fn config(&self) -> &BuildConfig {
        &self.config
    }

    fn stats(&self) -> &BuildStats {
        &self.stats
    }

    #[inline]
    fn closest_hit<O: Observer>(&self, _: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        self.encoded.closest_hit(ray, obs)
    }

    #[inline]
    fn any_hit<O: Observer>(&self, _: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        self.encoded.any_hit(ray, obs)
    }

    fn query(&self, _: AccelKind) -> Option<BvhQuery<'_>> {
        Some(self.encoded.query())
    }

    /// The image on its own: boxes hold their children.
    fn validate(&self, _: &Bvh2, _: &[AnyTree]) -> ValidationReport {
        self.encoded.validate()
    }

    /// The BVH2's root box is the union of the triangles' boxes (min and max are exact, so
    /// the order does not matter): the trait's default.
    fn scene_box(&self) -> Aabb {
        self.image()
            .triangle_slice()
            .iter()
            .fold(Aabb::EMPTY, |acc, t| acc.union(t.bounds()))
    }

    fn structure_stats(&self, bvh2_total: u64) -> StructureStats {
        let s = &self.encoded;
        StructureStats::new(
            self.kind().name(),
            s.internal_nodes as u64,
            s.leaves as u64,
            s.image.node_bytes(),
            s.image.index_bytes(),
            bvh2_total,
        )
        .with_sah_cost(s.sah_cost)
        .with_build_ms(s.time.as_secs_f64() * 1e3)
    }

    fn saved_fields(&self) -> BvhFields {
        BvhFields {
            internal_nodes: self.encoded.internal_nodes as u64,
            leaves: self.encoded.leaves as u64,
            sah_cost: self.encoded.sah_cost,
        }
    }

    fn from_saved(kind: TreeKind, image: MemoryImage, build: BuildConfig, f: BvhFields) -> Self {
        let encoded = BvhImage {
            arity: match kind {
                TreeKind::Bvh2 => 2,
                TreeKind::Bvh4 => 4,
                _ => 8,
            },
            image,
            internal_nodes: f.internal_nodes as usize,
            leaves: f.leaves as usize,
            sah_cost: f.sah_cost,
            time: Duration::ZERO,
            cpu: Default::default(),
        };
        BvhTree {
            stats: Self::build_stats(kind, &encoded, 0.0),
            encoded,
            config: build,
        }
    }

    fn check_saved(&self, f: &BvhFields) -> Result<(), Violation> {
        let img = &crate::saved::Regions::of(self.image());
        let (n, l) = (f.internal_nodes, f.leaves);
        match self.kind() {
            TreeKind::Bvh2 => crate::saved::check_bvh::<Node2>(img, n, l),
            TreeKind::Bvh4 => crate::saved::check_bvh::<Node4>(img, n, l),
            _ => crate::saved::check_bvh::<Node8>(img, n, l),
        }
    }
}

crate::query::query_by_traversal!(
    /// The batch forms trace each rayon job's rays through one [`BvhImage::query`] context.
    BvhImage,
    |s| s.image.triangle_slice(),
    query
);
query_via!(Bvh2Tree, |s| &s.tree.encoded);
query_via!(BvhTree, |s| &s.encoded);

impl Structures {
    /// The encoded BVH2 (52-byte nodes); its `time` is the BVH2 build time.
    pub fn bvh2_image(&self) -> &BvhImage {
        &self.structure::<BvhTree>(TreeKind::Bvh2).encoded
    }

    /// The encoded BVH4 (100-byte nodes); its `time` is the collapse time.
    pub fn bvh4(&self) -> &BvhImage {
        &self.structure::<BvhTree>(TreeKind::Bvh4).encoded
    }

    /// The encoded BVH8 (200-byte nodes); its `time` is the collapse time.
    pub fn bvh8(&self) -> &BvhImage {
        &self.structure::<BvhTree>(TreeKind::Bvh8).encoded
    }

    /// The encoded BVH that `kind` traverses (BVH2, BVH4, BVH8), or `None` for the others.
    pub fn encoded(&self, kind: AccelKind) -> Option<&BvhImage> {
        self.tree(kind.tree_kind())
            .get::<BvhTree>()
            .map(|b| &b.encoded)
    }
}
