//! The toy structure of `docs/extending.md`: every triangle in one leaf, tested one after
//! another. It exists to show what adding a structure takes (this folder and one registry
//! line, feature `toy`) and is checked by `tests/toy.rs` like any structure: the same
//! answers as the BVH2 on every ray, a saved form that loads back, statistics, a place in
//! [`Structures`](crate::Structures) and [`TreeSet`](crate::TreeSet).
//!
//! Image: no node words; the index region is one run of every triangle id in id order, the
//! last entry carrying [`RUN_END`] (an empty scene has none).

use crate::image::{MemoryImage, RUN_END, SharedTriangles};
use crate::observer::Observer;
use crate::saved::{FieldReader, FieldWriter, SavedError, SavedFields, Violation};
use crate::stats::{BuildStats, StructureStats};
use crate::structure::{NoQuery, Structure};
use crate::validate::ValidationReport;
use crate::wide::traverse::test_run;
use crate::{AccelError, AccelKind, AnyTree, BuildConfig, Bvh2, Bvh2Tree, Presets, TreeKind};
use dualsplit_geometry::{Hit, Ray};

/// Every triangle of a scene in one leaf.
#[derive(Clone, Debug)]
pub struct ToyTree {
    image: MemoryImage,
    config: BuildConfig,
    stats: BuildStats,
}

impl ToyTree {
    /// The toy over `triangles`.
    pub fn new(triangles: SharedTriangles, config: BuildConfig) -> Self {
        let n = triangles.len();
        let mut image = MemoryImage::with_triangles(0, n, triangles);
        for i in 0..n {
            image.words[i] = i as u32 | if i + 1 == n { RUN_END } else { 0 };
        }
        Self::of_image(image, config)
    }

    fn of_image(image: MemoryImage, config: BuildConfig) -> Self {
        let leaves = u64::from(!image.indices.is_empty());
        let stats = BuildStats::of_image(TreeKind::Toy, &image, 0, leaves, 0.0);
        Self {
            image,
            config,
            stats,
        }
    }

    /// Closest hit (or, with `ANY`, the first hit) of `ray`: the run's triangles.
    fn trace<O: Observer, const ANY: bool>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        if !ray.is_traceable() || self.image.indices.is_empty() {
            return None;
        }
        let r = ray.precompute();
        let (mut best, mut best_t) = (None, ray.t_max);
        let run = self.image.indices.start;
        // The outcome says what changed; `best` holds the answer either way.
        let _ = test_run::<O, ANY>(&self.image, run, &r, ray, obs, &mut best, &mut best_t);
        best
    }

    /// Closest hit of `ray`.
    pub fn closest_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        self.trace::<O, false>(ray, obs)
    }

    /// True when `ray` hits any triangle within `[t_min, t_max]`.
    pub fn any_hit<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        self.trace::<O, true>(ray, obs).is_some()
    }
}

crate::query::query_by_traversal!(ToyTree, |s| s.image.triangle_slice());

/// The toy's saved header fields: none.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ToyFields;

impl SavedFields for ToyFields {
    fn write(&self, _: &mut FieldWriter) {}

    fn read(_: TreeKind, _: &mut FieldReader) -> Result<Self, SavedError> {
        Ok(ToyFields)
    }
}

impl Structure for ToyTree {
    type Fields = ToyFields;
    type Query<'a> = NoQuery;

    fn derive(
        bvh2: &Bvh2Tree,
        _: TreeKind,
        _: &Presets,
        _: &[AnyTree],
    ) -> Result<Self, AccelError> {
        Ok(Self::new(bvh2.shared_triangles().clone(), *bvh2.config()))
    }

    fn kind(&self) -> TreeKind {
        TreeKind::Toy
    }

    fn image(&self) -> &MemoryImage {
        &self.image
    }

    fn config(&self) -> &BuildConfig {
        &self.config
    }

    fn stats(&self) -> &BuildStats {
        &self.stats
    }

    fn closest_hit<O: Observer>(&self, _: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        ToyTree::closest_hit(self, ray, obs)
    }

    fn any_hit<O: Observer>(&self, _: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        ToyTree::any_hit(self, ray, obs)
    }

    fn query(&self, _: AccelKind) -> Option<NoQuery> {
        None
    }

    /// Every triangle referenced once, in id order.
    fn validate(&self, _: &Bvh2, _: &[AnyTree]) -> ValidationReport {
        let mut rep = ValidationReport {
            structure: "toy",
            leaves: usize::from(!self.image.indices.is_empty()),
            triangles: self.image.triangle_slice().len(),
            ..Default::default()
        };
        if let Err(v) = self.check_saved(&ToyFields) {
            rep.error(v.what);
        } else {
            rep.triangles_referenced = rep.triangles;
        }
        rep
    }

    fn structure_stats(&self, bvh2_total: u64) -> StructureStats {
        StructureStats::new(
            "toy",
            0,
            self.stats.leaves,
            0,
            self.image.index_bytes(),
            bvh2_total,
        )
    }

    fn saved_fields(&self) -> ToyFields {
        ToyFields
    }

    fn from_saved(_: TreeKind, image: MemoryImage, build: BuildConfig, _: ToyFields) -> Self {
        Self::of_image(image, build)
    }

    /// No node words, and the index region is exactly the run of every id in order.
    fn check_saved(&self, _: &ToyFields) -> Result<(), Violation> {
        let img = &self.image;
        let n = img.triangle_slice().len();
        if !img.nodes.is_empty() || img.indices.len() != n {
            return Err(Violation {
                word: 0,
                what: format!(
                    "{} node words and {} index words for {n} triangles",
                    img.nodes.len(),
                    img.indices.len()
                ),
            });
        }
        for (i, w) in img.words[img.indices.clone()].iter().enumerate() {
            let want = i as u32 | if i + 1 == n { RUN_END } else { 0 };
            if *w != want {
                return Err(Violation {
                    word: img.indices.start + i,
                    what: format!("index word {w:#010x}, expected {want:#010x}"),
                });
            }
        }
        Ok(())
    }
}
