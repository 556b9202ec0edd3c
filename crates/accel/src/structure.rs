//! The one structure trait, [`Structure`], and the macro that turns the registry
//! (`registry.rs`, one line per structure) into everything that lists structures:
//! [`crate::AccelKind`], [`crate::TreeKind`],
//! [`AnyTree`](crate::AnyTree), the saved-tree kind codes and header fields, and the
//! [`Plain`](crate::Plain) query contexts.
//!
//! A structure is a tree type in its own folder (`crates/accel/src/<name>/`) that
//! implements [`Structure`]: how it is derived from the scene's BVH2, how each of its
//! traversals answers a ray, how it is checked, its statistics and its saved form. Generic
//! code (the sets, the saved-tree format, the statistics, the CLI, the simulator) reaches
//! it only through this trait and the registry (`docs/extending.md`).

use crate::image::MemoryImage;
use crate::observer::Observer;
use crate::query::RayQuery;
pub use crate::saved::SavedFields;
use crate::saved::Violation;
use crate::stats::{BuildStats, StructureStats};
use crate::validate::ValidationReport;
use crate::wide::Bvh2Tree;
use crate::{AccelError, AccelKind, BuildConfig, Bvh2, Presets, TreeKind};
use dualsplit_geometry::{Aabb, Hit, Ray};

/// One acceleration structure: a tree type registered once in `registry.rs`.
///
/// A tree type may stand for several [`TreeKind`]s (the BVH2, BVH4 and BVH8 are one
/// [`BvhTree`](crate::BvhTree)) and a tree kind for several traversals ([`AccelKind`]s: the
/// DST's software decoder and its hardware pipeline); the registry says which.
pub trait Structure: RayQuery + Sized + Clone + std::fmt::Debug + Send + Sync {
    /// The header fields a saved file records for this structure beside the regions'
    /// sizes and the build settings (`docs/tree-format.md`).
    type Fields: SavedFields;

    /// A query context for tracing rays one by one without observing them
    /// ([`crate::Tracer`]); [`NoQuery`] when the structure has none.
    type Query<'a>: PlainQuery
    where
        Self: 'a;

    /// The structure of `kind` derived from `bvh2` with `presets`; `built` holds the
    /// structures of the kinds before `kind` in [`TreeKind::ALL`] that are already built,
    /// which a structure derived from another one may reuse.
    fn derive(
        bvh2: &Bvh2Tree,
        kind: TreeKind,
        presets: &Presets,
        built: &[crate::AnyTree],
    ) -> Result<Self, AccelError>;

    /// Which structure this tree is.
    fn kind(&self) -> TreeKind;

    /// The byte-exact memory image its traversals read.
    fn image(&self) -> &MemoryImage;

    /// The BVH2 build settings it came from.
    fn config(&self) -> &BuildConfig;

    /// Size and build time.
    fn stats(&self) -> &BuildStats;

    /// Closest hit of `ray` through traversal `kind`, one of
    /// [`TreeKind::accel_kinds`] of [`Structure::kind`].
    fn closest_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<Hit>;

    /// True when `ray` hits any triangle within `[t_min, t_max]` through traversal `kind`.
    fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> bool;

    /// The query context of traversal `kind`, if its plain queries have one.
    fn query(&self, kind: AccelKind) -> Option<Self::Query<'_>>;

    /// Checks the tree against `bvh2`, the BVH2 it was derived from (or one built afresh
    /// with the same settings); `built` holds the other structures derived with it (as in
    /// [`Structure::derive`]), which a structure derived from another one checks against.
    fn validate(&self, bvh2: &Bvh2, built: &[crate::AnyTree]) -> ValidationReport;

    /// The box around every triangle: where a traversal that starts with a slab test
    /// starts (the union of the triangles' boxes for the others).
    fn scene_box(&self) -> Aabb {
        self.image()
            .triangle_slice()
            .iter()
            .fold(Aabb::EMPTY, |acc, t| acc.union(t.bounds()))
    }

    /// Whether this tree fits the fixed-geometry hardware unit its simulated traversals
    /// run on (a unit decodes one encoding and addresses a bounded node region); `Ok` for
    /// a structure whose units take any tree.
    fn fits_unit(&self) -> Result<(), UnitMismatch> {
        Ok(())
    }

