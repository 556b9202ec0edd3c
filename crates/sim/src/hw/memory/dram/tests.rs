//! The DRAM's tests: hand-computed latencies, and a plain reference implementation of the
//! same model compared read by read on random streams.

use super::*;

#[test]
fn the_percentile_is_the_smallest_latency_covering_the_share() {
    // 100 reads: 90 of 10 cycles, 5 of 20, 5 of 30.
    let mut h = vec![0; 64];
    h[10] = 90;
    h[20] = 5;
    h[30] = 5;
    assert_eq!(percentile(&h, 100, 95), 20);
    assert_eq!(percentile(&h, 100, 96), 30);
    assert_eq!(percentile(&h, 100, 90), 10);
    assert_eq!(percentile(&h, 0, 95), 0);
}
use crate::SimConfig;
use crate::config::DramConfig;
use dualsplit_geometry::Pcg32;

impl Dram {
    /// [`Dram::read`] in plain cycle numbers.
    fn rd(&mut self, line: u64, arrive: u64) -> (u64, DramAccess) {
        let (done, kind) = self.read(LineAddr::new(line), Cycle(arrive));
        (done.get(), kind)
    }

    /// [`Dram::read_at`] in plain cycle numbers.
    fn rd_at(&mut self, line: u64, arrive: u64, now: u64) -> (u64, DramAccess) {
        let (done, kind) = self.read_at(LineAddr::new(line), Cycle(arrive), Cycle(now));
        (done.get(), kind)
    }
}

/// lin2020's timings with 8 KB rows and no t_FAW, refresh or keep-open rule: the
/// organisation the hand-computed latencies below are written for (128 lines per row,
/// 16 channels, 16 banks).
fn plain() -> DramConfig {
    DramConfig {
        row_bytes: 8192,
        t_faw: 0,
        t_rfc: 0,
        t_refi: 0,
        keep_open: false,
        ..SimConfig::lin2020().dram
    }
}

fn dram() -> Dram {
    Dram::new(&plain())
}

#[test]
fn a_fifth_activation_waits_for_the_four_activate_window() {
    let cfg = DramConfig {
        t_faw: 80,
        ..plain()
    };
    let mut d = Dram::new(&cfg);
    // Five closed banks of channel 0 at cycle 0: activations at ticks 0, 13, 26, 39
    // (t_RRD), the fifth at 80 (t_FAW after the first), column 108, data at 136: done
    // at tick 140 = cycle 70.
    let bank = 128 * 16;
    let done: Vec<_> = (0..5).map(|b| d.rd(b * bank, 0).0).collect();
    assert_eq!(done[3], 50);
    assert_eq!(done[4], 70);
    // Without the window the fifth follows t_RRD: act 52, data at 108 rounded to the
    // burst grid 108, done 112 = cycle 56.
    let mut d = dram();
    assert_eq!((0..5).map(|b| d.rd(b * bank, 0).0).last(), Some(56));
}

