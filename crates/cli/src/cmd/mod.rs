//! One module per subcommand.
pub mod bench;
pub mod check;
pub mod info;
pub mod rays;
pub mod render;
pub mod report;
pub mod simulate;
pub mod stats;