    /// Size and build statistics for `dualsplit stats`, percentages relative to
    /// `bvh2_total` bytes.
    fn structure_stats(&self, bvh2_total: u64) -> StructureStats;

    /// The fields its saved header records.
    fn saved_fields(&self) -> Self::Fields;

    /// The tree of kind `kind` a saved file describes: its image, build settings and
    /// header fields, unchecked (the loader then runs [`Structure::check_saved`]).
    fn from_saved(
        kind: TreeKind,
        image: MemoryImage,
        build: BuildConfig,
        fields: Self::Fields,
    ) -> Self;

    /// Checks everything a traversal of the tree's image relies on
    /// (`docs/tree-format.md`, "Checks on load") and the counts `fields` records.
    fn check_saved(&self, fields: &Self::Fields) -> Result<(), Violation>;
}

/// Tracing rays one by one without observing them, through a structure's query context
/// ([`Structure::Query`]).
pub trait PlainQuery {
    /// Closest hit of `ray`.
    fn closest_hit(&mut self, ray: &Ray) -> Option<Hit>;
    /// True when `ray` hits any triangle within `[t_min, t_max]`.
    fn any_hit(&mut self, ray: &Ray) -> bool;
}

/// The query context of a structure that has none: no value exists.
#[derive(Clone, Copy, Debug)]
pub enum NoQuery {}

impl PlainQuery for NoQuery {
    fn closest_hit(&mut self, _: &Ray) -> Option<Hit> {
        match *self {}
    }
    fn any_hit(&mut self, _: &Ray) -> bool {
        match *self {}
    }
}

/// A tree its hardware unit cannot run ([`Structure::fits_unit`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{what}")]
pub struct UnitMismatch {
    /// The structure's command-line name.
    pub structure: &'static str,
    /// What the unit cannot take, and what it can.
    pub what: String,
}

