//! "On an RTX-style GPU": the paper's closing question (Lin et al. 2020, §5) — does a
//! dual-split tree's saving in memory traffic survive a GPU that fetches memory for warps? —
//! answered with the `simt` thread model (Vulkan-Sim's RT unit, Saed et al., MICRO 2022) on
//! its RTX 2060 configuration (`configs/rtx2060.toml`, compiled in).
//!
//! ```text
//!  one report scene ([`scene_index`]) ──▶ RT-unit structures × {cast, path}   at RES²
//!                                     └─▶ SWEPT × cast × (SWEEP_WARPS ∪ SWEEP_MSHR)
//! ```
//!
//! The structures come from the registry (`model::simt::rt_accels`; the sweep's from their
//! node units, [`swept`]), so nothing here names one. Every sentence of the summary is
//! computed from the frames of the run that wrote it.
//!
//! Cost: the `simt` model simulates every RT-unit cycle of 30 SMs, so its frames cost more
//! host time per ray than the `fast` model's; the frames are therefore small and on one
//! scene (the cheapest of the default scenes: see [`scene_index`]).

use crate::data::{ReportData, RtxData};
use crate::tables::{Cell, Section, Table};
use dualsplit_render::Workload;
use dualsplit_sim::{NodeUnit, SimAccel, SimConfig, SimResult};

/// The RTX 2060 as Vulkan-Sim configures it (every key cited in the file).
pub const RTX2060_TOML: &str = include_str!("../../../configs/rtx2060.toml");
/// Square resolution of the section's frames: 16,384 pixels are 512 warps, 17 per SM, so
/// an RT unit has warps waiting at every swept warp count up to 16.
pub const RES: u32 = 128;
/// Warps per RT unit of the sweep (`rt_max_warps`; the RTX 2060's 4 among them). Fewer
/// points than `scripts/simt-sweep.sh` runs, to keep the default report fast: each point
/// is three frames.
pub const SWEEP_WARPS: [u32; 4] = [1, 4, 8, 16];
/// MSHRs per RT unit of the sweep (`rt_max_mshr`; the RTX 2060's 64 among them).
pub const SWEEP_MSHR: [u32; 3] = [16, 64, 128];
/// The workload of the sweep: ray casting, the cheaper to simulate.
pub const SWEEP_WORKLOAD: Workload = Workload::Cast;
/// CPU-seconds the section's 27 frames take cold, structures built: 18.6 measured with
/// `/usr/bin/time` as the user time of `report --out r --res 64 --tms 64
/// builtin:forest?triangles=40000` after the same with `--no-rtx` had filled `r/cache`
/// (model 13, this project's 2-core host). The basis of `report --dry-run`'s estimate.
pub const CPU_SECONDS: f64 = 19.0;
/// SIMT efficiency below which the section calls it low.
pub const LOW_SIMT: f64 = 0.5;

/// The compiled-in RTX 2060 configuration.
pub fn config() -> Result<SimConfig, String> {
    SimConfig::from_toml(RTX2060_TOML).map_err(|e| format!("configs/rtx2060.toml: {e}"))
}

/// The configuration `base` with `warps` per RT unit and `mshr` MSHRs.
pub fn with_point(base: &SimConfig, warps: u32, mshr: u32) -> SimConfig {
    let mut cfg = base.clone();
    if let Some(s) = cfg.simt.as_mut() {
        s.rt_max_warps = warps;
        s.rt_max_mshr = mshr;
    }
    cfg
}

/// `(rt_max_warps, rt_max_mshr)` of `cfg` (zeros without a `[simt]` table).
pub fn point(cfg: &SimConfig) -> (u32, u32) {
    cfg.simt
        .as_ref()
        .map_or((0, 0), |s| (s.rt_max_warps, s.rt_max_mshr))
}

