//! The `fast` model's macro-operations: what a replayed thread issues.

use crate::hw::pipe::Pipe;

/// A macro-operation of a simulated thread: an instruction run, a load, or a pipeline op.
///
/// Eight bytes (a one-byte tag and narrow fields), so that the replay's op buffers take
/// half the host cache lines of a 16-byte op (`docs/simulator.md`, "How the simulator
/// runs fast").
/// The narrow fields are checked where ops are made ([`Op::load`], [`Recorder`](crate::model::fast::recorder::Recorder)): a value
/// that does not fit is an [`OpRangeError`], never a silent wrap.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// `n` single-issue instructions that use the results of earlier loads/pipeline ops;
    /// `fpinv` of them go to the shared reciprocal unit.
    Issue {
        /// Of which reciprocal / inverse-square-root ops.
        fpinv: u16,
        /// Instructions.
        n: u32,
    },
    /// `words` non-blocking word loads from word address `word` (byte address / 4; one
    /// issue slot each). A 32-bit word address covers 16 GiB of simulated memory.
    Load {
        /// Consecutive words.
        words: u16,
        /// Word address of the first word (byte address / 4).
        word: u32,
    },
    /// `n` operations on a pipeline; `parallel` sends them to `n` pipes in one issue slot
    /// (the "+" configurations), otherwise one issue slot each on the TM's pipes.
    Pipe {
        /// Which pipeline.
        pipe: Pipe,
        /// Operations.
        n: u8,
        /// All at once on parallel pipes.
        parallel: bool,
    },
}

const _: () = assert!(std::mem::size_of::<Op>() == 8, "Op must stay 8 bytes");

impl Op {
    /// A load of `words` words from word-aligned byte address `addr`, checked against the
    /// op's field widths (word address below 2^32, i.e. 16 GiB; at most 65 535 words).
    pub fn load(addr: u64, words: u64) -> Result<Op, OpRangeError> {
        let word = u32::try_from(addr / 4).map_err(|_| OpRangeError::Address { addr })?;
        let words = u16::try_from(words).map_err(|_| OpRangeError::Words { words })?;
        Ok(Op::Load { words, word })
    }
}

/// A traversal step that does not fit an 8-byte [`Op`] (a scene image beyond 16 GiB, a
/// fetch of more than 65 535 words, or an instruction run beyond the counters' widths).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum OpRangeError {
    /// The byte address's word index does not fit 32 bits.
    #[error("load at byte address {addr:#x} is beyond the simulator's 16 GiB address space")]
    Address {
        /// Byte address of the load.
        addr: u64,
    },
    /// More words in one fetch than a load op holds.
    #[error("a fetch of {words} words exceeds the 65 535 words of one load op")]
    Words {
        /// Words fetched.
        words: u64,
    },
    /// More reciprocal ops in one merged instruction run than an issue op holds.
    #[error("{fpinv} reciprocal ops in one instruction run exceed the 65 535 of one issue op")]
    Fpinv {
        /// Reciprocal ops of the run.
        fpinv: u64,
    },
    /// More instructions in one merged run than an issue op holds.
    #[error("{n} instructions in one run exceed the 2^32 − 1 of one issue op")]
    Issue {
        /// Instructions of the run.
        n: u64,
    },
}
