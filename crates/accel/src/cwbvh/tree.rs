//! The compressed BVH8's tree type ([`CwbvhTree`]) and what the registry needs of it
//! ([`Structure`]): derivation, queries, statistics and the saved form.

use super::{Cwbvh, check_structure};
use crate::image::MemoryImage;
use crate::observer::Observer;
use crate::query::query_via;
use crate::saved::{FieldReader, FieldWriter, SavedError, SavedFields, Violation, counts};
use crate::stats::{BuildStats, StructureStats};
use crate::structure::{NoQuery, Structure, own_frame};
use crate::validate::ValidationReport;
use crate::wide::{CollapseConfig, WideBvh};
use crate::{
    AccelError, AccelKind, AnyTree, BuildConfig, Bvh2, Bvh2Tree, Presets, Structures, TreeKind,
    ms_since,
};
use dualsplit_geometry::{Hit, Ray};
use std::time::Instant;

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
        Self::from_bvh2_with(bvh2, &CollapseConfig::default())
    }

    /// [`CwbvhTree::from_bvh2`] with explicit collapse costs.
    pub fn from_bvh2_with(
        bvh2: &Bvh2Tree,
        collapse_cfg: &CollapseConfig,
    ) -> Result<Self, AccelError> {
        let t0 = Instant::now();
        let wide = WideBvh::collapse_bvh8(bvh2.logical(), collapse_cfg);
        let collapse = t0.elapsed();
        let cwbvh = Cwbvh::from_wide(
            &wide,
            bvh2.logical(),
            bvh2.shared_triangles().clone(),
            collapse,
        )?;
        let stats = Self::build_stats(&cwbvh, ms_since(t0));
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

    fn build_stats(c: &Cwbvh, build_ms: f64) -> BuildStats {
        BuildStats::of_image(
            TreeKind::Cwbvh,
            c.image(),
            c.internal_nodes() as u64,
            c.leaves() as u64,
            build_ms,
        )
    }
}

crate::query::query_by_traversal!(Cwbvh, |s| s.image().triangle_slice());
query_via!(CwbvhTree, |s| &s.cwbvh);

/// The header fields a saved compressed BVH8 records: its node counts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CwbvhFields {
    internal_nodes: u64,
    leaves: u64,
}

impl SavedFields for CwbvhFields {
    fn write(&self, o: &mut FieldWriter) {
        o.u64(self.internal_nodes);
        o.u64(self.leaves);
    }

    fn read(_: TreeKind, i: &mut FieldReader) -> Result<Self, SavedError> {
        Ok(Self {
            internal_nodes: i.u64(),
            leaves: i.u64(),
        })
    }
}

impl Structure for CwbvhTree {
    type Fields = CwbvhFields;
    type Query<'a> = NoQuery;

    fn derive(
        bvh2: &Bvh2Tree,
        _: TreeKind,
        presets: &Presets,
        _: &[AnyTree],
    ) -> Result<Self, AccelError> {
        Self::from_bvh2_with(bvh2, &presets.collapse)
    }

    fn kind(&self) -> TreeKind {
        TreeKind::Cwbvh
    }

    fn image(&self) -> &MemoryImage {
        self.cwbvh.image()
    }

    fn config(&self) -> &BuildConfig {
        &self.config
    }

    fn stats(&self) -> &BuildStats {
        &self.stats
    }

    #[inline]
    fn closest_hit<O: Observer>(&self, _: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        own_frame(|| self.cwbvh.closest_hit(ray, obs))
    }

    #[inline]
    fn any_hit<O: Observer>(&self, _: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        own_frame(|| self.cwbvh.any_hit(ray, obs))
    }

    fn query(&self, _: AccelKind) -> Option<NoQuery> {
        None
    }

    /// On its own: every quantized box must contain its children's exact boxes.
    fn validate(&self, _: &Bvh2, _: &[AnyTree]) -> ValidationReport {
        self.cwbvh.validate()
    }

    fn structure_stats(&self, bvh2_total: u64) -> StructureStats {
        let c = &self.cwbvh;
        StructureStats::new(
            "cwbvh",
            c.internal_nodes() as u64,
            c.leaves() as u64,
            c.image().node_bytes(),
            c.image().index_bytes(),
            bvh2_total,
        )
        .with_build_ms(c.time().as_secs_f64() * 1e3)
    }

    fn saved_fields(&self) -> CwbvhFields {
        CwbvhFields {
            internal_nodes: self.cwbvh.internal_nodes() as u64,
            leaves: self.cwbvh.leaves() as u64,
        }
    }

    fn from_saved(_: TreeKind, image: MemoryImage, build: BuildConfig, f: CwbvhFields) -> Self {
        let cwbvh = Cwbvh::from_parts(image, f.internal_nodes as usize, f.leaves as usize);
        CwbvhTree {
            stats: Self::build_stats(&cwbvh, 0.0),
            cwbvh,
            config: build,
        }
    }

    fn check_saved(&self, f: &CwbvhFields) -> Result<(), Violation> {
        counts(
            check_structure(self.cwbvh.image()),
            f.internal_nodes,
            f.leaves,
        )
    }
}

impl Structures {
    /// The compressed BVH8, encoded from the same collapse as [`Structures::bvh8`].
    pub fn cwbvh(&self) -> &Cwbvh {
        &self.structure::<CwbvhTree>(TreeKind::Cwbvh).cwbvh
    }
}
