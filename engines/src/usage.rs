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

/// Bytes this process may still map under its address-space limit (`RLIMIT_AS`, `ulimit -v`):
/// the limit less what is mapped now (`VmSize`). None when there is no limit. An allocation past
/// it fails, and Rust's allocator then aborts: budgets are checked against this, not only RAM.
pub fn address_space_left() -> Option<u64> {
    let mut lim = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes only into `lim`, which we own.
    let rc = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut lim) };
    if rc != 0 || lim.rlim_cur == libc::RLIM_INFINITY {
        return None;
    }
    let mapped = std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            let line = s.lines().find(|l| l.starts_with("VmSize:"))?;
            line.split_whitespace().nth(1)?.parse::<u64>().ok()
        })
        .map_or(0, |kb| kb.saturating_mul(1024));
    Some(lim.rlim_cur.saturating_sub(mapped))
}