#[test]
fn refresh_blocks_activations_and_closes_rows() {
    let cfg = DramConfig {
        t_rfc: 220,
        t_refi: 15600,
        refresh_burst: 8,
        ..plain()
    };
    let mut d = Dram::new(&cfg);
    // USIMM: eight refreshes every 8 · 15,600 = 124,800 ticks, forced in the window
    // [124,800 − t_RP 28 − 8 · 220, 124,800) = [123,012, 124,800). Row 0 opened at
    // cycle 0; a read of it at cycle 61,600 (tick 123,200) falls in the window: the
    // refresh closed the row, so it is a closed-bank read activated at tick 124,800:
    // column 124,828, data 124,856, done 124,860 = cycle 62,430.
    assert_eq!(d.rd(0, 0), (30, DramAccess::Closed));
    assert_eq!(d.rd(1, 61_600), (62_430, DramAccess::Closed));
    // Before the window the row was still open.
    let mut d = Dram::new(&cfg);
    d.rd(0, 0);
    assert_eq!(d.rd(1, 61_000), (61_016, DramAccess::RowHit));
    // An activation must leave t_RAS (70 ticks) before the window: a closed bank read
    // at tick 122,950 (cycle 61,475) would activate at 122,950 + 70 > 123,012, so it
    // waits for the window's end: activate 124,800, done cycle 62,430.
    let mut d = Dram::new(&cfg);
    assert_eq!(d.rd(0, 61_475), (62_430, DramAccess::Closed));
    // One at tick 122,900 (cycle 61,450) has t_RAS before the window: 122,900 + 70 =
    // 122,970 ≤ 123,012; column 122,928, data 122,956, done 122,960 = cycle 61,480.
    let mut d = Dram::new(&cfg);
    assert_eq!(d.rd(0, 61_450), (61_480, DramAccess::Closed));
    // A column read needs t_RTP (15) before the window: the row opened at tick 0 is
    // read at tick 123,000 (cycle 61,500), 123,000 + 15 > 123,012: the row is closed
    // by then, so the read activates after the window.
    let mut d = Dram::new(&cfg);
    d.rd(0, 0);
    assert_eq!(d.rd(1, 61_500), (62_430, DramAccess::Closed));
    // One refresh per window (refresh_burst = 1): [15,600 − 28 − 220, 15,600).
    let one = DramConfig {
        refresh_burst: 1,
        ..cfg
    };
    let mut d = Dram::new(&one);
    d.rd(0, 0);
    assert_eq!(d.rd(1, 7_700), (7_830, DramAccess::Closed));
}

#[test]
fn a_row_is_held_open_for_a_read_arriving_before_its_precharge() {
    let cfg = DramConfig {
        keep_open: true,
        ..plain()
    };
    let row1 = 128 * 16 * 16;
    for (keep_open, want) in [
        (false, (128, DramAccess::Conflict)),
        (true, (46, DramAccess::RowHit)),
    ] {
        let mut d = Dram::new(&DramConfig {
            keep_open,
            ..cfg.clone()
        });
        // A: row 0, closed, act 0. B: row 1, a conflict: precharge at t_RAS 70, act 98.
        assert_eq!(d.rd(0, 0), (30, DramAccess::Closed));
        assert_eq!(d.rd(row1, 0), (80, DramAccess::Conflict));
        // E: row 0 at tick 60, after row 0's last column slot that fits before the
        // precharge (98 − t_RP 28 − t_RTP 15 = 55) but before the precharge (70).
        // USIMM holds the precharge while E is queued: E is a row hit, column 60,
        // data at 88 (slot 22), done 92 ticks = cycle 46. Without the rule E is a
        // conflict after B (cycle 128, `row_hit_overtakes_an_older_conflict`).
        assert_eq!(d.rd(3, 30), want, "keep_open {keep_open}");
        // A read arriving at the precharge (tick 70) or later is not held: a conflict
        // after B (without the rule, E reopened row 0 after B, so it is a row hit).
        let (_, kind) = d.rd(4, 35);
        let want = if keep_open {
            DramAccess::Conflict
        } else {
            DramAccess::RowHit
        };
        assert_eq!(kind, want, "keep_open {keep_open}");
    }
}

