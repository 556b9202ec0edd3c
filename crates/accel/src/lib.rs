//! Acceleration structures for dualsplit, all derived from one SAH binary BVH:
//!
//! ```text
//!   Bvh2 (build/) ──collapse──▶ BVH4 (Dammertz), BVH8 (Ylitie)     (wide/)
//!        └──────────convert──▶ DST, identical bounds               (dst/)
//!   each encoded into a byte-exact MemoryImage (image.rs) that its traversal reads
//! ```
//!
//! Every traversal is generic over an [`Observer`] (contract 2 of `docs/architecture.md`).
//! [`Structures`] builds all of them from one scene and dispatches by [`AccelKind`].

pub mod build;
pub mod dst;
pub mod image;
pub mod observer;

pub use build::{BuildConfig, Bvh2, Bvh2Node};
pub use image::MemoryImage;
pub use observer::{CountingObserver, DstNodeKind, NoObserver, NodeStep, Observer};

use dualsplit_geometry::{Aabb, Hit, Ray, Triangle, cull_limit};
use serde::{Deserialize, Serialize};

/// The traversal variants a workload can run on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AccelKind {
    /// Binary BVH, 52-byte nodes.
    Bvh2,
    /// 4-wide BVH (Dammertz collapse), 100-byte nodes.
    Bvh4,
    /// 8-wide BVH (Ylitie collapse), 200-byte nodes.
    Bvh8,
    /// Dual-split tree, software decoder (the paper's DST*).
    DstSw,
    /// Dual-split tree traversed by the hardware pipeline's step function.
    Dst,
}

impl AccelKind {
    /// All kinds, in report order.
    pub const ALL: [AccelKind; 5] = [
        AccelKind::Bvh2,
        AccelKind::Bvh4,
        AccelKind::Bvh8,
        AccelKind::DstSw,
        AccelKind::Dst,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            AccelKind::Bvh2 => "bvh2",
            AccelKind::Bvh4 => "bvh4",
            AccelKind::Bvh8 => "bvh8",
            AccelKind::DstSw => "dst-sw",
            AccelKind::Dst => "dst",
        }
    }

    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == s)
    }
}

/// Every structure built from one scene's BVH2.
///
/// PLACEHOLDER (skeleton): until the encoded structures land, every kind traverses the
/// logical BVH2. The API (`build`, `closest_hit`, `any_hit`) is the contract.
pub struct Structures {
    /// The scene's triangles (ids are indices).
    pub triangles: Vec<Triangle>,
    /// The source BVH2.
    pub bvh2: Bvh2,
}

impl Structures {
    /// Builds every structure for `triangles`.
    pub fn build(triangles: &[Triangle], cfg: &BuildConfig) -> Self {
        let boxes: Vec<Aabb> = triangles.iter().map(|t| t.bounds()).collect();
        let bvh2 = Bvh2::build(&boxes, cfg);
        Self {
            triangles: triangles.to_vec(),
            bvh2,
        }
    }

    /// Closest hit of `ray` on structure `kind`.
    pub fn closest_hit<O: Observer>(
        &self,
        _kind: AccelKind,
        ray: &Ray,
        obs: &mut O,
    ) -> Option<Hit> {
        let r = ray.precompute();
        let mut best: Option<Hit> = None;
        let mut best_t = ray.t_max;
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            let node = &self.bvh2.nodes[n as usize];
            let (e, x) = r.slab(
                node.bounds.min,
                node.bounds.max,
                ray.t_min,
                cull_limit(best_t),
            );
            if e > x {
                continue;
            }
            if node.is_leaf() {
                for &p in
                    &self.bvh2.prim_ids[node.first as usize..(node.first + node.count) as usize]
                {
                    let h = self.triangles[p as usize].intersect(&r, ray.t_min, best_t);
                    obs.triangle_test(p, h.is_some());
                    if let Some(h) = h {
                        if best.is_none_or(|b| !b.closer_than(h.t, p)) {
                            best = Some(Hit {
                                t: h.t,
                                prim: p,
                                u: h.u,
                                v: h.v,
                            });
                            best_t = h.t;
                        }
                    }
                }
            } else {
                stack.extend(node.children());
            }
        }
        best
    }

    /// True when `ray` hits any triangle within `[t_min, t_max]`.
    pub fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        self.closest_hit(kind, ray, obs).is_some()
    }
}
