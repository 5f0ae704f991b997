//! One module per subcommand.

pub mod check;
pub mod engines;
pub mod env;
pub mod history;
pub mod merge;
pub mod nightly;
pub mod plan;
pub mod render;
pub mod runs;
pub mod scene;
pub mod store_segments;
pub mod tree_stats;