#[test]
fn writes_wait_in_the_queue_until_the_high_watermark_or_no_reads() {
    let cfg = DramConfig {
        write_queue: 80,
        write_high: 4,
        write_low: 2,
        ..plain()
    };
    let mut d = Dram::new(&cfg);
    // A read in flight on channel 0 (done at cycle 30): writes to channel 0 queue.
    assert_eq!(d.rd(0, 0), (30, DramAccess::Closed));
    let bank1 = 128 * 16;
    for i in 0..4 {
        d.write(LineAddr::new(bank1 + i), Cycle(1), Cycle(1));
    }
    assert_eq!(
        d.stats().writes,
        0,
        "four writes, not above the high watermark"
    );
    // A second write to a queued line merges.
    d.write(LineAddr::new(bank1), Cycle(1), Cycle(1));
    assert_eq!(d.stats().writes_merged, 1);
    // The fifth distinct line passes the high watermark: drained down to two.
    d.write(LineAddr::new(bank1 + 4), Cycle(2), Cycle(2));
    let s = d.stats();
    assert_eq!((s.writes, s.write_activations, s.activations), (3, 1, 2));
    // A read of the written bank's row after the drain: a row hit, but not before the
    // last write's data + t_WTR. Writes: bank 1 activates at 13 (t_RRD after bank 0's),
    // columns at 41, 45, 49; data slots from (41 + t_CWD 13) / 4 → 14, 15, 16 — slot 14
    // is the read's (data 56-60), so 15, 16, 17: the last ends at tick 72; t_WTR 15:
    // no read column before 87. Read at cycle 3 (tick 6): column 87, data 115 → slot
    // 29, done 120 ticks = cycle 60.
    assert_eq!(d.rd(bank1 + 9, 3), (60, DramAccess::RowHit));
    // A write of a drained line merges until that write's column command (tick 41)
    // has issued; after it, it queues anew (a read is queued: no drain).
    d.write(LineAddr::new(bank1), Cycle(4), Cycle(4));
    assert_eq!(d.stats().writes_merged, 2);
    d.write(LineAddr::new(bank1), Cycle(30), Cycle(30));
    assert_eq!((d.stats().writes_merged, d.stats().writes), (2, 3));
    // With no read queued, a write drains at once.
    let mut d = Dram::new(&cfg);
    d.write(LineAddr::new(0), Cycle(100), Cycle(100));
    assert_eq!(d.stats().writes, 1);
    // write_queue = 0: stores are not sent to DRAM.
    let mut d = Dram::new(&DramConfig {
        write_queue: 0,
        ..cfg
    });
    d.write(LineAddr::new(0), Cycle(100), Cycle(100));
    assert_eq!(d.stats(), DramStats::default());
}

#[test]
fn a_write_holds_the_next_precharge_for_t_wr() {
    let mut d = Dram::new(&plain());
    // With no reads queued the write drains at once: bank 0 activates at tick 0,
    // column 28, data slot ceil((28 + 13) / 4) = 11, ends at 48. The conflicting read
    // at tick 0: precharge ≥ act + t_RAS 70 and ≥ 48 + t_WR 30 = 78 (> 70), act 106
    // (≥ t_RC 98), column 134, data 162 → slot 41, done 168 ticks = cycle 84. Without
    // the write it would be cycle 80 (`conflict_waits_for_t_ras`).
    d.write(LineAddr::new(0), Cycle(0), Cycle(0));
    assert_eq!(d.rd(128 * 16 * 16, 0), (84, DramAccess::Conflict));
    let s = d.stats();
    assert_eq!((s.reads, s.writes, s.activations), (1, 1, 2));
}

/// The same DRAM model (Lin et al. 2020 §5's GDDR5 memory) written for clarity, not
/// host speed: reservations in plain sets of taken ticks,
/// the read queue a min-heap of completion ticks, each bank's epochs a `VecDeque`.
mod reference {
    use super::super::bank::EPOCH_KEEP;
    use super::super::channel::{Refresh, faw_allows};
    use super::super::{DramAccess, DramStats};
    use crate::Cycle;
    use crate::config::DramConfig;
    use crate::hw::Tick;
    use std::cmp::Reverse;
    use std::collections::{BTreeSet, BinaryHeap, VecDeque};

    /// Taken ticks (or bus slots), all remembered.
    #[derive(Clone, Default)]
    struct Taken(BTreeSet<u64>);

    impl Taken {
        /// First start `s ≥ c` where `[s, s + len)` is free.
        fn find(&self, c: u64, len: u64) -> u64 {
            let mut s = c;
            while let Some(&x) = self.0.range(s..s + len).next() {
                s = x + 1;
            }
            s
        }
        fn reserve_span(&mut self, c: u64, len: u64) -> u64 {
            let s = self.find(c, len);
            self.0.extend(s..s + len);
            s
        }
    }

