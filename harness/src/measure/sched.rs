//! The scheduler's accounting of one thread, read from `/proc/thread-self` (where the pool's threads are when they are not on a CPU).
//!
//! `schedstat` gives the nanoseconds the thread ran, the nanoseconds it waited on a run queue
//! while runnable (preempted, or woken and not yet run) and its timeslices; `status` its
//! voluntary (it blocked or slept) and involuntary (it was preempted) context switches; `stat`
//! its minor and major page faults and the CPU it last ran on; `sched` its migrations between
//! CPUs. Over an interval of wall time W, W − ran − waited is what the thread spent asleep or
//! blocked (a futex, a page fault waiting for a lock or I/O, a `sched_yield` is not in it).
//!
//! With `RTBENCH_SCHED` set, [`crate::workload::trace::render_chunked`] prints one line per pool thread of
//! each render on stderr: these counts over the render's parallel region, and the wall seconds
//! the thread spent inside bands; one line per CPU with its seconds by state (user, system,
//! idle, iowait, steal) over the same region; with `RTBENCH_SCHED=bands` also one line per band
//! (thread, the CPU it started and ended on, start and end seconds).

// `RTBENCH_SCHED` (read once, in `measure::vars`) makes [`crate::workload::trace::render_chunked`] print the pool threads'
// scheduler accounting (one `sched` line per thread) on stderr.

/// One thread's scheduler counts at one moment (all cumulative since the thread started).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ThreadSched {
    /// Kernel thread id.
    pub tid: i64,
    /// Nanoseconds on a CPU (`schedstat` field 1).
    pub run_ns: u64,
    /// Nanoseconds runnable but waiting on a run queue (`schedstat` field 2).
    pub wait_ns: u64,
    /// Timeslices run (`schedstat` field 3).
    pub slices: u64,
    /// Context switches the thread asked for (blocked, slept, yielded to another task).
    pub voluntary: u64,
    /// Context switches forced on it (preempted).
    pub involuntary: u64,
    pub minflt: u64,
    pub majflt: u64,
    /// Migrations between CPUs (`se.nr_migrations` of `sched`; 0 when the file lacks it).
    pub migrations: u64,
    /// The CPU the thread last ran on (`stat` field 39).
    pub cpu: i64,
}

impl ThreadSched {
    /// Counts of `self` minus those of an earlier reading of the same thread (the CPU and the
    /// thread id are `self`'s).
    pub fn since(&self, earlier: &ThreadSched) -> ThreadSched {
        ThreadSched {
            tid: self.tid,
            run_ns: self.run_ns.saturating_sub(earlier.run_ns),
            wait_ns: self.wait_ns.saturating_sub(earlier.wait_ns),
            slices: self.slices.saturating_sub(earlier.slices),
            voluntary: self.voluntary.saturating_sub(earlier.voluntary),
            involuntary: self.involuntary.saturating_sub(earlier.involuntary),
            minflt: self.minflt.saturating_sub(earlier.minflt),
            majflt: self.majflt.saturating_sub(earlier.majflt),
            migrations: self.migrations.saturating_sub(earlier.migrations),
            cpu: self.cpu,
        }
    }
}

/// `schedstat`'s three numbers: run ns, run-queue wait ns, timeslices.
pub fn parse_schedstat(text: &str) -> Option<(u64, u64, u64)> {
    let mut it = text.split_whitespace().map(|x| x.parse::<u64>().ok());
    Some((it.next()??, it.next()??, it.next()??))
}

/// `status`'s voluntary and involuntary context switches.
pub fn parse_status_switches(text: &str) -> Option<(u64, u64)> {
    let field = |name: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(name))
            .and_then(|v| v.trim().parse::<u64>().ok())
    };
    Some((
        field("voluntary_ctxt_switches:")?,
        field("nonvoluntary_ctxt_switches:")?,
    ))
}

/// `stat`'s minor faults, major faults and last CPU (fields 10, 12 and 39, counted from 1; the
/// command name in parentheses may hold spaces, so fields are counted after its closing one).
pub fn parse_stat(text: &str) -> Option<(u64, u64, i64)> {
    let rest = &text[text.rfind(')')? + 1..];
    // Field 3 (state) is the first after the name.
    let f: Vec<&str> = rest.split_whitespace().collect();
    let at = |n: usize| f.get(n - 3).copied();
    Some((
        at(10)?.parse().ok()?,
        at(12)?.parse().ok()?,
        at(39)?.parse().ok()?,
    ))
}

