//! The `fast` thread model: each thread replays the real traversal's events as
//! macro-operations, each event charged the instructions and dependency stalls that the
//! configuration's compiled kernel spends on it, as measured by [`calibrate`].
//!
//! * [`frame`]: the workload (pixels from the global counter, each pixel's rays traced by
//!   the renderer's own traversal with a [`recorder::Recorder`] observing) and the thread
//!   model the event loop steps;
//! * [`recorder`]: the observer turning traversal events into [`op::Op`]s;
//! * [`event`], [`tally`], [`costs`]: the events, their counts, their measured costs;
//! * [`thread`]: one replaying thread (its ops against the TM's units);
//! * [`calibrate`]: measuring the costs from the compiled kernels.

/// The `fast` model's largest frame-time error against the `rv32` model measured on frames
/// the calibration never saw, rounded up: 12.1 % (BVH8+ path tracing on SimTRaX's Dragon
/// Box at 256×256; `docs/simulator.md`, "The `fast` model's calibration", has every
/// ratio). `tests/calibration.rs` fails when one of its frames exceeds it. Two
/// configurations whose `fast` frame times differ by less than this have no resolved order.
pub const FRAME_TIME_ERROR: f64 = 0.13;

pub mod calibrate;
pub mod costs;
pub mod event;
pub mod frame;
pub mod op;
pub mod recorder;
pub mod replay;
pub mod tally;
pub mod thread;

#[cfg(test)]
mod replay_tests;
