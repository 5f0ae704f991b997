//! Runs: the plan (jobs, child processes, the groups a shard takes whole), one measured run, the
//! regression plant beside the run it wraps, the rounds a run is spread over, and merging the
//! shards of a plan.

pub mod merge;
pub mod one;
pub mod plan;
pub mod plant;
pub mod rounds;
