//! The hardware units of the chip (Lin et al. 2020, §2.3, §4, Tables 1–2), one module per
//! unit, each owning its statistics. Nothing here knows which thread model drives it: a
//! request names the cycle it is made and learns when its unit takes it and when its result
//! is ready.
//!
//! * [`chip`]: the units of the whole chip and the handle a thread drives them through;
//! * [`tm`]: a thread multiprocessor: [`l1`] (L1 data cache controller), [`pipe`] (ray-box,
//!   ray-triangle and dual-split pipelines), the reciprocal unit, [`fu`] (functional-unit
//!   pools and classes), [`icache`] (instruction-cache fetch slots);
//! * [`atomic`]: the global atomic unit;
//! * [`memory`]: the L2 and GDDR5 DRAM behind the L1s;
//! * [`slots`], [`window`]: the reservation tables the units are made of;
//! * [`stalls`], [`counts`], [`energy`]: what the threads' cycles and instructions were,
//!   and what they cost;
//! * [`cycle`], [`addr`]: clock cycles, DRAM ticks and typed addresses.

pub mod addr;
pub mod atomic;
pub mod chip;
pub mod counts;
pub mod cycle;
pub mod energy;
pub mod fu;
pub mod icache;
pub mod issued;
pub mod l1;
pub mod memory;
pub mod pipe;
pub mod slots;
pub mod stalls;
pub mod tm;
pub mod window;

pub use addr::WordAddr;
pub use chip::{Chip, ChipStats};
pub use cycle::{Cycle, Tick};
pub use stalls::{Stall, Stalls};
