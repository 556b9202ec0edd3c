//! The fixed 512-byte header of a saved tree file (`docs/tree-format.md`): field order,
//! encoding and the checks made on it before anything is allocated.

use super::SavedError;
use crate::{BuildConfig, TreeKind};
use dualsplit_geometry::{Aabb, Vec3};

/// The first eight bytes of every saved tree file.
pub const MAGIC: [u8; 8] = *b"DSPLTREE";
/// The format version this crate writes and reads.
pub const FORMAT_VERSION: u32 = 1;
/// Bytes of the header, zero-padded.
pub const HEADER_BYTES: usize = 512;
/// Byte offset of the node words: one 4 KiB page, so that the words are page-aligned in the
/// file.
pub const WORDS_OFFSET: u64 = 4096;
/// Bytes of the SHA-256 checksum that ends the file.
pub const CHECKSUM_BYTES: u64 = 32;

/// A structure's own fields of the saved-tree header, after the fields every file has.
pub trait SavedFields: Copy + std::fmt::Debug + PartialEq {
    /// Writes the fields in the header's order.
    fn write(&self, out: &mut FieldWriter);

    /// Reads the fields of a tree of kind `kind`, refusing values no build makes.
    fn read(kind: TreeKind, input: &mut FieldReader) -> Result<Self, SavedError>;

    /// Refuses fields that loading would refuse (checked before a tree is written).
    fn check(&self) -> Result<(), SavedError> {
        Ok(())
    }

    /// The scene box the header records, for the structures that store one: loading checks
    /// it is exactly the bounds of the file's triangles.
    fn scene_box(&self) -> Option<Aabb> {
        None
    }
}

/// The decoded header, with the structure's own fields `F`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Header<F> {
    pub kind: TreeKind,
    pub node_words: u64,
    pub index_words: u64,
    pub triangles: u64,
    pub file_bytes: u64,
    pub triangle_hash: [u8; 32],
    pub build: BuildConfig,
    pub extra: F,
}

/// The file size a header with these region sizes implies, or `None` on overflow.
pub(super) fn implied_bytes(node_words: u64, index_words: u64, triangles: u64) -> Option<u64> {
    let words = node_words.checked_add(index_words)?.checked_mul(4)?;
    WORDS_OFFSET
        .checked_add(words)?
        .checked_add(triangles.checked_mul(36)?)?
        .checked_add(CHECKSUM_BYTES)
}

/// Writes header fields, little-endian, in order.
pub struct FieldWriter(Vec<u8>);
impl FieldWriter {
    /// Writes a `u32`.
    pub fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    /// Writes a `u64`.
    pub fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    /// Writes an `f32` by its bits.
    pub fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }
    /// Writes a box: min then max, x, y, z.
    pub fn scene_box(&mut self, b: Aabb) {
        for v in [b.min, b.max] {
            self.f32(v.x);
            self.f32(v.y);
            self.f32(v.z);
        }
    }
}

/// Reads header fields, little-endian, in order.
pub struct FieldReader<'a>(&'a [u8]);
impl FieldReader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        // The header buffer is HEADER_BYTES long and the fields use far fewer bytes.
        let (a, b) = self.0.split_at(N);
        self.0 = b;
        a.try_into().unwrap_or([0; N])
    }
    /// Reads a `u32`.
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    /// Reads a `u64`.
    pub fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
    /// Reads a box written by [`FieldWriter::scene_box`].
    pub fn scene_box(&mut self) -> Aabb {
        let mut v = [0f32; 6];
        for x in &mut v {
            *x = self.f32();
        }
        Aabb::new(Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]))
    }
    /// Reads an `f32` by its bits.
    pub fn f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }
}

