//! What the process has used so far: CPU seconds of every thread and minor page faults. For the
//! build diagnostics (`RTBENCH_BUILD_PHASES`) and the build bench: how many threads a
//! build kept busy, and how much of it went to faulting in fresh pages.

/// CPU seconds of every thread of the process (`CLOCK_PROCESS_CPUTIME_ID`) and its minor page
/// faults (`getrusage`), so far.
pub fn process() -> (f64, i64) {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid timespec to write; the clock exists on every Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    // SAFETY: an all-zero `rusage` is valid, and getrusage writes only into it.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: RUSAGE_SELF with a valid pointer.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    (ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9, u.ru_minflt)
}
