//! What the registry needs of the BVH family's trees ([`Structure`] for [`BvhTree`]): its
//! traversals, checks, statistics and saved form, and the typed accessors of
//! [`Structures`].

use super::tree::{Bvh2Tree, BvhTree};
use super::{BvhImage, BvhQuery, Node4, Node8};
use crate::bvh2::Node2;
use crate::image::MemoryImage;
use crate::observer::Observer;
use crate::saved::{FieldReader, FieldWriter, SavedError, SavedFields, Violation};
use crate::stats::{BuildStats, StructureStats};
use crate::structure::{PlainQuery, Structure};
use crate::validate::ValidationReport;
use crate::{AccelError, AccelKind, AnyTree, BuildConfig, Bvh2, Presets, Structures, TreeKind};
use dualsplit_geometry::{Aabb, Hit, Ray};
use std::time::Duration;

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
            _ => Ok(bvh2.tree().clone()),
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