/// `sched`'s `se.nr_migrations`.
pub fn parse_sched_migrations(text: &str) -> Option<u64> {
    text.lines()
        .find(|l| l.starts_with("se.nr_migrations"))
        .and_then(|l| l.split(':').nth(1))
        .and_then(|v| v.trim().parse().ok())
}

/// The calling thread's counts now; `None` where `/proc` does not give them (not Linux, or a
/// kernel without scheduler statistics).
pub fn read_self() -> Option<ThreadSched> {
    let read = |f: &str| std::fs::read_to_string(format!("/proc/thread-self/{f}")).ok();
    let (run_ns, wait_ns, slices) = parse_schedstat(&read("schedstat")?)?;
    let (voluntary, involuntary) = parse_status_switches(&read("status")?)?;
    let (minflt, majflt, cpu) = parse_stat(&read("stat")?)?;
    let migrations = read("sched")
        .as_deref()
        .and_then(parse_sched_migrations)
        .unwrap_or(0);
    // SAFETY: gettid has no preconditions.
    let tid = unsafe { libc::gettid() } as i64;
    Some(ThreadSched {
        tid,
        run_ns,
        wait_ns,
        slices,
        voluntary,
        involuntary,
        minflt,
        majflt,
        migrations,
        cpu,
    })
}

/// Each CPU's time so far by state from `/proc/stat` (`cpuN` lines, in the kernel's clock ticks,
/// `USER_HZ`, 100 a second on Linux): user, nice, system, idle, iowait, irq, softirq, steal.
/// Steal is the time the hypervisor ran something else on the virtual CPU: with
/// `CONFIG_PARAVIRT_TIME_ACCOUNTING` it is not counted in any task's run time, so a thread on a
/// CPU being stolen from shows as neither running nor waiting.
pub fn parse_proc_stat_cpus(text: &str) -> Vec<(usize, [u64; 8])> {
    text.lines()
        .filter_map(|l| {
            let mut it = l.split_whitespace();
            let cpu = it.next()?.strip_prefix("cpu")?.parse::<usize>().ok()?;
            let mut v = [0u64; 8];
            for x in v.iter_mut() {
                *x = it.next()?.parse().ok()?;
            }
            Some((cpu, v))
        })
        .collect()
}

/// [`parse_proc_stat_cpus`] of this machine now (empty where `/proc/stat` is not there).
pub fn read_cpus() -> Vec<(usize, [u64; 8])> {
    std::fs::read_to_string("/proc/stat")
        .map(|t| parse_proc_stat_cpus(&t))
        .unwrap_or_default()
}

/// One `sched cpu` line per CPU: seconds in each state between two readings.
pub fn cpu_lines(before: &[(usize, [u64; 8])], after: &[(usize, [u64; 8])]) -> Vec<String> {
    // SAFETY: sysconf has no preconditions.
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) }.max(1) as f64;
    after
        .iter()
        .filter_map(|(cpu, a)| {
            let b = before.iter().find(|x| x.0 == *cpu)?.1;
            let d = |k: usize| a[k].saturating_sub(b[k]) as f64 / hz;
            Some(format!(
                "sched cpu {cpu} user_s {:.2} system_s {:.2} idle_s {:.2} iowait_s {:.2} \
                 irq_s {:.2} softirq_s {:.2} steal_s {:.2}",
                d(0) + d(1),
                d(2),
                d(3),
                d(4),
                d(5),
                d(6),
                d(7)
            ))
        })
        .collect()
}

/// Every thread of this process with its nanoseconds on a CPU so far (`/proc/self/task/*/schedstat`).
pub fn process_threads() -> Vec<(i64, u64)> {
    let Ok(dir) = std::fs::read_dir("/proc/self/task") else {
        return Vec::new();
    };
    dir.filter_map(|e| {
        let e = e.ok()?;
        let tid = e.file_name().to_str()?.parse::<i64>().ok()?;
        let t = std::fs::read_to_string(e.path().join("schedstat")).ok()?;
        Some((tid, parse_schedstat(&t)?.0))
    })
    .collect()
}

