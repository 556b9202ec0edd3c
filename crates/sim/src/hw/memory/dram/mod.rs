//! GDDR5 main memory: channels of banks with open rows, per-channel data bus, read queue
//! (SimTRaX's USIMM configuration `gddr5_8ch.cfg` and timing file `1Gb_x16_amd2GHz.vi`;
//! USIMM `memory_controller.cc`, `scheduler.cc`).
//!
//! Address mapping (SimTRaX mapping 1), from the low bits up: line offset → column →
//! channel → bank → row, so one row of one channel holds `row_bytes` contiguous bytes.
//!
//! Each read is reserved when it arrives (immediate response, Eyerman et al. 2021):
//!
//! * **row hit** (bank's open row): column command at the bank's next column slot;
//! * **closed** (no open row): activate, then after t_RCD the column command;
//! * **conflict** (another row open): precharge (≥ t_RAS after its activate, ≥ t_RTP after
//!   its last read), activate after t_RP (≥ t_RC after the previous activate, ≥ t_RRD after
//!   the channel's previous activate), column command after t_RCD;
//!
//! then the data leaves t_CAS later in the channel bus's first free burst slot (slots are
//! t_burst long; a later-reserved row hit may fill a gap before an earlier conflict's data).
//!
//! An activation also keeps the channel's (one rank's) **four-activate window**: at most
//! four activations in any t_FAW ticks (USIMM `memory_controller.cc:134-170`). **Refresh**:
//! every t_REFI ticks each channel is refreshed for t_RFC ticks (window k ≥ 1 is
//! `[k·t_REFI, k·t_REFI + t_RFC)`, the same for every channel), in which no activation
//! issues, and which closes every open row: a read after a refresh finds its bank closed.
//! USIMM forces a refresh at such deadlines (`memory_controller.cc:215-218`); its refresh
//! times are per rank and follow the controller's state, ours are a fixed grid, and a column
//! command already placed is not moved out of a window (a simplification: a window is
//! t_RFC = 220 of t_REFI = 15,600 ticks).
//! A full read queue delays the request until the first of its channel's in-flight reads
//! completes (back-pressure). The queue is kept on the bus table itself: each in-flight
//! read is marked *pending* on its data-bus slot, which is also its completion time.
//!
//! **Row-hit-first scheduling (FR-FCFS).** Each bank keeps its schedule as a short list of
//! row *epochs*: the row, its activation tick and the last tick a column command may use it
//! (`close`: the next epoch's activation − t_RP − t_RTP; open-ended for the last epoch).
//! A read to a row that is open in an epoch still ahead of it is served there as a row hit
//! — in front of the older reads that caused the next epoch's precharge — provided its
//! column command (delayed to its data-bus slot) fits before `close`. That is what an
//! FR-FCFS controller does with the requests queued while t_RAS / t_RC / t_RRD hold a row
//! open: the oldest request to the open row goes first, the oldest conflict when none is
//! left. Because every read learns its completion when it arrives (the reservation model),
//! a row hit never *extends* an epoch: already promised later epochs keep their times, so a
//! hit arriving after `close` opens a new epoch like any conflict.
//!
//! **Host cost.** A DRAM read is on the replay's hot path (1.5 per node visit in the
//! synthetic bench), so the state a read touches is kept small and in few host cache lines:
//! the bank record is one 64-byte line holding the open row, the earliest epoch's expiry
//! tick and a 64-bit summary of the earlier epochs' rows, so most reads neither expire nor
//! scan epochs; the epochs themselves (16 bytes each) sit in one slab of per-bank rings; the
//! read queue is a bit plane of the bus table; the bus and t_RRD tables
//! ([`SparseSlots`](crate::hw::slots::SparseSlots)) settle most requests with one inline word test. The tests keep a
//! plain implementation of the same model (heap, `VecDeque`, plain sets) as a reference and
//! compare every read's result on random streams.

mod bank;
mod channel;
#[cfg(test)]
mod tests;

