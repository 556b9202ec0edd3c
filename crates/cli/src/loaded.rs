//! What `check`, `bench`, `render`, `trace` and `simulate` run on: every structure built
//! from the scene, only the structures of the traversals asked for (`simulate`, `render`:
//! [`Loaded::get_for`]), or with `--tree FILE` the one structure a saved tree file holds
//! (written by `dualsplit build`). This is the one place `--tree` becomes structures.
//!
//! A saved tree answers the traversals of its structure only: `dst-sw` and `dst` for a DST,
//! its own kind for a BVH2, BVH4 or BVH8 ([`dualsplit_accel::TreeKind::accel_kinds`]).
//! Asking `--accel` for another is an error that names the file and what it holds. The
//! tree must come from the scene given: its triangles are checked against the scene's when
//! it is loaded.
use crate::progress::Ctx;
use anyhow::Context;
use dualsplit_accel::{
    AccelKind, AnyTree, BuildConfig, MemoryImage, Observer, Plain, Structures, TraversalSet,
    TreeSet,
};
use dualsplit_geometry::{Aabb, Hit, Ray};
use dualsplit_scene::Scene;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The structures a command runs on, with how long they took to get.
// One value per command: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
pub enum Loaded {
    /// Every structure, built from the scene.
    Built {
        /// BVH2, BVH4, BVH8 and the DST.
        structures: Structures,
        /// Wall time of the build, in milliseconds.
        build_ms: f64,
    },
    /// The structures of some traversals only, built from the scene's BVH2.
    Some {
        /// Their trees.
        set: TreeSet,
        /// Wall time of the build, in milliseconds.
        build_ms: f64,
    },
    /// One structure, read from a saved tree file.
    Saved {
        /// The tree.
        tree: AnyTree,
        /// The file it came from.
        file: PathBuf,
        /// Wall time of reading and checking the file, in milliseconds.
        load_ms: f64,
    },
}

impl Loaded {
    /// Builds every structure of `scene` (default build settings), or with `tree` loads
    /// that file, checking that it was built from `scene`'s triangles; behind a spinner.
    pub fn get(scene: &Scene, tree: Option<&Path>, ctx: &Ctx) -> anyhow::Result<Loaded> {
        let t = Instant::now();
        match tree {
            None => {
                let sp = ctx.spinner("building BVH2, BVH4, BVH8, DST");
                let structures =
                    Structures::try_build(&scene.triangles, &BuildConfig::default())
                        .with_context(|| format!("building the structures of {}", scene.spec))?;
                sp.finish_and_clear();
                Ok(Loaded::Built {
                    structures,
                    build_ms: t.elapsed().as_secs_f64() * 1e3,
                })
            }
            Some(file) => {
                let sp = ctx.spinner(format!("loading {}", file.display()));
                let tree = AnyTree::load(file, Some(&scene.triangles)).with_context(|| {
                    format!("--tree {} with scene {}", file.display(), scene.spec)
                })?;
                sp.finish_and_clear();
                Ok(Loaded::Saved {
                    tree,
                    file: file.to_owned(),
                    load_ms: t.elapsed().as_secs_f64() * 1e3,
                })
            }
        }
    }