    #[derive(Clone, Copy)]
    struct Epoch {
        row: u64,
        act: u64,
        close: u64,
    }

    #[derive(Clone, Default)]
    struct Bank {
        epochs: VecDeque<Epoch>,
        open_row: Option<u64>,
        act: u64,
        col_ready: u64,
        last_col: u64,
    }

    #[derive(Clone, Default)]
    struct Channel {
        bus: Taken,
        acts: Taken,
        /// Every activation tick, ascending.
        faw: Vec<u64>,
        inflight: BinaryHeap<Reverse<u64>>,
    }

    /// The reference model.
    pub struct RefDram {
        cfg: DramConfig,
        banks: Vec<Bank>,
        channels: Vec<Channel>,
        /// Counters, as [`super::super::Dram::stats`].
        pub stats: DramStats,
    }

    impl RefDram {
        pub fn new(cfg: &DramConfig) -> Self {
            Self {
                cfg: cfg.clone(),
                banks: vec![Bank::default(); (cfg.channels * cfg.banks_per_channel) as usize],
                channels: vec![Channel::default(); cfg.channels as usize],
                stats: DramStats::default(),
            }
        }

        pub fn read(&mut self, line: u64, arrive: u64) -> (u64, DramAccess) {
            let c = &self.cfg;
            let tpc = c.ticks_per_cycle;
            let x = line / (c.row_bytes / 64);
            let chi = (x % c.channels as u64) as usize;
            let x = x / c.channels as u64;
            let bi = (x % c.banks_per_channel as u64) as usize;
            let row = x / c.banks_per_channel as u64;
            let ch = &mut self.channels[chi];
            let mut a = arrive * tpc;
            while ch.inflight.peek().is_some_and(|&Reverse(d)| d <= a) {
                ch.inflight.pop();
            }
            if ch.inflight.len() >= c.read_queue as usize {
                let Reverse(d) = ch.inflight.pop().expect("queue is full");
                self.stats.queue_wait_cycles += (d - a).div_ceil(tpc);
                a = d;
            }
            let bank = &mut self.banks[chi * c.banks_per_channel as usize + bi];
            while bank
                .epochs
                .front()
                .is_some_and(|e| e.close.saturating_add(EPOCH_KEEP) < a)
            {
                bank.epochs.pop_front();
            }
            let refresh = Refresh::new(c);
            let n = |t: u64| refresh.count(Tick(t));
            let mut result = None;
            if bank.open_row != Some(row) {
                for e in bank.epochs.iter().filter(|e| e.row == row) {
                    // Held open for a read arriving before the closing precharge.
                    let held = c.keep_open && e.close != u64::MAX && a < e.close + c.t_rtp;
                    let col = a.max(e.act + c.t_rcd);
                    if col > e.close && !held {
                        continue;
                    }
                    let slot = ch.bus.find((col + c.t_cas).div_ceil(c.t_burst), 1);
                    let col = slot * c.t_burst - c.t_cas;
                    if (col <= e.close || held) && n(col + c.t_rtp) == n(e.act) {
                        ch.bus.reserve_span(slot, 1);
                        result = Some((slot * c.t_burst + c.t_burst, DramAccess::RowHit));
                        break;
                    }
                }
            }
            let (done, kind) = match result {
                Some(r) => r,
                None => {
                    let open = if n(a.max(bank.col_ready) + c.t_rtp) == n(bank.act) {
                        bank.open_row
                    } else {
                        None
                    };
                    let (col, kind) = match open {
                        Some(r) if r == row => (a.max(bank.col_ready), DramAccess::RowHit),
                        open => {
                            let mut act = a;
                            let kind = if open.is_some() {
                                let pre = a.max(bank.act + c.t_ras).max(bank.last_col + c.t_rtp);
                                act = pre + c.t_rp;
                                DramAccess::Conflict
                            } else {
                                DramAccess::Closed
                            };
                            if open.is_some() || bank.act > 0 {
                                act = act.max(bank.act + c.t_rc);
                            }
                            let rrd = c.t_rrd.max(1);
                            loop {
                                act = ch.acts.find(act, rrd);
                                let f = refresh.free(Tick(act)).get();
                                if f != act {
                                    act = f;
                                } else if faw_allows(&ch.faw, act, c.t_faw) {
                                    break;
                                } else {
                                    act += 1;
                                }
                            }
                            ch.acts.reserve_span(act, rrd);
                            let i = ch.faw.partition_point(|&t| t <= act);
                            ch.faw.insert(i, act);
                            if let Some(last) = bank.epochs.back_mut() {
                                last.close = act - c.t_rp - c.t_rtp;
                            }
                            bank.epochs.push_back(Epoch {
                                row,
                                act,
                                close: u64::MAX,
                            });
                            bank.act = act;
                            bank.open_row = Some(row);
                            self.stats.activations += 1;
                            ((act + c.t_rcd).max(bank.col_ready), kind)
                        }
                    };
                    bank.col_ready = col + c.t_ccd;
                    bank.last_col = col;
                    let slot = ch.bus.reserve_span((col + c.t_cas).div_ceil(c.t_burst), 1);
                    (slot * c.t_burst + c.t_burst, kind)
                }
            };
            ch.inflight.push(Reverse(done));
            let done_cycle = done.div_ceil(tpc);
            let s = &mut self.stats;
            s.reads += 1;
            match kind {
                DramAccess::RowHit => s.row_hits += 1,
                DramAccess::Closed => s.row_closed += 1,
                DramAccess::Conflict => s.row_conflicts += 1,
            }
            s.latency_cycles += done_cycle - arrive;
            s.last_done = s.last_done.max(Cycle(done_cycle));
            (done_cycle, kind)
        }
    }
}