use crate::config::DramConfig;
use crate::hw::addr::LineAddr;
use crate::hw::{Cycle, Tick};
use bank::{Bank, Epochs, NO_ROW, activate};
use channel::{Channel, Refresh};
use serde::{Deserialize, Serialize};

/// How a read found its bank.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DramAccess {
    /// The row was open.
    RowHit,
    /// No row was open.
    Closed,
    /// Another row was open.
    Conflict,
}

/// Counters of the DRAM.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DramStats {
    /// 64-byte reads served.
    pub reads: u64,
    /// Row activations.
    pub activations: u64,
    /// Reads that hit the open row.
    pub row_hits: u64,
    /// Reads to a closed bank.
    pub row_closed: u64,
    /// Reads that had to close another row.
    pub row_conflicts: u64,
    /// 64-byte writes issued (drained from the write queue; stores go through the L2).
    #[serde(default)]
    pub writes: u64,
    /// Row activations for writes (included in `activations`).
    #[serde(default)]
    pub write_activations: u64,
    /// Writes merged with a queued write of the same line.
    #[serde(default)]
    pub writes_merged: u64,
    /// Core cycles reads spent waiting for a read-queue entry (summed over reads).
    pub queue_wait_cycles: u64,
    /// Sum over reads of (completion − arrival) in core cycles.
    pub latency_cycles: u64,
    /// Core cycle of the last completion.
    pub last_done: Cycle,
    /// The 95th percentile of (completion − arrival) over reads, in core cycles (the
    /// smallest latency that at least 95 % of reads do not exceed).
    #[serde(default)]
    pub latency_p95_cycles: u64,
}

/// Read latencies counted one bucket per core cycle up to this many cycles; longer ones
/// share the last bucket (the percentile then reports this bound).
const LATENCY_BUCKETS: usize = 4096;

/// The DRAM system.
#[derive(Clone, Debug)]
pub struct Dram {
    cfg: DramConfig,
    banks: Vec<Bank>,
    epochs: Epochs,
    channels: Vec<Channel>,
    col_bits: u32,
    ch_bits: u32,
    bank_bits: u32,
    /// Divisions by t_burst and by ticks_per_cycle.
    burst: Divisor,
    tpc: Divisor,
    refresh: Refresh,
    stats: DramStats,
    /// Reads by latency in core cycles ([`LATENCY_BUCKETS`]).
    latency_histogram: Vec<u64>,
}

/// Division by a timing constant: a shift when it is a power of two (t_burst = 4 and
/// ticks_per_cycle = 2 in the shipped configs), otherwise a division. A 64-bit division
/// costs tens of cycles on the host and `read_at` makes several per DRAM read.
#[derive(Clone, Copy, Debug)]
struct Divisor {
    d: u64,
    shift: Option<u32>,
}

impl Divisor {
    fn new(d: u64) -> Self {
        Self {
            d,
            shift: d.is_power_of_two().then(|| d.trailing_zeros()),
        }
    }

    /// `x / d`.
    #[inline(always)]
    fn div(self, x: u64) -> u64 {
        match self.shift {
            Some(s) => x >> s,
            None => x / self.d,
        }
    }

    /// `x.div_ceil(d)`.
    #[inline(always)]
    fn div_ceil(self, x: u64) -> u64 {
        match self.shift {
            Some(s) => (x >> s) + u64::from(x & (self.d - 1) != 0),
            None => x.div_ceil(self.d),
        }
    }
}

impl Dram {
    /// All banks closed, all buses idle.
    pub fn new(cfg: &DramConfig) -> Self {
        Self {
            cfg: cfg.clone(),
            banks: vec![Bank::default(); (cfg.channels * cfg.banks_per_channel) as usize],
            epochs: Epochs::new((cfg.channels * cfg.banks_per_channel) as usize),
            channels: vec![Channel::default(); cfg.channels as usize],
            col_bits: (cfg.row_bytes / 64).trailing_zeros(),
            ch_bits: cfg.channels.trailing_zeros(),
            bank_bits: cfg.banks_per_channel.trailing_zeros(),
            burst: Divisor::new(cfg.t_burst),
            tpc: Divisor::new(cfg.ticks_per_cycle),
            refresh: Refresh::new(cfg),
            stats: DramStats::default(),
            latency_histogram: vec![0; LATENCY_BUCKETS],
        }
    }

