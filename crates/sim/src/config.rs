//! The hardware configuration: every parameter of the model, read from commented TOML
//! (`configs/lin2020.toml` is the paper's Table 1; Lin et al. 2020, §4, Table 1).
//!
//! Every field has a default equal to [`SimConfig::lin2020`], so a TOML file only needs the
//! values it changes; unknown keys are rejected (a measurement tool never ignores an option).

pub use crate::ranges::ConfigError;
use crate::ranges::{RANGES, Value};
use serde::{Deserialize, Serialize};

/// Hardware configuration of the simulated TRaX chip.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimConfig {
    /// Thread multiprocessors (TMs).
    pub tms: u32,
    /// Thread processors (TPs) per TM.
    pub tps_per_tm: u32,
    /// Core clock in GHz.
    pub clock_ghz: f64,
    /// The per-TM L1 data cache.
    #[serde(deserialize_with = "l1_partial")]
    pub l1: CacheConfig,
    /// The chip-wide L2 cache.
    #[serde(deserialize_with = "l2_partial")]
    pub l2: CacheConfig,
    /// GDDR5 main memory.
    pub dram: DramConfig,
    /// Functional units and pipelines per TM.
    pub units: UnitConfig,
    /// Energy per event.
    pub energy: EnergyConfig,
    /// Which variant of the compiled kernels the `rv32` model runs.
    pub kernels: KernelsConfig,
    /// The GPU chip of the `simt` model (absent on TRaX chips).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub simt: Option<crate::model::simt::config::SimtConfig>,
}

/// A cache: size, line, banks, associativity and hit latency.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CacheConfig {
    /// Capacity in bytes.
    pub size_bytes: u64,
    /// Line size in bytes (L1 and L2 must match).
    pub line_bytes: u64,
    /// Word-interleaved banks (bank = word address mod banks), one access per bank per cycle;
    /// a power of two.
    pub banks: u32,
    /// Ways per set (1 = direct-mapped, as in SimTRaX).
    pub associativity: u32,
    /// Hit latency in core cycles (for L2: on top of the L1 latency). lin2020's L2 takes 5:
    /// a CACTI 7 access time of 4.98 ns for 4 MB, 128 banks at 65 nm (`docs/sources.md`).
    pub hit_latency: u64,
    /// L2 only: bank = line address mod banks (`true`) or word address mod banks (`false`,
    /// the default and lin2020: SimTRaX `sim/L2Cache.cc:170`). Ignored for the L1, which
    /// word loads make word-interleaved.
    #[serde(default)]
    pub line_interleaved: bool,
    /// L2 only: a request that finds its bank taken in its cycle is refused and the thread
    /// issues nothing until the bank accepts it (`true`, SimTRaX `sim/L2Cache.cc:180-185`,
    /// retry `sim/IssueUnit.cc:769-787`), or only the request waits for its bank (`false`).
    /// Ignored for the L1.
    #[serde(default)]
    pub refuse_conflicts: bool,
}

/// A `[l1]` or `[l2]` table as written: the keys it leaves out keep that cache's
/// [`SimConfig::lin2020`] value (the L1's and the L2's defaults differ, so
/// `#[serde(default)]` on [`CacheConfig`] could not give them).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PartialCache {
    size_bytes: Option<u64>,
    line_bytes: Option<u64>,
    banks: Option<u32>,
    associativity: Option<u32>,
    hit_latency: Option<u64>,
    line_interleaved: Option<bool>,
    refuse_conflicts: Option<bool>,
}

impl PartialCache {
    fn over(self, d: CacheConfig) -> CacheConfig {
        CacheConfig {
            size_bytes: self.size_bytes.unwrap_or(d.size_bytes),
            line_bytes: self.line_bytes.unwrap_or(d.line_bytes),
            banks: self.banks.unwrap_or(d.banks),
            associativity: self.associativity.unwrap_or(d.associativity),
            hit_latency: self.hit_latency.unwrap_or(d.hit_latency),
            line_interleaved: self.line_interleaved.unwrap_or(d.line_interleaved),
            refuse_conflicts: self.refuse_conflicts.unwrap_or(d.refuse_conflicts),
        }
    }
}

