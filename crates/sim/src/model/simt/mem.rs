//! The `simt` model's memory: sectored set-associative caches with LRU replacement (the
//! RT unit's L1 and the chip's L2) and GDDR6 channels with open rows and a data bus.
//!
//! Time on the SM side is in core cycles; the channels keep femtoseconds so that the
//! core and DRAM clocks need not divide each other, and hand back core cycles (rounded
//! up).

use crate::model::simt::config::{SimtCache, SimtConfig};
use std::collections::{BTreeMap, HashMap};

/// A sectored cache's state: which lines are present, with which sectors, in LRU order.
#[derive(Debug)]
pub struct Cache {
    sets: u64,
    ways: usize,
    line_bytes: u64,
    sector_bytes: u64,
    /// Present lines: line address → (last use, valid sectors).
    lines: HashMap<u64, (u64, u64)>,
    /// Per set: last use → line address (the first entry is the LRU line).
    lru: Vec<BTreeMap<u64, u64>>,
    clock: u64,
}

/// The outcome of a cache access.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lookup {
    /// The sector is present.
    Hit,
    /// The line is present, the sector is not (it is now marked present).
    SectorMiss,
    /// The line was absent (it is now allocated, evicting the LRU line when the set is full).
    LineMiss,
}

impl Cache {
    /// An empty cache of geometry `c` (`sets_scale` slices of `c.sets` sets each) filled
    /// `sector_bytes` at a time.
    pub fn new(c: &SimtCache, sets_scale: u32, sector_bytes: u32) -> Self {
        let sets = c.sets as u64 * sets_scale as u64;
        Self {
            sets,
            ways: c.ways as usize,
            line_bytes: c.line_bytes as u64,
            sector_bytes: sector_bytes as u64,
            lines: HashMap::new(),
            lru: (0..sets).map(|_| BTreeMap::new()).collect(),
            clock: 0,
        }
    }

    /// Accesses the sector holding byte `addr`, allocating it when absent.
    pub fn access(&mut self, addr: u64) -> Lookup {
        let line = addr / self.line_bytes;
        let bit = 1u64 << ((addr % self.line_bytes) / self.sector_bytes);
        let set = (line % self.sets) as usize;
        self.clock += 1;
        let now = self.clock;
        if let Some((used, sectors)) = self.lines.get_mut(&line) {
            self.lru[set].remove(used);
            self.lru[set].insert(now, line);
            *used = now;
            let hit = *sectors & bit != 0;
            *sectors |= bit;
            return if hit { Lookup::Hit } else { Lookup::SectorMiss };
        }
        if self.lru[set].len() >= self.ways
            && let Some((_, victim)) = self.lru[set].pop_first()
        {
            self.lines.remove(&victim);
        }
        self.lru[set].insert(now, line);
        self.lines.insert(line, (now, bit));
        Lookup::LineMiss
    }
}

/// One GDDR6 channel: each bank's open row and when it takes its next command, and when
/// the data bus is free (femtoseconds).
#[derive(Clone, Debug)]
struct Channel {
    banks: Vec<(Option<u64>, u64)>,
    bus_free: u64,
}

/// Counters of the memory below the SMs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemCounts {
    /// L2 sector accesses.
    pub l2_accesses: u64,
    /// Of which hits (the sector present, possibly still in flight).
    pub l2_hits: u64,
    /// DRAM sector reads.
    pub dram_reads: u64,
    /// Of which found their row open.
    pub dram_row_hits: u64,
    /// Row activations.
    pub dram_activations: u64,
}

/// The L2 and the GDDR6 channels, shared by every SM.
#[derive(Debug)]
pub struct Memory {
    l2: Cache,
    /// Sectors whose DRAM read is in flight: when their data reaches the L2 (core cycle).
    in_flight: HashMap<u64, u64>,
    channels: Vec<Channel>,
    l1_latency: u64,
    l2_latency: u64,
    channel_shift: u32,
    row_bytes: u64,
    /// Femtoseconds per core cycle and per DRAM cycle.
    core_fs: u64,
    dram_fs: u64,
    t_rcd: u64,
    t_rp: u64,
    t_cl: u64,
    t_burst: u64,
    dram_latency: u64,
    sector_bytes: u64,
    /// Counters.
    pub counts: MemCounts,
}

impl Memory {
    /// The memory of `c` (validated).
    pub fn new(c: &SimtConfig) -> Self {
        let fs = |mhz: f64| (1e9 / mhz).round() as u64;
        let dram_fs = fs(c.dram_mhz);
        Self {
            l2: Cache::new(&c.l2, c.l2_slices, c.chunk_bytes),
            in_flight: HashMap::new(),
            channels: vec![
                Channel {
                    banks: vec![(None, 0); c.dram_banks as usize],
                    bus_free: 0,
                };
                c.dram_channels as usize
            ],
            l1_latency: c.l1.hit_latency,
            l2_latency: c.l2.hit_latency,
            channel_shift: c.channel_shift,
            row_bytes: c.row_bytes,
            core_fs: fs(c.core_mhz),
            dram_fs,
            t_rcd: c.t_rcd * dram_fs,
            t_rp: c.t_rp * dram_fs,
            t_cl: c.t_cl * dram_fs,
            t_burst: (c.chunk_bytes as u64).div_ceil(c.dram_bytes_per_cycle as u64) * dram_fs,
            dram_latency: c.dram_latency * dram_fs,
            sector_bytes: c.chunk_bytes as u64,
            counts: MemCounts::default(),
        }
    }

