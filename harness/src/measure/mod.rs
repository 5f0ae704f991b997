//! The one home of measuring: one [`span::Sample`] per timed region from one span, one repeat
//! and warm-up policy, clocks, peak RSS, the thread pool and the one [`threads::Threads`] type,
//! the CPU list, the scheduler and memory probes, the environment a result records, and every
//! `RTBENCH_*` variable read once ([`vars`]). Intervals are computed by the reports crate
//! (`rtbench_reports::interval`), which reads results without the harness.

pub mod clock;
pub mod environment;
pub mod memory;
pub mod repeat;
pub mod rss;
pub mod sched;
pub mod span;
pub mod threads;
pub mod vars;
