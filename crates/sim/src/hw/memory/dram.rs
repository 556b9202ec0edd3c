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
//! ([`SparseSlots`]) settle most requests with one inline word test. The tests keep a
//! plain implementation of the same model (heap, `VecDeque`, plain sets) as a reference and
//! compare every read's result on random streams.

use crate::config::DramConfig;
use crate::hw::addr::LineAddr;
use crate::hw::slots::SparseSlots;
use crate::hw::{Cycle, Tick};
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

/// A row's time open in a bank's schedule. Its `close` (the last tick a column command
/// may read it) is the next epoch's activate − t_RP − t_RTP, open-ended for the last
/// epoch: it is derived from the next entry rather than stored, so an epoch is 16 bytes
/// and opening one writes nothing else.
#[derive(Clone, Copy, Debug)]
struct Epoch {
    row: u64,
    /// Tick of its activate.
    act: Tick,
}

/// Ticks an epoch is kept after its `close` (reads arrive slightly out of order: fluffy
/// time).
const EPOCH_KEEP: u64 = 256;

/// `Bank::open_row` when no row is open (rows are line numbers / 128 or less: < 2^58).
const NO_ROW: u64 = u64::MAX;

/// One bank: 64 bytes, one host cache line. Its row epochs are a ring in [`Epochs`]; the
/// record keeps what most reads need so that they do not touch the ring: when the
/// earliest epoch expires, and which rows the earlier epochs hold.
#[derive(Clone, Debug)]
#[repr(align(64))]
struct Bank {
    /// The open row (the last epoch's), or [`NO_ROW`].
    open_row: u64,
    /// Tick of the last activate.
    act: Tick,
    /// Earliest tick of the next column command.
    col_ready: Tick,
    /// Tick of the last column command (for t_RTP).
    last_col: Tick,
    /// The earliest epoch expires once a read's tick exceeds this: its close (the next
    /// epoch's activate − t_RP − t_RTP) + [`EPOCH_KEEP`]; `Tick::MAX` while only one epoch
    /// is live.
    expiry: Tick,
    /// Bit `row mod 64` set for each live epoch but the last (and possibly for expired
    /// ones: refreshed whenever a read scans them all), so a read whose bit is clear has no
    /// earlier epoch of its row to try.
    rows: u64,
    /// Ring position of the earliest live epoch.
    head: u32,
    /// Live epochs (`0` before the first activate).
    len: u32,
}

impl Default for Bank {
    fn default() -> Self {
        Self {
            open_row: NO_ROW,
            act: Tick(0),
            col_ready: Tick(0),
            last_col: Tick(0),
            expiry: Tick::MAX,
            rows: 0,
            head: 0,
            len: 0,
        }
    }
}

/// Every bank's live row epochs, oldest first: bank `b`'s ring is
/// `slab[b · cap .. (b + 1) · cap]` (`cap` a power of two, doubled for all banks the first
/// time one needs more), so opening an epoch writes 16 bytes and no allocation is touched.
#[derive(Clone, Debug)]
struct Epochs {
    slab: Vec<Epoch>,
    /// log2(`cap`).
    shift: u32,
}

impl Epochs {
    fn new(banks: usize) -> Self {
        let shift = 3;
        Self {
            slab: vec![
                Epoch {
                    row: 0,
                    act: Tick(0),
                };
                banks << shift
            ],
            shift,
        }
    }

    /// Slab index of bank `b`'s `i`-th live epoch.
    #[inline]
    fn at(&self, b: usize, bank: &Bank, i: u32) -> usize {
        let mask = (1u32 << self.shift) - 1;
        (b << self.shift) + (bank.head.wrapping_add(i) & mask) as usize
    }

    /// `expiry` for bank `b` whose epochs are as they are now (`gap` = t_RP + t_RTP).
    #[inline]
    fn expiry(&self, b: usize, bank: &Bank, gap: u64) -> Tick {
        if bank.len < 2 {
            Tick::MAX
        } else {
            (self.slab[self.at(b, bank, 1)].act - gap).saturating_add(EPOCH_KEEP)
        }
    }

