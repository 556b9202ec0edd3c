//! The documented range of every configuration key ([`RANGES`]), checked when a
//! configuration is loaded ([`crate::SimConfig::validate`]).
//!
//! The bounds keep every quantity the engine derives from the configuration far from
//! overflow, so its arithmetic needs no run-time checks: counts multiply to at most 2^20
//! threads and 2^20 DRAM banks, a latency is at most 2^16 cycles (2^16 DRAM ticks), so a
//! 64-bit cycle count would need more than 2^47 dependent operations of the longest
//! latency to wrap, and every energy is a finite number of nanojoules, so a frame's energy
//! is a finite sum of finite products. They are wide enough for any chip the paper's
//! model describes (the paper's Table 1 chip sits well inside each); what fits the host's
//! memory is checked separately ([`crate::footprint`]).

/// Why a configuration was rejected.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The TOML did not parse or had an unknown key.
    #[error("config parse error: {0}")]
    Parse(#[from] toml::de::Error),
    /// A value is out of range.
    #[error("config value `{field}` = {value} is invalid: {reason}")]
    Invalid {
        /// The key, as written in the TOML (`l1.hit_latency`).
        field: &'static str,
        /// Its value as given.
        value: String,
        /// What it must be.
        reason: String,
    },
}

/// A configuration value as read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// A count, size or latency.
    Int(u64),
    /// A clock, energy or power.
    Real(f64),
    /// A switch (any value is valid).
    Flag(bool),
    /// One of a key's named choices.
    Choice(&'static str),
}

/// The valid values of one key.
#[derive(Clone, Copy, Debug)]
pub struct KeyRange {
    /// The key, as written in the TOML.
    pub key: &'static str,
    /// Smallest valid value.
    pub min: f64,
    /// Largest valid value.
    pub max: f64,
    /// The value must be a power of two.
    pub pow2: bool,
    /// The value must be a multiple of this (1: any).
    pub multiple: u64,
    /// The unit, for messages and the documentation.
    pub unit: &'static str,
    /// The valid names of a [`Value::Choice`] key (empty for the others).
    pub choices: &'static [&'static str],
}

const fn int(key: &'static str, min: u64, max: u64, unit: &'static str) -> KeyRange {
    KeyRange {
        key,
        min: min as f64,
        max: max as f64,
        pow2: false,
        multiple: 1,
        unit,
        choices: &[],
    }
}

const fn pow2(key: &'static str, min: u64, max: u64, unit: &'static str) -> KeyRange {
    KeyRange {
        pow2: true,
        ..int(key, min, max, unit)
    }
}

const fn real(key: &'static str, min: f64, max: f64, unit: &'static str) -> KeyRange {
    KeyRange {
        key,
        min,
        max,
        pow2: false,
        multiple: 1,
        unit,
        choices: &[],
    }
}

const fn flag(key: &'static str) -> KeyRange {
    real(key, 0.0, 1.0, "true or false")
}

