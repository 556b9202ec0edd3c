//! The RT unit of one SM, as Vulkan-Sim models it: it holds up to `rt_max_warps` warps,
//! each thread with its list of transactions; every cycle it sends one 32-byte chunk of the
//! next transaction to the cache, the chunks of one transaction first, then the first
//! non-stalled warp's next transaction, threads of a warp asking for the same transaction
//! sharing it; it sends none while more than `rt_max_mshr` misses are outstanding. When a
//! transaction's chunks have all returned, the thread waits the intersection latency of its
//! type before it asks for its next one; a warp leaves when all its threads are done.

use crate::model::simt::config::SimtConfig;
use crate::model::simt::mem::{Cache, Lookup, Memory};
use crate::model::simt::txn::{Txn, TxnKind};
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap, VecDeque};

/// Most chunks of one transaction (the recorder splits longer reads).
pub const MAX_CHUNKS: u64 = 64;

/// One thread in the unit: its transactions and where it is in them.
#[derive(Clone, Debug, Default)]
pub struct Lane {
    /// Its transactions in traversal order.
    pub txns: Vec<Txn>,
    next: usize,
    /// Chunks of the current transaction not yet returned (bit per chunk).
    chunks: u64,
    /// Its current transaction is queued or in flight.
    marked: bool,
    done_at: u64,
}

/// A warp in (or waiting for) the unit.
#[derive(Debug)]
pub struct RtWarp {
    /// The SM's warp slot.
    pub slot: usize,
    /// Its threads (inactive threads have no transactions).
    pub lanes: Vec<Lane>,
    left: usize,
    enter: u64,
    exit: u64,
    /// Transactions asked for and not yet sent (address, bytes, kind), distinct.
    pending: VecDeque<Txn>,
    /// Threads with a ray.
    active: u32,
}

impl RtWarp {
    /// A warp of `lanes` from SM slot `slot`; `active` of them traced a ray.
    pub fn new(slot: usize, lanes: Vec<Lane>, active: u32) -> Self {
        Self {
            slot,
            lanes,
            left: 0,
            enter: 0,
            exit: 0,
            pending: VecDeque::new(),
            active,
        }
    }
}

/// A lane of `txns`.
pub fn lane(txns: Vec<Txn>) -> Lane {
    Lane {
        txns,
        ..Lane::default()
    }
}

/// The RT unit's counters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RtCounts {
    /// Warp-cycles resident in the unit.
    pub warp_cycles: u64,
    /// Thread-cycles of threads with a ray, from the warp's entry to the thread's end.
    pub active_lane_cycles: u64,
    /// Warp visits.
    pub visits: u64,
    /// Warp-cycles spent waiting for a place in the unit.
    pub wait_cycles: u64,
    /// Transactions sent to the cache (after sharing within a warp).
    pub sent: u64,
    /// Chunk requests sent to the cache.
    pub chunks: u64,
    /// Of which hit the L1.
    pub l1_hits: u64,
    /// Of which joined an outstanding miss to the same chunk.
    pub l1_merged: u64,
    /// Cycles in which the MSHR limit held back a transaction.
    pub mshr_stall_cycles: u64,
}

/// A chunk in flight back to the unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Return {
    at: u64,
    seq: u64,
    chunk: u64,
    /// A hit's requester (warp slot, transaction address); `None` for a miss, whose
    /// requesters wait in the MSHR.
    hit: Option<(usize, u64)>,
}

/// The RT unit.
#[derive(Debug)]
pub struct RtUnit {
    max_warps: usize,
    max_mshr: usize,
    chunk: u64,
    l1_latency: u64,
    latency: [u64; 4],
    warps: Vec<RtWarp>,
    waiting: VecDeque<(RtWarp, u64)>,
    /// The current transaction's chunks still to send: (chunk, warp slot, transaction address).
    chunk_q: VecDeque<(u64, usize, u64)>,
    l1: Cache,
    mshr: HashMap<u64, Vec<(usize, u64)>>,
    returns: BinaryHeap<Reverse<Return>>,
    /// Threads whose intersection latency ends: (cycle, warp slot, lane).
    ready: BinaryHeap<Reverse<(u64, usize, usize)>>,
    seq: u64,
    /// Counters.
    pub counts: RtCounts,
}

