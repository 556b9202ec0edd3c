//! The simulator's configuration parser on arbitrary text: a configuration or a typed
//! error, never a panic; an accepted configuration passes its own range checks again and
//! its memory estimate at the largest frame does not overflow (debug arithmetic).
#![no_main]

use dualsplit_sim::footprint::Footprint;
use dualsplit_sim::{SimAccel, SimConfig, ThreadModel};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(cfg) = SimConfig::from_toml(text)
    {
        let _ = cfg.dram_peak_bytes_per_cycle();
        assert!(cfg.validate().is_ok());
        for model in [ThreadModel::Rv32, ThreadModel::Fast] {
            let _ = Footprint::estimate(&cfg, SimAccel::Bvh8Plus, model, 1 << 28).total();
        }
    }
});
