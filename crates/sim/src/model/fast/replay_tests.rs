//! Tests of the replay on the hardware units: exact cycles of loads, pipelines and stalls.

use crate::config::SimConfig;
use crate::hw::atomic::AtomicUnit;
use crate::hw::pipe::Pipe;
use crate::hw::slots::Slots;
use crate::hw::{Chip, Stalls};
use crate::model::fast::op::Op;
use crate::model::fast::replay::{WorkSource, run as run_chip, run_with as run_chip_with};
use crate::model::fast::thread::Thread;

struct Programs(Vec<Vec<Op>>);
impl WorkSource for Programs {
    fn next(
        &mut self,
        _id: usize,
        t: &mut Thread,
        _a: &mut AtomicUnit,
        _s: &mut Stalls,
    ) -> Option<Vec<Op>> {
        // One program per thread.
        if t.has_no_program() {
            self.0.pop()
        } else {
            None
        }
    }
}

fn one_thread(cfg: &SimConfig, box_pipes: u32, prog: Vec<Op>) -> (u64, Chip) {
    let mut chip = Chip::new(cfg, box_pipes);
    let mut th = vec![Thread::new(0)];
    let end = run_chip(&mut chip, &mut th, &mut Programs(vec![prog]));
    (end.get(), chip)
}

fn use_data() -> Op {
    Op::Issue { n: 1, fpinv: 0 }
}

/// Random programs of every op kind on 4 TMs × 8 threads (loads that hit, merge and
/// miss, serial and parallel pipeline ops, reciprocal and plain instruction runs,
/// atomics between programs): with forward entries, and on 2–4 host threads, every
/// counter and the end cycle equal those of the plain wake-ups on one.
#[test]
fn forwards_and_host_threads_change_no_result() {
    struct Random(dualsplit_geometry::Pcg32, Vec<u32>);
    impl WorkSource for Random {
        fn next(
            &mut self,
            id: usize,
            t: &mut Thread,
            atomic: &mut AtomicUnit,
            stalls: &mut Stalls,
        ) -> Option<Vec<Op>> {
            if self.1[id] == 0 {
                return None;
            }
            self.1[id] -= 1;
            let r = &mut self.0;
            if r.below(2) == 0 {
                t.atomic(atomic, stalls);
            }
            let mut ops = Vec::new();
            for _ in 0..1 + r.below(40) {
                ops.push(match r.below(4) {
                    0 => Op::Load {
                        word: r.below(1 << 16),
                        words: 1 + r.below(20) as u16,
                    },
                    1 => Op::Pipe {
                        pipe: [Pipe::Box, Pipe::Triangle, Pipe::DualSplit][r.below(3) as usize],
                        n: 1 + r.below(4) as u8,
                        parallel: r.below(2) == 0,
                    },
                    _ => {
                        let n = r.below(20);
                        let fpinv = if r.below(4) == 0 { r.below(n + 1) } else { 0 };
                        Op::Issue {
                            n,
                            fpinv: fpinv as u16,
                        }
                    }
                });
            }
            Some(ops)
        }
    }
    let mut cfg = SimConfig::lin2020();
    cfg.tms = 4;
    cfg.tps_per_tm = 8;
    for seed in 0..20 {
        let run = |forwards, host_threads| {
            let mut chip = Chip::new(&cfg, 4);
            let mut th: Vec<Thread> = (0..32).map(|i| Thread::new(i / 8)).collect();
            let mut work = Random(dualsplit_geometry::Pcg32::new(seed, 3), vec![6; 32]);
            let end = run_chip_with(&mut chip, &mut th, &mut work, forwards, host_threads);
            (end, chip.stats())
        };
        let plain = run(false, 1);
        assert!(
            plain.1.stalls.memory > 0 && plain.1.stalls.pipeline_busy > 0,
            "{plain:?}"
        );
        assert_eq!(run(true, 1), plain, "seed {seed}");
        // Split over host threads, the TMs' requests still reach the shared units in the
        // same order.
        for host_threads in [2, 3, 4] {
            assert_eq!(
                run(true, host_threads),
                plain,
                "seed {seed}, {host_threads}"
            );
        }
    }
}

/// A thread record and a reservation table each fit one host cache line (64 bytes).
#[test]
fn host_records_fit_a_cache_line() {
    assert_eq!(std::mem::size_of::<Thread>(), 64);
    assert_eq!(std::mem::align_of::<Thread>(), 64);
    assert_eq!(std::mem::size_of::<Slots>(), 32);
    assert_eq!(std::mem::align_of::<Slots>(), 32);
}