/// Every read's completion and kind, and the counters, equal the reference model's on
/// random streams: lines concentrated on a few channels, banks and rows (row hits,
/// conflicts, earlier epochs of the same row), arrivals jittered ahead of a rising
/// event time with idle gaps (the rings recycle) and bursts, read queues from 1 entry
/// (always full) to 64 (full in the bursts, or not at all in the light streams), and
/// timings that are not powers of two.
#[test]
fn reads_match_the_reference_model_on_random_streams() {
    for seed in 0..24u64 {
        let mut rng = Pcg32::new(seed, 21);
        let mut cfg = SimConfig::lin2020().dram;
        cfg.read_queue = [1, 2, 5, 16, 64, 64][seed as usize % 6];
        // Bursts separated by idle gaps; "light" streams also advance between reads.
        let light = seed % 6 == 4;
        if seed % 4 == 3 {
            (cfg.ticks_per_cycle, cfg.t_burst, cfg.t_rrd) = (3, 3, 7);
        }
        // Frequent refreshes and a wide four-activate window, so both bind often.
        if seed % 5 == 1 {
            (cfg.t_refi, cfg.t_rfc, cfg.t_faw) = (700, 60, 120);
        }
        if seed % 7 == 2 {
            (cfg.t_refi, cfg.t_faw) = (0, 0);
        }
        // The keep-open rule on and off; one refresh per window or USIMM's eight.
        cfg.keep_open = seed % 3 != 0;
        if seed % 2 == 0 {
            cfg.refresh_burst = 1;
        }
        let mut d = Dram::new(&cfg);
        let mut r = reference::RefDram::new(&cfg);
        let lines_per_row = cfg.row_bytes / 64;
        let (chs, banks, rows) = (1 + rng.below(3), 1 + rng.below(4), 1 + rng.below(6));
        let mut now = 0;
        for i in 0..4000 {
            now += match rng.below(400) {
                0..2 => 2000 + rng.below(5000) as u64,
                2..80 if light => rng.below(40) as u64,
                _ => 0,
            };
            let arrive = now + rng.below(60) as u64;
            let (ch, bank, row) = (rng.below(chs), rng.below(banks), rng.below(rows));
            let line = ((row as u64 * cfg.banks_per_channel as u64 + bank as u64)
                * cfg.channels as u64
                + ch as u64)
                * lines_per_row
                + rng.below(lines_per_row as u32) as u64;
            let got = d.rd_at(line, arrive, now);
            assert_eq!(got, r.read(line, arrive), "seed {seed}, read {i}");
        }
        // The reference model keeps no latency histogram.
        let got = DramStats {
            latency_p95_cycles: 0,
            ..d.stats()
        };
        assert_eq!(got, r.stats, "seed {seed}");
        if !light {
            assert!(
                d.stats().queue_wait_cycles > 0,
                "seed {seed}: queue never full"
            );
        }
    }
}