fn l1_partial<'de, D: serde::Deserializer<'de>>(d: D) -> Result<CacheConfig, D::Error> {
    Ok(PartialCache::deserialize(d)?.over(SimConfig::lin2020().l1))
}

fn l2_partial<'de, D: serde::Deserializer<'de>>(d: D) -> Result<CacheConfig, D::Error> {
    Ok(PartialCache::deserialize(d)?.over(SimConfig::lin2020().l2))
}

/// GDDR5 main memory; timings in DRAM clock ticks (`ticks_per_cycle` per core cycle).
/// lin2020's timings are those SimTRaX ships for its "GDDR5" (USIMM's `1Gb_x16_amd2GHz.vi`):
/// DDR3-1600 values rescaled to a 2 GHz controller, and its organisation (8 KB rows,
/// 16 GB addressed) is not the paper's 2 GB (`docs/sources.md`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DramConfig {
    /// Channels (each with its own data bus).
    pub channels: u32,
    /// Banks per channel.
    pub banks_per_channel: u32,
    /// Bytes of one row of one channel.
    pub row_bytes: u64,
    /// DRAM controller ticks per core cycle.
    pub ticks_per_cycle: u64,
    /// Column access strobe latency.
    pub t_cas: u64,
    /// Activate-to-read delay.
    pub t_rcd: u64,
    /// Precharge time.
    pub t_rp: u64,
    /// Minimum activate-to-precharge time.
    pub t_ras: u64,
    /// Minimum activate-to-activate time in one bank.
    pub t_rc: u64,
    /// Minimum activate-to-activate time in one channel (different banks).
    pub t_rrd: u64,
    /// Read-to-precharge delay.
    pub t_rtp: u64,
    /// Column-to-column delay in one bank.
    pub t_ccd: u64,
    /// Data-bus occupancy of one 64-byte line.
    pub t_burst: u64,
    /// Four-activate window: at most four activations in any `t_faw` ticks of one channel
    /// (its one rank); 0 = no limit.
    pub t_faw: u64,
    /// Refresh cycle time of one refresh command.
    pub t_rfc: u64,
    /// Refresh interval; 0 = no refresh. USIMM issues `refresh_burst` refreshes together
    /// every `refresh_burst · t_refi` ticks: each channel is blocked for t_RP +
    /// `refresh_burst` · t_RFC ticks ending at that deadline, every row is closed, and no
    /// activation (column read) issues less than t_RAS (t_RTP) before the window.
    pub t_refi: u64,
    /// Refreshes per forced-refresh window (USIMM: 8).
    pub refresh_burst: u32,
    /// Read-queue entries per channel; a full queue stalls the request (back-pressure).
    pub read_queue: u32,
    /// USIMM's rule that a row is not precharged while a queued read still needs it: a
    /// read of a row that arrives before the precharge that closes it is served from it.
    pub keep_open: bool,
    /// Write-queue entries per channel (stores go through the L2 to it); 0 = stores are
    /// not sent to DRAM. A drain is reserved as soon as the queue passes `write_high`, so
    /// with `write_high` below it the queue never fills.
    pub write_queue: u32,
    /// Write drain starts when the write queue holds more than this many writes.
    pub write_high: u32,
    /// Write drain stops when the write queue holds this many writes or fewer (or
    /// `write_high`, if that is fewer).
    pub write_low: u32,
    /// Column-write to data delay.
    pub t_cwd: u64,
    /// Write recovery: end of the write data to the bank's precharge.
    pub t_wr: u64,
    /// Write-to-read turnaround: end of the write data to the channel's next column read.
    pub t_wtr: u64,
    /// Energy of one 64-byte read burst, nJ.
    pub e_read_nj: f64,
    /// Energy of one row activation (and its precharge), nJ.
    pub e_activate_nj: f64,
    /// Background plus refresh power of all channels, W.
    pub background_w: f64,
}

