//! The two thread models: how the simulated threads execute their kernel.
//!
//! * [`rv32`]: thread processors executing the compiled RV32IMF kernels instruction by
//!   instruction (the reference);
//! * [`fast`]: threads replaying the real traversal's events as macro-ops, each charged the
//!   instructions the compiled kernel spends on it, as measured by [`fast::calibrate`].
//!
//! Both implement [`crate::engine::Lane`] and drive the same [`crate::hw`] units.

pub mod fast;
pub mod rv32;
pub mod simt;
