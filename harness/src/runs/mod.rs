//! Runs and sweeps: the environment, one measured run, and the plans that run many.

pub mod env;
pub mod one;
pub mod plan;
pub mod shard;
