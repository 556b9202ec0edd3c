//! Saved trees: one structure's memory image and the triangles it references, in a
//! versioned, checksummed file (`docs/tree-format.md`).
//!
//! ```text
//!   0     header (512 B): magic, format version, kind, sizes, triangle hash, build config,
//!         the structure's own fields; zero-padded to byte 4096
//!   4096  node words, index words (little-endian u32)
//!   ...   triangles (9 × f32 each, id order)
//!   end   SHA-256 of every byte before it
//! ```
//!
//! Loading checks, in order: the magic, the version, that the sizes in the header add up
//! to the file's length (before anything is allocated), the checksum, and, when the caller
//! names the scene, that the file's triangles are the scene's, bit for bit (the error names
//! both triangle hashes), then the structure ([`AnyTree::check_structure`](crate::AnyTree::check_structure): offsets, runs,
//! triangle ids, no cycle), so that even a file forged with a recomputed checksum cannot
//! make a traversal panic, loop or read the wrong memory. Each failure is a [`SavedError`];
//! nothing panics.
//!
//! The format names no structure: it writes and reads a `SavedTree` (the registry's
//! [`AnyTree`](crate::AnyTree), whose `save`, `load` and the rest call this module), whose
//! kind selects the header fields ([`SavedFields`]) that follow the common ones.
//!
//! Loading reads the file into memory rather than mapping it: a file mapping is `unsafe`
//! (another process may change or truncate the file under it), and this crate allows
//! `unsafe` only in its SIMD leaf file (a prefetch hint). The node and index words are read straight into their final buffer
//! ([`crate::image::Words`], an anonymous huge-page mapping for large images), with no
//! intermediate copy, and the triangles straight into their shared allocation.
//!
//! ```
//! use dualsplit_accel::math::{Ray, Triangle, Vec3};
//! use dualsplit_accel::{AnyTree, BuildConfig, Bvh2Tree, DstConfig, DstTree, RayQuery};
//! let tris = vec![Triangle::new(Vec3::new(-1.0, -1.0, 2.0), Vec3::new(1.0, -1.0, 2.0), Vec3::new(0.0, 1.0, 2.0))];
//! let bvh2 = Bvh2Tree::build(&tris[..], &BuildConfig::default()).unwrap();
//! let dst = AnyTree::from(DstTree::from_bvh2(&bvh2, &DstConfig::hardware()).unwrap());
//! let bytes = dst.to_bytes();
//! let back = AnyTree::from_bytes(&bytes, Some(&tris)).unwrap();
//! let ray = Ray::new(Vec3::ZERO, Vec3::Z);
//! assert_eq!(back.intersect(&ray), dst.intersect(&ray));
//! let mut bad = bytes.clone();
//! let middle = bad.len() / 2;
//! bad[middle] ^= 1;
//! assert!(AnyTree::from_bytes(&bad, None).is_err());
//! ```

mod header;
mod structure;

pub use header::{CHECKSUM_BYTES, FORMAT_VERSION, HEADER_BYTES, MAGIC, WORDS_OFFSET};

pub(crate) use header::check_cost;
pub use header::{FieldReader, FieldWriter, SavedFields};
pub use structure::Violation;
pub(crate) use structure::{Regions, Runs, check_bvh, check_regions, counts, violation};

use crate::image::{MemoryImage, SharedTriangles, Words};
use crate::{BuildConfig, TreeKind};
use dualsplit_geometry::Triangle;
use header::Header;
use sha2::{Digest, Sha256};
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

/// Why a saved tree could not be read.
#[derive(Debug, thiserror::Error)]
pub enum SavedError {
    /// Reading or writing the file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: io::Error,
    },
    /// A load error, with the file it came from.
    #[error("{}: {source}", path.display())]
    At {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        source: Box<SavedError>,
    },
    /// The path names a directory, device, named pipe or socket, which is never opened.
    #[error("{}: not a regular file ({kind}); only regular files are read", path.display())]
    NotAFile {
        /// The file.
        path: PathBuf,
        /// What it is instead.
        kind: &'static str,
    },
    /// The file does not start with [`MAGIC`].
    #[error("not a dualsplit tree file (bad magic)")]
    NotATree,
    /// A format version this crate does not read.
    #[error("tree file format version {found}, this build reads version {supported}")]
    UnsupportedVersion {
        /// The file's version.
        found: u32,
        /// The version this crate reads.
        supported: u32,
    },
    /// The file is shorter (truncated) or longer than its header says.
    #[error("tree file is {found} bytes, its header says {expected} (truncated or damaged)")]
    Length {
        /// Bytes the header says.
        expected: u64,
        /// Bytes there are.
        found: u64,
    },
    /// The data ended before the length it was said to have.
    #[error("tree file ended early (truncated while reading)")]
    EndedEarly,
    /// The header's fields contradict each other.
    #[error("malformed tree file: {0}")]
    Malformed(String),
    /// The checksum does not match the contents.
    #[error("tree file is corrupt: checksum mismatch")]
    Checksum,
    /// The tree's structure is inconsistent (a file forged with a recomputed checksum, or
    /// written by a faulty encoder): a child or run outside its region, a node reached
    /// twice, an invalid node header, a triangle id out of range, or counts that contradict
    /// the header. Checked after the checksum, before the tree is returned.
    #[error("malformed {structure} tree at word {word}: {what}")]
    Structure {
        /// The structure (`bvh2`, `bvh4`, `bvh8`, `dst`).
        structure: &'static str,
        /// The image word (node region, or index region for an index entry) at fault.
        word: u64,
        /// What is wrong.
        what: String,
    },
    /// The tree was built from other triangles than the scene it is used with.
    #[error(
        "tree file was built from another scene (triangle hash {found}, the scene's is {expected})"
    )]
    WrongScene {
        /// The scene's triangle hash (hex).
        expected: String,
        /// The file's triangle hash (hex).
        found: String,
    },
}

