//! The SPD workload: camera, surfaces, and the wavefront tracer.

pub mod camera;
pub mod crosscheck;
pub mod footprint;
pub mod frustum;
pub mod memory;
pub mod out_of_core;
pub mod paging;
pub mod pass_003;
pub mod rayshade_memory;
pub mod replacement;
pub mod sched;
pub mod surface;
pub mod tiles;
pub mod trace;
pub mod view_file;

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
    let mut scene = src.load()?;
    // The objects were collected one by one into a growing vector; its spare capacity (up to
    // half of it: 0.6 MiB of gears4's 1.3 MiB) would stay resident through build and trace.
    scene.objects.shrink_to_fit();
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

/// `--json` owns stdout: a setting that makes a library print there (Embree's `verbose`, which
/// writes on stdout from C++) is refused with it.
pub fn check_json_settings(json: bool, settings: &[(String, String)]) -> Result<()> {
    if let Some((_, v)) = settings
        .iter()
        .find(|(k, v)| json && k == "verbose" && v != "0")
    {
        return Err(input(format!(
            "--set verbose={v}: Embree prints on stdout, which --json owns (drop one of them)"
        )));
    }
    Ok(())
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
    // `--engine plugin:PATH[:key=value…]` (render, check): the same entry as in `--engines`.
    let (name, settings) = if name.starts_with("plugin:") {
        let mut e = crate::select::engines(Some(name), "--engine")?;
        let (n, mut s) = e.remove(0);
        s.extend(settings);
        (n, s)
    } else {
        (name.to_string(), settings)
    };
    let t = Instant::now();
    let e = build_engine(&name, input, settings)?;
    Ok((e, t.elapsed().as_secs_f64()))
}

/// Threads this machine runs at once (`std::thread::available_parallelism`, 1 if unknown).
pub fn available_threads() -> usize {
    std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1)
}

/// Environment variable that raises the most threads `--threads` takes above the machine's
/// (`RTBENCH_MAX_THREADS=2`): for instruction counts and tests of a two-thread trace on a
/// process pinned to one core (`taskset -c 1`, where the machine's count reads 1). Threads
/// beyond the cores time nothing but the scheduler: not for time figures.
pub const MAX_THREADS_VAR: &str = "RTBENCH_MAX_THREADS";

/// The most threads `--threads` takes: the machine's ([`available_threads`]), or more with
/// [`MAX_THREADS_VAR`] (at most 64).
pub fn thread_limit() -> usize {
    let most = available_threads();
    std::env::var(MAX_THREADS_VAR)
        .ok()
        .and_then(|v| v.trim().parse::<usize>().ok())
        .map_or(most, |n| most.max(n.min(64)))
}

/// A rayon pool with `threads` threads (all cores when `None`). More threads than the machine
/// runs at once are refused: they measure nothing but the scheduler (100,000 made a load
/// average of 800 on two cores before failing); [`MAX_THREADS_VAR`] raises the limit.
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
    if std::env::var_os(PIN_THREADS_VAR).is_some() {
        let cpus = allowed_cpus();
        if !cpus.is_empty() {
            b = b.start_handler(move |i| pin_to_cpu(cpus[i % cpus.len()]));
        }
    }
    b.build()
        .map_err(|e| input(format!("cannot start threads: {e}")))
}

/// Environment variable that pins each thread of every pool [`pool`] makes to one CPU of those
/// the process may run on (thread i to the i-th, round robin): an experiment on where the
/// scheduler puts the pool's threads (issue 20, acceptance 3), not a default.
pub const PIN_THREADS_VAR: &str = "RTBENCH_PIN_THREADS";

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

/// Bytes the workload holds per pixel corner, at least: measured 80 (in-memory engines) to 210
/// (breadth-first) at --size 2048 (corners, rays, hits, paths, shading records), rounded up.
pub const BYTES_PER_CORNER: u64 = 256;

/// Memory this process can still have: the smaller of the machine's available memory
/// (`MemAvailable`) and the address space left under its limit (`ulimit -v`, less what is
/// mapped already). None when neither is known.
pub fn memory_available() -> Option<u64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok().and_then(|t| {
        let line = t.lines().find(|l| l.starts_with("MemAvailable:"))?;
        line.split_whitespace().nth(1)?.parse::<u64>().ok()
    });
    let mem = meminfo.map(|kb| kb.saturating_mul(1024));
    let limit = rtbench_engines::usage::address_space_left();
    match (mem, limit) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    }
}

fn gib(b: u64) -> String {
    format!("{:.1} GiB", b as f64 / (1u64 << 30) as f64)
}

/// `--size`: from 1 to 16384, and an image whose workload fits in the memory available.
pub fn check_size(size: u32) -> Result<()> {
    if !(1..=16384).contains(&size) {
        return Err(input(format!("--size {size}: must be from 1 to 16384")));
    }
    let corners = (size as u64 + 1).pow(2);
    let need = corners * BYTES_PER_CORNER;
    if let Some(have) = memory_available().filter(|&have| need > have) {
        return Err(input(format!(
            "--size {size}: the workload needs at least {} ({BYTES_PER_CORNER} B per pixel \
             corner), {} is available",
            gib(need),
            gib(have)
        )));
    }
    Ok(())
}

