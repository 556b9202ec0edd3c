//! A channel's shared state (data bus, activation spacing, four-activate window, write
//! queue) and the refresh schedule.

use crate::config::DramConfig;
use crate::hw::Tick;
use crate::hw::slots::SparseSlots;

#[derive(Clone, Debug, Default)]
pub(super) struct Channel {
    /// Data-bus reservations in units of one burst (t_burst ticks). The read queue is the
    /// bus's pending plane: a read in flight is marked pending on its bus slot `s`, and its
    /// data is complete at tick `(s + 1) · t_burst` (every read has a slot of its own, so
    /// the earliest pending slot is the earliest completion).
    pub(super) bus: SparseSlots<2>,
    /// Activations, each holding t_RRD ticks (minimum spacing between activations).
    pub(super) acts: SparseSlots,
    /// Ticks of the activations that may still share a t_FAW window with a later one,
    /// ascending.
    pub(super) faw: Vec<u64>,
    /// The write queue, oldest first: each write's line and the tick of its column command,
    /// `u64::MAX` until it is drained (a drained write stays queued, and later writes of
    /// its line merge into it, until its column command issues).
    pub(super) writes: Vec<(u64, u64)>,
    /// No column read before this tick: the end of the last drained write's data + t_WTR.
    pub(super) wtr: u64,
}

/// The refresh schedule as USIMM issues it (`memory_controller.cc:215-218`, `:2097-2121`,
/// `:1943-1956`): every `period` = `refresh_burst` · t_REFI ticks a channel's one rank is
/// refreshed `refresh_burst` times together, forced at the deadline k · `period` (k ≥ 1):
/// from k · `period` − `window` (`window` = t_RP + `refresh_burst` · t_RFC) to the deadline
/// no command issues, and every row is closed. Before a window, an activation issues only
/// if t_RAS fits before the window's start (`:913`, `:1537`) and a column read only if
/// t_RTP does (`:933`). `period = 0`: no refresh.
#[derive(Clone, Copy, Debug)]
pub(super) struct Refresh {
    pub(super) period: u64,
    pub(super) window: u64,
    pub(super) t_ras: u64,
}

impl Refresh {
    pub(super) fn new(c: &DramConfig) -> Self {
        let burst = u64::from(c.refresh_burst);
        Self {
            period: c.t_refi * burst,
            window: c.t_rp + c.t_rfc * burst,
            t_ras: c.t_ras,
        }
    }

    /// How many refresh windows have started by tick `t`.
    #[inline]
    pub(super) fn count(self, t: Tick) -> u64 {
        (t.get() + self.window)
            .checked_div(self.period)
            .unwrap_or(0)
    }

    /// The first tick at or after `t` at which an activation may issue: outside every
    /// window, and at least t_RAS before the next one starts.
    #[inline]
    pub(super) fn free(self, t: Tick) -> Tick {
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
pub(super) fn faw_allows(acts: &[u64], s: u64, faw: u64) -> bool {
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
