//! Where the threads' cycles went, whichever thread model drives them.

use serde::{Deserialize, Serialize};

/// Why a thread waited (stall breakdown, in thread-cycles).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Stalls {
    /// Waiting for load data (L1 hit latency, L2, DRAM).
    pub memory: u64,
    /// Waiting for a pipeline result (latency).
    pub pipeline_latency: u64,
    /// Waiting for a free pipeline (contention with the TM's other threads).
    pub pipeline_busy: u64,
    /// Waiting for the shared reciprocal unit's result or a free slot on it.
    pub fpinv: u64,
    /// A bank already used this cycle: an L1 bank conflict, or an L2 bank refusing a miss
    /// (the thread retries until it is accepted).
    pub l1_bank: u64,
    /// Waiting for the global atomic unit (pixel hand-out).
    pub atomic: u64,
    /// Finished early while other threads still ran.
    pub idle: u64,
    /// Compiled kernels: waiting for an operand from a functional unit's latency (ALU, FP,
    /// pools, the reciprocal unit, the local store).
    #[serde(default)]
    pub dependency: u64,
    /// Compiled kernels: waiting for a free unit of a shared pool or the reciprocal unit.
    #[serde(default)]
    pub fu_busy: u64,
    /// Compiled kernels: an instruction-cache bank already served its fetches this cycle.
    #[serde(default)]
    pub icache: u64,
}

/// One cause of a stall: the counter of [`Stalls`] a thread model counts a wait under.
/// Both thread models count every stalled cycle through [`Stalls::count`], and a pending
/// result remembers the cause its wait will be counted under as one of these.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stall {
    /// [`Stalls::memory`].
    Memory,
    /// [`Stalls::pipeline_latency`].
    PipelineLatency,
    /// [`Stalls::pipeline_busy`].
    PipelineBusy,
    /// [`Stalls::fpinv`].
    Fpinv,
    /// [`Stalls::l1_bank`].
    L1Bank,
    /// [`Stalls::atomic`].
    Atomic,
    /// [`Stalls::idle`].
    Idle,
    /// [`Stalls::dependency`].
    Dependency,
    /// [`Stalls::fu_busy`].
    FuBusy,
    /// [`Stalls::icache`].
    Icache,
}

impl Stalls {
    /// Counts `cycles` stalled thread-cycles under `cause`.
    #[inline(always)]
    pub fn count(&mut self, cause: Stall, cycles: u64) {
        let c = match cause {
            Stall::Memory => &mut self.memory,
            Stall::PipelineLatency => &mut self.pipeline_latency,
            Stall::PipelineBusy => &mut self.pipeline_busy,
            Stall::Fpinv => &mut self.fpinv,
            Stall::L1Bank => &mut self.l1_bank,
            Stall::Atomic => &mut self.atomic,
            Stall::Idle => &mut self.idle,
            Stall::Dependency => &mut self.dependency,
            Stall::FuBusy => &mut self.fu_busy,
            Stall::Icache => &mut self.icache,
        };
        *c += cycles;
    }

    /// Adds `o`'s counts to these.
    pub fn add(&mut self, o: &Stalls) {
        let Stalls {
            memory,
            pipeline_latency,
            pipeline_busy,
            fpinv,
            l1_bank,
            atomic,
            idle,
            dependency,
            fu_busy,
            icache,
        } = *o;
        self.memory += memory;
        self.pipeline_latency += pipeline_latency;
        self.pipeline_busy += pipeline_busy;
        self.fpinv += fpinv;
        self.l1_bank += l1_bank;
        self.atomic += atomic;
        self.idle += idle;
        self.dependency += dependency;
        self.fu_busy += fu_busy;
        self.icache += icache;
    }
}