    /// Drops bank `b`'s epochs closed more than [`EPOCH_KEEP`] ticks before tick `a` (the
    /// last epoch never closes).
    #[inline]
    fn expire(&self, b: usize, bank: &mut Bank, a: Tick, gap: u64) {
        if bank.expiry < a {
            self.expire_slow(b, bank, a, gap);
        }
    }

    #[inline]
    fn expire_slow(&self, b: usize, bank: &mut Bank, a: Tick, gap: u64) {
        while bank.expiry < a {
            bank.head = bank.head.wrapping_add(1);
            bank.len -= 1;
            bank.expiry = self.expiry(b, bank, gap);
        }
    }

    /// Opens `row` at tick `act` in bank `b` (the bank's open row and activate are still
    /// the previous epoch's; its ring has room: [`Dram::read_at`] grows it first).
    #[inline]
    fn push(&mut self, b: usize, bank: &mut Bank, row: u64, act: Tick, gap: u64) {
        debug_assert!(bank.len < 1 << self.shift);
        let i = self.at(b, bank, bank.len);
        self.slab[i] = Epoch { row, act };
        if bank.len > 0 {
            bank.rows |= 1 << (bank.open_row & 63);
        }
        bank.len += 1;
        if bank.len == 2 {
            bank.expiry = (act - gap).saturating_add(EPOCH_KEEP);
        }
    }

    /// Doubles every bank's ring; each ring starts at position 0 afterwards.
    #[cold]
    fn grow(&mut self, banks: &mut [Bank]) {
        let shift = self.shift + 1;
        let mut slab = vec![
            Epoch {
                row: 0,
                act: Tick(0),
            };
            banks.len() << shift
        ];
        for (b, bank) in banks.iter_mut().enumerate() {
            for i in 0..bank.len {
                slab[(b << shift) + i as usize] = self.slab[self.at(b, bank, i)];
            }
            bank.head = 0;
        }
        (self.slab, self.shift) = (slab, shift);
    }
}

#[derive(Clone, Debug, Default)]
struct Channel {
    /// Data-bus reservations in units of one burst (t_burst ticks). The read queue is the
    /// bus's pending plane: a read in flight is marked pending on its bus slot `s`, and its
    /// data is complete at tick `(s + 1) · t_burst` (every read has a slot of its own, so
    /// the earliest pending slot is the earliest completion).
    bus: SparseSlots<2>,
    /// Activations, each holding t_RRD ticks (minimum spacing between activations).
    acts: SparseSlots,
    /// Ticks of the activations that may still share a t_FAW window with a later one,
    /// ascending.
    faw: Vec<u64>,
    /// The write queue, oldest first: each write's line and the tick of its column command,
    /// `u64::MAX` until it is drained (a drained write stays queued, and later writes of
    /// its line merge into it, until its column command issues).
    writes: Vec<(u64, u64)>,
    /// No column read before this tick: the end of the last drained write's data + t_WTR.
    wtr: u64,
}

/// The refresh schedule as USIMM issues it (`memory_controller.cc:215-218`, `:2097-2121`,
/// `:1943-1956`): every `period` = `refresh_burst` · t_REFI ticks a channel's one rank is
/// refreshed `refresh_burst` times together, forced at the deadline k · `period` (k ≥ 1):
/// from k · `period` − `window` (`window` = t_RP + `refresh_burst` · t_RFC) to the deadline
/// no command issues, and every row is closed. Before a window, an activation issues only
/// if t_RAS fits before the window's start (`:913`, `:1537`) and a column read only if
/// t_RTP does (`:933`). `period = 0`: no refresh.
#[derive(Clone, Copy, Debug)]
struct Refresh {
    period: u64,
    window: u64,
    t_ras: u64,
}

impl Refresh {
    fn new(c: &DramConfig) -> Self {
        let burst = u64::from(c.refresh_burst);
        Self {
            period: c.t_refi * burst,
            window: c.t_rp + c.t_rfc * burst,
            t_ras: c.t_ras,
        }
    }

    /// How many refresh windows have started by tick `t`.
    #[inline]
    fn count(self, t: Tick) -> u64 {
        (t.get() + self.window)
            .checked_div(self.period)
            .unwrap_or(0)
    }