    /// (channel, bank, row) of a line number (byte address / 64).
    pub fn map(&self, line: LineAddr) -> (usize, usize, u64) {
        let line = line.get();
        let (ch, b, row) = self.locate(line);
        (ch, b >> self.ch_bits, row)
    }

    /// The mapping of [`Dram::map`] as indices: (channel, bank record, row), bank records
    /// numbered bank · channels + channel, so both indices are masks of the same bits by
    /// power-of-two table lengths (and the indexing needs no bounds test).
    #[inline]
    fn locate(&self, line: u64) -> (usize, usize, u64) {
        let x = line >> self.col_bits;
        (
            x as usize & (self.channels.len() - 1),
            x as usize & (self.banks.len() - 1),
            x >> (self.ch_bits + self.bank_bits),
        )
    }

    /// Reads `line` arriving at core cycle `arrive`; returns the core cycle its data has
    /// arrived and how the bank was found.
    pub fn read(&mut self, line: LineAddr, arrive: Cycle) -> (Cycle, DramAccess) {
        self.read_at(line, arrive, Cycle::ZERO)
    }

    /// As [`Dram::read`], when no read will ever arrive before core cycle `now` (the
    /// engine's current event time, `now ≤ arrive`): the channel's reservation tables then
    /// forget what ended before it. The result is the same as `read`'s.
    pub fn read_at(&mut self, line: LineAddr, arrive: Cycle, now: Cycle) -> (Cycle, DramAccess) {
        let line = line.get();
        debug_assert!(now <= arrive);
        let (chi, b, row) = self.locate(line);
        self.make_room(chi, b, now);
        let c = &self.cfg;
        let tpc = c.ticks_per_cycle;
        let ch = &mut self.channels[chi];
        // The read's tick; the schedule below is in ticks.
        let mut a = arrive.to_ticks(tpc);
        // Reads complete by `a` leave the queue: slot `s` completes at (s + 1) · t_burst ≤ a,
        // i.e. s < ⌊a / t_burst⌋ (every pending slot is at or after the bus floor, which
        // is at most that: the floor comes from `now ≤ arrive`).
        ch.bus.retire_before(self.burst.div(a.get()));
        if ch.bus.pending() >= c.read_queue
            && let Some(s) = ch.bus.retire_first()
        {
            let d = Tick(s * c.t_burst + c.t_burst);
            self.stats.queue_wait_cycles += self.tpc.div_ceil(d - a);
            a = d;
        }
        let bank = &mut self.banks[b];
        let gap = c.t_rp + c.t_rtp;
        let refresh = self.refresh;
        let epochs = &mut self.epochs;
        epochs.expire(b, bank, a, gap);
        // No column read before the last drained write's data has ended + t_WTR.
        let wtr = Tick(ch.wtr);
        // Row-hit-first: an earlier epoch of this row still ahead of the read serves it
        // (the last epoch is the open row's).
        if bank.open_row != row && bank.rows & 1 << (row & 63) != 0 {
            let mut hit = None;
            let mut rows = 0;
            for i in 0..bank.len - 1 {
                let e = epochs.slab[epochs.at(b, bank, i)];
                rows |= 1 << (e.row & 63);
                if e.row != row {
                    continue;
                }
                let close = epochs.slab[epochs.at(b, bank, i + 1)].act - gap;
                // USIMM holds the precharge that ends the epoch while a queued read needs
                // its row (`scheduler.cc:217-231`): a read arriving before that precharge
                // (the next epoch's activate − t_RP) is served from the row.
                let held = c.keep_open && a < close + c.t_rtp;
                let col = a.max(e.act + c.t_rcd).max(wtr);
                if col > close && !held {
                    continue;
                }
                // The column command waits for its data-bus slot (t_CAS before it).
                let slot = ch.bus.peek(self.burst.div_ceil((col + c.t_cas).get()));
                let col = Tick(slot * c.t_burst) - c.t_cas;
                if (col <= close || held) && refresh.count(col + c.t_rtp) == refresh.count(e.act) {
                    hit = Some(slot);
                    break;
                }
            }
            if hit.is_none() {
                bank.rows = rows;
            }
            if let Some(slot) = hit {
                ch.bus.reserve_pending(slot);
                let done = Tick(slot * c.t_burst + c.t_burst);
                return self.finish(arrive, done, DramAccess::RowHit);
            }
        }
        // A refresh since the bank's last activation closed its row.
        let open = if refresh.count(a.max(bank.col_ready) + c.t_rtp) == refresh.count(bank.act) {
            bank.open_row
        } else {
            NO_ROW
        };
        let (col, kind) = if open == row {
            (a.max(bank.col_ready), DramAccess::RowHit)
        } else {
            let (act, kind) = activate(c, refresh, ch, epochs, b, bank, row, a, open);
            ((act + c.t_rcd).max(bank.col_ready), kind)
        };
        let col = col.max(wtr);
        bank.col_ready = col + c.t_ccd;
        bank.last_col = bank.last_col.max(col);
        // The data bus takes the first free burst slot once the data is ready; a read whose
        // row is open can use a slot before a conflicting read reserved earlier, which is
        // the effect of FR-FCFS on the bus.
        let data = ch
            .bus
            .reserve_pending(self.burst.div_ceil((col + c.t_cas).get()))
            * c.t_burst;
        let done = Tick(data + c.t_burst);
        self.finish(arrive, done, kind)
    }

