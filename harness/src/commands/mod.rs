//! One module per subcommand.

pub mod check;
pub mod engines;
pub mod render;
pub mod reproduce;
pub mod reproduce_thrashing;
pub mod runs;
pub mod scene;
pub mod tree_stats;
pub mod yamauchi;
