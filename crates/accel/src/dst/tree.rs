//! The DST's tree type ([`DstTree`], both of its traversals) and what the registry needs
//! of it ([`Structure`]): derivation, queries, statistics and the saved form.

use super::saved::check_dst;
use super::{Dst, DstConfig, DstCosts, DstQuery, DstStats, Partitioning};
use crate::image::MemoryImage;
use crate::observer::Observer;
use crate::query::RayQuery;
use crate::query::query_via;
use crate::saved::{FieldReader, FieldWriter, SavedError, SavedFields, Violation, check_cost};
use crate::stats::{BuildStats, StructureStats};
use crate::structure::{PlainQuery, Structure, own_frame};
use crate::validate::ValidationReport;
use crate::{
    AccelError, AccelKind, AnyTree, BuildConfig, Bvh2, Bvh2Tree, Presets, Structures, TreeKind,
    ms_since,
};
use dualsplit_geometry::{Aabb, Hit, Ray, Triangle};
use std::time::Instant;

impl AccelKind {
    /// The DST's software decoder (the paper's DST\*), the fast CPU traversal: an
    /// unambiguous name for [`AccelKind::DstSw`].
    pub const DST_SOFTWARE: AccelKind = AccelKind::DstSw;
    /// The DST traversed by the hardware pipeline model: an unambiguous name for
    /// [`AccelKind::Dst`].
    pub const DST_PIPELINE: AccelKind = AccelKind::Dst;
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
        let dst = Dst::from_bvh2(bvh2.logical(), bvh2.shared_triangles().clone(), preset)?;
        let stats = Self::build_stats(&dst, ms_since(t0));
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

    fn build_stats(d: &Dst, build_ms: f64) -> BuildStats {
        let s = d.stats();
        BuildStats::of_image(
            TreeKind::Dst,
            d.image(),
            s.internal_nodes(),
            s.leaves + s.carving_leaves,
            build_ms,
        )
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

/// A [`Dst`] queried through the model of the paper's hardware dual-split pipeline
/// ([`crate::AccelKind::Dst`]): every node step is computed by the pipeline's step function.
/// Same answers as the software decoder, several times slower on a CPU; it exists to check
/// and simulate the hardware.
#[derive(Clone, Copy, Debug)]
pub struct DstPipeline<'a>(pub &'a Dst);

impl RayQuery for DstPipeline<'_> {
    #[inline]
    fn intersect_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        self.0.closest_hit_pipeline(ray, obs)
    }
    #[inline]
    fn occluded_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        self.0.any_hit_pipeline(ray, obs)
    }
    fn triangles(&self) -> &[Triangle] {
        self.0.triangles()
    }
}

crate::query::query_by_traversal!(
    /// A [`Dst`] queried through its software decoder (the paper's DST\*,
    /// [`crate::AccelKind::DstSw`]): the fast CPU traversal. The batch forms trace each
    /// rayon job's rays through one [`Dst::query`] context.
    Dst,
    |s| Dst::triangles(s),
    query
);
query_via!(DstTree, |s| &s.dst);

impl ValidationReport {
    /// The report of [`crate::dst::Dst::validate`] in this shape: the DST must rebuild every
    /// box of `bvh` exactly from its planes and reference every triangle once.
    pub fn of_dst(dst: &Dst, bvh: &Bvh2) -> Self {
        let mut rep = ValidationReport {
            structure: "dst",
            triangles: dst.triangles().len(),
            ..Default::default()
        };
        match dst.validate(bvh) {
            Ok(v) => {
                rep.internal_nodes = v.internal_nodes as usize;
                rep.leaves = v.leaves as usize;
                rep.triangles_referenced = v.index_entries as usize;
                rep.max_depth = v.max_depth as usize;
            }
            Err(e) => rep.error(e.to_string()),
        }
        rep
    }
}

/// The header fields a saved DST records: its conversion settings, the scene box its
/// traversal starts from, and its statistics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DstFields {
    config: DstConfig,
    scene_box: Aabb,
    stats: DstStats,
}