#[test]
fn closed_then_hit_then_conflict_exact_latencies() {
    let mut d = dram();
    // Closed: tRCD 14 + tCAS 14 + burst 2 = 30 core cycles.
    assert_eq!(d.rd(0, 1000), (1030, DramAccess::Closed));
    // Row hit on the same row (line 1 is column 1 of row 0): tCAS 14 + burst 2.
    assert_eq!(d.rd(1, 2000), (2016, DramAccess::RowHit));
    // Conflict: same channel and bank, next row. Lines per row 128, channels 16, banks 16.
    let other_row = 128 * 16 * 16;
    assert_eq!(d.map(LineAddr::new(other_row)), (0, 0, 1));
    // tRP 14 + tRCD 14 + tCAS 14 + burst 2 = 44.
    assert_eq!(d.rd(other_row, 3000), (3044, DramAccess::Conflict));
    let s = d.stats();
    assert_eq!((s.reads, s.activations, s.row_hits), (3, 2, 1));
}

#[test]
fn conflict_waits_for_t_ras() {
    let mut d = dram();
    assert_eq!(d.rd(0, 0).0, 30);
    // Immediately conflicting: precharge may not start before act + tRAS (35 ns).
    // act at 0, pre at 35 ns, act at 49 ns (= tRC too), data at 49 + 14 + 14 = 77 ns,
    // rounded up to the 2 ns burst slot grid (78), + burst 2 = 80.
    assert_eq!(d.rd(128 * 16 * 16, 0), (80, DramAccess::Conflict));
}

#[test]
fn row_hit_overtakes_an_older_conflict() {
    let mut d = dram();
    let row1 = 128 * 16 * 16;
    // A: row 0, closed: act at tick 0, column 28, data slot 14 (ticks 56–60): cycle 30.
    assert_eq!(d.rd(0, 0), (30, DramAccess::Closed));
    // B: row 1, conflict: precharge at t_RAS (70), act 98 (= t_RC), column 126, data at
    // 154 rounded up to the burst grid 156, done 160 ticks: cycle 80. Row 0's epoch now
    // closes at 98 − t_RP 28 − t_RTP 15 = tick 55.
    assert_eq!(d.rd(row1, 0), (80, DramAccess::Conflict));
    // C: row 0 again, one cycle after B. In arrival order it would be a second conflict
    // (≥ 49 ns after B's activate). Row-hit-first: row 0 is still open before B's
    // precharge, so C is a row hit: column at 28, data slot 14 is A's, so slot 15
    // (column effectively at 60 − 28 = 32 ≤ 55), done at tick 64: cycle 32, before B.
    assert_eq!(d.rd(1, 1), (32, DramAccess::RowHit));
    // D: row 0 at cycle 20 (tick 40): column 40, data at 68 = slot 17, done 72: cycle 36.
    assert_eq!(d.rd(2, 20), (36, DramAccess::RowHit));
    // E: row 0 at cycle 30 (tick 60 > 55): too late for row 0's epoch, so a conflict
    // after B: precharge at B's act 98 + t_RAS 70 = 168, act 196 (= 98 + t_RC), column
    // 224, data 252, done 256 ticks: cycle 128.
    assert_eq!(d.rd(3, 30), (128, DramAccess::Conflict));
    let s = d.stats();
    assert_eq!(
        (s.reads, s.activations, s.row_hits, s.row_conflicts),
        (5, 3, 2, 2)
    );
}