/// Functional units and fixed-function pipelines of one TM.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct UnitConfig {
    /// Ray-box pipelines of the serial configurations (BVH2/4/8); the "+" configurations
    /// have as many as the node's arity.
    pub box_pipes: u32,
    /// Ray-box pipeline latency (cycles, initiation interval 1).
    pub box_latency: u64,
    /// Ray-triangle pipelines (the paper gives no count; lin2020 assumes one per TM).
    pub tri_pipes: u32,
    /// Ray-triangle pipeline latency.
    pub tri_latency: u64,
    /// Dual-split pipelines.
    pub dst_pipes: u32,
    /// Dual-split pipeline latency.
    pub dst_latency: u64,
    /// Latency of a quantized ray-box pipeline (the CWBVH configurations' ray-box pipelines:
    /// a dequantization stage in front of a ray-box pipeline).
    pub qbox_latency: u64,
    /// Latency of the quantized dual-split pipeline (DST-Q: a dequantization stage in front
    /// of the dual-split pipeline).
    pub qdst_latency: u64,
    /// Shared reciprocal / inverse-square-root units.
    pub fpinv_units: u32,
    /// Their latency.
    pub fpinv_latency: u64,
    /// Latency of the global atomic increment that hands out pixels.
    pub atomic_latency: u64,
    /// Compiled kernels: latency of a TP's own integer ALU (also FP sign/move ops).
    pub int_latency: u64,
    /// Compiled kernels: latency of a TP's own FP adder.
    pub fpadd_latency: u64,
    /// Compiled kernels: latency of a TP's own FP multiplier.
    pub fpmul_latency: u64,
    /// Compiled kernels: integer ALUs (add and bitwise) per TM shared by its TPs; 0 = each
    /// TP has its own (paper §2.3). SimTRaX's `bigcache.config:16` has INTADD 16.
    pub int_units: u32,
    /// Compiled kernels: FP adders per TM shared by its TPs; 0 = each TP has its own.
    pub fpadd_units: u32,
    /// Compiled kernels: FP multipliers per TM shared by its TPs; 0 = each TP has its own.
    pub fpmul_units: u32,
    /// Compiled kernels: FP compare units per TM (shared pool).
    pub fpcmp_units: u32,
    /// Their latency.
    pub fpcmp_latency: u64,
    /// Compiled kernels: FP min/max units per TM (shared pool).
    pub fpminmax_units: u32,
    /// Their latency.
    pub fpminmax_latency: u64,
    /// Compiled kernels: int/FP conversion units per TM (shared pool).
    pub conv_units: u32,
    /// Their latency.
    pub conv_latency: u64,
    /// Compiled kernels: branch units per TM (shared pool).
    pub branch_units: u32,
    /// Their latency.
    pub branch_latency: u64,
    /// Compiled kernels: integer multipliers per TM (shared pool).
    pub intmul_units: u32,
    /// Their latency.
    pub intmul_latency: u64,
    /// Compiled kernels: latency of a TP's local store (its stack).
    pub local_store_latency: u64,
    /// Compiled kernels: bytes of each TP's local store.
    pub local_store_bytes: u32,
    /// Compiled kernels: instruction caches per TM; thread `i` fetches from cache
    /// `i mod icaches`.
    pub icaches: u32,
    /// Banks of each instruction cache (bank = instruction index mod banks; a power of two).
    pub icache_banks: u32,
    /// Fetches one bank serves per cycle (0 = no limit).
    pub icache_fetches: u32,
}