#[test]
fn l1_hit_takes_one_cycle() {
    let cfg = SimConfig::lin2020();
    let mut chip = Chip::new(&cfg, 1);
    // Warm the line, then time a hit directly.
    let fill = chip.load_word(0, 0, 0);
    assert_eq!(chip.load_word(0, 1, fill), fill + 1);
    assert_eq!(chip.stats().caches.l1_hits, 1);
}

#[test]
fn cold_load_is_a_closed_row_read_and_reload_hits_l2() {
    let cfg = SimConfig::lin2020();
    let mut chip = Chip::new(&cfg, 1);
    // L1 1 + L2 5 + closed row (tRCD 14 + tCAS 14 + burst 2) = 36.
    assert_eq!(chip.load_word(0, 0, 100), 136);
    // Another TM: L1 miss, L2 hit: 1 + 5.
    assert_eq!(chip.load_word(1, 0, 200), 206);
    // Same TM, another line in the same DRAM row: row hit, 1 + 5 + 14 + 2 = 22.
    assert_eq!(chip.load_word(0, 16, 300), 322);
    assert_eq!(chip.stats().caches.l2_hits, 1);
    assert_eq!(chip.stats().dram.row_hits, 1);
}

#[test]
fn row_conflict_load() {
    // 2 KB rows (configs/dram-2kb-rows.toml), the organisation this test was written for.
    let mut cfg = SimConfig::lin2020();
    cfg.dram.row_bytes = 2048;
    let mut chip = Chip::new(&cfg, 1);
    chip.load_word(0, 0, 0);
    // Same channel and bank, next row: 32 lines × 16 channels × 16 banks × 16 words.
    let w = 32 * 16 * 16 * 16;
    // 1 + 5 + tRP 14 + tRCD 14 + tCAS 14 + burst 2 = 50.
    assert_eq!(chip.load_word(0, w, 1000), 1050);
    assert_eq!(chip.stats().dram.row_conflicts, 1);
}

#[test]
fn l2_banks_interleave_by_word_or_by_line() {
    // Words 0 and 128 (lines 0 and 8) missing in two TMs in the same cycle: word
    // interleaving (SimTRaX) puts both on L2 bank 0, so the second waits one cycle; line
    // interleaving puts them on banks 0 and 8.
    let mut cfg = SimConfig::lin2020();
    for (by_line, wait) in [(false, 1), (true, 0)] {
        cfg.l2.line_interleaved = by_line;
        let mut chip = Chip::new(&cfg, 1);
        chip.load_word(0, 0, 10);
        chip.load_word(1, 128, 10);
        assert_eq!(
            chip.stats().caches.l2_bank_wait,
            wait,
            "line_interleaved = {by_line}"
        );
    }
}

#[test]
fn a_conflicting_miss_replaces_a_line_only_when_its_fill_arrives() {
    // SimTRaX installs lines at their arrival (L1Cache/L2Cache UpdateCache) and finds
    // lines in flight on its pending lists. 2 KB rows (configs/dram-2kb-rows.toml), the
    // organisation the bank numbers below are written for.
    let mut cfg = SimConfig::lin2020();
    cfg.dram.row_bytes = 2048;
    let mut chip = Chip::new(&cfg, 1);
    // Line 0 cold: 136 (L1 1 + L2 5 + closed row 30).
    assert_eq!(chip.load_word(0, 0, 100), 136);
    // Line 1024 (word 16384) maps to the same L1 set (64 KB direct-mapped): a closed-row
    // read on channel 0, bank 2 (32 lines per row), 36 cycles.
    assert_eq!(chip.load_word(0, 16384, 200), 236);
    // Line 0 is still in the L1 until 236: a 1-cycle hit, no L2 access.
    assert_eq!(chip.load_word(0, 1, 202), 203);
    assert_eq!(chip.stats().caches.l2_accesses, 2);
    // Line 2048 (same set; channel 0, bank 4, closed; its activation t_RRD after line
    // 1024's at tick 412: act 425, column 453, data at 481 rounded up to the 2 ns burst grid,
    // 484 + 4 = 488 ticks) takes the set's tag while 1024 is still in flight; 1024 stays on
    // the in-flight list and a miss to it merges.
    assert_eq!(chip.load_word(0, 32768, 203), 244);
    assert_eq!(chip.load_word(0, 16385, 205), 236);
    assert_eq!(chip.stats().caches.l2_accesses, 3);
    assert_eq!(chip.stats().caches.l1_merged, 1);
    // Once 2048 has arrived, line 0 is gone: an L1 miss, L2 hit (1 + 5).
    assert_eq!(chip.load_word(0, 2, 250), 256);
    assert_eq!(chip.stats().caches.l2_accesses, 4);
    assert_eq!(chip.stats().dram.reads, 3);
}

