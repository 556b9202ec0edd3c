//! [`TreeSet`]: only the structures a run asks for, each derived from one BVH2 of the scene,
//! as one [`TraversalSet`]. A run that simulates or renders a few traversals builds their
//! trees and nothing else ([`Structures`](crate::Structures) builds all of them).
//!
//! Each tree is the one [`AnyTree::derive`] makes (the same as `dualsplit build` saves), a
//! structure derived from another reusing it when the set has it, so
//! a traversal answers every ray exactly as it does in [`Structures`](crate::Structures),
//! and its memory image is the same, word for word.
//!
//! ```
//! use dualsplit_accel::math::{Ray, Triangle, Vec3};
//! use dualsplit_accel::{AccelKind, BuildConfig, NoObserver, TraversalSet, TreeSet};
//! let tris = vec![Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0))];
//! let set = TreeSet::build(&tris[..], &BuildConfig::default(), &[AccelKind::Dst, AccelKind::Bvh2])?;
//! assert_eq!(set.kinds(), [AccelKind::Bvh2, AccelKind::DstSw, AccelKind::Dst]);
//! let ray = Ray::new(Vec3::ZERO, Vec3::Z);
//! let t = TraversalSet::closest_hit(&set, AccelKind::Dst, &ray, &mut NoObserver).map(|h| h.t);
//! assert_eq!(t, Some(2.0));
//! # Ok::<(), dualsplit_accel::AccelError>(())
//! ```

use crate::image::{MemoryImage, SharedTriangles};
use crate::observer::Observer;
use crate::set::TraversalSet;
use crate::structure::UnitMismatch;
use crate::{AccelError, AccelKind, AnyTree, BuildConfig, Bvh2Tree, Plain, Presets, TreeKind};
use dualsplit_geometry::{Aabb, Hit, Ray};

/// The trees of some traversals, derived from one BVH2 (at least one tree).
pub struct TreeSet {
    /// In [`TreeKind::ALL`] order, one per kind.
    trees: Vec<AnyTree>,
    /// Every traversal of the trees, in [`AccelKind::ALL`] order.
    kinds: Vec<AccelKind>,
}

impl TreeSet {
    /// Builds the BVH2 of `triangles` with `cfg`, then the tree of each of `kinds` (the
    /// BVH2 itself for [`AccelKind::Bvh2`]); `kinds` must not be empty.
    pub fn build(
        triangles: impl Into<SharedTriangles>,
        cfg: &BuildConfig,
        kinds: &[AccelKind],
    ) -> Result<Self, AccelError> {
        assert!(!kinds.is_empty(), "a tree set needs at least one traversal");
        let bvh2 = Bvh2Tree::build(triangles, cfg)?;
        let wanted: Vec<TreeKind> = TreeKind::ALL
            .into_iter()
            .filter(|t| kinds.iter().any(|&k| TreeKind::of_accel(k) == *t))
            .collect();
        let mut trees = Vec::with_capacity(wanted.len());
        for &t in &wanted {
            let tree = AnyTree::derive_with(&bvh2, t, &Presets::default(), &trees)?;
            trees.push(tree);
        }
        let kinds = AccelKind::ALL
            .into_iter()
            .filter(|&k| trees.iter().any(|t| t.kind() == TreeKind::of_accel(k)))
            .collect();
        Ok(Self { trees, kinds })
    }

    /// The trees, in [`TreeKind::ALL`] order.
    pub fn trees(&self) -> &[AnyTree] {
        &self.trees
    }

    /// The tree traversal `kind` reads, if the set has it.
    #[inline]
    fn tree(&self, kind: AccelKind) -> Option<&AnyTree> {
        let t = TreeKind::of_accel(kind);
        self.trees.iter().find(|tree| tree.kind() == t)
    }
}

impl TraversalSet for TreeSet {
    fn kinds(&self) -> &[AccelKind] {
        &self.kinds
    }

    #[inline]
    fn closest_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        self.tree(kind)
            .and_then(|t| TraversalSet::closest_hit(t, kind, ray, obs))
    }

    #[inline]
    fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        self.tree(kind)
            .is_some_and(|t| TraversalSet::any_hit(t, kind, ray, obs))
    }

    fn plain(&self, kind: AccelKind) -> Option<Plain<'_>> {
        self.tree(kind).and_then(|t| TraversalSet::plain(t, kind))
    }

    /// The image of `kind`'s tree (the first tree's for a kind the set lacks).
    fn image(&self, kind: AccelKind) -> &MemoryImage {
        self.tree(kind).unwrap_or(&self.trees[0]).image()
    }

    fn scene_box(&self) -> Aabb {
        TraversalSet::scene_box(&self.trees[0])
    }

    fn fits_unit(&self, kind: AccelKind) -> Result<(), UnitMismatch> {
        self.tree(kind)
            .map_or(Ok(()), |t| TraversalSet::fits_unit(t, kind))
    }
}