impl SavedError {
    pub(crate) fn malformed(s: String) -> Self {
        SavedError::Malformed(s)
    }

    /// The error without its file context ([`SavedError::At`] unwrapped).
    pub fn cause(&self) -> &SavedError {
        match self {
            SavedError::At { source, .. } => source.cause(),
            e => e,
        }
    }

    fn at(self, path: &Path) -> Self {
        match self {
            e @ (SavedError::Io { .. } | SavedError::At { .. }) => e,
            e => SavedError::At {
                path: path.to_owned(),
                source: Box::new(e),
            },
        }
    }
}

/// SHA-256 of triangles as stored (36 little-endian bytes each, id order): what a saved
/// tree records to recognise its scene.
pub fn triangle_hash(triangles: &[Triangle]) -> [u8; 32] {
    let mut h = Sha256::new();
    hash_triangles(&mut h, triangles);
    h.finalize().into()
}

fn hash_triangles(h: &mut Sha256, triangles: &[Triangle]) {
    if cfg!(target_endian = "little") {
        h.update(bytemuck::cast_slice::<Triangle, u8>(triangles));
    } else {
        for t in triangles {
            for v in t.v {
                for c in v.to_array() {
                    h.update(c.to_le_bytes());
                }
            }
        }
    }
}

fn hex(h: &[u8; 32]) -> String {
    h.iter().map(|b| format!("{b:02x}")).collect()
}

/// Writes `words` as little-endian bytes into `out` and the hash.
fn put_words<W: Write>(out: &mut HashingWriter<W>, words: &[u32]) -> io::Result<()> {
    if cfg!(target_endian = "little") {
        out.write_all(bytemuck::cast_slice(words))
    } else {
        for w in words {
            out.write_all(&w.to_le_bytes())?;
        }
        Ok(())
    }
}

struct HashingWriter<W> {
    inner: W,
    hash: Sha256,
}

impl<W: Write> HashingWriter<W> {
    fn write_all(&mut self, b: &[u8]) -> io::Result<()> {
        self.hash.update(b);
        self.inner.write_all(b)
    }
}

/// A tree the saved-tree format writes and reads: its kind (code and name), image, build
/// settings and its kind's own header fields. The registry's [`AnyTree`](crate::AnyTree) is
/// one.
pub(crate) trait SavedTree: Sized {
    /// The header fields of the tree's kind.
    type Fields: SavedFields;

    /// Which structure the tree is.
    fn kind(&self) -> TreeKind;

    /// The memory image saved.
    fn image(&self) -> &MemoryImage;

    /// The BVH2 build settings the tree came from.
    fn config(&self) -> &BuildConfig;

    /// The header fields of this tree.
    fn fields(&self) -> Self::Fields;

    /// Its structure's own checks of the image against `fields` (offsets, node headers,
    /// counts).
    fn check_fields(&self, fields: &Self::Fields) -> Result<(), Violation>;

    /// The tree of kind `kind` a checked header describes (unchecked itself).
    fn assemble(
        kind: TreeKind,
        image: MemoryImage,
        build: BuildConfig,
        fields: Self::Fields,
    ) -> Self;
}