#[test]
fn miss_to_line_in_flight_merges() {
    let cfg = SimConfig::lin2020();
    let mut chip = Chip::new(&cfg, 1);
    let r0 = chip.load_word(0, 0, 0);
    let r1 = chip.load_word(0, 1, 1);
    assert_eq!(r1, r0);
    assert_eq!(chip.stats().caches.l1_merged, 1);
    assert_eq!(chip.stats().caches.l2_accesses, 1);
    assert_eq!(chip.stats().dram.reads, 1);
}

#[test]
fn thread_load_then_use_waits_for_data() {
    let cfg = SimConfig::lin2020();
    // Load at cycle 0 (cold: 36), use at 36, one issue: finish 37.
    let (end, chip) = one_thread(&cfg, 1, vec![Op::Load { word: 0, words: 1 }, use_data()]);
    assert_eq!(end, 37);
    assert_eq!(chip.stats().stalls.memory, 35);
}

#[test]
fn bank_conflict_costs_one_cycle() {
    let cfg = SimConfig::lin2020();
    // Two threads on one TM load words 0 and 16 (both bank 0) at cycle 0: the second
    // gets the bank at cycle 1.
    let mut chip = Chip::new(&cfg, 1);
    let mut th = vec![Thread::new(0), Thread::new(0)];
    let progs = vec![
        vec![Op::Load { word: 16, words: 1 }],
        vec![Op::Load { word: 0, words: 1 }],
    ];
    run_chip(&mut chip, &mut th, &mut Programs(progs));
    assert_eq!(chip.stats().stalls.l1_bank, 1);
    // A single 16-word line load spans all 16 banks without conflict.
    let (_, chip) = one_thread(&cfg, 1, vec![Op::Load { word: 0, words: 16 }]);
    assert_eq!(chip.stats().stalls.l1_bank, 0);
}

#[test]
fn a_pipeline_op_takes_only_its_issue_slots() {
    let cfg = SimConfig::lin2020();
    let box_op = |n, parallel| Op::Pipe {
        pipe: Pipe::Box,
        n,
        parallel,
    };
    // The latency the kernel exposes is part of the measured issue runs (`model/fast/calibrate.rs`):
    // issue at 0, use at 1: end 2.
    let (end, _) = one_thread(&cfg, 1, vec![box_op(1, false), use_data()]);
    assert_eq!(end, 2);
    // Four serial box tests on one pipe: issued in cycles 0 to 3, used at 4: end 5.
    let (end, _) = one_thread(&cfg, 1, vec![box_op(4, false), use_data()]);
    assert_eq!(end, 5);
    // Four in parallel on four pipes: one issue, use at 1: end 2.
    let (end, _) = one_thread(&cfg, 4, vec![box_op(4, true), use_data()]);
    assert_eq!(end, 2);
    let dst = Op::Pipe {
        pipe: Pipe::DualSplit,
        n: 1,
        parallel: false,
    };
    let (end, chip) = one_thread(&cfg, 1, vec![dst, use_data()]);
    assert_eq!(end, 2);
    assert_eq!(chip.stats().units.dst_ops, 1);
}

#[test]
fn two_threads_share_one_pipeline() {
    let cfg = SimConfig::lin2020();
    let mut chip = Chip::new(&cfg, 1);
    let mut th = vec![Thread::new(0), Thread::new(0)];
    let op = Op::Pipe {
        pipe: Pipe::Box,
        n: 1,
        parallel: false,
    };
    let progs = vec![vec![op, use_data()], vec![op, use_data()]];
    let end = run_chip(&mut chip, &mut th, &mut Programs(progs)).get();
    // The second thread gets the pipe at cycle 1 and uses its result at 2: end 3.
    assert_eq!(end, 3);
    assert_eq!(chip.stats().stalls.pipeline_busy, 1);
}

#[test]
fn fpinv_is_shared_and_long() {
    let cfg = SimConfig::lin2020();
    // 3 reciprocals at 0, 1, 2 (pipelined unit), last result 18; 5 more issues 3..7;
    // then use at 18: end 19.
    let (end, _) = one_thread(&cfg, 1, vec![Op::Issue { n: 8, fpinv: 3 }, use_data()]);
    assert_eq!(end, 19);
}
