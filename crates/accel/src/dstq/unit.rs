//! The quantized dual-split pipeline: what the simulator's `rt.dstqp` computes for one
//! record (`docs/isa.md`), the exact DST's pipeline step (`dst::pipeline::step`, Lin et al.
//! 2020, Fig. 6) behind a dequantization stage that turns the record's two k-bit offsets
//! into planes with the cluster's frame, exactly as [`DstQ`](super::DstQ)'s traversal does.
//!
//! The unit's geometry is fixed, as a hardware unit's is: [`UNIT_BITS`]-bit planes in
//! clusters of at most [`UNIT_CLUSTER_BYTES`] bytes (the default [`DstQConfig`]). A record
//! is named by one word: its cluster's word address shifted left by [`POS_BITS`], or'd with
//! its bit position in the cluster ([`name`]).

use super::DstQConfig;
use super::frame::Frame;
use super::layout::ROOT_BIT;
use super::record::{ChildRef, QHeader, RecordFormat, read_bits};
use crate::dst::HeaderOffset;
use crate::dst::pipeline::{PipelineInput, ReturnCode, step};

/// Bits per plane offset the unit decodes.
pub const UNIT_BITS: u32 = 8;
/// Largest cluster the unit addresses, in bytes.
pub const UNIT_CLUSTER_BYTES: u32 = 64;
/// Bits of a record's position in its cluster, in a name.
pub const POS_BITS: u32 = 9;
/// Largest node region the names reach: 2^(32 − [`POS_BITS`]) words (32 MiB).
pub const UNIT_MAX_NODE_BYTES: u64 = 4 << (32 - POS_BITS);

/// True when a tree of `cfg` can run on the unit.
pub fn unit_supports(cfg: &DstQConfig) -> bool {
    cfg.bits == UNIT_BITS && cfg.cluster_bytes == UNIT_CLUSTER_BYTES
}

/// The name of the record at bit `bit` of the cluster whose frame is at word `cluster`.
#[inline(always)]
pub fn name(cluster: u32, bit: u32) -> u32 {
    cluster << POS_BITS | bit
}

/// What the unit returns for one record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitOutput {
    /// The exact DST pipeline's return code.
    pub code: ReturnCode,
    /// Codes 1 and 2: the name of the record to continue at; code 3: the index entry of
    /// the triangle run; code 0: 0.
    pub next: u32,
    /// Code 2: the name of the far child to push; else 0.
    pub stack: u32,
    /// Output interval start.
    pub t_min_out: f32,
    /// Output interval end.
    pub t_max_out: f32,
}

/// One record, named `at`: `frame` the four words at its cluster's start, `words` the three
/// words from the one holding its first bit (bit `at mod 32` of `words[0]`), the ray's
/// origin and inverse direction and the interval `[t_min, t_max]`.
pub fn unit_step(
    frame: [u32; 4],
    words: [u32; 3],
    at: u32,
    origin: [f32; 3],
    inv_dir: [f32; 3],
    t_min: f32,
    t_max: f32,
) -> UnitOutput {
    let fmt = RecordFormat::new(UNIT_BITS, UNIT_CLUSTER_BYTES);
    let k = fmt.k;
    let f = Frame::from_words(frame);
    let bit = (at % 32) as usize;
    let h = QHeader::read(read_bits(&words, bit, 32), &fmt);
    let hb = h.header_bits(&fmt) as usize;
    let exact = h.exact();
    let (a0, a1) = plane_axes(exact);
    let q0 = read_bits(&words, bit + hb, k);
    let q1 = read_bits(&words, bit + hb + k as usize, k);
    // The exact pipeline on the dequantized planes; its offset field is zero, so its
    // `offset` says only which child is near (0: the left, else the right).
    let out = step(&PipelineInput {
        word: exact,
        p0: f.plane(a0, q0),
        p1: f.plane(a1, q1),
        origin,
        inv_dir,
        t_min,
        t_max,
    });
    let cluster = at >> POS_BITS;
    let child = || match h.child(&fmt) {
        ChildRef::Local(b) => (cluster, b),
        ChildRef::Cluster(c) => (c, ROOT_BIT),
    };
    let (next, stack) = match out.code {
        ReturnCode::Miss => (0, 0),
        ReturnCode::Leaf => (h.run(), 0),
        _ if exact.is_split() => {
            let (c, left) = child();
            let right = left + h.left_bits(&fmt);
            let (near, far) = if out.offset == 0 {
                (left, right)
            } else {
                (right, left)
            };
            let far = if out.code == ReturnCode::BothChildren {
                name(c, far)
            } else {
                0
            };
            (name(c, near), far)
        }
        _ => {
            let (c, b) = child();
            (name(c, b), 0)
        }
    };
    UnitOutput {
        code: out.code,
        next,
        stack,
        t_min_out: out.t_min_out,
        t_max_out: out.t_max_out,
    }
}

/// The axes of the planes P0 and P1 (Lin et al. 2020, App. A): one axis for both planes of
/// a 1-D node (splitting: field A; single-axis carving: field B), the pair of a dual-axis
/// carving node. A plain leaf has no planes (axis 0, unused).
fn plane_axes(w: HeaderOffset) -> (usize, usize) {
    let field_a = w.axis_pair_bits() as usize;
    if w.is_plain_leaf() {
        (0, 0)
    } else if w.is_dual() {
        (field_a >> 1, (field_a & 1) + 1)
    } else if w.is_carving() {
        let b = w.field_b_bits() as usize & 3;
        (b, b)
    } else {
        (field_a, field_a)
    }
}
