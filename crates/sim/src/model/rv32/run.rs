//! The functional driver: runs one thread to its `ebreak`.

use super::elf::Program;
use super::hart::{ExecError, Hart};
use super::memory::{FrameMemory, Memory};
use crate::hw::fu::{FU_CLASSES, fu_index};
use dualsplit_accel::MemoryImage;

/// Why a run stopped before `ebreak`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum RunError {
    /// An instruction failed.
    #[error(transparent)]
    Exec(#[from] ExecError),
    /// The step budget ran out before `ebreak`.
    #[error("no ebreak within {steps} instructions (pc {pc:#010x})")]
    StepBudget {
        /// Instructions executed.
        steps: u64,
        /// The pc when the budget ran out.
        pc: u32,
    },
}

/// Counts of a functional run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RunStats {
    /// Instructions retired, including the final `ebreak`.
    pub instructions: u64,
    /// Loads and stores (global and local), and memory operands of the ray-tracing
    /// instructions.
    pub memory_accesses: u64,
    /// Taken branches and jumps.
    pub taken_branches: u64,
    /// Instructions per functional-unit class, indexed by [`fu_index`].
    pub per_fu: [u64; FU_CLASSES],
}

/// Runs `hart` until it executes `ebreak`, at most `max_steps` instructions. On success the
/// hart is halted with its pc on the `ebreak`.
pub fn run_to_halt<M: Memory>(
    hart: &mut Hart,
    prog: &Program,
    mem: &mut M,
    max_steps: u64,
) -> Result<RunStats, RunError> {
    let mut s = RunStats::default();
    while s.instructions < max_steps {
        let r = hart.step(prog, mem)?;
        s.instructions += 1;
        s.memory_accesses += r.mem.is_some() as u64;
        s.taken_branches += r.taken as u64;
        s.per_fu[fu_index(r.info.fu)] += 1;
        if hart.halted {
            return Ok(s);
        }
    }
    Err(RunError::StepBudget {
        steps: s.instructions,
        pc: hart.pc,
    })
}

/// Runs `hart` until `ebreak` counting instructions only (the fastest loop; for speed
/// measurements and when the counts are not needed). Returns the instructions retired.
pub fn run_counting<M: Memory>(
    hart: &mut Hart,
    prog: &Program,
    mem: &mut M,
    max_steps: u64,
) -> Result<u64, RunError> {
    let mut n = 0;
    while n < max_steps {
        hart.step(prog, mem)?;
        n += 1;
        if hart.halted {
            return Ok(n);
        }
    }
    Err(RunError::StepBudget {
        steps: n,
        pc: hart.pc,
    })
}

/// Runs a whole frame functionally on one thread: maps `image`, `params` and a zeroed
/// frame buffer of `frame_bytes` bytes ([`FrameMemory`]), starts one [`Hart`] with
/// `local_store_bytes` of local store at the program's entry, and runs it to `ebreak`
/// (a kernel loops on `rt.atominc` until the pixels run out). Returns the frame buffer's
/// bytes and the run's counts.
pub fn run_frame(
    prog: &Program,
    image: &MemoryImage,
    params: &[u8],
    frame_bytes: usize,
    local_store_bytes: u32,
    max_steps: u64,
) -> Result<(Vec<u8>, RunStats), RunError> {
    let mut mem = FrameMemory::new(image, params, frame_bytes);
    let mut hart = Hart::new(prog, local_store_bytes);
    let stats = run_to_halt(&mut hart, prog, &mut mem, max_steps)?;
    Ok((mem.frame, stats))
}