/// Energy per event in nanojoules (65 nm).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EnergyConfig {
    /// Integer add, branch, bitwise op.
    pub int_nj: f64,
    /// FP add/sub.
    pub fpadd_nj: f64,
    /// FP multiply.
    pub fpmul_nj: f64,
    /// FP min/max/compare.
    pub fpcmp_nj: f64,
    /// FP reciprocal / inverse square root.
    pub fpinv_nj: f64,
    /// One register-file access (3 per instruction).
    pub rf_access_nj: f64,
    /// One instruction-cache fetch (1 per instruction).
    pub icache_nj: f64,
    /// One local-store (stack) access.
    pub local_store_nj: f64,
    /// One L1 access (per load word).
    pub l1_nj: f64,
    /// One L2 access.
    pub l2_nj: f64,
    /// One ray-box pipeline op.
    pub box_pipe_nj: f64,
    /// One ray-triangle pipeline op.
    pub tri_pipe_nj: f64,
    /// One dual-split pipeline op.
    pub dst_pipe_nj: f64,
    /// One quantized ray-box pipeline op (one child box dequantized and tested).
    pub qbox_pipe_nj: f64,
    /// One quantized dual-split pipeline op (two planes dequantized, one node tested).
    pub qdst_pipe_nj: f64,
}

/// The variant of the compiled kernels (`kernels/`): the `[kernels]` table. The default
/// (lin2020) is the one the sources describe: the paper's traversals (`parity = true`) and
/// SimTRaX's pipeline input registers (`node_fetch = "loads"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct KernelsConfig {
    /// `true`: the traversals as Lin et al. 2020 describe them (§4: "ray-box intersection
    /// tests are executed serially for each box in a BVH node", empty slots holding
    /// degenerate boxes, §4.2, then the hits are ordered, §4.4; the DST ray is clipped to
    /// the scene box by one `rt.box`); `false`: the serial BVH kernels test only the present
    /// children and the DST kernels clip in software.
    pub parity: bool,
    /// How the ray-tracing instructions get their node words.
    pub node_fetch: NodeFetch,
    /// `true`: the frame's shadow rays are traced as its render settings ask (one at every
    /// hit by default); `false`: no shadow rays, the light sample counted as visible
    /// (`RenderSettings::shadows`). A key of the chip's configuration so that a study can
    /// vary it; the paper does not say whether its path tracer casts shadow rays.
    pub shadows: bool,
    /// How the serial and "+" BVH kernels order a node's hit children (a reading of §4.4's
    /// "additional operations for child node ordering"; the paper does not give the
    /// method). Only with `parity` and `node_fetch = "loads"` (the other variants are not
    /// built with it).
    pub child_order: ChildOrder,
}

/// How a BVH kernel puts a node's hit children in traversal order. Both give the same
/// order (nearest first, ties in slot order), so the same rays visit the same nodes; they
/// differ in the instructions spent on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ChildOrder {
    /// Each hit child is inserted into the order as its box test returns (an insertion
    /// sort of the hits only): the renderer's traversal, written as kernel code.
    #[default]
    Hits,
    /// Every slot's entry distance, a miss as +∞, is sorted by a sorting network over all
    /// of the node's slots (1, 5 and 19 compare-exchanges for BVH2, BVH4 and BVH8), then
    /// the hits are pushed: a fixed cost per node, as a hardware-minded kernel might do it.
    /// A reading of §4.4, not a source.
    AllSlots,
}

impl ChildOrder {
    /// Its TOML spelling.
    pub fn name(self) -> &'static str {
        match self {
            ChildOrder::Hits => "hits",
            ChildOrder::AllSlots => "all-slots",
        }
    }
}

impl Default for KernelsConfig {
    fn default() -> Self {
        Self {
            parity: true,
            node_fetch: NodeFetch::Loads,
            shadows: true,
            child_order: ChildOrder::Hits,
        }
    }
}

/// How the kernels hand node words to the ray-box, ray-triangle and dual-split pipelines
/// (`docs/isa.md`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NodeFetch {
    /// `rt.box`, `rt.boxn`, `rt.tri`, `rt.dst` read their words through a memory operand,
    /// all in one issue.
    Operand,
    /// One `rt.ldp` per word into the pipeline input registers, then the register form:
    /// SimTRaX's `LOADPIPEGLB` form (`sim/Instruction.h`, lines 110–111).
    #[default]
    Loads,
}

