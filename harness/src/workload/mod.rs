//! The SPD workload: camera, surfaces, and the wavefront tracer.

pub mod camera;
pub mod crosscheck;
pub mod out_of_core;
pub mod paging;
pub mod pass_003;
pub mod surface;
pub mod trace;

use crate::error::{input, Result};
use crate::source::Source;
use rtbench_engines::geometry::Geometry;
use rtbench_engines::{build_engine, BuildInput, Engine};
use std::sync::Arc;
use std::time::Instant;

/// A scene ready for engines, with how long getting it ready took.
pub struct Prepared {
    pub input: BuildInput,
    pub generate_s: f64,
    pub prepare_s: f64,
}

pub fn prepare(src: &Source) -> Result<Prepared> {
    let t = Instant::now();
    let scene = src.load()?;
    if scene.objects.is_empty() {
        return Err(input(format!("{}: the scene has no objects", src.label())));
    }
    let generate_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let geometry = Geometry::from_scene(&scene);
    let prepare_s = t.elapsed().as_secs_f64();
    Ok(Prepared {
        input: BuildInput {
            scene: Arc::new(scene),
            geometry: Arc::new(geometry),
        },
        generate_s,
        prepare_s,
    })
}

/// Parses `--set key=value` arguments.
pub fn parse_settings(set: &[String]) -> Result<Vec<(String, String)>> {
    set.iter()
        .map(|s| match s.split_once('=') {
            Some((k, v)) if !k.is_empty() => Ok((k.trim().to_string(), v.trim().to_string())),
            _ => Err(input(format!("--set '{s}': expected key=value"))),
        })
        .collect()
}

/// Builds an engine and times the build (the SPD's preprocessing, with scene preparation).
pub fn build(
    name: &str,
    input: &BuildInput,
    settings: Vec<(String, String)>,
) -> Result<(Box<dyn Engine>, f64)> {
    let t = Instant::now();
    let e = build_engine(name, input, settings)?;
    Ok((e, t.elapsed().as_secs_f64()))
}

/// A rayon pool with `threads` threads (all cores when `None`).
pub fn pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    if threads == Some(0) {
        return Err(input("--threads must be at least 1"));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| input(format!("cannot start threads: {e}")))
}

pub fn check_size(size: u32) -> Result<()> {
    if !(1..=16384).contains(&size) {
        return Err(input(format!("--size {size}: must be from 1 to 16384")));
    }
    Ok(())
}

/// Peak resident set size of this process (Linux `VmHWM`), in bytes.
pub fn peak_rss_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// CPU seconds the calling thread has used (`CLOCK_THREAD_CPUTIME_ID`). The trace's CPU time
/// is counted on our own threads only: a whole-process figure would include the worker threads
/// of Embree's TBB, which spin on after a build and made Embree's time vary twofold between runs.
pub fn thread_cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes only into `t`, which we own; the clock id is a constant.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    if rc != 0 {
        return 0.0;
    }
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}
