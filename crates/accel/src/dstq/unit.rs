//! The quantized dual-split pipeline: what the simulator's `rt.dstqp` computes for one
//! record (`docs/isa.md`), the exact DST's pipeline step (`dst::pipeline::step`, Lin et al.
//! 2020, Fig. 6) behind a dequantization stage that turns the record's two k-bit offsets
//! into planes with the cluster's frame, exactly as [`DstQ`](super::DstQ)'s traversal does.
//!
//! The unit's geometry is fixed, as a hardware unit's is: [`UNIT_BITS`]-bit planes in
//! [`UNIT_CLUSTER_BYTES`]-byte clusters (the default [`DstQConfig`]); the node region
//! starts at byte 0 of the image, so a record is named by its *bit address* (byte address
//! of its cluster block × 8 + its bit position in the block).

use super::DstQConfig;
use super::frame::Frame;
use super::layout::ROOT_BIT;
use super::record::{ChildRef, QHeader, read_bits};
use crate::dst::HeaderOffset;
use crate::dst::pipeline::{PipelineInput, ReturnCode, step};

/// Bits per plane offset the unit decodes.
pub const UNIT_BITS: u32 = 8;
/// Bytes per cluster block the unit addresses.
pub const UNIT_CLUSTER_BYTES: u32 = 64;
/// Bits per cluster block.
const BLOCK_BITS: u32 = UNIT_CLUSTER_BYTES * 8;

/// True when a tree of `cfg` can run on the unit.
pub fn unit_supports(cfg: &DstQConfig) -> bool {
    cfg.bits == UNIT_BITS && cfg.cluster_bytes == UNIT_CLUSTER_BYTES
}

/// What the unit returns for one record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitOutput {
    /// The exact DST pipeline's return code.
    pub code: ReturnCode,
    /// Codes 1 and 2: the bit address of the record to continue at; code 3: the index entry
    /// of the triangle run; code 0: 0.
    pub next: u32,
    /// Code 2: the bit address of the far child to push; else 0.
    pub stack: u32,
    /// Output interval start.
    pub t_min_out: f32,
    /// Output interval end.
    pub t_max_out: f32,
}

/// One record at bit address `at`: `frame` the four words at its block's start, `words`
/// the three words from the one holding its first bit (bit `at % 32` of `words[0]`), the
/// ray's origin and inverse direction and the interval `[t_min, t_max]`.
pub fn unit_step(
    frame: [u32; 4],
    words: [u32; 3],
    at: u32,
    origin: [f32; 3],
    inv_dir: [f32; 3],
    t_min: f32,
    t_max: f32,
) -> UnitOutput {
    let k = UNIT_BITS;
    let f = Frame::from_words(frame);
    let bit = (at % 32) as usize;
    let h = QHeader::from_bits(read_bits(&words, bit, 32));
    let exact = h.exact();
    // The exact pipeline on the dequantized planes, its offset field zeroed: its `offset`
    // then says which child is near (0: the left, else the right) and nothing else.
    let word = HeaderOffset::from_bits(exact.bits() & !((1 << 26) - 1));
    let (a0, a1) = plane_axes(exact);
    let q0 = read_bits(&words, bit + 32, k);
    let q1 = read_bits(&words, bit + 32 + k as usize, k);
    let out = step(&PipelineInput {
        word,
        p0: f.plane(a0, q0),
        p1: f.plane(a1, q1),
        origin,
        inv_dir,
        t_min,
        t_max,
    });
    let block = at / BLOCK_BITS * BLOCK_BITS;
    let child = || match h.child() {
        ChildRef::Local(b) => block + b,
        ChildRef::Cluster(c) => c * BLOCK_BITS + ROOT_BIT,
    };
    let (next, stack) = match out.code {
        ReturnCode::Miss => (0, 0),
        ReturnCode::Leaf => (h.run(), 0),
        _ if exact.is_split() => {
            let left = child();
            let lsize = if h.left_is_internal() { 32 + 2 * k } else { 32 };
            let right = left + lsize;
            let (near, far) = if out.offset == 0 {
                (left, right)
            } else {
                (right, left)
            };
            (
                near,
                if out.code == ReturnCode::BothChildren {
                    far
                } else {
                    0
                },
            )
        }
        _ => (child(), 0),
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
        (w.field_b_bits() as usize & 3, w.field_b_bits() as usize & 3)
    } else {
        (field_a, field_a)
    }
}