impl NodeFetch {
    /// Its TOML spelling.
    pub fn name(self) -> &'static str {
        match self {
            NodeFetch::Operand => "operand",
            NodeFetch::Loads => "loads",
        }
    }
}

impl KernelsConfig {
    /// The variant's index among [`KernelsConfig::ALL`] (`shadows` is read at run time
    /// from the parameter block, not a variant of the compiled kernels). `child_order =
    /// "all-slots"` is built with `parity` and `"loads"` only ([`SimConfig::validate`]).
    pub fn index(self) -> usize {
        if self.child_order == ChildOrder::AllSlots {
            return 4;
        }
        self.parity as usize | ((self.node_fetch == NodeFetch::Loads) as usize) << 1
    }

    /// Every variant of the compiled kernels, in the order of [`KernelsConfig::index`]
    /// (with shadow rays).
    pub const ALL: [KernelsConfig; 5] = [
        KernelsConfig {
            parity: false,
            node_fetch: NodeFetch::Operand,
            shadows: true,
            child_order: ChildOrder::Hits,
        },
        KernelsConfig {
            parity: true,
            node_fetch: NodeFetch::Operand,
            shadows: true,
            child_order: ChildOrder::Hits,
        },
        KernelsConfig {
            parity: false,
            node_fetch: NodeFetch::Loads,
            shadows: true,
            child_order: ChildOrder::Hits,
        },
        KernelsConfig {
            parity: true,
            node_fetch: NodeFetch::Loads,
            shadows: true,
            child_order: ChildOrder::Hits,
        },
        KernelsConfig {
            parity: true,
            node_fetch: NodeFetch::Loads,
            shadows: true,
            child_order: ChildOrder::AllSlots,
        },
    ];

    /// The suffix of its kernels' file names (`kernels/Makefile`): `""`, `-parity`,
    /// `-loads`, `-parity-loads` or `-parity-loads-sortall`.
    pub fn suffix(self) -> &'static str {
        [
            "",
            "-parity",
            "-loads",
            "-parity-loads",
            "-parity-loads-sortall",
        ][self.index()]
    }
}

impl Default for SimConfig {
    fn default() -> Self {
        Self::lin2020()
    }
}

impl Default for DramConfig {
    fn default() -> Self {
        SimConfig::lin2020().dram
    }
}

impl Default for UnitConfig {
    fn default() -> Self {
        SimConfig::lin2020().units
    }
}

impl Default for EnergyConfig {
    fn default() -> Self {
        SimConfig::lin2020().energy
    }
}