    /// A sector the RT L1 missed at core cycle `now`: the cycle its data is back at the SM.
    /// Requests arrive in non-decreasing `now` (the frame steps the SMs in time order), so
    /// each channel serves them first come, first served.
    pub fn read(&mut self, sector: u64, now: u64) -> u64 {
        let at_l2 = now + self.l1_latency + self.l2_latency;
        self.counts.l2_accesses += 1;
        let lookup = self.l2.access(sector);
        if lookup == Lookup::Hit {
            self.counts.l2_hits += 1;
            return match self.in_flight.get(&sector) {
                Some(&ready) if ready > at_l2 => ready,
                Some(_) => {
                    self.in_flight.remove(&sector);
                    at_l2
                }
                None => at_l2,
            };
        }
        let done = self.dram(sector, at_l2);
        self.in_flight.insert(sector, done);
        done
    }

    /// A DRAM sector read issued at core cycle `at`: the core cycle its data returns.
    fn dram(&mut self, addr: u64, at: u64) -> u64 {
        self.counts.dram_reads += 1;
        let n = self.channels.len() as u64;
        let high = addr >> self.channel_shift;
        let ch = (high % n) as usize;
        // The address within the channel: the channel bits taken out.
        let local = ((high / n) << self.channel_shift) | (addr & ((1 << self.channel_shift) - 1));
        let banks = self.channels[ch].banks.len() as u64;
        let bank = ((local / self.row_bytes) % banks) as usize;
        let row = local / self.row_bytes / banks;
        let t = at * self.core_fs;
        let chan = &mut self.channels[ch];
        let (open, ready) = &mut chan.banks[bank];
        let start = t.max(*ready);
        let activate = match *open {
            Some(r) if r == row => {
                self.counts.dram_row_hits += 1;
                0
            }
            Some(_) => self.t_rp + self.t_rcd,
            None => self.t_rcd,
        };
        if activate > 0 {
            self.counts.dram_activations += 1;
        }
        *open = Some(row);
        *ready = start + activate;
        let data = start + activate + self.t_cl;
        let xfer = data.max(chan.bus_free);
        chan.bus_free = xfer + self.t_burst;
        let back = xfer + self.t_burst + self.dram_latency;
        let _ = self.dram_fs;
        back.div_ceil(self.core_fs)
    }

    /// Bytes of a sector.
    pub fn sector_bytes(&self) -> u64 {
        self.sector_bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn geometry(sets: u32, ways: u32) -> SimtCache {
        SimtCache {
            sets,
            line_bytes: 128,
            ways,
            hit_latency: 1,
        }
    }

    #[test]
    fn sectors_fill_one_at_a_time_and_lru_evicts() {
        let mut c = Cache::new(&geometry(1, 2), 1, 32);
        assert_eq!(c.access(0), Lookup::LineMiss);
        assert_eq!(c.access(8), Lookup::Hit);
        assert_eq!(c.access(40), Lookup::SectorMiss);
        assert_eq!(c.access(40), Lookup::Hit);
        assert_eq!(c.access(128), Lookup::LineMiss);
        assert_eq!(c.access(0), Lookup::Hit); // line 0 is now the most recent
        assert_eq!(c.access(256), Lookup::LineMiss); // evicts line 1
        assert_eq!(c.access(0), Lookup::Hit);
        assert_eq!(c.access(128), Lookup::LineMiss);
    }

    #[test]
    fn open_rows_are_faster_and_the_bus_serialises() {
        let cfg = crate::model::simt::tests::rtx();
        let mut m = Memory::new(&cfg);
        let first = m.read(0, 0);
        let row_hit = m.read(32, first) - first;
        let mut other = Memory::new(&cfg);
        let cold = other.read(0, 0);
        assert!(row_hit < cold, "row hit {row_hit} vs cold {cold}");
        assert_eq!(m.counts.dram_row_hits, 1);
        // Many sectors of one channel at once: the bus spaces their returns.
        let mut b = Memory::new(&cfg);
        let stride = (cfg.dram_channels as u64) << cfg.channel_shift;
        let last = (0..64)
            .map(|i| b.read((1 << 30) | (i * stride), 0))
            .max()
            .unwrap();
        assert!(last >= cold + 60, "{last} vs {cold}");
        // A second read of an in-flight sector waits for it, not for DRAM again.
        let mut d = Memory::new(&cfg);
        let t = d.read(4096, 0);
        assert_eq!(d.read(4096, 1), t);
        assert_eq!(d.counts.dram_reads, 1);
    }
}
