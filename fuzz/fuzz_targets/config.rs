//! The simulator's configuration parser on arbitrary text: a configuration or a typed
//! error, never a panic.
#![no_main]

use dualsplit_sim::SimConfig;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Ok(cfg) = SimConfig::from_toml(text)
    {
        let _ = cfg.dram_peak_bytes_per_cycle();
    }
});