/// The scene of the section among the report's `specs`: the forest builtin when the report
/// has it, else the first. Measured on model 13 (`dualsplit simulate SCENE --model simt
/// --config configs/rtx2060.toml --accel bvh2,bvh4,bvh8,cwbvh,dst,dst-q --res 64
/// --sim-threads 1`, CPU seconds for both workloads): forest 2.9, hairball 4.9, atrium 15.5
/// (its path rays bounce inside a closed room), Dragon Box 8.6 with its build.
pub fn scene_index(specs: &[String]) -> usize {
    specs
        .iter()
        .position(|s| s.starts_with("builtin:forest"))
        .unwrap_or(0)
}

/// The structures an RT unit holds ([`dualsplit_sim::model::simt::rt_accels`]).
pub fn structures() -> Vec<SimAccel> {
    dualsplit_sim::model::simt::rt_accels().collect()
}

/// The structures of the sweep: the reference BVH2, the exact dual-split tree (the
/// dual-split pipeline's) and the compressed wide BVH (the quantized box unit's).
pub fn swept() -> Vec<SimAccel> {
    structures()
        .into_iter()
        .filter(|a| {
            *a == SimAccel::Bvh2
                || matches!(
                    a.node_unit(),
                    NodeUnit::DualSplitPipe | NodeUnit::QuantizedBoxPipe
                )
        })
        .collect()
}

/// Every frame of the section: (structure, workload, warps, MSHRs), each once.
pub fn plan(base: &SimConfig) -> Vec<(SimAccel, Workload, u32, u32)> {
    let (w0, m0) = point(base);
    let mut out = Vec::new();
    for workload in [Workload::Cast, Workload::Path] {
        for a in structures() {
            out.push((a, workload, w0, m0));
        }
    }
    let points = SWEEP_WARPS
        .iter()
        .map(|&w| (w, m0))
        .chain(SWEEP_MSHR.iter().map(|&m| (w0, m)));
    for (w, m) in points {
        for a in swept() {
            let job = (a, SWEEP_WORKLOAD, w, m);
            if !out.contains(&job) {
                out.push(job);
            }
        }
    }
    out
}

/// Peak DRAM bandwidth of `cfg`'s GDDR6 (channels × bytes per command cycle × clock), GB/s.
pub fn peak_dram_gbps(cfg: &SimConfig) -> f64 {
    cfg.simt.as_ref().map_or(0.0, |s| {
        f64::from(s.dram_channels) * f64::from(s.dram_bytes_per_cycle) * s.dram_mhz * 1e6 / 1e9
    })
}

/// The figures of one frame the section shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// Frame time, µs.
    pub frame_us: f64,
    /// Mean resident warps over the RT unit's places.
    pub rt_occupancy: f64,
    /// SIMT efficiency in the RT unit.
    pub simt_in: f64,
    /// SIMT efficiency outside it.
    pub simt_out: f64,
    /// Transactions per ray (threads' lists).
    pub transactions: f64,
    /// 32-B chunks per ray (threads' lists).
    pub chunks: f64,
    /// Chunk requests per ray, after sharing in the warp.
    pub requests: f64,
    /// L1 hit rate (hits over chunk requests).
    pub l1_hit: f64,
    /// L2 hit rate.
    pub l2_hit: f64,
    /// DRAM bytes per ray.
    pub dram_bytes: f64,
    /// DRAM GB/s over the frame.
    pub dram_gbps: f64,
}

impl Figures {
    /// The figures of `r`, if it is a `simt` frame.
    pub fn of(r: &SimResult) -> Option<Self> {
        let s = r.simt.as_ref()?;
        let rate = |hits: u64, n: u64| if n > 0 { hits as f64 / n as f64 } else { 0.0 };
        Some(Self {
            frame_us: r.frame_ms * 1e3,
            rt_occupancy: s.rt_occupancy,
            simt_in: s.rt_simt_efficiency,
            simt_out: s.shading_simt_efficiency,
            transactions: s.transactions_per_ray,
            chunks: s.chunks_per_ray,
            requests: s.requests_per_ray,
            l1_hit: rate(s.l1_hits, s.l1_requests),
            l2_hit: rate(s.l2_hits, s.l2_accesses),
            dram_bytes: s.dram_bytes_per_ray,
            dram_gbps: s.dram_gb_per_s,
        })
    }

