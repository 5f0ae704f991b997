//! The one way a timed region is measured: a [`Span`] started before it and stopped after it
//! gives one [`Sample`] (wall seconds, the workers' CPU seconds, the process's CPU seconds, page
//! faults, context switches). A field added to [`Sample`] is measured here and recorded with every repeat of every
//! run, table and night.

use super::clock::{process_cpu_seconds, thread_cpu_seconds};
pub use rtbench_reports::results::Sample;
use std::time::Instant;

/// Whose CPU time is the work's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Workers {
    /// The threads of the current rayon pool, summed (and the calling thread, when it is not one
    /// of them): not Embree's TBB workers, which spin on after a build and made Embree's time
    /// vary twofold between runs.
    Pool,
    /// The calling thread alone (a trace that runs on one thread).
    Caller,
}

/// A started measurement.
pub struct Span {
    workers: Workers,
    wall: Instant,
    thread_cpu: f64,
    process_cpu: f64,
    usage: Usage,
}

/// The process's counts from `getrusage`.
#[derive(Clone, Copy, Default)]
struct Usage {
    minor_faults: u64,
    major_faults: u64,
    context_switches: u64,
}

fn usage() -> Usage {
    // SAFETY: a zeroed rusage is a valid value; getrusage writes only into it.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: RUSAGE_SELF is a constant; `u` is ours.
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) } != 0 {
        return Usage::default();
    }
    Usage {
        minor_faults: u.ru_minflt as u64,
        major_faults: u.ru_majflt as u64,
        context_switches: (u.ru_nvcsw + u.ru_nivcsw) as u64,
    }
}

/// CPU seconds used so far by the threads of the current rayon pool, summed, and by the calling
/// thread when it is outside any pool.
fn pool_cpu_seconds() -> f64 {
    let pool: f64 = rayon::broadcast(|_| thread_cpu_seconds()).into_iter().sum();
    if rayon::current_thread_index().is_none() {
        pool + thread_cpu_seconds()
    } else {
        pool
    }
}

fn workers_cpu(w: Workers) -> f64 {
    match w {
        Workers::Pool => pool_cpu_seconds(),
        Workers::Caller => thread_cpu_seconds(),
    }
}

impl Span {
    pub fn start(workers: Workers) -> Span {
        let usage = usage();
        let process_cpu = process_cpu_seconds();
        let thread_cpu = workers_cpu(workers);
        Span {
            workers,
            wall: Instant::now(),
            thread_cpu,
            process_cpu,
            usage,
        }
    }

    /// Wall seconds since the start.
    pub fn elapsed_s(&self) -> f64 {
        self.wall.elapsed().as_secs_f64()
    }

    /// What the span measured up to now.
    pub fn stop(&self) -> Sample {
        let wall_s = self.elapsed_s();
        let thread_cpu_s = workers_cpu(self.workers) - self.thread_cpu;
        let process_cpu_s = process_cpu_seconds() - self.process_cpu;
        let u = usage();
        Sample {
            wall_s,
            thread_cpu_s,
            process_cpu_s,
            minor_faults: u.minor_faults.saturating_sub(self.usage.minor_faults),
            major_faults: u.major_faults.saturating_sub(self.usage.major_faults),
            context_switches: u
                .context_switches
                .saturating_sub(self.usage.context_switches),
        }
    }
}

/// `f` measured by one span.
pub fn span<T>(workers: Workers, f: impl FnOnce() -> T) -> (T, Sample) {
    let s = Span::start(workers);
    let out = f();
    (out, s.stop())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_span_of_work_counts_its_time_and_its_page_faults() {
        let (v, s) = span(Workers::Caller, || {
            // 16 MiB touched page by page: thousands of minor faults.
            let mut v = vec![0u8; 16 << 20];
            for i in (0..v.len()).step_by(4096) {
                v[i] = 1;
            }
            // Kept: an optimised build dropped the unread writes, and with them the faults.
            std::hint::black_box(&mut v);
            let t = std::time::Instant::now();
            let mut x = 0u64;
            while t.elapsed().as_millis() < 20 {
                x = x.wrapping_add(std::hint::black_box(1));
            }
            v.len() as u64 + x
        });
        assert!(v > 0);
        assert!(s.wall_s >= 0.02, "{s:?}");
        assert!(
            s.thread_cpu_s > 0.0 && s.thread_cpu_s <= s.process_cpu_s + 1e-3,
            "{s:?}"
        );
        assert!(s.minor_faults >= 1000, "{s:?}");
    }
}
