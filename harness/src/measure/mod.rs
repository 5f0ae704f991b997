//! The one home of measuring: clocks, peak RSS, the thread pool and the CPU list, and the
//! scheduler and memory probes.

pub mod clock;
pub mod environment;
pub mod memory;
pub mod rss;
pub mod sched;
pub mod threads;