/// Checks everything a traversal of `tree`'s image relies on, as loading a saved tree
/// does (`docs/tree-format.md`, "Checks on load"): child offsets and index runs
/// inside their regions, every node reached once from the root (no cycle), runs ended
/// by [`crate::image::RUN_END`] and not overlapping, triangle ids below the triangle
/// count, each structure's own node checks, and the counts the header records. Linear time.
pub(crate) fn check_structure<T: SavedTree>(tree: &T) -> Result<(), SavedError> {
    let img = Regions::of(tree.image());
    check_regions(&img)
        .and_then(|()| tree.check_fields(&tree.fields()))
        .map_err(|v| SavedError::Structure {
            structure: tree.kind().name(),
            word: v.word as u64,
            what: v.what,
        })
}

/// The file header of `tree`.
fn header<T: SavedTree>(tree: &T) -> Header<T::Fields> {
    let img = tree.image();
    let extra = tree.fields();
    let (n, i, t) = (
        img.nodes.len() as u64,
        img.indices.len() as u64,
        img.triangle_slice().len() as u64,
    );
    Header {
        kind: tree.kind(),
        node_words: n,
        index_words: i,
        triangles: t,
        file_bytes: header::implied_bytes(n, i, t).unwrap_or(u64::MAX),
        triangle_hash: triangle_hash(img.triangle_slice()),
        // What the builder used: it clamps the bins and takes at least one triangle per
        // leaf, so the recorded settings pass `check_build`.
        build: BuildConfig {
            bins: tree.config().bins.clamp(2, 256),
            max_leaf_size: tree.config().max_leaf_size.max(1),
            ..*tree.config()
        },
        extra,
    }
}

/// Writes `tree` in the saved-tree format to `w`. The same tree always gives the
/// same bytes (no time stamps; build times are not stored). A tree built with a
/// negative or non-finite cost is refused (`InvalidInput`): loading would refuse it.
pub(crate) fn write_to<T: SavedTree, W: Write>(tree: &T, w: W) -> io::Result<()> {
    let h = header(tree);
    let checked = header::check_build(&h.build).and_then(|()| h.extra.check());
    if let Err(e) = checked {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, e.to_string()));
    }
    let mut out = HashingWriter {
        inner: w,
        hash: Sha256::new(),
    };
    let mut head = h.encode();
    head.resize(WORDS_OFFSET as usize, 0);
    out.write_all(&head)?;
    let img = tree.image();
    put_words(&mut out, &img.words[img.nodes.start..img.indices.end])?;
    let tris = img.triangle_slice();
    if cfg!(target_endian = "little") {
        out.write_all(bytemuck::cast_slice(tris))?;
    } else {
        put_words(&mut out, bytemuck::cast_slice(tris))?;
    }
    let sum: [u8; 32] = out.hash.finalize().into();
    out.inner.write_all(&sum)?;
    out.inner.flush()
}