impl RtUnit {
    /// An empty unit of `c` (validated).
    pub fn new(c: &SimtConfig) -> Self {
        let by = |k: TxnKind| match k.vulkan_sim_index() {
            Some(i) => c.intersection_latency[i],
            None => c.dual_split_latency,
        };
        Self {
            max_warps: c.rt_max_warps as usize,
            max_mshr: c.rt_max_mshr as usize,
            chunk: c.chunk_bytes as u64,
            l1_latency: c.l1.hit_latency,
            latency: [
                by(TxnKind::BoxNode),
                by(TxnKind::DualSplitNode),
                by(TxnKind::LeafEntries),
                by(TxnKind::Triangle),
            ],
            warps: Vec::new(),
            waiting: VecDeque::new(),
            chunk_q: VecDeque::new(),
            l1: Cache::new(&c.l1, 1, c.chunk_bytes),
            mshr: HashMap::new(),
            returns: BinaryHeap::new(),
            ready: BinaryHeap::new(),
            seq: 0,
            counts: RtCounts::default(),
        }
    }

    /// The chunks of `t` (their first addresses).
    fn chunks_of(&self, t: &Txn) -> std::ops::Range<u64> {
        let first = t.addr / self.chunk;
        let last = (t.addr + t.bytes.max(1) as u64 - 1) / self.chunk;
        first..last + 1
    }

    /// A warp arrives at cycle `now`; it waits when the unit is full.
    pub fn submit(&mut self, warp: RtWarp, now: u64) {
        if self.warps.len() < self.max_warps && self.waiting.is_empty() {
            self.enter(warp, now);
        } else {
            self.waiting.push_back((warp, now));
        }
    }

    fn enter(&mut self, mut w: RtWarp, now: u64) {
        w.enter = now;
        w.exit = now;
        w.left = 0;
        for (i, l) in w.lanes.iter_mut().enumerate() {
            l.done_at = now;
            if !l.txns.is_empty() {
                w.left += 1;
                self.ready.push(Reverse((now, w.slot, i)));
            }
        }
        self.counts.visits += 1;
        self.warps.push(w);
    }

    fn warp(&mut self, slot: usize) -> Option<&mut RtWarp> {
        self.warps.iter_mut().find(|w| w.slot == slot)
    }

    /// Chunk `chunk` of the transaction at `base` returned to warp `slot` at `now`.
    fn deliver(&mut self, slot: usize, base: u64, chunk: u64, now: u64) {
        let chunk_bytes = self.chunk;
        let lat = self.latency;
        let mut readies = Vec::new();
        let Some(w) = self.warp(slot) else {
            return;
        };
        for (i, l) in w.lanes.iter_mut().enumerate() {
            let Some(t) = l.txns.get(l.next) else {
                continue;
            };
            if !l.marked || t.addr != base {
                continue;
            }
            let bit = chunk - t.addr / chunk_bytes;
            l.chunks &= !(1u64 << bit);
            if l.chunks != 0 {
                continue;
            }
            let ready = now + lat[t.kind as usize];
            l.next += 1;
            l.marked = false;
            if l.next == l.txns.len() {
                l.done_at = ready;
                w.left -= 1;
                w.exit = w.exit.max(ready);
            } else {
                readies.push((ready, i));
            }
        }
        for (ready, i) in readies {
            self.ready.push(Reverse((ready, slot, i)));
        }
    }

    /// Thread `lane` of warp `slot` asks for its next transaction.
    fn mark(&mut self, slot: usize, lane: usize) {
        let chunk = self.chunk;
        let Some(w) = self.warp(slot) else {
            return;
        };
        let l = &mut w.lanes[lane];
        let t = l.txns[l.next];
        let range = (t.addr / chunk)..((t.addr + t.bytes.max(1) as u64 - 1) / chunk + 1);
        l.chunks = if range.end - range.start >= MAX_CHUNKS {
            u64::MAX
        } else {
            (1u64 << (range.end - range.start)) - 1
        };
        l.marked = true;
        if !w
            .pending
            .iter()
            .any(|p| p.addr == t.addr && p.bytes == t.bytes)
        {
            w.pending.push_back(t);
        }
    }