/// Calls `f` in a function of its own. Traversals with large loops take their queries
/// through it: inlined into a dispatcher, their loops gave the dispatcher a frame of some
/// 1.5 KB whose entry and exit every ray paid, the BVH queries' short path to the CPU-side
/// copy included.
#[inline(never)]
pub(crate) fn own_frame<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// Defines, from the registry's list of structures, the enums and dispatch that list them.
///
/// Each entry is a tree type (the [`AnyTree`](crate::AnyTree) variant and its
/// [`Structure`] type), then each [`TreeKind`] it stands for (variant, command-line name,
/// saved-file code), then each traversal of that kind ([`AccelKind`] variant and
/// command-line name). The order is the report order.
macro_rules! structures {
    // An entry without a condition: always compiled.
    (@norm [$($done:tt)*] $(#[$tm:meta])* $tv:ident($tty:ty) { $($body:tt)* } $($rest:tt)*) => {
        $crate::structure::structures!(@norm [$($done)* [all()] $(#[$tm])* $tv($tty) { $($body)* }] $($rest)*);
    };
    // An entry compiled under `cfg($cfg)` (`Toy(...) if feature = "toy" { ... }`).
    (@norm [$($done:tt)*] $(#[$tm:meta])* $tv:ident($tty:ty) if $cfg:meta { $($body:tt)* } $($rest:tt)*) => {
        $crate::structure::structures!(@norm [$($done)* [$cfg] $(#[$tm])* $tv($tty) { $($body)* }] $($rest)*);
    };
    (@norm [$($done:tt)*]) => {
        $crate::structure::structures!(@gen $($done)*);
    };
    (@first $ty:ident; $first:ident $($rest:ident)*) => {
        $ty::$first
    };
    (@gen $(
        [$cfg:meta]
        $(#[$tm:meta])*
        $tv:ident($tty:ty) {
            $(
                $(#[$km:meta])*
                $kv:ident = $kname:literal, code $code:literal, traversals [$(
                    $(#[$am:meta])*
                    $av:ident = $aname:literal
                ),+ $(,)?];
            )+
        }
    )+) => {
        /// The traversal variants a workload can run on (`registry.rs`).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[serde(rename_all = "kebab-case")]
        pub enum AccelKind {
            $($($( #[cfg($cfg)] $(#[$am])* $av, )+)+)+
        }

        impl AccelKind {
            /// All kinds, in report order.
            pub const ALL: [AccelKind; Self::COUNT] = {
                let mut all = [$crate::structure::structures!(@first AccelKind; $($($($av)+)+)+); Self::COUNT];
                let mut i = 0;
                $($($( #[cfg($cfg)] { all[i] = AccelKind::$av; i += 1; } )+)+)+
                assert!(i == Self::COUNT);
                all
            };

            /// How many kinds there are.
            const COUNT: usize = {
                let mut n = 0;
                $($($( #[cfg($cfg)] { n += 1; let _ = $aname; } )+)+)+
                n
            };

            /// The reference traversal: the first registered (the BVH2's), the one ray
            /// sets are recorded on and every other traversal is checked against.
            pub const REFERENCE: AccelKind = AccelKind::ALL[0];

            /// The command-line name.
            pub fn name(self) -> &'static str {
                match self {
                    $($($( #[cfg($cfg)] AccelKind::$av => $aname, )+)+)+
                }
            }

            /// Parses a command-line name.
            pub fn parse(s: &str) -> Option<Self> {
                Self::ALL.into_iter().find(|k| k.name() == s)
            }

            /// The command-line names, comma-separated, for help and messages.
            pub fn names() -> String {
                Self::ALL.map(|k| k.name()).join(", ")
            }

            /// The structure this traversal reads.
            pub fn tree_kind(self) -> TreeKind {
                match self {
                    $($($( #[cfg($cfg)] AccelKind::$av => TreeKind::$kv, )+)+)+
                }
            }
        }

        /// The structures a tree can be (`registry.rs`).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[serde(rename_all = "kebab-case")]
        pub enum TreeKind {
            $($( #[cfg($cfg)] $(#[$km])* $kv, )+)+
        }

        impl TreeKind {
            /// All kinds, in report order.
            pub const ALL: [TreeKind; Self::COUNT] = {
                let mut all = [$crate::structure::structures!(@first TreeKind; $($($kv)+)+); Self::COUNT];
                let mut i = 0;
                $($( #[cfg($cfg)] { all[i] = TreeKind::$kv; i += 1; } )+)+
                assert!(i == Self::COUNT);
                all
            };

            /// How many kinds there are.
            const COUNT: usize = {
                let mut n = 0;
                $($( #[cfg($cfg)] { n += 1; let _ = $kname; } )+)+
                n
            };

            /// The reference structure: the first registered, the BVH2 every other one
            /// is derived from.
            pub const REFERENCE: TreeKind = TreeKind::ALL[0];

            /// The command-line name.
            pub fn name(self) -> &'static str {
                match self {
                    $($( #[cfg($cfg)] TreeKind::$kv => $kname, )+)+
                }
            }

            /// Parses a command-line name.
            pub fn parse(s: &str) -> Option<Self> {
                Self::ALL.into_iter().find(|k| k.name() == s)
            }

            /// The command-line names, comma-separated, for help and messages.
            pub fn names() -> String {
                Self::ALL.map(|k| k.name()).join(", ")
            }

            /// The traversals that read this structure's image (for a DST both decoders,
            /// [`AccelKind::DST_SOFTWARE`] first).
            pub fn accel_kinds(self) -> &'static [AccelKind] {
                match self {
                    $($( #[cfg($cfg)] TreeKind::$kv => &[$(AccelKind::$av),+], )+)+
                }
            }

            /// The structure [`AccelKind`] `k` traverses.
            pub fn of_accel(k: AccelKind) -> Self {
                k.tree_kind()
            }

            /// The Rust type that holds a tree of this kind, as the registry writes it
            /// (`crate::dst::DstTree`): its module is the structure's folder.
            pub fn rust_type(self) -> &'static str {
                match self {
                    $($( #[cfg($cfg)] TreeKind::$kv => stringify!($tty), )+)+
                }
            }

            /// The code of this kind in a saved file's header (`docs/tree-format.md`).
            pub(crate) fn code(self) -> u32 {
                match self {
                    $($( #[cfg($cfg)] TreeKind::$kv => $code, )+)+
                }
            }

            /// The kind a saved file's header code names.
            pub(crate) fn from_code(code: u32) -> Option<Self> {
                match code {
                    $($( #[cfg($cfg)] $code => Some(TreeKind::$kv), )+)+
                    _ => None,
                }
            }
        }

        impl std::fmt::Display for TreeKind {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        /// One structure of any kind: what a saved tree file holds.
        #[derive(Clone, Debug)]
        pub enum AnyTree {
            $( #[cfg($cfg)] $(#[$tm])* $tv($tty), )+
        }

        $(
            #[cfg($cfg)]
            impl From<$tty> for AnyTree {
                fn from(t: $tty) -> Self {
                    AnyTree::$tv(t)
                }
            }
        )+

        impl AnyTree {
            /// The structure of `kind` derived from `bvh2` with `presets`, reusing what
            /// `built` holds (see [`Structure::derive`]).
            pub fn derive_with(
                bvh2: &Bvh2Tree,
                kind: TreeKind,
                presets: &Presets,
                built: &[AnyTree],
            ) -> Result<AnyTree, AccelError> {
                match kind {
                    $( #[cfg($cfg)] $(TreeKind::$kv)|+ => {
                        <$tty as Structure>::derive(bvh2, kind, presets, built).map(AnyTree::$tv)
                    } )+
                }
            }

            /// Which structure.
            pub fn kind(&self) -> TreeKind {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::kind(t), )+
                }
            }

            /// The byte-exact memory image.
            pub fn image(&self) -> &MemoryImage {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::image(t), )+
                }
            }

            /// The BVH2 build settings.
            pub fn config(&self) -> &BuildConfig {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::config(t), )+
                }
            }

            /// Size and build time.
            pub fn stats(&self) -> &BuildStats {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::stats(t), )+
                }
            }

            /// Checks the tree against `bvh2`, the BVH2 it was derived from (or one built
            /// afresh with the same settings, [`Presets::default`]): a BVH image on its
            /// own (boxes hold their children), a DST against `bvh2`'s boxes, a compressed
            /// BVH8 for quantized boxes that contain their children's exact boxes, a
            /// quantized DST against the DST converted from `bvh2` ([`Structure::validate`]).
            pub fn validate(&self, bvh2: &Bvh2) -> ValidationReport {
                self.validate_among(bvh2, &[])
            }

            /// [`AnyTree::validate`] with the other structures derived with this one.
            pub fn validate_among(&self, bvh2: &Bvh2, built: &[AnyTree]) -> ValidationReport {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::validate(t, bvh2, built), )+
                }
            }

            /// The box around every triangle ([`Structure::scene_box`]).
            pub fn scene_box(&self) -> Aabb {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::scene_box(t), )+
                }
            }

            /// Whether the tree fits its hardware unit ([`Structure::fits_unit`]).
            pub fn fits_unit(&self) -> Result<(), UnitMismatch> {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::fits_unit(t), )+
                }
            }

            /// Size and build statistics, percentages relative to `bvh2_total` bytes.
            pub fn structure_stats(&self, bvh2_total: u64) -> StructureStats {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::structure_stats(t, bvh2_total), )+
                }
            }

            /// Closest hit through traversal `kind`, or `None` when this tree is not the
            /// structure `kind` reads ([`TreeKind::accel_kinds`]).
            #[inline]
            pub fn closest_hit<O: Observer>(
                &self,
                kind: AccelKind,
                ray: &Ray,
                obs: &mut O,
            ) -> Option<Option<Hit>> {
                if kind.tree_kind() != self.kind() {
                    return None;
                }
                Some(match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::closest_hit(t, kind, ray, obs), )+
                })
            }

            /// Any hit through traversal `kind`, or `None` when this tree is not the
            /// structure `kind` reads.
            #[inline]
            pub fn any_hit<O: Observer>(&self, kind: AccelKind, ray: &Ray, obs: &mut O) -> Option<bool> {
                if kind.tree_kind() != self.kind() {
                    return None;
                }
                Some(match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::any_hit(t, kind, ray, obs), )+
                })
            }

            /// The tree inside, if it is a `T`.
            pub fn get<T: Structure + 'static>(&self) -> Option<&T> {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => (t as &dyn std::any::Any).downcast_ref::<T>(), )+
                }
            }

            /// The query context of traversal `kind` of this tree, if it has one.
            pub fn plain_query(&self, kind: AccelKind) -> Option<Plain<'_>> {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => Structure::query(t, kind).map(Plain::$tv), )+
                }
            }
        }

        /// The query context of one traversal of any structure ([`Structure::Query`],
        /// [`crate::TraversalSet::plain`]), which a [`crate::Tracer`] traces through.
        pub enum Plain<'a> {
            $( #[doc = concat!("A context of a `", stringify!($tty), "`.")]
#[cfg($cfg)] $tv(<$tty as Structure>::Query<'a>), )+
        }

        impl PlainQuery for Plain<'_> {
            #[inline]
            fn closest_hit(&mut self, ray: &Ray) -> Option<Hit> {
                match self {
                    $( #[cfg($cfg)] Plain::$tv(q) => q.closest_hit(ray), )+
                }
            }
            #[inline]
            fn any_hit(&mut self, ray: &Ray) -> bool {
                match self {
                    $( #[cfg($cfg)] Plain::$tv(q) => q.any_hit(ray), )+
                }
            }
        }

        /// Queries an [`AnyTree`] through its default traversal (the first of its
        /// [`TreeKind::accel_kinds`]: the software decoder for a DST).
        impl RayQuery for AnyTree {
            #[inline]
            fn intersect_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => t.intersect_observed(ray, obs), )+
                }
            }
            #[inline]
            fn occluded_observed<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => t.occluded_observed(ray, obs), )+
                }
            }
            fn triangles(&self) -> &[dualsplit_geometry::Triangle] {
                self.image().triangle_slice()
            }
            fn intersect_batch(&self, rays: &[Ray]) -> Vec<Option<Hit>> {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => t.intersect_batch(rays), )+
                }
            }
            fn occluded_batch(&self, rays: &[Ray]) -> Vec<bool> {
                match self {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => t.occluded_batch(rays), )+
                }
            }
        }

        /// The saved-header fields of any structure ([`Structure::Fields`]).
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub(crate) enum AnyFields {
            $( #[cfg($cfg)] $tv(<$tty as Structure>::Fields), )+
        }

        impl SavedFields for AnyFields {
            fn read(kind: TreeKind, input: &mut FieldReader) -> Result<Self, SavedError> {
                Ok(match kind {
                    $( #[cfg($cfg)] $(TreeKind::$kv)|+ => AnyFields::$tv(SavedFields::read(kind, input)?), )+
                })
            }

            fn write(&self, out: &mut FieldWriter) {
                match self {
                    $( #[cfg($cfg)] AnyFields::$tv(f) => f.write(out), )+
                }
            }

            fn check(&self) -> Result<(), SavedError> {
                match self {
                    $( #[cfg($cfg)] AnyFields::$tv(f) => f.check(), )+
                }
            }

            fn scene_box(&self) -> Option<Aabb> {
                match self {
                    $( #[cfg($cfg)] AnyFields::$tv(f) => f.scene_box(), )+
                }
            }
        }

        impl AnyFields {
            /// The fields of `tree`.
            pub(crate) fn of(tree: &AnyTree) -> Self {
                match tree {
                    $( #[cfg($cfg)] AnyTree::$tv(t) => AnyFields::$tv(Structure::saved_fields(t)), )+
                }
            }

            /// The tree of kind `kind` these fields describe (unchecked).
            pub(crate) fn assemble(self, kind: TreeKind, image: MemoryImage, build: BuildConfig) -> AnyTree {
                match self {
                    $( #[cfg($cfg)] AnyFields::$tv(f) => AnyTree::$tv(Structure::from_saved(kind, image, build, f)), )+
                }
            }

            /// Checks `tree` against these fields ([`Structure::check_saved`]).
            pub(crate) fn check_tree(&self, tree: &AnyTree) -> Result<(), Violation> {
                match (self, tree) {
                    $( #[cfg($cfg)] (AnyFields::$tv(f), AnyTree::$tv(t)) => t.check_saved(f), )+
                    #[allow(unreachable_patterns)]
                    _ => Err(Violation {
                        word: 0,
                        what: format!("the header's fields are not a {}'s", tree.kind()),
                    }),
                }
            }
        }
    };
    ($($input:tt)+) => {
        $crate::structure::structures!(@norm [] $($input)+);
    };
}

pub(crate) use structures;