/// Checks the build settings a header records: what a build can record (the builder
/// clamps the bins to 2..=256 and takes at least one triangle per leaf, and
/// [`AnyTree::write_to`](crate::AnyTree::write_to) refuses other costs).
pub(super) fn check_build(b: &BuildConfig) -> Result<(), SavedError> {
    if b.max_leaf_size == 0 {
        return Err(SavedError::malformed(
            "build setting max_leaf_size is 0; at least 1".into(),
        ));
    }
    if !(2..=256).contains(&b.bins) {
        return Err(SavedError::malformed(format!(
            "build setting bins is {}; from 2 to 256",
            b.bins
        )));
    }
    check_cost("build setting", "cost_traversal", b.cost_traversal)?;
    check_cost("build setting", "cost_triangle", b.cost_triangle)
}

/// A cost must be a finite number ≥ 0.
pub(crate) fn check_cost(what: &str, name: &str, c: f32) -> Result<(), SavedError> {
    if c.is_finite() && c >= 0.0 {
        Ok(())
    } else {
        Err(SavedError::malformed(format!(
            "{what} {name} is {c}; a finite number of at least 0"
        )))
    }
}

impl<F: SavedFields> Header<F> {
    /// The header's `HEADER_BYTES` bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut o = FieldWriter(Vec::with_capacity(HEADER_BYTES));
        o.0.extend_from_slice(&MAGIC);
        o.u32(FORMAT_VERSION);
        o.u32(self.kind.code());
        o.u64(self.file_bytes);
        o.u64(WORDS_OFFSET);
        o.u64(self.node_words);
        o.u64(self.index_words);
        o.u64(self.triangles);
        o.0.extend_from_slice(&self.triangle_hash);
        let b = &self.build;
        o.u32(b.max_leaf_size);
        o.f32(b.cost_traversal);
        o.f32(b.cost_triangle);
        o.u32(b.bins);
        o.u32(b.parallel_threshold);
        self.extra.write(&mut o);
        o.0.resize(HEADER_BYTES, 0);
        o.0
    }

    /// Decodes and checks a header read from a file of `actual_bytes` bytes: magic,
    /// version, kind, and region sizes that add up to the file's size (so nothing larger
    /// than the file is ever allocated).
    pub fn decode(h: &[u8; HEADER_BYTES], actual_bytes: u64) -> Result<Self, SavedError> {
        let mut i = FieldReader(h);
        if i.take::<8>() != MAGIC {
            return Err(SavedError::NotATree);
        }
        let version = i.u32();
        if version != FORMAT_VERSION {
            return Err(SavedError::UnsupportedVersion {
                found: version,
                supported: FORMAT_VERSION,
            });
        }
        let code = i.u32();
        let Some(kind) = TreeKind::from_code(code) else {
            return Err(SavedError::malformed(format!(
                "unknown structure kind {code}"
            )));
        };
        let file_bytes = i.u64();
        if file_bytes != actual_bytes {
            return Err(SavedError::Length {
                expected: file_bytes,
                found: actual_bytes,
            });
        }
        let words_offset = i.u64();
        if words_offset != WORDS_OFFSET {
            return Err(SavedError::malformed(format!(
                "node words at byte {words_offset}, expected {WORDS_OFFSET}"
            )));
        }
        let node_words = i.u64();
        let index_words = i.u64();
        let triangles = i.u64();
        if implied_bytes(node_words, index_words, triangles) != Some(file_bytes) {
            return Err(SavedError::malformed(format!(
                "{node_words} node words, {index_words} index words and {triangles} triangles \
                 do not make a file of {file_bytes} bytes"
            )));
        }
        let triangle_hash = i.take::<32>();
        let build = BuildConfig {
            max_leaf_size: i.u32(),
            cost_traversal: i.f32(),
            cost_triangle: i.f32(),
            bins: i.u32(),
            parallel_threshold: i.u32(),
        };
        check_build(&build)?;
        let extra = F::read(kind, &mut i)?;
        Ok(Header {
            kind,
            node_words,
            index_words,
            triangles,
            file_bytes,
            triangle_hash,
            build,
            extra,
        })
    }
}
