//! The process's resident memory: its peak (`VmHWM`), restartable per step.

/// Peak resident set size of this process (Linux `VmHWM`), in bytes.
/// Starts the peak RSS (`VmHWM`) afresh from the current RSS (Linux's `clear_refs` 5), so that
/// one step of a long run reports its own peak; false where the kernel does not allow it.
///
/// First the allocator hands back what earlier steps freed (glibc's `malloc_trim`): freed memory
/// that malloc keeps for reuse still counts as resident, and a step measured after a larger one
/// would carry that one's peak in its own.
pub fn reset_peak_rss() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free heap pages to the kernel; it has no preconditions.
    unsafe {
        libc::malloc_trim(0);
    }
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

pub fn peak_rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
