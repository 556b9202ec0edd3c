//! One structure of any kind: [`AnyTree`] (the registry's enum of the tree types, in
//! `registry.rs`) as it is derived ([`AnyTree::derive`]), saved and loaded
//! ([`AnyTree::save`], [`AnyTree::load`]: the format of [`crate::saved`], which this file
//! gives the registry's kinds and header fields). Each structure's tree type lives in its
//! folder and carries its [`BuildStats`](crate::BuildStats); [`crate::Bvh2Tree`] is the SAH
//! BVH2 every other structure is derived from.
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
use crate::registry::{AnyFields, AnyTree, Presets, TreeKind};
use crate::saved::{self, SavedError, SavedTree, Violation};
use crate::{AccelError, BuildConfig, Bvh2Tree};
use dualsplit_geometry::Triangle;
use std::io::{self, Read, Write};
use std::path::Path;

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

impl SavedTree for AnyTree {
    type Fields = AnyFields;

    fn kind(&self) -> TreeKind {
        AnyTree::kind(self)
    }

    fn image(&self) -> &MemoryImage {
        AnyTree::image(self)
    }

    fn config(&self) -> &BuildConfig {
        AnyTree::config(self)
    }

    fn fields(&self) -> AnyFields {
        AnyFields::of(self)
    }

    fn check_fields(&self, fields: &AnyFields) -> Result<(), Violation> {
        fields.check_tree(self)
    }

    fn assemble(kind: TreeKind, image: MemoryImage, build: BuildConfig, fields: AnyFields) -> Self {
        fields.assemble(kind, image, build)
    }
}

/// The saved-tree file ([`crate::saved`], `docs/tree-format.md`).
impl AnyTree {
    /// Checks everything a traversal of this tree's image relies on, as loading a saved
    /// tree does (`docs/tree-format.md`, "Checks on load"): child offsets and index runs
    /// inside their regions, every node reached once from the root (no cycle), runs ended
    /// by [`crate::image::RUN_END`] and not overlapping, triangle ids below the triangle
    /// count, each structure's own node checks, and the counts the header records. Linear time.
    pub fn check_structure(&self) -> Result<(), SavedError> {
        saved::check_structure(self)
    }

    /// Writes the tree in the saved-tree format to `w`. The same tree always gives the
    /// same bytes (no time stamps; build times are not stored). A tree built with a
    /// negative or non-finite cost is refused (`InvalidInput`): loading would refuse it.
    pub fn write_to<W: Write>(&self, w: W) -> io::Result<()> {
        saved::write_to(self, w)
    }

    /// The saved-tree file as bytes (empty for a tree [`AnyTree::write_to`] refuses).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut v = Vec::new();
        // Writing to a Vec cannot fail; a refused tree writes nothing.
        if self.write_to(&mut v).is_err() {
            v.clear();
        }
        v
    }

    /// Saves the tree to `path` (created or replaced).
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), SavedError> {
        let path = path.as_ref();
        let io = |source| SavedError::Io {
            path: path.to_owned(),
            source,
        };
        let f = std::fs::File::create(path).map_err(io)?;
        self.write_to(io::BufWriter::with_capacity(1 << 20, f))
            .map_err(io)
    }

    /// Reads a saved tree of `len` bytes from `r`. With `scene`, the tree must have been
    /// built from exactly these triangles ([`SavedError::WrongScene`] otherwise).
    pub fn read_from<R: Read>(
        r: R,
        len: u64,
        scene: Option<&[Triangle]>,
    ) -> Result<AnyTree, SavedError> {
        saved::read_from(r, len, scene)
    }

    /// Reads a saved tree from bytes (see [`AnyTree::read_from`]).
    pub fn from_bytes(bytes: &[u8], scene: Option<&[Triangle]>) -> Result<AnyTree, SavedError> {
        Self::read_from(bytes, bytes.len() as u64, scene)
    }

    /// Loads the saved tree at `path`. With `scene`, the tree must have been built from
    /// exactly these triangles. Errors name the file.
    pub fn load(path: impl AsRef<Path>, scene: Option<&[Triangle]>) -> Result<AnyTree, SavedError> {
        saved::load(path.as_ref(), scene)
    }
}