impl SavedFields for DstFields {
    fn write(&self, o: &mut FieldWriter) {
        let (config, stats) = (&self.config, &self.stats);
        o.f32(config.costs.split);
        o.f32(config.costs.single_carve);
        o.f32(config.costs.dual_carve);
        o.f32(config.costs.triangle);
        o.u32(match config.partitioning {
            Partitioning::Identical => 0,
            Partitioning::Similar => 1,
        });
        o.scene_box(self.scene_box);
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

    fn read(_: TreeKind, i: &mut FieldReader) -> Result<Self, SavedError> {
        let costs = DstCosts {
            split: i.f32(),
            single_carve: i.f32(),
            dual_carve: i.f32(),
            triangle: i.f32(),
        };
        check_costs(&costs)?;
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
        Ok(DstFields {
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
        })
    }

    fn check(&self) -> Result<(), SavedError> {
        check_costs(&self.config.costs)
    }

    fn scene_box(&self) -> Option<Aabb> {
        Some(self.scene_box)
    }
}

/// Every DST cost must be a finite number ≥ 0.
fn check_costs(costs: &DstCosts) -> Result<(), SavedError> {
    for (name, c) in [
        ("split", costs.split),
        ("single_carve", costs.single_carve),
        ("dual_carve", costs.dual_carve),
        ("triangle", costs.triangle),
    ] {
        check_cost("DST cost", name, c)?;
    }
    Ok(())
}

impl PlainQuery for DstQuery<'_> {
    #[inline]
    fn closest_hit(&mut self, ray: &Ray) -> Option<Hit> {
        DstQuery::closest_hit(self, ray)
    }
    #[inline]
    fn any_hit(&mut self, ray: &Ray) -> bool {
        DstQuery::any_hit(self, ray)
    }
}

impl Structure for DstTree {
    type Fields = DstFields;
    type Query<'a> = DstQuery<'a>;

    fn derive(
        bvh2: &Bvh2Tree,
        _: TreeKind,
        presets: &Presets,
        _: &[AnyTree],
    ) -> Result<Self, AccelError> {
        Self::from_bvh2(bvh2, &presets.dst)
    }

    fn kind(&self) -> TreeKind {
        TreeKind::Dst
    }

    fn image(&self) -> &MemoryImage {
        self.dst.image()
    }

    fn config(&self) -> &BuildConfig {
        &self.config
    }

    fn stats(&self) -> &BuildStats {
        &self.stats
    }

    /// The hardware pipeline's step function for [`AccelKind::Dst`], the software decoder
    /// (DST\*) otherwise.
    #[inline]
    fn closest_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        match kind {
            AccelKind::Dst => own_frame(|| self.dst.closest_hit_pipeline(ray, obs)),
            _ => own_frame(|| self.dst.closest_hit(ray, obs)),
        }
    }

    #[inline]
    fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        match kind {
            AccelKind::Dst => own_frame(|| self.dst.any_hit_pipeline(ray, obs)),
            _ => own_frame(|| self.dst.any_hit(ray, obs)),
        }
    }

    /// The software decoder's context ([`DstQuery`]); the pipeline has none.
    fn query(&self, kind: AccelKind) -> Option<DstQuery<'_>> {
        (kind == AccelKind::DstSw).then(|| self.dst.query())
    }

    /// Against `bvh2`'s boxes: the DST must rebuild every one exactly.
    fn validate(&self, bvh2: &Bvh2, _: &[AnyTree]) -> ValidationReport {
        ValidationReport::of_dst(&self.dst, bvh2)
    }

    fn scene_box(&self) -> Aabb {
        self.dst.scene_box()
    }

    /// Its node bytes include the 24-byte scene box stored beside the tree; `sah_cost` is
    /// NaN (the DST's cost model is not the BVH's SAH).
    fn structure_stats(&self, bvh2_total: u64) -> StructureStats {
        let d = self.dst.stats();
        StructureStats {
            nodes: d.internal_nodes() + d.leaves,
            ..StructureStats::new(
                "dst",
                d.internal_nodes(),
                d.leaves + d.carving_leaves,
                d.total_bytes - d.index_bytes,
                d.index_bytes,
                bvh2_total,
            )
            .with_convert_ms(self.stats.build_ms)
            .with_dst(d)
        }
    }

    fn saved_fields(&self) -> DstFields {
        DstFields {
            config: *self.dst.config(),
            scene_box: self.dst.scene_box(),
            stats: self.dst.stats(),
        }
    }

    fn from_saved(_: TreeKind, image: MemoryImage, build: BuildConfig, f: DstFields) -> Self {
        let dst = Dst::from_parts(image, f.scene_box, f.config, f.stats);
        DstTree {
            stats: Self::build_stats(&dst, 0.0),
            dst,
            config: build,
        }
    }

    fn check_saved(&self, f: &DstFields) -> Result<(), Violation> {
        check_dst(&crate::saved::Regions::of(self.image()), &f.stats)
    }
}

impl Structures {
    /// Like [`Structures::try_build`] with an explicit DST configuration.
    pub fn try_build_with(
        triangles: &[Triangle],
        cfg: &BuildConfig,
        dst_cfg: &DstConfig,
    ) -> Result<Self, AccelError> {
        let presets = Presets {
            dst: *dst_cfg,
            ..Presets::default()
        };
        Self::try_build_presets(triangles, cfg, &presets)
    }

    /// The dual-split tree (identical bounds, [`DstConfig::hardware`] unless built with
    /// other presets).
    pub fn dst(&self) -> &Dst {
        &self.structure::<DstTree>(TreeKind::Dst).dst
    }
}
