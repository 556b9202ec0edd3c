//! A bank's schedule: its record, its row epochs, and opening a row ([`activate`]).

use super::DramAccess;
use super::channel::{Channel, Refresh, faw_allows};
use crate::config::DramConfig;
use crate::hw::Tick;

/// A row's time open in a bank's schedule. Its `close` (the last tick a column command
/// may read it) is the next epoch's activate − t_RP − t_RTP, open-ended for the last
/// epoch: it is derived from the next entry rather than stored, so an epoch is 16 bytes
/// and opening one writes nothing else.
#[derive(Clone, Copy, Debug)]
pub(super) struct Epoch {
    pub(super) row: u64,
    /// Tick of its activate.
    pub(super) act: Tick,
}

/// Ticks an epoch is kept after its `close` (reads arrive slightly out of order: fluffy
/// time).
pub(super) const EPOCH_KEEP: u64 = 256;

/// `Bank::open_row` when no row is open (rows are line numbers / 128 or less: < 2^58).
pub(super) const NO_ROW: u64 = u64::MAX;

/// One bank: 64 bytes, one host cache line. Its row epochs are a ring in [`Epochs`]; the
/// record keeps what most reads need so that they do not touch the ring: when the
/// earliest epoch expires, and which rows the earlier epochs hold.
#[derive(Clone, Debug)]
#[repr(align(64))]
pub(super) struct Bank {
    /// The open row (the last epoch's), or [`NO_ROW`].
    pub(super) open_row: u64,
    /// Tick of the last activate.
    pub(super) act: Tick,
    /// Earliest tick of the next column command.
    pub(super) col_ready: Tick,
    /// Tick of the last column command (for t_RTP).
    pub(super) last_col: Tick,
    /// The earliest epoch expires once a read's tick exceeds this: its close (the next
    /// epoch's activate − t_RP − t_RTP) + [`EPOCH_KEEP`]; `Tick::MAX` while only one epoch
    /// is live.
    pub(super) expiry: Tick,
    /// Bit `row mod 64` set for each live epoch but the last (and possibly for expired
    /// ones: refreshed whenever a read scans them all), so a read whose bit is clear has no
    /// earlier epoch of its row to try.
    pub(super) rows: u64,
    /// Ring position of the earliest live epoch.
    pub(super) head: u32,
    /// Live epochs (`0` before the first activate).
    pub(super) len: u32,
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
pub(super) struct Epochs {
    pub(super) slab: Vec<Epoch>,
    /// log2(`cap`).
    pub(super) shift: u32,
}

impl Epochs {
    pub(super) fn new(banks: usize) -> Self {
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
    pub(super) fn at(&self, b: usize, bank: &Bank, i: u32) -> usize {
        let mask = (1u32 << self.shift) - 1;
        (b << self.shift) + (bank.head.wrapping_add(i) & mask) as usize
    }

    /// `expiry` for bank `b` whose epochs are as they are now (`gap` = t_RP + t_RTP).
    #[inline]
    pub(super) fn expiry(&self, b: usize, bank: &Bank, gap: u64) -> Tick {
        if bank.len < 2 {
            Tick::MAX
        } else {
            (self.slab[self.at(b, bank, 1)].act - gap).saturating_add(EPOCH_KEEP)
        }
    }

    /// Drops bank `b`'s epochs closed more than [`EPOCH_KEEP`] ticks before tick `a` (the
    /// last epoch never closes).
    #[inline]
    pub(super) fn expire(&self, b: usize, bank: &mut Bank, a: Tick, gap: u64) {
        if bank.expiry < a {
            self.expire_slow(b, bank, a, gap);
        }
    }

    #[inline]
    pub(super) fn expire_slow(&self, b: usize, bank: &mut Bank, a: Tick, gap: u64) {
        while bank.expiry < a {
            bank.head = bank.head.wrapping_add(1);
            bank.len -= 1;
            bank.expiry = self.expiry(b, bank, gap);
        }
    }

    /// Opens `row` at tick `act` in bank `b` (the bank's open row and activate are still
    /// the previous epoch's; its ring has room: [`Dram::read_at`] grows it first).
    #[inline]
    pub(super) fn push(&mut self, b: usize, bank: &mut Bank, row: u64, act: Tick, gap: u64) {
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
    pub(super) fn grow(&mut self, banks: &mut [Bank]) {
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

/// Opens `row` in bank `b` (record `bank`, whose open row is `open`, [`NO_ROW`] if none)
/// of channel `ch` for a request at tick `a`: a conflict precharges the open row (≥ t_RAS
/// after its activate, ≥ t_RTP after its last column command), the activation follows
/// after t_RP and ≥ t_RC after the bank's previous one, at the first tick free of other
/// activations' t_RRD spans, of refresh windows and of a fifth activation in a t_FAW
/// window. Returns the activation's tick and how the bank was found.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn activate(
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
