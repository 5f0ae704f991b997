//! The process's resident memory: its peak (`VmHWM`), restartable per step.

/// Peak resident set size of this process (Linux `VmHWM`), in bytes.
/// Starts the peak RSS (`VmHWM`) afresh from the current RSS (Linux's `clear_refs` 5), so that
/// one step of a long run reports its own peak; false where the kernel does not allow it.
pub fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

pub fn peak_rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
