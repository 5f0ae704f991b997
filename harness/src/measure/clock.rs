//! CPU clocks of the calling thread and of the whole process.

/// CPU seconds the calling thread has used (`CLOCK_THREAD_CPUTIME_ID`). The trace's CPU time
/// is counted on our own threads only: a whole-process figure would include the worker threads
/// of Embree's TBB, which spin on after a build and made Embree's time vary twofold between runs.
pub fn thread_cpu_seconds() -> f64 {
    cpu_seconds(libc::CLOCK_THREAD_CPUTIME_ID)
}

/// CPU seconds the whole process has used (`CLOCK_PROCESS_CPUTIME_ID`): for runs without
/// Embree, where a process that got less than its core shows as CPU time well below wall time.
pub fn process_cpu_seconds() -> f64 {
    cpu_seconds(libc::CLOCK_PROCESS_CPUTIME_ID)
}

fn cpu_seconds(clock: libc::clockid_t) -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes only into `t`, which we own; the clock id is a constant.
    let rc = unsafe { libc::clock_gettime(clock, &mut t) };
    if rc != 0 {
        return 0.0;
    }
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}