    /// Grows the epoch rings when bank `b`'s is full (a request opens at most one epoch)
    /// and lets channel `chi`'s tables forget what ended before core cycle `now`.
    #[inline]
    fn make_room(&mut self, chi: usize, b: usize, now: Cycle) {
        if self.banks[b].len == 1 << self.epochs.shift {
            self.epochs.grow(&mut self.banks);
        }
        let c = &self.cfg;
        let ch = &mut self.channels[chi];
        let floor = now.to_ticks(c.ticks_per_cycle).get();
        ch.bus.forget_before(self.burst.div(floor));
        ch.acts.forget_before(floor);
        let old = ch.faw.partition_point(|&t| t + c.t_faw < floor);
        if old > 0 {
            ch.faw.drain(..old);
        }
    }

    /// A 64-byte write of `line` (a store the L2 passed on, SimTRaX `sim/L2Cache.cc:374-383`)
    /// arriving at core cycle `arrive`, `now ≤ arrive` the engine's event time. It joins
    /// its channel's write queue, merging with a queued write of the same line (USIMM
    /// `memory_controller.cc:839-841`), drained or not, until that write's column command
    /// issues; the store does not wait for it. The queue is
    /// drained as USIMM's scheduler does (`scheduler.cc:87-107`): when it holds more than
    /// `write_high` writes, down to `write_low`; when no read is queued, entirely. A drained
    /// write is reserved like a read at the tick of the write that started the drain
    /// (activating its row when another is open), with t_CWD to its data, t_WR from the
    /// data's end to the bank's next precharge and t_WTR to the channel's next column read.
    /// `dram.write_queue = 0`: stores are not sent to DRAM.
    pub fn write(&mut self, line: LineAddr, arrive: Cycle, now: Cycle) {
        let c = &self.cfg;
        if c.write_queue == 0 {
            return;
        }
        let line = line.get();
        let (chi, _, _) = self.locate(line);
        let a = arrive.to_ticks(c.ticks_per_cycle);
        let ch = &mut self.channels[chi];
        // Writes whose column command has issued by `a` have left the queue.
        ch.writes.retain(|&(_, col)| col > a.get());
        if ch.writes.iter().any(|&(l, _)| l == line) {
            self.stats.writes_merged += 1;
            return;
        }
        ch.writes.push((line, u64::MAX));
        ch.bus.retire_before(self.burst.div(a.get()));
        let queued = ch.writes.len();
        let keep = if queued > c.write_high as usize {
            c.write_low.min(c.write_high) as usize
        } else if ch.bus.pending() == 0 {
            0
        } else {
            return;
        };
        // Drain the oldest writes not yet drained until `keep` would be left.
        let mut n = queued.saturating_sub(keep);
        for i in 0..queued {
            if n == 0 {
                break;
            }
            let (l, col) = self.channels[chi].writes[i];
            if col == u64::MAX {
                let col = self.write_now(l, a, now);
                self.channels[chi].writes[i].1 = col.get();
                n -= 1;
            }
        }
    }