#[test]
fn interleaved_rows_pay_one_activation_per_row_and_epoch() {
    // Two rows of one bank requested alternately, all at once: in arrival order every
    // read would be a conflict (8 activations); row-hit-first groups them per row.
    let mut d = dram();
    let row1 = 128 * 16 * 16;
    for i in 0..4 {
        d.rd(i, 0);
        d.rd(row1 + i, 0);
    }
    let s = d.stats();
    assert_eq!((s.reads, s.activations, s.row_hits), (8, 2, 6));
}

#[test]
fn a_backed_up_bank_does_not_delay_another_bank_of_its_channel() {
    let mut d = dram();
    let row = 128 * 16 * 16;
    // 20 different rows of bank 0 (channel 0), all at cycle 0: each waits t_RC for the
    // previous one, so the last data is ~1 µs ahead.
    let last = (0..20).map(|r| d.rd(r * row, 0).0).max().unwrap();
    assert!(last > 900, "{last}");
    // Bank 1 of channel 0 at cycle 0: closed row, its activation only spaced t_RRD
    // (13 ticks) after bank 0's first: act 13, column 41, data at 69 rounded to the
    // burst grid 72, done 76 ticks = cycle 38 (not behind bank 0's far-future bursts).
    assert_eq!(d.rd(128 * 16, 0), (38, DramAccess::Closed));
}

#[test]
fn divisor_equals_plain_division() {
    for d in [1u64, 2, 3, 4, 5, 8, 12, 16] {
        let div = Divisor::new(d);
        for x in (0..200).chain([u64::MAX - 1, u64::MAX]) {
            assert_eq!(div.div(x), x / d, "{x} / {d}");
            assert_eq!(div.div_ceil(x), x.div_ceil(d), "{x} div_ceil {d}");
        }
    }
}

#[test]
fn mapping_is_column_channel_bank_row() {
    let d = dram();
    assert_eq!(d.map(LineAddr::new(127)), (0, 0, 0));
    assert_eq!(d.map(LineAddr::new(128)), (1, 0, 0));
    assert_eq!(d.map(LineAddr::new(128 * 16)), (0, 1, 0));
}

#[test]
fn one_channel_streams_at_one_line_per_burst() {
    let mut d = dram();
    // 100 row-hit reads of one row arriving together: the bus serialises them.
    let dones: Vec<_> = (0..100).map(|i| d.rd(i % 128, 0).0).collect();
    for w in dones.windows(2) {
        assert_eq!(w[1] - w[0], 2, "one 64-B line per 2 ns per channel");
    }
}

#[test]
fn saturates_at_peak_bandwidth_and_no_faster() {
    let cfg = SimConfig::lin2020();
    let mut d = Dram::new(&cfg.dram);
    // 64 K lines, all requested at cycle 0, spread over every channel and bank.
    let n = 65_536u64;
    let last = (0..n).map(|l| d.rd(l, 0).0).max().unwrap();
    let bytes_per_cycle = (n * 64) as f64 / last as f64;
    let peak = cfg.dram_peak_bytes_per_cycle();
    assert_eq!(peak, 512.0);
    assert!(
        bytes_per_cycle <= peak,
        "{bytes_per_cycle} above peak {peak}"
    );
    assert!(
        bytes_per_cycle > 0.97 * peak,
        "{bytes_per_cycle} well below peak"
    );
}

#[test]
fn full_read_queue_back_pressures() {
    let mut cfg = SimConfig::lin2020().dram;
    cfg.read_queue = 2;
    let mut d = Dram::new(&cfg);
    d.rd(0, 0);
    d.rd(1, 0);
    d.rd(2, 0);
    assert!(d.stats().queue_wait_cycles > 0);
    let mut cfg = SimConfig::lin2020().dram;
    cfg.read_queue = 64;
    let mut d = Dram::new(&cfg);
    (0..3).for_each(|l| {
        d.rd(l, 0);
    });
    assert_eq!(d.stats().queue_wait_cycles, 0);
}
