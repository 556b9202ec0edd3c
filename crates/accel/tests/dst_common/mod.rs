//! The DST fixtures of `dualsplit-testkit` under the module name `dst_common`, for test
//! files that declare `mod dst_common;`. New tests use `dualsplit_testkit` directly.

pub use dualsplit_testkit::dst::build;
pub use dualsplit_testkit::scenes::load_shipped;
