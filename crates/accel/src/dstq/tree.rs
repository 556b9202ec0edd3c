//! The quantized DST's tree type ([`DstQTree`]) and what the registry needs of it
//! ([`Structure`]): derivation (from the DST when one is built beside it), queries, the
//! check against its unit's geometry, statistics and the saved form.

use super::unit::{UNIT_BITS, UNIT_CLUSTER_BYTES, UNIT_MAX_NODE_BYTES, unit_supports};
use super::{DstQ, DstQConfig};
use crate::dst::{Dst, DstConfig, DstTree};
use crate::image::MemoryImage;
use crate::observer::Observer;
use crate::query::query_via;
use crate::saved::{FieldReader, FieldWriter, SavedError, SavedFields, Violation, violation};
use crate::stats::{BuildStats, StructureStats};
use crate::structure::{NoQuery, Structure, UnitMismatch, own_frame};
use crate::validate::ValidationReport;
use crate::{
    AccelError, AccelKind, AnyTree, BuildConfig, Bvh2, Bvh2Tree, Presets, Structures, TreeKind,
    ms_since,
};
use dualsplit_geometry::{Aabb, Hit, Ray};
use std::time::Instant;

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
        let stats = Self::build_stats(&dstq, ms_since(t0));
        Ok(Self {
            dstq,
            config: dst.config,
            stats,
        })
    }

    /// Converts `bvh2` into a DST with the hardware preset and quantizes it with `cfg`; the
    /// build time counts both steps.
    pub fn from_bvh2(bvh2: &Bvh2Tree, cfg: &DstQConfig) -> Result<Self, AccelError> {
        Self::from_bvh2_with(bvh2, &DstConfig::hardware(), cfg)
    }

    /// [`DstQTree::from_bvh2`] from the DST converted with `dst_cfg`.
    pub fn from_bvh2_with(
        bvh2: &Bvh2Tree,
        dst_cfg: &DstConfig,
        cfg: &DstQConfig,
    ) -> Result<Self, AccelError> {
        let t0 = Instant::now();
        let mut t = Self::from_dst(&DstTree::from_bvh2(bvh2, dst_cfg)?, cfg)?;
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

    fn build_stats(q: &DstQ, build_ms: f64) -> BuildStats {
        let s = q.stats();
        BuildStats::of_image(
            TreeKind::DstQ,
            q.image(),
            s.internal_nodes(),
            s.leaf_count(),
            build_ms,
        )
    }
}

crate::query::query_by_traversal!(DstQ, |s| s.image().triangle_slice());
query_via!(DstQTree, |s| &s.dstq);

/// The header fields a saved quantized DST records: its encoding and the scene box its
/// traversal starts from (no counts: the tree has none but its walk's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DstQFields {
    config: DstQConfig,
    scene_box: Aabb,
}

impl SavedFields for DstQFields {
    fn write(&self, o: &mut FieldWriter) {
        o.u32(self.config.bits);
        o.u32(self.config.cluster_bytes);
        o.scene_box(self.scene_box);
    }

    fn read(_: TreeKind, i: &mut FieldReader) -> Result<Self, SavedError> {
        let config = DstQConfig {
            bits: i.u32(),
            cluster_bytes: i.u32(),
        };
        config
            .check()
            .map_err(|e| SavedError::malformed(e.to_string()))?;
        Ok(Self {
            config,
            scene_box: i.scene_box(),
        })
    }

    fn scene_box(&self) -> Option<Aabb> {
        Some(self.scene_box)
    }
}

impl Structure for DstQTree {
    type Fields = DstQFields;
    type Query<'a> = NoQuery;

    /// Quantizes the DST in `built` if there is one, else converts one with `presets.dst`.
    fn derive(
        bvh2: &Bvh2Tree,
        _: TreeKind,
        presets: &Presets,
        built: &[AnyTree],
    ) -> Result<Self, AccelError> {
        match built.iter().find_map(AnyTree::get::<DstTree>) {
            Some(dst) => Self::from_dst(dst, &presets.dstq),
            None => Self::from_bvh2_with(bvh2, &presets.dst, &presets.dstq),
        }
    }