    /// Every figure, in the table's column order.
    pub fn all(&self) -> [f64; 11] {
        [
            self.frame_us,
            self.rt_occupancy,
            self.simt_in,
            self.simt_out,
            self.transactions,
            self.chunks,
            self.requests,
            self.l1_hit,
            self.l2_hit,
            self.dram_bytes,
            self.dram_gbps,
        ]
    }
}

/// The frame table's columns after the structure's.
pub const COLUMNS: [&str; 11] = [
    "frame time (µs)",
    "RT occupancy",
    "SIMT efficiency in RT unit",
    "SIMT efficiency outside",
    "transactions / ray",
    "chunks / ray",
    "requests / ray",
    "L1 hit",
    "L2 hit",
    "DRAM B / ray",
    "DRAM GB/s",
];

fn workload_text(w: Workload) -> &'static str {
    match w {
        Workload::Cast => "ray casting with a shadow ray",
        Workload::Path => "path tracing",
    }
}

/// The base frames of `workload`, in registry order, with their figures.
fn frames(rtx: &RtxData, workload: Workload) -> Vec<(SimAccel, Figures)> {
    structures()
        .into_iter()
        .filter_map(|a| Some((a, Figures::of(rtx.base(a, workload)?)?)))
        .collect()
}

fn frame_table(rtx: &RtxData, workload: Workload) -> Table {
    let mut header = vec!["structure".to_string()];
    header.extend(COLUMNS.iter().map(|c| c.to_string()));
    let rows = frames(rtx, workload)
        .into_iter()
        .map(|(a, f)| {
            let mut row = vec![Cell::text(a.label())];
            for (i, v) in f.all().into_iter().enumerate() {
                row.push(match i {
                    1..=3 | 7 | 8 => Cell {
                        text: format!("{v:.2}"),
                        value: Some(v),
                    },
                    _ => Cell::num(v),
                });
            }
            row
        })
        .collect();
    Table {
        id: format!("rtx-{}", workload.name()),
        caption: format!(
            "{} on {} at {r}×{r}, simt model, RTX 2060 ({} warps and {} MSHRs per RT unit). Transactions and 32-B chunks from each thread's list; requests: the chunks the RT units sent after the threads of a warp shared identical transactions. RT occupancy: mean resident warps over the unit's places, over the whole frame.",
            capitalise(workload_text(workload)),
            rtx.scene,
            rtx.base_warps,
            rtx.base_mshr,
            r = rtx.res
        ),
        header,
        paper_columns: Vec::new(),
        rows,
    }
}

/// Frame time (µs) and DRAM GB/s of each swept structure at each value of one key.
fn sweep_table(rtx: &RtxData, mshr: bool) -> Table {
    let values: Vec<u32> = if mshr {
        SWEEP_MSHR.to_vec()
    } else {
        SWEEP_WARPS.to_vec()
    };
    let mut header = vec!["structure".to_string()];
    for &v in &values {
        let base = if mshr { rtx.base_mshr } else { rtx.base_warps };
        let mark = if v == base { " (RTX 2060)" } else { "" };
        header.push(format!(
            "{v} {}{mark} µs",
            if mshr { "MSHRs" } else { "warps" }
        ));
    }
    let rows = swept()
        .into_iter()
        .map(|a| {
            let mut row = vec![Cell::text(a.label())];
            for &v in &values {
                let (w, m) = if mshr {
                    (rtx.base_warps, v)
                } else {
                    (v, rtx.base_mshr)
                };
                row.push(
                    rtx.get(a, SWEEP_WORKLOAD, w, m)
                        .map_or_else(Cell::none, |r| Cell::num(r.frame_ms * 1e3)),
                );
            }
            row
        })
        .collect();
    Table {
        id: format!("rtx-sweep-{}", if mshr { "mshr" } else { "warps" }),
        caption: format!(
            "Frame time (µs), {} on {} at {r}×{r}, with {} per RT unit varied and every other key at the RTX 2060's value (as scripts/simt-sweep.sh varies them).",
            workload_text(SWEEP_WORKLOAD),
            rtx.scene,
            if mshr { "the MSHRs" } else { "the warps" },
            r = rtx.res
        ),
        header,
        paper_columns: Vec::new(),
        rows,
    }
}

