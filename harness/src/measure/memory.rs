//! The process's memory between the phases of a render (peak RSS ≤ 3 ×
//! structure bytes + 16 MiB): what is resident after each phase, on request, and handing the
//! build's freed heap back to the system before the trace.

// `RTBENCH_MEMORY_PHASES=1` (read once, `measure::vars`) makes [`phase`] print the process's
// memory after each phase of `rtbench render` on stderr.

/// One line of kibibytes from `/proc/self/status` (`VmRSS`, `VmHWM`, `RssAnon`, `RssFile`).
fn status_kib(status: &str, key: &str) -> u64 {
    status
        .lines()
        .find(|l| l.starts_with(key))
        .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        .unwrap_or(0)
}

/// With `RTBENCH_MEMORY_PHASES` set, prints on stderr the resident set after phase `name` (`VmRSS`, split
/// into anonymous memory and mapped files), its peak so far (`VmHWM`), and what the allocator
/// holds: bytes in use by the program and bytes it keeps from the system (glibc's `mallinfo2`:
/// main heap + other threads' arenas + blocks mapped on their own).
pub fn phase(name: &str) {
    if !super::vars::values().memory_phases {
        return;
    }
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let (in_use, held) = heap_kib();
    eprintln!(
        "memory {name}: rss {} KiB (anon {}, file {}), peak {} KiB; heap in use {in_use} KiB, held {held} KiB",
        status_kib(&s, "VmRSS:"),
        status_kib(&s, "RssAnon:"),
        status_kib(&s, "RssFile:"),
        status_kib(&s, "VmHWM:"),
    );
}

/// (bytes in use, bytes held) by malloc, in KiB.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn heap_kib() -> (u64, u64) {
    // SAFETY: mallinfo2 only reads the allocator's statistics.
    let m = unsafe { libc::mallinfo2() };
    (
        ((m.uordblks + m.hblkhd) / 1024) as u64,
        ((m.arena + m.hblkhd) / 1024) as u64,
    )
}

#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn heap_kib() -> (u64, u64) {
    (0, 0)
}

/// Hands the heap pages the program has freed back to the system (glibc's `malloc_trim(0)`).
/// Called between the build and the trace: the build's scratch (primitive boxes, the binary
/// build tree, bins) is freed into the main thread's heap, but the trace runs on the pool's
/// threads, which allocate from their own arenas, so glibc kept those pages resident through
/// the whole trace (gears4 bvh8 at 512², 24.31 MiB peak against 22.49 MiB with
/// `MALLOC_TRIM_THRESHOLD_=0`). Changes no answer; elsewhere a no-op.
pub fn release_free_heap() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free pages of the allocator's own arenas.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Memory this process can still have: the smaller of the machine's available memory
/// (`MemAvailable`) and the address space left under its limit (`ulimit -v`, less what is
/// mapped already). None when neither is known.
pub fn memory_available() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok().and_then(|t| {
        let line = t.lines().find(|l| l.starts_with("MemAvailable:"))?;
        line.split_whitespace().nth(1)?.parse::<u64>().ok()
    });
    let mem = meminfo.map(|kb| kb.saturating_mul(1024));
    // The limit less what is mapped already: what an allocation may still take.
    let limit = rtbench_engines::usage::address_space_left();
    match (mem, limit) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_lines_are_read_in_kib() {
        let s = "Name:\trtbench\nVmHWM:\t   25000 kB\nVmRSS:\t   24000 kB\nRssAnon:\t  12000 kB\n";
        assert_eq!(status_kib(s, "VmHWM:"), 25000);
        assert_eq!(status_kib(s, "VmRSS:"), 24000);
        assert_eq!(status_kib(s, "RssAnon:"), 12000);
        assert_eq!(status_kib(s, "RssFile:"), 0);
    }

    /// Freed heap pages leave the resident set after the trim: 16 MiB in 4 KiB blocks (below
    /// glibc's mmap threshold, so they live in the heap), all freed but one at the end that
    /// keeps the heap's top from shrinking by itself.
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    #[test]
    fn trim_returns_freed_heap_pages() {
        let rss = || {
            let s = std::fs::read_to_string("/proc/self/status").unwrap();
            status_kib(&s, "VmRSS:")
        };
        let handle = std::thread::spawn(move || {
            let mut blocks: Vec<Vec<u8>> = (0..4096).map(|_| vec![1u8; 4096]).collect();
            let keep = blocks.pop().unwrap();
            drop(blocks);
            let before = rss();
            release_free_heap();
            let after = rss();
            drop(keep);
            (before, after)
        });
        let (before, after) = handle.join().unwrap();
        assert!(
            before > after + 8 * 1024,
            "trim freed only {} KiB",
            before.saturating_sub(after)
        );
    }
}