    fn kind(&self) -> TreeKind {
        TreeKind::DstQ
    }

    fn image(&self) -> &MemoryImage {
        self.dstq.image()
    }

    fn config(&self) -> &BuildConfig {
        &self.config
    }

    fn stats(&self) -> &BuildStats {
        &self.stats
    }

    #[inline]
    fn closest_hit<O: Observer>(&self, _: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        own_frame(|| self.dstq.closest_hit(ray, obs))
    }

    #[inline]
    fn any_hit<O: Observer>(&self, _: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        own_frame(|| self.dstq.any_hit(ray, obs))
    }

    fn query(&self, _: AccelKind) -> Option<NoQuery> {
        None
    }

    /// Against the DST in `built`, or else the DST converted from `bvh2` with the hardware
    /// preset: the same decisions, planes only looser.
    fn validate(&self, bvh2: &Bvh2, built: &[AnyTree]) -> ValidationReport {
        if let Some(dst) = built.iter().find_map(AnyTree::get::<DstTree>) {
            return self.dstq.validate(dst.dst());
        }
        let tris = self.image().triangle_data.clone();
        match Dst::from_bvh2(bvh2, tris, &DstConfig::hardware()) {
            Ok(dst) => self.dstq.validate(&dst),
            Err(e) => {
                let mut rep = self.dstq.validate_structure();
                rep.error(format!("the exact DST of the reference BVH2 fails: {e}"));
                rep
            }
        }
    }

    fn scene_box(&self) -> Aabb {
        self.dstq.scene_box()
    }

    /// The quantized dual-split unit decodes one geometry ([`unit_supports`]), and its
    /// records' names (cluster word address << 9 | bit position) must fit 32 bits (a node
    /// region up to 32 MiB).
    fn fits_unit(&self) -> Result<(), UnitMismatch> {
        let cfg = self.dstq.config();
        if !unit_supports(cfg) {
            return Err(UnitMismatch {
                structure: "dst-q",
                what: format!(
                    "dst-q with {}-bit planes in {}-byte clusters: the quantized dual-split \
                     unit decodes {UNIT_BITS}-bit planes in {UNIT_CLUSTER_BYTES}-byte clusters only",
                    cfg.bits, cfg.cluster_bytes
                ),
            });
        }
        let bytes = self.image().node_bytes();
        if bytes > UNIT_MAX_NODE_BYTES {
            return Err(UnitMismatch {
                structure: "dst-q",
                what: format!(
                    "the DST-Q node region (records named by a 23-bit cluster word address and \
                     a 9-bit position) takes {bytes} bytes; the kernels' memory map holds at \
                     most {UNIT_MAX_NODE_BYTES}"
                ),
            });
        }
        Ok(())
    }

    fn structure_stats(&self, bvh2_total: u64) -> StructureStats {
        let q = &self.dstq;
        // One walk counts the records.
        let s = q.stats();
        StructureStats::new(
            "dst-q",
            s.internal_nodes(),
            s.leaf_count(),
            q.bytes_total() - q.image().index_bytes(),
            q.image().index_bytes(),
            bvh2_total,
        )
        .with_convert_ms(self.stats.build_ms)
    }

    fn saved_fields(&self) -> DstQFields {
        DstQFields {
            config: *self.dstq.config(),
            scene_box: self.dstq.scene_box(),
        }
    }

    fn from_saved(_: TreeKind, image: MemoryImage, build: BuildConfig, f: DstQFields) -> Self {
        let dstq = DstQ::from_parts(image, f.scene_box, f.config);
        DstQTree {
            stats: Self::build_stats(&dstq, 0.0),
            dstq,
            config: build,
        }
    }

    fn check_saved(&self, _: &DstQFields) -> Result<(), Violation> {
        self.dstq
            .check_structure()
            .map_err(|(word, what)| violation(word, what))
    }
}

impl Structures {
    /// The quantized DST, encoded from [`Structures::dst`].
    pub fn dstq(&self) -> &DstQ {
        &self.structure::<DstQTree>(TreeKind::DstQ).dstq
    }
}
