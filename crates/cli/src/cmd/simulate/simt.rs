//! The table `dualsplit simulate --model simt` prints: the GPU's figures (RT units, SIMT
//! efficiency, transactions, memory) instead of the TRaX chip's.

use dualsplit_report::units;
use dualsplit_sim::SimResult;
use dualsplit_sim::model::simt::config::SimtConfig;
use std::time::Duration;

/// Prints the header, one block per configuration and, for several, a comparison.
pub fn print(
    scene: &str,
    triangles: usize,
    size: (u32, u32, &str),
    c: &SimtConfig,
    results: &[(SimResult, Duration)],
) {
    outln!(
        "scene {scene} ({triangles} triangles), {}×{} {}, {} SMs × {} warps of {}, RT unit {} warps / {} MSHRs, simt thread model (no energy: no source gives one)",
        size.0,
        size.1,
        size.2,
        c.sms,
        c.warps_per_sm,
        c.warp_size,
        c.rt_max_warps,
        c.rt_max_mshr
    );
    for (r, host) in results {
        let Some(f) = &r.simt else { continue };
        outln!("== {}", r.accel.map_or("?", |a| a.label()));
        outln!(
            "  frame time     {} ({} cycles), {} rays",
            units::time_ms(r.frame_ms),
            r.cycles,
            r.rays
        );
        outln!(
            "  RT units       occupancy {:.1} %, SIMT efficiency {:.1} % (outside {:.1} %, {} of {} warp phases divergent)",
            100.0 * f.rt_occupancy,
            100.0 * f.rt_simt_efficiency,
            100.0 * f.shading_simt_efficiency,
            f.divergent_phases,
            f.shading_phases
        );
        outln!(
            "  per ray        {:.1} transactions, {:.1} chunks; {:.1} requests after sharing in the warp",
            f.transactions_per_ray,
            f.chunks_per_ray,
            f.requests_per_ray
        );
        outln!(
            "  memory         L1 hit {:.1} %, L2 hit {:.1} %, DRAM {:.0} B per ray, {:.1} GB/s, row-hit rate {:.1} %",
            100.0 * r.l1_hit_rate,
            100.0 * r.l2_hit_rate,
            f.dram_bytes_per_ray,
            f.dram_gb_per_s,
            100.0 * r.row_hit_rate
        );
        outln!("  host           {:.2} s", host.as_secs_f64());
    }
    if results.len() < 2 {
        return;
    }
    let base = &results[0].0;
    outln!(
        "\ncomparison (frame time and DRAM bytes as % of {})",
        base.accel.map_or("?", |a| a.label())
    );
    outln!("config  frame time   %      DRAM B/ray   %      txn/ray  requests/ray  RT occ.");
    for (r, _) in results {
        let Some(f) = &r.simt else { continue };
        let b = base.simt.as_ref().map_or(0.0, |b| b.dram_bytes_per_ray);
        let pct = |a: f64, b: f64| if b > 0.0 { 100.0 * a / b } else { 0.0 };
        outln!(
            "{:<7} {:>10} {:>6.1} % {:>10.0} {:>6.1} % {:>8.1} {:>13.1} {:>7.1} %",
            r.accel.map_or("?", |a| a.label()),
            units::time_ms(r.frame_ms),
            pct(r.frame_ms, base.frame_ms),
            f.dram_bytes_per_ray,
            pct(f.dram_bytes_per_ray, b),
            f.transactions_per_ray,
            f.requests_per_ray,
            100.0 * f.rt_occupancy
        );
    }
}