/// A generated scene about to be held in memory, and the structures of `engines` over it, fit in
/// the memory available (RAM and the address-space limit), by the estimate of [`footprint`];
/// `force` skips this (`--sf 40` of tree ran the machine out of memory, `--tessellate 1000`
/// and an address-space limit aborted).
pub fn check_scene_fits(src: &Source, engines: &[&str], force: bool) -> Result<()> {
    let Source::Program(p, o) = src else {
        return Ok(());
    };
    if force {
        return Ok(());
    }
    let f = footprint::Census::of(*p, o);
    let need = f.bytes(engines);
    if let Some(have) = memory_available().filter(|&have| need > have) {
        return Err(input(format!(
            "{}: {} objects ({} primitives to build over) need about {} in memory with {}, {} is \
             available (--force to try anyway)",
            src.label(),
            f.objects,
            f.primitives(),
            gib(need),
            engines.join(" and "),
            gib(have)
        )));
    }
    Ok(())
}

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

/// Feature sizes below this share of the scene's scale (its largest coordinate, the camera's
/// included) are not resolved by the `f32` engines: f32 keeps 24 bits, so at 1e5 a feature
/// spans fewer than 200 representable steps and hit tests on it come apart from the `f64`
/// reference (a triangle of ±1e-5 seen from 5 units; a cone whose radii differ by 10^6).
pub const F32_FEATURE_RATIO: f64 = 1e5;

/// A one-line warning when the scene holds a feature the `f32` engines cannot represent at the
/// scene's scale ([`F32_FEATURE_RATIO`]); render and check print it.
pub fn precision_warning(scene: &rtbench_scenes::Scene) -> Option<String> {
    use rtbench_scenes::Shape;
    let mut scale = scene.view.from.abs().max_element();
    let mut smallest = f64::INFINITY;
    for o in &scene.objects {
        let b = o.shape.bounds();
        scale = scale
            .max(b.min.abs().max_element())
            .max(b.max.abs().max_element());
        let feature = match &o.shape {
            Shape::Sphere { radius, .. } => *radius,
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => {
                let radii = [*base_radius, *apex_radius]
                    .into_iter()
                    .filter(|r| *r > 0.0)
                    .fold(f64::INFINITY, f64::min);
                radii.min((*apex - *base).length())
            }
            // A polygon's size, not its shortest edge: a sliver is still where it is.
            Shape::Polygon(_) | Shape::Patch { .. } => {
                let d = (b.max - b.min).length();
                if d > 0.0 {
                    d
                } else {
                    f64::INFINITY
                }
            }
        };
        smallest = smallest.min(feature);
    }
    (smallest.is_finite() && smallest > 0.0 && scale / smallest > F32_FEATURE_RATIO).then(|| {
        format!(
            "{}: a feature of {smallest:.3e} at a scale of {scale:.3e} (ratio {:.1e} > {F32_FEATURE_RATIO:e}): the f32 engines cannot resolve it and may miss hits the f64 reference sees",
            scene.name,
            scale / smallest
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(objects: Vec<rtbench_scenes::Shape>) -> rtbench_scenes::Scene {
        let mut s = rtbench_scenes::generate_scene(
            rtbench_scenes::spd::Program::Tetra,
            &rtbench_scenes::spd::Options::standard(rtbench_scenes::spd::Program::Tetra),
        )
        .unwrap();
        s.objects = objects
            .into_iter()
            .map(|shape| rtbench_scenes::Object { material: 0, shape })
            .collect();
        s
    }

    /// Features the f32 engines cannot resolve are named; ordinary scenes pass silently.
    #[test]
    fn tiny_features_are_warned_of() {
        use glam::DVec3;
        use rtbench_scenes::Shape;
        let tri = |r: f64| {
            Shape::Polygon(vec![
                DVec3::new(-r, -r, 0.0),
                DVec3::new(r, -r, 0.0),
                DVec3::new(0.0, r, 0.0),
            ])
        };
        assert!(precision_warning(&scene(vec![tri(1.0)])).is_none());
        assert!(precision_warning(&scene(vec![tri(1e-5)])).is_some());
        assert!(precision_warning(&scene(vec![tri(1e-20)])).is_some());
        let cone = Shape::Cone {
            base: DVec3::ZERO,
            base_radius: 1.0,
            apex: DVec3::new(0.0, 1.0, 0.0),
            apex_radius: 1e-6,
        };
        assert!(precision_warning(&scene(vec![cone])).is_some());
        let tetra = rtbench_scenes::generate_scene(
            rtbench_scenes::spd::Program::Tetra,
            &rtbench_scenes::spd::Options::standard(rtbench_scenes::spd::Program::Tetra),
        )
        .unwrap();
        assert!(precision_warning(&tetra).is_none());
    }
}
