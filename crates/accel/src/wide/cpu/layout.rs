//! The copy's memory layout: nodes of four ([`Chunk`]) or eight ([`Chunk8`]) lanes, the
//! child words, and triangle packets ([`TriPacket`]). How a node's lanes are read and
//! tested is [`super::lanes`].

/// Lanes of one SSE register of `f32`: children per [`Chunk`], triangles per [`TriPacket`].
pub const LANES: usize = 4;

/// Child word of a leaf: bit 31 set, bits 0–30 the slot of its first triangle in
/// [`CpuBvh::packets`](super::CpuBvh::packets) (`4 · packet + lane`).
pub const LEAF: u32 = 1 << 31;

/// Child word of an empty lane while the copy is made, and of an unused stack entry. The
/// finished copy replaces it by the sentinel's word (see [`Chunk`]).
pub const EMPTY: u32 = u32::MAX;

/// A BVH2 or BVH4 node of the copy: its children's boxes plane by plane, then their child
/// words.
///
/// An empty lane holds the degenerate box, min `+∞` and max `−∞`, which a ray with a finite
/// origin and direction never meets (its near plane distances are `+∞` and its far ones
/// `−∞`: `1 / d` is never 0 for a finite `d`), so the box test needs no check of the child
/// word. For other rays (a NaN distance keeps the running bound) the word is still safe:
/// it names the sentinel, a leaf of one padding lane in the copy's last packet (all
/// vertices 0, id [`EMPTY`]), a zero-area triangle that [`Triangle::intersect`] never
/// hits.
///
/// [`Triangle::intersect`]: dualsplit_geometry::Triangle::intersect
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(16))]
pub struct Chunk {
    /// `planes[p][lane]`: plane `p` of the lane's box, in the image's box-word order
    /// (min.x, min.y, min.z, max.x, max.y, max.z). Empty lanes hold the degenerate box.
    pub planes: [[f32; LANES]; 6],
    /// Per lane: a node (its index) or a leaf ([`LEAF`] | first triangle); an empty lane
    /// names the sentinel leaf.
    pub child: [u32; LANES],
}

/// A BVH8 node of the copy, laid out as [`Chunk`] with eight lanes, so that one AVX
/// register holds a plane of all eight children (and two SSE registers one half each).
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(32))]
pub struct Chunk8 {
    /// `planes[p][lane]`, as [`Chunk::planes`].
    pub planes: [[f32; 8]; 6],
    /// Per lane, as in [`Chunk`]: a node or a leaf (the sentinel for an empty lane).
    pub child: [u32; 8],
}

/// Four consecutive triangles of the leaf-ordered triangle list, vertex coordinates lane by
/// lane, with their ids. A leaf starts at a lane (its child word names the slot `4 · packet
/// + lane`) and ends at the first lane from there whose id has
/// [`RUN_END`](crate::image::RUN_END) set. Leaves follow one another, except that a leaf
/// which would span one packet more than its size needs (`⌈n / 4⌉`) starts at the next
/// packet's first lane: the lanes skipped, like the rest of the last packet of triangles,
/// are [`EMPTY`] padding, and one packet of them follows it (the sentinel).
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(16))]
pub struct TriPacket {
    /// `v[3 * vertex + axis][lane]`.
    pub v: [[f32; LANES]; 9],
    /// Triangle ids; [`RUN_END`](crate::image::RUN_END) on a leaf's last one, [`EMPTY`] on
    /// padding lanes.
    pub prim: [u32; LANES],
}

pub(crate) const EMPTY_PACKET: TriPacket = TriPacket {
    v: [[0.0; LANES]; 9],
    prim: [EMPTY; LANES],
};