    /// Like [`Loaded::get`], but without `tree` builds only the structures that the
    /// traversals `kinds` read (every structure when `kinds` is empty).
    pub fn get_for(
        scene: &Scene,
        tree: Option<&Path>,
        kinds: &[AccelKind],
        ctx: &Ctx,
    ) -> anyhow::Result<Loaded> {
        if tree.is_some() || kinds.is_empty() {
            return Self::get(scene, tree, ctx);
        }
        let t = Instant::now();
        let names: Vec<&str> = kinds.iter().map(|k| k.name()).collect();
        let sp = ctx.spinner(format!("building the trees of {}", names.join(", ")));
        let set = TreeSet::build(&scene.triangles[..], &BuildConfig::default(), kinds)
            .with_context(|| format!("building the structures of {}", scene.spec))?;
        sp.finish_and_clear();
        Ok(Loaded::Some {
            set,
            build_ms: t.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// What was built or loaded and how long it took, as one JSON object:
    /// `{"scene", "build_ms"}` or `{"scene", "tree", "kind", "load_ms"}`.
    pub fn timing_json(&self, scene: &Scene) -> serde_json::Value {
        match self {
            Loaded::Built { build_ms, .. } | Loaded::Some { build_ms, .. } => {
                serde_json::json!({"scene": scene.name, "build_ms": build_ms})
            }
            Loaded::Saved {
                tree,
                file,
                load_ms,
            } => serde_json::json!({
                "scene": scene.name, "tree": file.display().to_string(),
                "kind": tree.kind().to_string(), "load_ms": load_ms,
            }),
        }
    }

    /// One line saying what was built or loaded and how long it took.
    pub fn summary(&self) -> String {
        match self {
            Loaded::Built { build_ms, .. } => {
                format!("structures built in {:.2} s", build_ms / 1e3)
            }
            Loaded::Some { set, build_ms } => {
                let names: Vec<&str> = set.trees().iter().map(|t| t.kind().name()).collect();
                format!("{} built in {:.2} s", names.join(", "), build_ms / 1e3)
            }
            Loaded::Saved {
                tree,
                file,
                load_ms,
            } => format!(
                "tree {} ({}) loaded in {load_ms:.1} ms (load_ms), no build",
                file.display(),
                tree.kind()
            ),
        }
    }

    /// Checks that `kind` (given as `--accel VALUE`) has a traversal here.
    pub fn require(&self, value: &str, kind: AccelKind) -> anyhow::Result<()> {
        match self {
            Loaded::Saved { tree, file, .. } if !tree.supports(kind) => {
                anyhow::bail!(
                    "--accel {value}: tree file {} holds a {}, whose traversals are {}; \
                     save a {} tree with `dualsplit build SCENE --accel {}`, or leave out --tree",
                    file.display(),
                    tree.kind(),
                    tree.kind_names(),
                    dualsplit_accel::TreeKind::of_accel(kind),
                    dualsplit_accel::TreeKind::of_accel(kind)
                )
            }
            _ => Ok(()),
        }
    }

    /// The traversals to run: `asked` (each checked with [`Loaded::require`]), or every
    /// one there is when `asked` is empty.
    pub fn kinds_or_all(&self, asked: &[AccelKind]) -> anyhow::Result<Vec<AccelKind>> {
        if asked.is_empty() {
            return Ok(self.kinds().to_vec());
        }
        for &k in asked {
            self.require(k.name(), k)?;
        }
        Ok(asked.to_vec())
    }
}

/// Each call goes to the built structures or to the tree.
impl TraversalSet for Loaded {
    fn kinds(&self) -> &[AccelKind] {
        match self {
            Loaded::Built { structures, .. } => TraversalSet::kinds(structures),
            Loaded::Some { set, .. } => set.kinds(),
            Loaded::Saved { tree, .. } => tree.kinds(),
        }
    }

    #[inline]
    fn closest_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit> {
        match self {
            Loaded::Built { structures, .. } => structures.closest_hit(kind, ray, obs),
            Loaded::Some { set, .. } => TraversalSet::closest_hit(set, kind, ray, obs),
            Loaded::Saved { tree, .. } => TraversalSet::closest_hit(tree, kind, ray, obs),
        }
    }

    #[inline]
    fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> bool {
        match self {
            Loaded::Built { structures, .. } => structures.any_hit(kind, ray, obs),
            Loaded::Some { set, .. } => TraversalSet::any_hit(set, kind, ray, obs),
            Loaded::Saved { tree, .. } => TraversalSet::any_hit(tree, kind, ray, obs),
        }
    }

    fn plain(&self, kind: AccelKind) -> Option<Plain<'_>> {
        match self {
            Loaded::Built { structures, .. } => TraversalSet::plain(structures, kind),
            Loaded::Some { set, .. } => TraversalSet::plain(set, kind),
            Loaded::Saved { tree, .. } => TraversalSet::plain(tree, kind),
        }
    }

    fn image(&self, kind: AccelKind) -> &MemoryImage {
        match self {
            Loaded::Built { structures, .. } => structures.image(kind),
            Loaded::Some { set, .. } => TraversalSet::image(set, kind),
            Loaded::Saved { tree, .. } => TraversalSet::image(tree, kind),
        }
    }

    fn scene_box(&self) -> Aabb {
        match self {
            Loaded::Built { structures, .. } => TraversalSet::scene_box(structures),
            Loaded::Some { set, .. } => TraversalSet::scene_box(set),
            Loaded::Saved { tree, .. } => TraversalSet::scene_box(tree),
        }
    }

    fn fits_unit(&self, kind: AccelKind) -> Result<(), dualsplit_accel::UnitMismatch> {
        match self {
            Loaded::Built { structures, .. } => TraversalSet::fits_unit(structures, kind),
            Loaded::Some { set, .. } => TraversalSet::fits_unit(set, kind),
            Loaded::Saved { tree, .. } => TraversalSet::fits_unit(tree, kind),
        }
    }
}