/// The `sched process` line: how many threads the process has at the end of a region, and the
/// seconds its threads outside the pool (`pool`: their ids) ran during it (`before`, `after`:
/// [`process_threads`] at its start and end; a thread started during the region counts whole).
/// A library's worker thread spinning beside the trace shows here.
pub fn process_line(before: &[(i64, u64)], after: &[(i64, u64)], pool: &[i64]) -> String {
    let others: u64 = after
        .iter()
        .filter(|(tid, _)| !pool.contains(tid))
        .map(|(tid, ns)| {
            let was = before.iter().find(|b| b.0 == *tid).map_or(0, |b| b.1);
            ns.saturating_sub(was)
        })
        .sum();
    format!(
        "sched process threads {} pool {} others_run_s {:.6}",
        after.len(),
        pool.len(),
        others as f64 * 1e-9
    )
}

/// The CPU the calling thread is running on now (-1 where unknown).
pub fn cpu() -> i32 {
    // SAFETY: sched_getcpu has no preconditions.
    unsafe { libc::sched_getcpu() }
}

/// Wall seconds covered by a set of (start, end) intervals (their union): the time a thread was
/// inside bands, where a band it ran while waiting inside another lies within the other's.
pub fn covered_seconds(intervals: &[(f64, f64)]) -> f64 {
    let mut v: Vec<(f64, f64)> = intervals.to_vec();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut total = 0.0;
    let mut cur: Option<(f64, f64)> = None;
    for (s, e) in v {
        cur = match cur {
            Some((cs, ce)) if s <= ce => Some((cs, ce.max(e))),
            Some((cs, ce)) => {
                total += ce - cs;
                Some((s, e))
            }
            None => Some((s, e)),
        };
    }
    if let Some((cs, ce)) = cur {
        total += ce - cs;
    }
    total
}

