//! Threads: how many this machine runs, the most `--threads` takes, the CPUs the process may run
//! on, and the rayon pool every parallel phase runs in.

use crate::error::{input, Result};
use std::fmt;
use std::str::FromStr;

/// How many threads a trace runs on: a count, or `all` the machine runs at once. One spelling
/// wherever a thread count is given (`--threads`, a suite's `threads`, `--set threads=`), one
/// default ([`Threads::DEFAULT`]), parsed by [`FromStr`] alone.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Threads {
    Count(usize),
    All,
}

impl Threads {
    /// One thread: the steadiest figure on a shared machine, and the one every ratio to Embree
    /// is compared at unless asked otherwise.
    pub const DEFAULT: Threads = Threads::Count(1);
    /// The accepted forms, as error messages name them.
    pub const FORMS: &'static str = "a count of at least 1, or all";

    /// The count a pool is made with (`None`: all cores).
    pub fn count(self) -> Option<usize> {
        match self {
            Threads::Count(n) => Some(n),
            Threads::All => None,
        }
    }
}

impl Default for Threads {
    fn default() -> Threads {
        Threads::DEFAULT
    }
}

impl FromStr for Threads {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Threads, String> {
        match s.trim() {
            "all" => Ok(Threads::All),
            t => match t.parse::<usize>() {
                Ok(n) if n >= 1 => Ok(Threads::Count(n)),
                _ => Err(format!("threads '{s}': expected {}", Threads::FORMS)),
            },
        }
    }
}

impl fmt::Display for Threads {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Threads::Count(n) => write!(f, "{n}"),
            Threads::All => f.write_str("all"),
        }
    }
}

/// `--threads` for clap: [`Threads`]'s one spelling.
pub fn parse_threads(s: &str) -> std::result::Result<Threads, String> {
    s.parse::<Threads>()
        .map_err(|_| format!("expected {}", Threads::FORMS))
}

/// Threads this machine runs at once (`std::thread::available_parallelism`, 1 if unknown).
pub fn available_threads() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
}

// `RTBENCH_MAX_THREADS` (read once, in `measure::vars`) raises the most threads `--threads` takes above the machine's
// (`RTBENCH_MAX_THREADS=2`): for instruction counts and tests of a two-thread trace on a
// process pinned to one core (`taskset -c 1`, where the machine's count reads 1). Threads
// beyond the cores time nothing but the scheduler: not for time figures.

/// The most threads `--threads` takes: the machine's ([`available_threads`]), or more with
/// `RTBENCH_MAX_THREADS` (at most 64).
pub fn thread_limit() -> usize {
    let most = available_threads();
    super::vars::values()
        .max_threads
        .map_or(most, |n| most.max(n.min(super::vars::MOST_THREADS)))
}

/// A rayon pool with `threads` threads (all cores when `None`). More threads than the machine
/// runs at once are refused: they measure nothing but the scheduler (100,000 made a load
/// average of 800 on two cores before failing); `RTBENCH_MAX_THREADS` raises the limit.
pub fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    if threads == Some(0) {
        return Err(input("--threads must be at least 1"));
    }
    let most = thread_limit();
    if let Some(n) = threads.filter(|&n| n > most) {
        return Err(input(format!(
            "--threads {n}: more than the {most} this machine runs at once"
        )));
    }
    let mut b = rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0));
    if super::vars::values().pin_threads {
        let cpus = allowed_cpus();
        if !cpus.is_empty() {
            b = b.start_handler(move |i| pin_to_cpu(cpus[i % cpus.len()]));
        }
    }
    b.build()
        .map_err(|e| input(format!("cannot start threads: {e}")))
}

// `RTBENCH_PIN_THREADS` (read once, in `measure::vars`) pins each thread of every pool [`pool`]
// makes to one CPU of those the process may run on (thread i to the i-th, round robin): an
// experiment on where the scheduler puts the pool's threads, not a default.

/// The CPUs the calling thread may run on (empty where that cannot be read).
pub fn allowed_cpus() -> Vec<usize> {
    // SAFETY: a zeroed cpu_set_t is a valid empty set; sched_getaffinity writes only into it.
    let mut set: libc::cpu_set_t = unsafe { std::mem::zeroed() };
    // SAFETY: pid 0 is the calling thread; the size is the set's own.
    let rc =
        unsafe { libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) };
    if rc != 0 {
        return Vec::new();
    }
    (0..libc::CPU_SETSIZE as usize)
        // SAFETY: `c` is below CPU_SETSIZE, the set's capacity.
        .filter(|&c| unsafe { libc::CPU_ISSET(c, &set) })
        .collect()
}

/// Pins the calling thread to `cpu` (best effort: a refusal leaves it where it was).
pub fn pin_to_cpu(cpu: usize) {
    // SAFETY: as in `allowed_cpus`; CPU_SET writes only into `set`, `cpu` < CPU_SETSIZE is checked.
    unsafe {
        if cpu >= libc::CPU_SETSIZE as usize {
            return;
        }
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(cpu, &mut set);
        libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set);
    }
}