/// The section, when the report ran its frames.
pub fn section(data: &ReportData) -> Option<Section> {
    let rtx = data.rtx.as_ref()?;
    let mut notes = vec![ENERGY_NOTE.to_string()];
    if let Some(e) = rtx.error() {
        notes.push(format!("Some frames were not simulated: {e}."));
    }
    Some(Section {
        id: "rtx".into(),
        title: "On an RTX-style GPU — the paper's §5 question".into(),
        summary: summary(rtx),
        notes,
        tables: vec![
            frame_table(rtx, Workload::Cast),
            frame_table(rtx, Workload::Path),
            sweep_table(rtx, false),
            sweep_table(rtx, true),
        ],
    })
}

/// Why the section has no energy.
pub const ENERGY_NOTE: &str = "No energy is given: Vulkan-Sim's RTX 2060 configuration turns its power model off (-power_simulation_enabled 0), and no other source gives the energy of its units, so none is estimated.";

/// "24% fewer" / "9% more" for `ours` against `base`.
fn fewer(ours: f64, base: f64) -> String {
    if base <= 0.0 {
        return "—".into();
    }
    let d = 1.0 - ours / base;
    if d >= 0.0 {
        format!("{:.0}% fewer", 100.0 * d)
    } else {
        format!("{:.0}% more", -100.0 * d)
    }
}

/// `+29%`, `-0.5%`: a relative change, with a decimal below 1%.
fn signed_pct(v: f64) -> String {
    if v.abs() < 0.01 {
        format!("{:+.1}%", 100.0 * v)
    } else {
        format!("{:+.0}%", 100.0 * v)
    }
}

fn low_high(v: &[f64]) -> (f64, f64) {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (lo, hi)
}

/// The generated paragraph: which structure wins and why, whether the dual-split trees'
/// saving survives sharing in the warp, what the sweeps show, and the check against
/// Vulkan-Sim; every number from `rtx`.
pub fn summary(rtx: &RtxData) -> String {
    let mut out = vec![format!(
        "Lin et al. close (§5) with a question their chip cannot answer: does a dual-split tree's saving in memory traffic survive a GPU that fetches memory for warps in 32-B chunks and 128-B lines? Here the simt model (Vulkan-Sim's RT unit on its RTX 2060 configuration, docs/simulator.md) runs {} at {r}×{r}.",
        rtx.scene,
        r = rtx.res
    )];
    for workload in [Workload::Cast, Workload::Path] {
        out.extend(winner(rtx, workload));
    }
    out.extend(dual_split_saving(rtx));
    out.extend(regime(rtx));
    out.extend(sweeps(rtx));
    out.extend(vulkan_sim_check(rtx));
    out.join(" ")
}