const fn choice(key: &'static str, choices: &'static [&'static str]) -> KeyRange {
    KeyRange {
        choices,
        ..real(key, 0.0, 0.0, "")
    }
}

/// The longest latency of any unit, cache or DRAM timing (cycles or ticks).
pub const MAX_LATENCY: u64 = 1 << 16;
/// The most units or pipelines of one kind per TM.
const MAX_UNITS: u64 = 64;
/// The largest energy of one event, nJ (a millijoule).
const MAX_NJ: f64 = 1e6;

/// Every key of [`crate::SimConfig`] with its valid values (`docs/robustness.md` lists
/// them; a test checks that every key has exactly one entry).
pub const RANGES: &[KeyRange] = &[
    int("tms", 1, 1024, "TMs"),
    int("tps_per_tm", 1, 1024, "TPs"),
    real("clock_ghz", 0.001, 1000.0, "GHz"),
    int("l1.size_bytes", 64, 1 << 30, "bytes"),
    int("l1.line_bytes", 64, 64, "bytes"),
    pow2("l1.banks", 1, 4096, "banks"),
    int("l1.associativity", 1, 64, "ways"),
    int("l1.hit_latency", 1, MAX_LATENCY, "cycles"),
    flag("l1.line_interleaved"),
    flag("l1.refuse_conflicts"),
    int("l2.size_bytes", 64, 1 << 30, "bytes"),
    int("l2.line_bytes", 64, 64, "bytes"),
    pow2("l2.banks", 1, 4096, "banks"),
    int("l2.associativity", 1, 64, "ways"),
    int("l2.hit_latency", 0, MAX_LATENCY, "cycles"),
    flag("l2.line_interleaved"),
    flag("l2.refuse_conflicts"),
    pow2("dram.channels", 1, 1024, "channels"),
    pow2("dram.banks_per_channel", 1, 1024, "banks"),
    pow2("dram.row_bytes", 64, 1 << 20, "bytes"),
    int("dram.ticks_per_cycle", 1, 64, "ticks"),
    int("dram.t_cas", 0, MAX_LATENCY, "ticks"),
    int("dram.t_rcd", 0, MAX_LATENCY, "ticks"),
    int("dram.t_rp", 0, MAX_LATENCY, "ticks"),
    int("dram.t_ras", 0, MAX_LATENCY, "ticks"),
    int("dram.t_rc", 0, MAX_LATENCY, "ticks"),
    // The activate window is a 64-tick bitmask per channel (`hw/memory/dram/channel.rs`, a `SparseSlots` span).
    int("dram.t_rrd", 0, 64, "ticks"),
    int("dram.t_rtp", 0, MAX_LATENCY, "ticks"),
    int("dram.t_ccd", 0, MAX_LATENCY, "ticks"),
    int("dram.t_burst", 1, MAX_LATENCY, "ticks"),
    int("dram.t_faw", 0, MAX_LATENCY, "ticks"),
    int("dram.t_rfc", 0, MAX_LATENCY, "ticks"),
    int("dram.t_refi", 0, 1 << 24, "ticks"),
    int("dram.refresh_burst", 1, 64, "refreshes"),
    int("dram.read_queue", 1, 1 << 16, "entries"),
    flag("dram.keep_open"),
    int("dram.write_queue", 0, 1 << 16, "entries"),
    int("dram.write_high", 0, 1 << 16, "entries"),
    int("dram.write_low", 0, 1 << 16, "entries"),
    int("dram.t_cwd", 0, MAX_LATENCY, "ticks"),
    int("dram.t_wr", 0, MAX_LATENCY, "ticks"),
    int("dram.t_wtr", 0, MAX_LATENCY, "ticks"),
    real("dram.e_read_nj", 0.0, MAX_NJ, "nJ"),
    real("dram.e_activate_nj", 0.0, MAX_NJ, "nJ"),
    real("dram.background_w", 0.0, 1e6, "W"),
    int("units.box_pipes", 1, MAX_UNITS, "pipelines"),
    int("units.box_latency", 1, MAX_LATENCY, "cycles"),
    int("units.tri_pipes", 1, MAX_UNITS, "pipelines"),
    int("units.tri_latency", 1, MAX_LATENCY, "cycles"),
    int("units.dst_pipes", 1, MAX_UNITS, "pipelines"),
    int("units.dst_latency", 1, MAX_LATENCY, "cycles"),
    int("units.qbox_latency", 1, MAX_LATENCY, "cycles"),
    int("units.qdst_latency", 1, MAX_LATENCY, "cycles"),
    int("units.fpinv_units", 1, MAX_UNITS, "units"),
    int("units.fpinv_latency", 1, MAX_LATENCY, "cycles"),
    int("units.atomic_latency", 1, MAX_LATENCY, "cycles"),
    int("units.int_latency", 1, MAX_LATENCY, "cycles"),
    int("units.fpadd_latency", 1, MAX_LATENCY, "cycles"),
    int("units.fpmul_latency", 1, MAX_LATENCY, "cycles"),
    int("units.int_units", 0, MAX_UNITS, "units"),
    int("units.fpadd_units", 0, MAX_UNITS, "units"),
    int("units.fpmul_units", 0, MAX_UNITS, "units"),
    int("units.fpcmp_units", 1, MAX_UNITS, "units"),
    int("units.fpcmp_latency", 1, MAX_LATENCY, "cycles"),
    int("units.fpminmax_units", 1, MAX_UNITS, "units"),
    int("units.fpminmax_latency", 1, MAX_LATENCY, "cycles"),
    int("units.conv_units", 1, MAX_UNITS, "units"),
    int("units.conv_latency", 1, MAX_LATENCY, "cycles"),
    int("units.branch_units", 1, MAX_UNITS, "units"),
    int("units.branch_latency", 1, MAX_LATENCY, "cycles"),
    int("units.intmul_units", 1, MAX_UNITS, "units"),
    int("units.intmul_latency", 1, MAX_LATENCY, "cycles"),
    int("units.local_store_latency", 1, MAX_LATENCY, "cycles"),
    KeyRange {
        multiple: 16,
        ..int("units.local_store_bytes", 1024, 1 << 20, "bytes")
    },
    int("units.icaches", 1, MAX_UNITS, "caches"),
    pow2("units.icache_banks", 1, 1024, "banks"),
    int("units.icache_fetches", 0, MAX_UNITS, "fetches per cycle"),
    real("energy.int_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.fpadd_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.fpmul_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.fpcmp_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.fpinv_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.rf_access_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.icache_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.local_store_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.l1_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.l2_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.box_pipe_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.tri_pipe_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.dst_pipe_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.qbox_pipe_nj", 0.0, MAX_NJ, "nJ"),
    real("energy.qdst_pipe_nj", 0.0, MAX_NJ, "nJ"),
    flag("kernels.parity"),
    choice("kernels.node_fetch", &["operand", "loads"]),
    flag("kernels.shadows"),
    choice("kernels.child_order", &["hits", "all-slots"]),
];

impl KeyRange {
    /// What the value must be, in words (`an integer from 1 to 1024 TMs`).
    pub fn describe(&self) -> String {
        if self.unit == "true or false" {
            return "true or false".into();
        }
        if !self.choices.is_empty() {
            let quoted: Vec<String> = self.choices.iter().map(|c| format!("\"{c}\"")).collect();
            return quoted.join(" or ");
        }
        let num = |v: f64| {
            if v.fract() == 0.0 && v.abs() < 1e15 {
                format!("{}", v as u64)
            } else {
                format!("{v}")
            }
        };
        let what = match (self.pow2, self.multiple) {
            (true, _) => "a power of two".to_string(),
            (false, 1) if self.unit == "GHz" || self.unit == "nJ" || self.unit == "W" => {
                "a finite number".to_string()
            }
            (false, 1) => "an integer".to_string(),
            (false, m) => format!("a multiple of {m}"),
        };
        if self.min == self.max {
            format!("{} {}", num(self.min), self.unit)
        } else {
            format!(
                "{what} from {} to {} {}",
                num(self.min),
                num(self.max),
                self.unit
            )
        }
    }

    /// Checks `value` against this range.
    pub fn check(&self, value: Value) -> Result<(), ConfigError> {
        let (ok, shown) = match value {
            Value::Flag(b) => (true, b.to_string()),
            Value::Choice(c) => (self.choices.contains(&c), format!("\"{c}\"")),
            Value::Int(v) => (
                (v as f64) >= self.min
                    && (v as f64) <= self.max
                    && (!self.pow2 || v.is_power_of_two())
                    && v.is_multiple_of(self.multiple),
                v.to_string(),
            ),
            // `!(a ≤ v ≤ b)` also refuses NaN.
            Value::Real(v) => (v >= self.min && v <= self.max, v.to_string()),
        };
        if ok {
            Ok(())
        } else {
            Err(ConfigError::Invalid {
                field: self.key,
                value: shown,
                reason: format!("must be {}", self.describe()),
            })
        }
    }
}