/// Reads a saved tree of `len` bytes from `r`. With `scene`, the tree must have been
/// built from exactly these triangles ([`SavedError::WrongScene`] otherwise).
pub(crate) fn read_from<T: SavedTree, R: Read>(
    mut r: R,
    len: u64,
    scene: Option<&[Triangle]>,
) -> Result<T, SavedError> {
    let short = |e: io::Error| match e.kind() {
        io::ErrorKind::UnexpectedEof => SavedError::EndedEarly,
        _ => SavedError::Io {
            path: PathBuf::new(),
            source: e,
        },
    };
    let mut hash = Sha256::new();
    let mut head = [0u8; HEADER_BYTES];
    if len < WORDS_OFFSET + CHECKSUM_BYTES {
        r.read_exact(&mut head[..len.min(HEADER_BYTES as u64) as usize])
            .map_err(short)?;
        if head[..8.min(len as usize)] != MAGIC[..8.min(len as usize)] {
            return Err(SavedError::NotATree);
        }
        return Err(SavedError::Length {
            expected: WORDS_OFFSET + CHECKSUM_BYTES,
            found: len,
        });
    }
    r.read_exact(&mut head).map_err(short)?;
    let h = Header::<T::Fields>::decode(&head, len)?;
    hash.update(head);
    let mut pad = vec![0u8; WORDS_OFFSET as usize - HEADER_BYTES];
    r.read_exact(&mut pad).map_err(short)?;
    hash.update(&pad);

    // The sizes add up to `len` (checked by `decode`), so these fit in memory as the
    // file did.
    let n_words = (h.node_words + h.index_words) as usize;
    let mut words = Words::zeroed(n_words);
    {
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut words[..]);
        r.read_exact(bytes).map_err(short)?;
        hash.update(&*bytes);
    }
    if cfg!(target_endian = "big") {
        for w in words.iter_mut() {
            *w = u32::from_le(*w);
        }
    }
    // Read straight into the shared allocation the tree keeps (a fresh `Arc`, so
    // `get_mut` always gives it; collecting a sized iterator allocates once).
    let mut tris: SharedTriangles =
        std::iter::repeat_n(Triangle::default(), h.triangles as usize).collect();
    {
        let Some(slice) = std::sync::Arc::get_mut(&mut tris) else {
            return Err(SavedError::malformed("triangle buffer is shared".into()));
        };
        let bytes: &mut [u8] = bytemuck::cast_slice_mut(slice);
        r.read_exact(bytes).map_err(short)?;
        hash.update(&*bytes);
        if cfg!(target_endian = "big") {
            let f: &mut [u32] = bytemuck::cast_slice_mut(slice);
            for w in f {
                *w = u32::from_le(*w);
            }
        }
    }
    let mut sum = [0u8; 32];
    r.read_exact(&mut sum).map_err(short)?;
    let mut extra = [0u8; 1];
    if r.read(&mut extra).map_err(short)? != 0 {
        return Err(SavedError::Length {
            expected: len,
            found: len + 1,
        });
    }
    if <[u8; 32]>::from(hash.finalize()) != sum {
        return Err(SavedError::Checksum);
    }
    // The file's triangles (checksummed with everything else) against the scene's, bit
    // for bit: cheaper than hashing the scene, and exact. The hashes only name them.
    if let Some(scene) = scene
        && bytemuck::cast_slice::<Triangle, u8>(&tris)
            != bytemuck::cast_slice::<Triangle, u8>(scene)
    {
        return Err(SavedError::WrongScene {
            expected: hex(&triangle_hash(scene)),
            // The triangles' own hash, not the header's copy: a forged header cannot
            // name another scene than the file holds.
            found: hex(&triangle_hash(&tris)),
        });
    }
    // Only the bytes this version writes: a forged file with other bytes in unused
    // header fields or the padding would load but not write back the same file.
    if let Some(at) = h
        .encode()
        .iter()
        .chain(std::iter::repeat(&0u8))
        .zip(head.iter().chain(&pad))
        .position(|(a, b)| a != b)
    {
        return Err(SavedError::malformed(format!(
            "header byte {at} is not what this version writes (unused fields and padding are zero)"
        )));
    }
    // The DST's and DST-Q's scene box is where their traversals start (the first slab
    // test): it must be exactly the bounds of the file's triangles, as a build makes it.
    if let Some(scene_box) = &h.extra.scene_box() {
        let bounds = tris
            .iter()
            .fold(dualsplit_geometry::Aabb::EMPTY, |b, t| b.union(t.bounds()));
        let bits = |b: &dualsplit_geometry::Aabb| {
            (
                b.min.to_array().map(f32::to_bits),
                b.max.to_array().map(f32::to_bits),
            )
        };
        if bits(scene_box) != bits(&bounds) {
            return Err(SavedError::malformed(format!(
                "scene box {:?} to {:?} is not the bounds of the file's triangles ({:?} to {:?})",
                scene_box.min, scene_box.max, bounds.min, bounds.max
            )));
        }
    }
    let tree = assemble::<T>(&h, words, tris);
    // Everything a traversal indexes with, so a forged file cannot make one panic,
    // loop or read the wrong memory (`structure`).
    check_structure(&tree)?;
    Ok(tree)
}

/// Loads the saved tree at `path`. With `scene`, the tree must have been built from
/// exactly these triangles. Errors name the file.
pub(crate) fn load<T: SavedTree>(path: &Path, scene: Option<&[Triangle]>) -> Result<T, SavedError> {
    let io = |source| SavedError::Io {
        path: path.to_owned(),
        source,
    };
    // Only a regular file (links followed) is opened: a named pipe would block the open
    // until a writer appears, a device never end. Checked again on the handle.
    let not_a_file = |meta: &std::fs::Metadata| SavedError::NotAFile {
        path: path.to_owned(),
        kind: file_kind(meta.file_type()),
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(not_a_file(&meta));
    }
    let f = std::fs::File::open(path).map_err(io)?;
    let meta = f.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(not_a_file(&meta));
    }
    let len = meta.len();
    read_from(io::BufReader::with_capacity(1 << 16, f), len, scene).map_err(|e| match e {
        SavedError::Io { source, .. } => io(source),
        e => e.at(path),
    })
}

/// What a non-regular file is, for [`SavedError::NotAFile`].
fn file_kind(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a named pipe";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a file"
    }
}

/// The tree a checked header and its regions describe.
fn assemble<T: SavedTree>(h: &Header<T::Fields>, words: Words, tris: SharedTriangles) -> T {
    let nodes = h.node_words as usize;
    let tri_start = nodes + h.index_words as usize;
    let image = MemoryImage {
        words,
        nodes: 0..nodes,
        indices: nodes..tri_start,
        triangles: tri_start..tri_start + 9 * tris.len(),
        triangle_data: tris,
    };
    T::assemble(h.kind, image, h.build, h.extra)
}