/// Which structure is fastest, the order, and whether it follows transactions per ray.
fn winner(rtx: &RtxData, workload: Workload) -> Option<String> {
    let mut f = frames(rtx, workload);
    if f.is_empty() {
        return None;
    }
    f.sort_by(|x, y| x.1.frame_us.total_cmp(&y.1.frame_us));
    let order: Vec<String> = f
        .iter()
        .map(|(a, g)| format!("{} {:.1} µs", a.label(), g.frame_us))
        .collect();
    let mut by_txn = f.clone();
    by_txn.sort_by(|x, y| x.1.transactions.total_cmp(&y.1.transactions));
    let same = by_txn.iter().map(|x| x.0).eq(f.iter().map(|x| x.0));
    let fewest = by_txn[0].0 == f[0].0;
    let (best, g) = f[0];
    let why = if same {
        "the order of frame times is exactly the order of transactions per ray".to_string()
    } else if fewest {
        "the fastest needs the fewest transactions per ray, though the rest are not ordered by them"
            .to_string()
    } else {
        format!(
            "the order is not that of transactions per ray (fewest: {} with {:.1})",
            by_txn[0].0.label(),
            by_txn[0].1.transactions
        )
    };
    Some(format!(
        "{}: {} is fastest ({}); {} ({} needs {:.1} transactions per ray; {}).",
        capitalise(workload_text(workload)),
        best.label(),
        order.join(", "),
        why,
        best.label(),
        g.transactions,
        f.iter()
            .skip(1)
            .map(|(a, g)| format!("{} {:.1}", a.label(), g.transactions))
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

fn capitalise(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map_or_else(String::new, |f| f.to_uppercase().chain(c).collect())
}

/// Each dual-split structure against BVH2: DRAM bytes, chunks before sharing in the warp,
/// requests after.
fn dual_split_saving(rtx: &RtxData) -> Vec<String> {
    let mut out = Vec::new();
    for a in structures()
        .into_iter()
        .filter(|a| a.node_unit().is_dual_split())
    {
        let mut parts = Vec::new();
        for workload in [Workload::Cast, Workload::Path] {
            let get = |x| rtx.base(x, workload).and_then(Figures::of);
            let (Some(d), Some(b)) = (get(a), get(SimAccel::Bvh2)) else {
                continue;
            };
            let before = 1.0 - d.chunks / b.chunks;
            let after = 1.0 - d.requests / b.requests;
            let verdict = if after >= before - 0.02 {
                "the saving survives sharing in the warp"
            } else if after > 0.0 {
                "sharing in the warp shrinks the saving: BVH2's threads share more of their chunks"
            } else {
                "sharing in the warp undoes the saving: BVH2's threads share more of their chunks"
            };
            parts.push(format!(
                "in {} it reads {} DRAM bytes per ray than BVH2 ({:.0} vs {:.0}); before sharing in the warp its threads ask for {} 32-B chunks ({:.1} vs {:.1}), after it the RT units send {} requests ({:.1} vs {:.1}): {verdict}",
                workload.name(),
                fewer(d.dram_bytes, b.dram_bytes),
                d.dram_bytes,
                b.dram_bytes,
                fewer(d.chunks, b.chunks),
                d.chunks,
                b.chunks,
                fewer(d.requests, b.requests),
                d.requests,
                b.requests
            ));
        }
        if !parts.is_empty() {
            out.push(format!("{}: {}.", a.label(), parts.join("; ")));
        }
    }
    out
}

/// Whether the frames are bound by DRAM bandwidth or by latency.
fn regime(rtx: &RtxData) -> Option<String> {
    let mut gbps = Vec::new();
    let mut occ = Vec::new();
    for w in [Workload::Cast, Workload::Path] {
        for (_, f) in frames(rtx, w) {
            gbps.push(f.dram_gbps);
            occ.push(f.rt_occupancy);
        }
    }
    if gbps.is_empty() || rtx.peak_dram_gbps <= 0.0 {
        return None;
    }
    let (glo, ghi) = low_high(&gbps);
    let (olo, ohi) = low_high(&occ);
    let share = ghi / rtx.peak_dram_gbps;
    let reading = if share < 0.5 {
        "far from it: the RT units wait on chains of dependent transactions (latency), not on DRAM bandwidth, so the structure with the shortest chain wins and bytes saved buy little"
    } else {
        "near enough to it that DRAM bandwidth, and so bytes per ray, matter"
    };
    Some(format!(
        "The RT units are {:.0}–{:.0}% occupied while DRAM carries {glo:.0}–{ghi:.0} GB/s of its {:.0} GB/s: {reading}.",
        100.0 * olo,
        100.0 * ohi,
        rtx.peak_dram_gbps
    ))
}

/// Frame time of `a` at a sweep point.
fn sweep_us(rtx: &RtxData, a: SimAccel, w: u32, m: u32) -> Option<f64> {
    rtx.get(a, SWEEP_WORKLOAD, w, m).map(|r| r.frame_ms * 1e3)
}

/// What the sweeps show, per swept structure.
fn sweeps(rtx: &RtxData) -> Vec<String> {
    let (w0, m0) = (rtx.base_warps, rtx.base_mshr);
    let (wmin, wmax) = (SWEEP_WARPS[0], SWEEP_WARPS[SWEEP_WARPS.len() - 1]);
    let (mmin, mmax) = (SWEEP_MSHR[0], SWEEP_MSHR[SWEEP_MSHR.len() - 1]);
    let mut lines = Vec::new();
    for a in swept() {
        let (Some(t_wmin), Some(t0), Some(t_wmax), Some(t_mmin), Some(t_mmax)) = (
            sweep_us(rtx, a, wmin, m0),
            sweep_us(rtx, a, w0, m0),
            sweep_us(rtx, a, wmax, m0),
            sweep_us(rtx, a, w0, mmin),
            sweep_us(rtx, a, w0, mmax),
        ) else {
            continue;
        };
        lines.push(format!(
            "{} {:.2}× faster from {wmin} to {w0} warps (ideal {:.0}×) and {:.2}× from {w0} to {wmax}; frame time {} with {mmin} MSHRs instead of {m0}, {} with {mmax}",
            a.label(),
            t_wmin / t0,
            f64::from(w0) / f64::from(wmin),
            t0 / t_wmax,
            signed_pct(t_mmin / t0 - 1.0),
            signed_pct(t_mmax / t0 - 1.0)
        ));
    }
    if lines.is_empty() {
        return Vec::new();
    }
    // Which swept structure is fastest at the most warps, against at the base.
    let fastest = |w| {
        swept()
            .into_iter()
            .filter_map(|a| Some((a, sweep_us(rtx, a, w, m0)?)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .map(|x| x.0)
    };
    let mut out = vec![format!(
        "Sweep ({}, frame time): {}.",
        SWEEP_WORKLOAD.name(),
        lines.join("; ")
    )];
    if let (Some(f0), Some(fmax)) = (fastest(w0), fastest(wmax)) {
        out.push(if f0 == fmax {
            format!(
                "{} stays the fastest of them from {w0} to {wmax} warps per RT unit.",
                f0.label()
            )
        } else {
            format!(
                "With {wmax} warps per RT unit {} overtakes {}: with enough rays in flight to hide the chains, bytes matter again.",
                fmax.label(),
                f0.label()
            )
        });
    }
    out
}

/// The plausibility check against Vulkan-Sim.
fn vulkan_sim_check(rtx: &RtxData) -> Option<String> {
    let mut eff = Vec::new();
    for w in [Workload::Cast, Workload::Path] {
        for (_, f) in frames(rtx, w) {
            eff.push(f.simt_in);
        }
    }
    if eff.is_empty() {
        return None;
    }
    let (lo, hi) = low_high(&eff);
    let verdict = if hi < LOW_SIMT {
        format!("below {LOW_SIMT:.1} in every frame: the same direction")
    } else {
        format!("not below {LOW_SIMT:.1} in every frame: that direction is not reproduced")
    };
    let warps_dir = swept().into_iter().all(|a| {
        let t: Vec<Option<f64>> = SWEEP_WARPS
            .iter()
            .filter(|&&w| w <= rtx.base_warps)
            .map(|&w| sweep_us(rtx, a, w, rtx.base_mshr))
            .collect();
        t.windows(2)
            .all(|p| matches!(p, [Some(x), Some(y)] if y < x))
    });
    Some(format!(
        "Check against Vulkan-Sim: its authors report warp divergence and low SIMD efficiency as the inefficiency of ray tracing on their GPU (Saed et al., MICRO 2022, abstract; artifact description, zenodo.org/records/6981923); here the SIMT efficiency in the RT unit is {lo:.2}–{hi:.2}, {verdict}. Their paper's figures were not available to this work, so no number of theirs is compared, only directions. Up to the configured {} warps per RT unit every swept structure {} as more warps enter the unit, as Vulkan-Sim's unit implies (a warp beyond -gpgpu_rt_max_warps waits: src/gpgpu-sim/shader.cc:2862).",
        rtx.base_warps,
        if warps_dir {
            "gets faster"
        } else {
            "does not get faster at every step"
        }
    ))
}