    /// Reserves one drained write of `line` from tick `a` (see [`Dram::write`]); returns
    /// the tick of its column command.
    fn write_now(&mut self, line: u64, a: Tick, now: Cycle) -> Tick {
        let (chi, b, row) = self.locate(line);
        self.make_room(chi, b, now);
        let c = &self.cfg;
        let ch = &mut self.channels[chi];
        let bank = &mut self.banks[b];
        let gap = c.t_rp + c.t_rtp;
        let refresh = self.refresh;
        let epochs = &mut self.epochs;
        epochs.expire(b, bank, a, gap);
        let open = if refresh.count(a.max(bank.col_ready) + c.t_rtp) == refresh.count(bank.act) {
            bank.open_row
        } else {
            NO_ROW
        };
        let col = if open == row {
            a.max(bank.col_ready)
        } else {
            let (act, _) = activate(c, refresh, ch, epochs, b, bank, row, a, open);
            self.stats.write_activations += 1;
            (act + c.t_rcd).max(bank.col_ready)
        };
        bank.col_ready = col + c.t_ccd;
        let slot = ch.bus.reserve(self.burst.div_ceil((col + c.t_cwd).get()));
        let end = slot * c.t_burst + c.t_burst;
        // The bank's next precharge waits t_WR after the data (it waits t_RTP after the
        // last column command).
        bank.last_col = bank
            .last_col
            .max(Tick((end + c.t_wr).saturating_sub(c.t_rtp)));
        ch.wtr = ch.wtr.max(end + c.t_wtr);
        self.stats.writes += 1;
        Tick(slot * c.t_burst) - c.t_cwd
    }

    /// Counts a read arriving at core cycle `arrive` whose data is complete at tick `done`.
    fn finish(&mut self, arrive: Cycle, done: Tick, kind: DramAccess) -> (Cycle, DramAccess) {
        let done_cycle = Cycle(self.tpc.div_ceil(done.get()));
        let s = &mut self.stats;
        match kind {
            DramAccess::RowHit => s.row_hits += 1,
            DramAccess::Closed => s.row_closed += 1,
            DramAccess::Conflict => s.row_conflicts += 1,
        }
        let latency = done_cycle - arrive;
        s.latency_cycles += latency;
        s.last_done = s.last_done.max(done_cycle);
        self.latency_histogram[(latency as usize).min(LATENCY_BUCKETS - 1)] += 1;
        (done_cycle, kind)
    }

    /// Counters so far.
    pub fn stats(&self) -> DramStats {
        // Every read is a row hit, a closed bank or a conflict, and activates a row unless
        // it is a row hit: the two sums are not counted on the way.
        let s = self.stats;
        let reads = s.row_hits + s.row_closed + s.row_conflicts;
        DramStats {
            reads,
            activations: s.row_closed + s.row_conflicts + s.write_activations,
            latency_p95_cycles: percentile(&self.latency_histogram, reads, 95),
            ..s
        }
    }
}

/// The smallest bucket index at or below which at least `pct` % of the `total` counts lie.
fn percentile(histogram: &[u64], total: u64, pct: u64) -> u64 {
    let need = (total * pct).div_ceil(100);
    let mut seen = 0;
    for (i, &n) in histogram.iter().enumerate() {
        seen += n;
        if seen >= need && need > 0 {
            return i as u64;
        }
    }
    0
}
