//! One module per subcommand.

pub mod check;
pub mod engines;
pub mod render;
pub mod runs;
pub mod scene;
pub mod tree_stats;