impl SimConfig {
    /// The paper's Table 1 configuration (Lin et al. 2020, §4, Table 1), with the parameters
    /// the paper does not give taken from SimTRaX as documented in `configs/lin2020.toml`.
    pub fn lin2020() -> Self {
        Self {
            tms: 64,
            tps_per_tm: 32,
            clock_ghz: 1.0,
            l1: CacheConfig {
                size_bytes: 64 * 1024,
                line_bytes: 64,
                banks: 16,
                associativity: 1,
                hit_latency: 1,
                line_interleaved: false, // ignored: the L1 is word-interleaved
                refuse_conflicts: false, // ignored: an L1 conflict stalls the thread's issue
            },
            l2: CacheConfig {
                size_bytes: 4 * 1024 * 1024,
                line_bytes: 64,
                banks: 128,
                associativity: 1,
                hit_latency: 5,
                line_interleaved: false,
                refuse_conflicts: true,
            },
            dram: DramConfig {
                channels: 16,
                banks_per_channel: 16,
                row_bytes: 8192,
                ticks_per_cycle: 2,
                t_cas: 28,
                t_rcd: 28,
                t_rp: 28,
                t_ras: 70,
                t_rc: 98,
                t_rrd: 13,
                t_rtp: 15,
                t_ccd: 4,
                t_burst: 4,
                t_faw: 80,
                t_rfc: 220,
                t_refi: 15600,
                refresh_burst: 8,
                read_queue: 80,
                keep_open: true,
                write_queue: 80,
                write_high: 40,
                write_low: 20,
                t_cwd: 13,
                t_wr: 30,
                t_wtr: 15,
                e_read_nj: 9.8,
                e_activate_nj: 61.3,
                background_w: 26.7,
            },
            units: UnitConfig {
                box_pipes: 1,
                box_latency: 8,
                tri_pipes: 1,
                tri_latency: 24,
                dst_pipes: 1,
                dst_latency: 8,
                qbox_latency: 11,
                qdst_latency: 11,
                fpinv_units: 1,
                fpinv_latency: 16,
                atomic_latency: 4,
                int_latency: 1,
                fpadd_latency: 2,
                fpmul_latency: 2,
                int_units: 0,
                fpadd_units: 0,
                fpmul_units: 0,
                fpcmp_units: 16,
                fpcmp_latency: 1,
                fpminmax_units: 16,
                fpminmax_latency: 1,
                conv_units: 16,
                conv_latency: 1,
                branch_units: 16,
                branch_latency: 1,
                intmul_units: 2,
                intmul_latency: 1,
                local_store_latency: 1,
                local_store_bytes: 4096,
                icaches: 2,
                icache_banks: 16,
                icache_fetches: 2,
            },
            energy: EnergyConfig {
                int_nj: 0.000572,
                fpadd_nj: 0.0074,
                fpmul_nj: 0.0142,
                fpcmp_nj: 0.000536,
                fpinv_nj: 0.1563,
                rf_access_nj: 0.00789613,
                icache_nj: 0.01349,
                local_store_nj: 0.00692867,
                l1_nj: 0.3107,
                l2_nj: 1.71,
                box_pipe_nj: 0.1377,
                tri_pipe_nj: 0.71,
                dst_pipe_nj: 0.0610,
                qbox_pipe_nj: 0.1890,
                qdst_pipe_nj: 0.0781,
            },
            kernels: KernelsConfig {
                parity: true,
                node_fetch: NodeFetch::Loads,
                shadows: true,
                child_order: ChildOrder::Hits,
            },
            simt: None,
        }
    }

    /// Parses a TOML configuration (missing keys take the [`SimConfig::lin2020`] values) and
    /// validates it.
    pub fn from_toml(text: &str) -> Result<Self, ConfigError> {
        let cfg: SimConfig = toml::from_str(text)?;
        cfg.validate()?;
        Ok(cfg)
    }

    /// Checks every value against its documented range ([`RANGES`]) and the relations
    /// between values the engine relies on (equal L1 and L2 lines, power-of-two sets).
    pub fn validate(&self) -> Result<(), ConfigError> {
        if let Some(simt) = &self.simt {
            simt.validate()?;
        }
        // `values()` lists the keys in `RANGES`' order (tested).
        for ((key, value), range) in self.values().into_iter().zip(RANGES) {
            debug_assert_eq!(key, range.key);
            range.check(value)?;
        }
        for (key, c) in [("l1", &self.l1), ("l2", &self.l2)] {
            let lines = c.size_bytes / c.line_bytes;
            let sets = lines / c.associativity as u64;
            if c.size_bytes % c.line_bytes != 0
                || lines % c.associativity as u64 != 0
                || !sets.is_power_of_two()
            {
                return Err(ConfigError::Invalid {
                    field: if key == "l1" {
                        "l1.size_bytes"
                    } else {
                        "l2.size_bytes"
                    },
                    value: c.size_bytes.to_string(),
                    reason: format!(
                        "{} lines of {} bytes in {}-way sets must make a power-of-two number of sets",
                        lines, c.line_bytes, c.associativity
                    ),
                });
            }
        }
        let d = &self.dram;
        let burst = u64::from(d.refresh_burst);
        if d.t_refi != 0 && d.t_refi * burst <= d.t_rp + d.t_rfc * burst + d.t_ras {
            return Err(ConfigError::Invalid {
                field: "dram.t_refi",
                value: d.t_refi.to_string(),
                reason: format!(
                    "{burst} refresh intervals must exceed the refresh window t_rp + {burst} × \
                     t_rfc plus t_ras ({} ticks), or t_refi be 0 for no refresh",
                    d.t_rp + d.t_rfc * burst + d.t_ras
                ),
            });
        }
        let k = &self.kernels;
        if k.child_order == ChildOrder::AllSlots && !(k.parity && k.node_fetch == NodeFetch::Loads)
        {
            return Err(ConfigError::Invalid {
                field: "kernels.child_order",
                value: k.child_order.name().into(),
                reason: "the all-slots kernels are built with parity = true and node_fetch = \"loads\" only".into(),
            });
        }
        if self.l1.line_bytes != self.l2.line_bytes {
            return Err(ConfigError::Invalid {
                field: "l2.line_bytes",
                value: self.l2.line_bytes.to_string(),
                reason: "L1 and L2 lines must both be 64 bytes (one DRAM burst pair)".into(),
            });
        }
        Ok(())
    }