    /// Sends one chunk request at `now`.
    fn send(&mut self, chunk: u64, slot: usize, base: u64, now: u64, mem: &mut Memory) {
        self.counts.chunks += 1;
        let addr = chunk * self.chunk;
        if let Some(waiters) = self.mshr.get_mut(&chunk) {
            waiters.push((slot, base));
            self.counts.l1_merged += 1;
            return;
        }
        self.seq += 1;
        if self.l1.access(addr) == Lookup::Hit {
            self.counts.l1_hits += 1;
            self.returns.push(Reverse(Return {
                at: now + self.l1_latency,
                seq: self.seq,
                chunk,
                hit: Some((slot, base)),
            }));
        } else {
            let at = mem.read(addr, now);
            self.mshr.insert(chunk, vec![(slot, base)]);
            self.returns.push(Reverse(Return {
                at,
                seq: self.seq,
                chunk,
                hit: None,
            }));
        }
    }

    /// One cycle at `now`: returns, threads ready for their next transaction, warps that
    /// leave (appended to `done` with their exit cycle), then one chunk sent.
    pub fn cycle(&mut self, now: u64, mem: &mut Memory, done: &mut Vec<(RtWarp, u64)>) {
        while let Some(Reverse(r)) = self.returns.peek().copied() {
            if r.at > now {
                break;
            }
            self.returns.pop();
            match r.hit {
                Some((slot, base)) => self.deliver(slot, base, r.chunk, r.at),
                None => {
                    for (slot, base) in self.mshr.remove(&r.chunk).unwrap_or_default() {
                        self.deliver(slot, base, r.chunk, r.at);
                    }
                }
            }
        }
        while let Some(Reverse((at, slot, lane))) = self.ready.peek().copied() {
            if at > now {
                break;
            }
            self.ready.pop();
            self.mark(slot, lane);
        }
        let mut i = 0;
        while i < self.warps.len() {
            let w = &self.warps[i];
            if w.left == 0 && w.exit <= now {
                let w = self.warps.remove(i);
                self.counts.warp_cycles += w.exit - w.enter;
                self.counts.active_lane_cycles +=
                    w.lanes.iter().map(|l| l.done_at - w.enter).sum::<u64>();
                let exit = w.exit;
                done.push((w, exit));
            } else {
                i += 1;
            }
        }
        while self.warps.len() < self.max_warps
            && let Some((w, arrived)) = self.waiting.pop_front()
        {
            self.counts.wait_cycles += now - arrived;
            self.enter(w, now);
            // Its threads ask for their first transactions now.
            while let Some(Reverse((at, slot, lane))) = self.ready.peek().copied() {
                if at > now {
                    break;
                }
                self.ready.pop();
                self.mark(slot, lane);
            }
        }
        // The memory stage: the current transaction's chunks first.
        if let Some((chunk, slot, base)) = self.chunk_q.pop_front() {
            self.send(chunk, slot, base, now, mem);
            return;
        }
        let next = self.warps.iter().position(|w| !w.pending.is_empty());
        let Some(i) = next else {
            return;
        };
        if self.mshr.len() > self.max_mshr {
            self.counts.mshr_stall_cycles += 1;
            return;
        }
        let slot = self.warps[i].slot;
        let Some(t) = self.warps[i].pending.pop_front() else {
            return;
        };
        self.counts.sent += 1;
        let mut chunks = self.chunks_of(&t);
        if let Some(first) = chunks.next() {
            self.chunk_q.extend(chunks.map(|c| (c, slot, t.addr)));
            self.send(first, slot, t.addr, now, mem);
        }
    }

    /// Warps resident or waiting.
    pub fn busy(&self) -> bool {
        !self.warps.is_empty() || !self.waiting.is_empty()
    }

    /// The next cycle after `now` at which the unit has something to do (`u64::MAX` when
    /// nothing until a warp arrives).
    pub fn next_wake(&self, now: u64) -> u64 {
        let sending = !self.chunk_q.is_empty()
            || (self.mshr.len() <= self.max_mshr
                && self.warps.iter().any(|w| !w.pending.is_empty()));
        if sending {
            return now + 1;
        }
        let mut t = u64::MAX;
        if let Some(Reverse(r)) = self.returns.peek() {
            t = t.min(r.at);
        }
        if let Some(Reverse((at, _, _))) = self.ready.peek() {
            t = t.min(*at);
        }
        for w in &self.warps {
            if w.left == 0 {
                t = t.min(w.exit);
            }
        }
        t.max(now + 1)
    }

    /// Threads with a ray in the warps resident (for occupancy sampling by callers).
    pub fn resident(&self) -> usize {
        self.warps.len()
    }

    /// Active threads of a warp, as submitted.
    pub fn active(w: &RtWarp) -> u32 {
        w.active
    }
}
