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

impl Stalls {
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
