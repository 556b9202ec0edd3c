//! The tree types of the BVH family: [`Bvh2Tree`] (the SAH BVH2 every structure is
//! derived from, logical and encoded) and [`BvhTree`] (an encoded BVH2, BVH4 or BVH8).
//! What the registry needs of them ([`Structure`](crate::Structure)) is
//! [`super::structure`]: the structure trait takes the BVH2 every structure is derived
//! from, so this file sits below it.

use super::{BvhImage, CollapseConfig, WideBvh};
use crate::image::{MemoryImage, SharedTriangles};
use crate::query::query_via;
use crate::stats::BuildStats;
use crate::{AccelError, BuildConfig, Bvh2, TreeKind, ms_since};
use dualsplit_geometry::Aabb;
use std::time::Instant;

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
    pub(super) fn build_stats(kind: TreeKind, encoded: &BvhImage, build_ms: f64) -> BuildStats {
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

crate::query::query_by_traversal!(
    /// The batch forms trace each rayon job's rays through one [`BvhImage::query`] context.
    BvhImage,
    |s| s.image.triangle_slice(),
    query
);
query_via!(Bvh2Tree, |s| &s.tree.encoded);
query_via!(BvhTree, |s| &s.encoded);