    /// Every key of the configuration with its value, in TOML key form.
    pub fn values(&self) -> Vec<(&'static str, Value)> {
        use Value::{Flag, Int, Real};
        let (l1, l2, d, u, e) = (&self.l1, &self.l2, &self.dram, &self.units, &self.energy);
        let int = |v: u32| Int(v as u64);
        vec![
            ("tms", int(self.tms)),
            ("tps_per_tm", int(self.tps_per_tm)),
            ("clock_ghz", Real(self.clock_ghz)),
            ("l1.size_bytes", Int(l1.size_bytes)),
            ("l1.line_bytes", Int(l1.line_bytes)),
            ("l1.banks", int(l1.banks)),
            ("l1.associativity", int(l1.associativity)),
            ("l1.hit_latency", Int(l1.hit_latency)),
            ("l1.line_interleaved", Flag(l1.line_interleaved)),
            ("l1.refuse_conflicts", Flag(l1.refuse_conflicts)),
            ("l2.size_bytes", Int(l2.size_bytes)),
            ("l2.line_bytes", Int(l2.line_bytes)),
            ("l2.banks", int(l2.banks)),
            ("l2.associativity", int(l2.associativity)),
            ("l2.hit_latency", Int(l2.hit_latency)),
            ("l2.line_interleaved", Flag(l2.line_interleaved)),
            ("l2.refuse_conflicts", Flag(l2.refuse_conflicts)),
            ("dram.channels", int(d.channels)),
            ("dram.banks_per_channel", int(d.banks_per_channel)),
            ("dram.row_bytes", Int(d.row_bytes)),
            ("dram.ticks_per_cycle", Int(d.ticks_per_cycle)),
            ("dram.t_cas", Int(d.t_cas)),
            ("dram.t_rcd", Int(d.t_rcd)),
            ("dram.t_rp", Int(d.t_rp)),
            ("dram.t_ras", Int(d.t_ras)),
            ("dram.t_rc", Int(d.t_rc)),
            ("dram.t_rrd", Int(d.t_rrd)),
            ("dram.t_rtp", Int(d.t_rtp)),
            ("dram.t_ccd", Int(d.t_ccd)),
            ("dram.t_burst", Int(d.t_burst)),
            ("dram.t_faw", Int(d.t_faw)),
            ("dram.t_rfc", Int(d.t_rfc)),
            ("dram.t_refi", Int(d.t_refi)),
            ("dram.refresh_burst", int(d.refresh_burst)),
            ("dram.read_queue", int(d.read_queue)),
            ("dram.keep_open", Flag(d.keep_open)),
            ("dram.write_queue", int(d.write_queue)),
            ("dram.write_high", int(d.write_high)),
            ("dram.write_low", int(d.write_low)),
            ("dram.t_cwd", Int(d.t_cwd)),
            ("dram.t_wr", Int(d.t_wr)),
            ("dram.t_wtr", Int(d.t_wtr)),
            ("dram.e_read_nj", Real(d.e_read_nj)),
            ("dram.e_activate_nj", Real(d.e_activate_nj)),
            ("dram.background_w", Real(d.background_w)),
            ("units.box_pipes", int(u.box_pipes)),
            ("units.box_latency", Int(u.box_latency)),
            ("units.tri_pipes", int(u.tri_pipes)),
            ("units.tri_latency", Int(u.tri_latency)),
            ("units.dst_pipes", int(u.dst_pipes)),
            ("units.dst_latency", Int(u.dst_latency)),
            ("units.qbox_latency", Int(u.qbox_latency)),
            ("units.qdst_latency", Int(u.qdst_latency)),
            ("units.fpinv_units", int(u.fpinv_units)),
            ("units.fpinv_latency", Int(u.fpinv_latency)),
            ("units.atomic_latency", Int(u.atomic_latency)),
            ("units.int_latency", Int(u.int_latency)),
            ("units.fpadd_latency", Int(u.fpadd_latency)),
            ("units.fpmul_latency", Int(u.fpmul_latency)),
            ("units.int_units", int(u.int_units)),
            ("units.fpadd_units", int(u.fpadd_units)),
            ("units.fpmul_units", int(u.fpmul_units)),
            ("units.fpcmp_units", int(u.fpcmp_units)),
            ("units.fpcmp_latency", Int(u.fpcmp_latency)),
            ("units.fpminmax_units", int(u.fpminmax_units)),
            ("units.fpminmax_latency", Int(u.fpminmax_latency)),
            ("units.conv_units", int(u.conv_units)),
            ("units.conv_latency", Int(u.conv_latency)),
            ("units.branch_units", int(u.branch_units)),
            ("units.branch_latency", Int(u.branch_latency)),
            ("units.intmul_units", int(u.intmul_units)),
            ("units.intmul_latency", Int(u.intmul_latency)),
            ("units.local_store_latency", Int(u.local_store_latency)),
            ("units.local_store_bytes", int(u.local_store_bytes)),
            ("units.icaches", int(u.icaches)),
            ("units.icache_banks", int(u.icache_banks)),
            ("units.icache_fetches", int(u.icache_fetches)),
            ("energy.int_nj", Real(e.int_nj)),
            ("energy.fpadd_nj", Real(e.fpadd_nj)),
            ("energy.fpmul_nj", Real(e.fpmul_nj)),
            ("energy.fpcmp_nj", Real(e.fpcmp_nj)),
            ("energy.fpinv_nj", Real(e.fpinv_nj)),
            ("energy.rf_access_nj", Real(e.rf_access_nj)),
            ("energy.icache_nj", Real(e.icache_nj)),
            ("energy.local_store_nj", Real(e.local_store_nj)),
            ("energy.l1_nj", Real(e.l1_nj)),
            ("energy.l2_nj", Real(e.l2_nj)),
            ("energy.box_pipe_nj", Real(e.box_pipe_nj)),
            ("energy.tri_pipe_nj", Real(e.tri_pipe_nj)),
            ("energy.dst_pipe_nj", Real(e.dst_pipe_nj)),
            ("energy.qbox_pipe_nj", Real(e.qbox_pipe_nj)),
            ("energy.qdst_pipe_nj", Real(e.qdst_pipe_nj)),
            ("kernels.parity", Flag(self.kernels.parity)),
            (
                "kernels.node_fetch",
                Value::Choice(self.kernels.node_fetch.name()),
            ),
            ("kernels.shadows", Flag(self.kernels.shadows)),
            (
                "kernels.child_order",
                Value::Choice(self.kernels.child_order.name()),
            ),
        ]
    }

    /// Peak DRAM bandwidth in bytes per core cycle (64 B per `t_burst` per channel).
    pub fn dram_peak_bytes_per_cycle(&self) -> f64 {
        64.0 * self.dram.channels as f64 * self.dram.ticks_per_cycle as f64
            / self.dram.t_burst as f64
    }
}