/// One `sched` line: a pool thread's counts over a parallel region of `wall_s` seconds, with the
/// seconds it spent inside bands (`in_bands_s`), its bands and when its last band ended.
pub fn line(
    thread: usize,
    wall_s: f64,
    d: &ThreadSched,
    bands: usize,
    in_bands_s: f64,
    last_end_s: f64,
) -> String {
    let run = d.run_ns as f64 * 1e-9;
    let wait = d.wait_ns as f64 * 1e-9;
    format!(
        "sched thread {thread} tid {} wall_s {wall_s:.6} run_s {run:.6} runq_wait_s {wait:.6} \
         off_s {:.6} slices {} vcsw {} nvcsw {} minflt {} majflt {} migrations {} cpu {} \
         bands {bands} in_bands_s {in_bands_s:.6} last_band_end_s {last_end_s:.6}",
        d.tid,
        (wall_s - run - wait).max(0.0),
        d.slices,
        d.voluntary,
        d.involuntary,
        d.minflt,
        d.majflt,
        d.migrations,
        d.cpu,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_proc_files() {
        assert_eq!(
            parse_schedstat("123456 7890 12\n"),
            Some((123456, 7890, 12))
        );
        assert_eq!(parse_schedstat("1 2"), None);
        let status = "Name:\trtbench\nState:\tR (running)\nvoluntary_ctxt_switches:\t15\n\
                      nonvoluntary_ctxt_switches:\t3\n";
        assert_eq!(parse_status_switches(status), Some((15, 3)));
        // A name with spaces and a parenthesis; minflt 501, majflt 2, processor 1.
        let mut stat = String::from("4242 (rayon (x) 1) R 1 2 3 4 5 6 501 7 2 8");
        for i in 14..39 {
            stat.push_str(&format!(" {}", if i == 38 { 99 } else { 0 }));
        }
        stat.push_str(" 1 0 0\n");
        assert_eq!(parse_stat(&stat), Some((501, 2, 1)));
        let sched = "x (1, #threads: 3)\n---\nse.exec_start : 1.0\nse.nr_migrations   :   7\n";
        assert_eq!(parse_sched_migrations(sched), Some(7));
    }

    #[test]
    fn a_difference_counts_only_the_interval() {
        let a = ThreadSched {
            tid: 5,
            run_ns: 100,
            wait_ns: 10,
            slices: 3,
            voluntary: 4,
            involuntary: 1,
            minflt: 50,
            majflt: 0,
            migrations: 2,
            cpu: 0,
        };
        let b = ThreadSched {
            run_ns: 350,
            wait_ns: 15,
            slices: 5,
            voluntary: 9,
            minflt: 60,
            cpu: 1,
            ..a
        };
        let d = b.since(&a);
        assert_eq!((d.run_ns, d.wait_ns, d.slices), (250, 5, 2));
        assert_eq!((d.voluntary, d.involuntary, d.minflt), (5, 0, 10));
        assert_eq!((d.migrations, d.cpu, d.tid), (0, 1, 5));
        let l = line(0, 1e-6, &d, 2, 0.5, 0.75);
        assert!(l.starts_with("sched thread 0 tid 5 "), "{l}");
        assert!(l.contains(" vcsw 5 nvcsw 0 minflt 10 "), "{l}");
    }

    /// On Linux the calling thread's own counts read, and its run time grows while it works.
    #[cfg(target_os = "linux")]
    #[test]
    fn reads_this_thread() {
        let a = read_self().expect("/proc/thread-self");
        let mut x = 0u64;
        let t = std::time::Instant::now();
        while t.elapsed().as_millis() < 20 {
            x = x.wrapping_add(std::hint::black_box(1));
        }
        let b = read_self().unwrap();
        assert!(x > 0);
        assert_eq!(a.tid, b.tid);
        assert!(b.since(&a).run_ns > 0, "{a:?} {b:?}");
    }

    #[test]
    fn parses_the_cpu_lines_of_proc_stat() {
        let text = "cpu  9 0 9 9 9 0 0 9 0 0\ncpu0 100 1 20 300 4 0 5 6 0 0\n\
                    cpu1 200 0 30 400 0 0 0 16 0 0\nintr 1 2\n";
        let v = parse_proc_stat_cpus(text);
        assert_eq!(v.len(), 2);
        assert_eq!(v[0], (0, [100, 1, 20, 300, 4, 0, 5, 6]));
        let mut later = v.clone();
        later[1].1[7] += 50;
        let lines = cpu_lines(&v, &later);
        assert_eq!(lines.len(), 2);
        assert!(lines[0].ends_with("steal_s 0.00"), "{}", lines[0]);
        assert!(!lines[1].ends_with("steal_s 0.00"), "{}", lines[1]);
    }

    #[test]
    fn the_process_line_counts_threads_outside_the_pool() {
        let before = [(1, 100), (2, 1_000), (3, 5_000)];
        let after = [(1, 300), (2, 2_000_000_000), (3, 5_000), (4, 500_000_000)];
        // Threads 2 and 3 are the pool's; 1 ran 200 ns more, 4 started during the region.
        let l = process_line(&before, &after, &[2, 3]);
        assert_eq!(l, "sched process threads 4 pool 2 others_run_s 0.500000");
        assert!(process_threads().iter().any(|t| t.1 > 0));
    }

    /// `RTBENCH_PIN_THREADS`' pinning: a thread pinned to one of its allowed CPUs may then run
    /// only there (a thread of its own, so the test's other threads keep their CPUs).
    #[cfg(target_os = "linux")]
    #[test]
    fn a_pinned_thread_runs_on_its_cpu() {
        std::thread::spawn(|| {
            let cpus = crate::measure::threads::allowed_cpus();
            assert!(!cpus.is_empty());
            let last = *cpus.last().unwrap();
            crate::measure::threads::pin_to_cpu(last);
            assert_eq!(crate::measure::threads::allowed_cpus(), vec![last]);
            assert_eq!(cpu(), last as i32);
        })
        .join()
        .unwrap();
    }

    #[test]
    fn covered_seconds_is_the_union() {
        assert_eq!(covered_seconds(&[]), 0.0);
        // A band run inside another's wait counts once; a gap is not covered.
        let c = covered_seconds(&[(0.0, 1.0), (0.25, 0.5), (2.0, 2.5), (0.75, 1.5)]);
        assert!((c - 2.0).abs() < 1e-12, "{c}");
    }
}
