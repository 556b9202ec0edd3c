//! Building exactly one structure: each structure's tree type (in its folder, listed by the
//! registry) carries its [`BuildStats`]; [`crate::Bvh2Tree`] is the SAH BVH2
//! every other structure is derived from, and [`AnyTree`] holds whichever one a saved file
//! contains ([`AnyTree::derive`] makes any of them).
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

use crate::image::MemoryImage;
use crate::registry::{AnyTree, Presets, TreeKind};
use crate::{AccelError, Bvh2Tree};
use serde::Serialize;

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
    /// The statistics of a tree of `kind` with `image`, the node counts given and its
    /// build time.
    pub(crate) fn of_image(
        kind: TreeKind,
        image: &MemoryImage,
        internal_nodes: u64,
        leaves: u64,
        build_ms: f64,
    ) -> Self {
        Self {
            kind: Some(kind),
            build_ms,
            internal_nodes,
            leaves,
            node_bytes: image.node_bytes(),
            index_bytes: image.index_bytes(),
            triangles: image.triangle_slice().len() as u64,
        }
    }

    /// Node plus index bytes (the size the paper's Table 3 compares).
    pub fn bytes_total(&self) -> u64 {
        self.node_bytes + self.index_bytes
    }
}

impl AnyTree {
    /// The structure of `kind` derived from `bvh2` with the default settings `dualsplit
    /// build` uses ([`Presets::default`]), or `None` for the reference structure
    /// ([`TreeKind::REFERENCE`]): the BVH2 is `bvh2` itself ([`Bvh2Tree::into_tree`]).
    pub fn derive(bvh2: &Bvh2Tree, kind: TreeKind) -> Option<Result<AnyTree, AccelError>> {
        if kind == TreeKind::REFERENCE {
            return None;
        }
        Some(AnyTree::derive_with(bvh2, kind, &Presets::default(), &[]))
    }

    /// The triangles as one shared allocation.
    pub fn shared_triangles(&self) -> &crate::SharedTriangles {
        &self.image().triangle_data
    }
}

/// `RayQuery` for a tree type through the structure inside it (`|s| &s.inner`).
macro_rules! query_via {
    ($ty:ty, |$s:ident| $inner:expr) => {
        impl $crate::query::RayQuery for $ty {
            #[inline]
            fn intersect_observed<O: $crate::observer::Observer>(
                &self,
                ray: &dualsplit_geometry::Ray,
                obs: &mut O,
            ) -> Option<dualsplit_geometry::Hit> {
                let $s = self;
                $crate::query::RayQuery::intersect_observed($inner, ray, obs)
            }
            #[inline]
            fn occluded_observed<O: $crate::observer::Observer>(
                &self,
                ray: &dualsplit_geometry::Ray,
                obs: &mut O,
            ) -> bool {
                let $s = self;
                $crate::query::RayQuery::occluded_observed($inner, ray, obs)
            }
            fn triangles(&self) -> &[dualsplit_geometry::Triangle] {
                let $s = self;
                $crate::query::RayQuery::triangles($inner)
            }
            fn intersect_batch(
                &self,
                rays: &[dualsplit_geometry::Ray],
            ) -> Vec<Option<dualsplit_geometry::Hit>> {
                let $s = self;
                $crate::query::RayQuery::intersect_batch($inner, rays)
            }
            fn occluded_batch(&self, rays: &[dualsplit_geometry::Ray]) -> Vec<bool> {
                let $s = self;
                $crate::query::RayQuery::occluded_batch($inner, rays)
            }
        }
    };
}

pub(crate) use query_via;