    /// The first tick at or after `t` at which an activation may issue: outside every
    /// window, and at least t_RAS before the next one starts.
    #[inline]
    fn free(self, t: Tick) -> Tick {
        if self.period == 0 {
            return t;
        }
        let k = self.count(t);
        if k >= 1 && t.get() < k * self.period {
            // Inside window k: after its deadline the next window is a period away.
            return Tick(k * self.period);
        }
        let next = (k + 1) * self.period - self.window;
        if t.get() + self.t_ras > next {
            Tick((k + 1) * self.period)
        } else {
            t
        }
    }
}

/// Whether an activation at tick `s` keeps every `faw`-tick window of a channel at four
/// activations or fewer, given the channel's activations `acts` (ascending; they keep the
/// rule among themselves, so a window that breaks it holds `s`).
fn faw_allows(acts: &[u64], s: u64, faw: u64) -> bool {
    if faw == 0 {
        return true;
    }
    let lo = acts.partition_point(|&t| t + faw <= s);
    let hi = acts.partition_point(|&t| t < s + faw);
    let near = &acts[lo..hi];
    let at = near.partition_point(|&t| t <= s);
    // Windows holding `s`: any five consecutive of near[..at] + s + near[at..] spanning
    // less than `faw` (read in place: this runs on every activation).
    let get = |i: usize| match i.cmp(&at) {
        std::cmp::Ordering::Less => near[i],
        std::cmp::Ordering::Equal => s,
        std::cmp::Ordering::Greater => near[i - 1],
    };
    let len = near.len() + 1;
    (at.saturating_sub(4)..=at)
        .filter(|&i| i + 4 < len)
        .all(|i| get(i + 4) - get(i) >= faw)
}

/// Opens `row` in bank `b` (record `bank`, whose open row is `open`, [`NO_ROW`] if none)
/// of channel `ch` for a request at tick `a`: a conflict precharges the open row (≥ t_RAS
/// after its activate, ≥ t_RTP after its last column command), the activation follows
/// after t_RP and ≥ t_RC after the bank's previous one, at the first tick free of other
/// activations' t_RRD spans, of refresh windows and of a fifth activation in a t_FAW
/// window. Returns the activation's tick and how the bank was found.
#[allow(clippy::too_many_arguments)]
#[inline]
fn activate(
    c: &DramConfig,
    refresh: Refresh,
    ch: &mut Channel,
    epochs: &mut Epochs,
    b: usize,
    bank: &mut Bank,
    row: u64,
    a: Tick,
    open: u64,
) -> (Tick, DramAccess) {
    let gap = c.t_rp + c.t_rtp;
    let mut act = a;
    let kind = if open != NO_ROW {
        let pre = a.max(bank.act + c.t_ras).max(bank.last_col + c.t_rtp);
        act = pre + c.t_rp;
        DramAccess::Conflict
    } else {
        DramAccess::Closed
    };
    if open != NO_ROW || bank.act > Tick(0) {
        act = act.max(bank.act + c.t_rc);
    }
    let rrd = c.t_rrd.max(1);
    let mut s = act.get();
    loop {
        s = ch.acts.peek_span(s, rrd);
        let f = refresh.free(Tick(s)).get();
        if f != s {
            s = f;
        } else if faw_allows(&ch.faw, s, c.t_faw) {
            break;
        } else {
            s += 1;
        }
    }
    let placed = ch.acts.reserve_span(s, rrd);
    debug_assert_eq!(placed, s);
    if c.t_faw > 0 {
        let i = ch.faw.partition_point(|&t| t <= s);
        ch.faw.insert(i, s);
    }
    let act = Tick(s);
    epochs.push(b, bank, row, act, gap);
    bank.act = act;
    bank.open_row = row;
    (act, kind)
}

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

#[cfg(test)]
mod tests {
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
        use super::super::{DramAccess, DramStats, EPOCH_KEEP, Refresh, faw_allows};
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
                                    let pre =
                                        a.max(bank.act + c.t_ras).max(bank.last_col + c.t_rtp);
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
}
