//! Engines for rtbench's own tests, registered only when the environment variable
//! `RTBENCH_TEST_ENGINES=1` is set (never in `rtbench engines` otherwise):
//!
//! - `test-slow`: wraps another engine (`inner=bvh4`) and, after each batch, spins for
//!   `RTBENCH_TEST_SLOWDOWN` (an environment variable, e.g. `0.2`) times the time the batch took,
//!   so its query time grows by exactly that fraction on any machine. The slowdown is read from
//!   the environment, not a setting, so the run's key is the same with and without it.
//! - `test-panic`: panics in its first query (a crashing engine).
//! - `test-hog`: allocates and touches `bytes` bytes at build (an engine that outgrows memory).

use crate::engine::{BuildInput, Counters, Engine, EngineError, Settings};
use crate::ray::{Hit, Ray};
use std::time::Instant;

pub fn enabled() -> bool {
    std::env::var("RTBENCH_TEST_ENGINES").is_ok_and(|v| v == "1")
}

/// How a wrapper builds the engine it wraps, by name: the registry's `build_engine`, handed in
/// by the registry's entries ([`crate::registry`]), so this module does not depend on the
/// registry that lists it.
pub type InnerBuild =
    fn(&str, &BuildInput, Vec<(String, String)>) -> Result<Box<dyn Engine>, EngineError>;

struct Slow {
    inner: Box<dyn Engine>,
    factor: f64,
}

fn spin(d: std::time::Duration, factor: f64) {
    let until = Instant::now() + d.mul_f64(factor);
    while Instant::now() < until {
        std::hint::spin_loop();
    }
}

impl Engine for Slow {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], c: &mut Counters) {
        let t = Instant::now();
        self.inner.intersect(rays, hits, c);
        spin(t.elapsed(), self.factor);
    }
    fn occluded(&self, rays: &[Ray], o: &mut [bool], c: &mut Counters) {
        let t = Instant::now();
        self.inner.occluded(rays, o, c);
        spin(t.elapsed(), self.factor);
    }
    fn structure_bytes(&self) -> u64 {
        self.inner.structure_bytes()
    }
}

pub fn build_slow(
    input: &BuildInput,
    mut s: Settings,
    build: InnerBuild,
) -> Result<Box<dyn Engine>, EngineError> {
    let inner: String = s.get("inner", "bvh4".to_string())?;
    s.finish()?;
    let factor = std::env::var("RTBENCH_TEST_SLOWDOWN")
        .ok()
        .and_then(|v| v.parse::<f64>().ok())
        .unwrap_or(0.0)
        .max(0.0);
    Ok(Box::new(Slow {
        inner: build(&inner, input, vec![])?,
        factor,
    }))
}

struct Panics;

impl Engine for Panics {
    fn intersect(&self, _: &[Ray], _: &mut [Hit], _: &mut Counters) {
        panic!("test-panic: a crashing engine, as asked");
    }
    fn occluded(&self, _: &[Ray], _: &mut [bool], _: &mut Counters) {
        panic!("test-panic: a crashing engine, as asked");
    }
    fn structure_bytes(&self) -> u64 {
        0
    }
}

pub fn build_panic(_: &BuildInput, s: Settings) -> Result<Box<dyn Engine>, EngineError> {
    s.finish()?;
    Ok(Box::new(Panics))
}

struct Hog {
    inner: Box<dyn Engine>,
    held: Vec<u8>,
}

impl Engine for Hog {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], c: &mut Counters) {
        self.inner.intersect(rays, hits, c)
    }
    fn occluded(&self, rays: &[Ray], o: &mut [bool], c: &mut Counters) {
        self.inner.occluded(rays, o, c)
    }
    fn structure_bytes(&self) -> u64 {
        self.held.len() as u64
    }
}

pub fn build_hog(
    input: &BuildInput,
    mut s: Settings,
    build: InnerBuild,
) -> Result<Box<dyn Engine>, EngineError> {
    let bytes: usize = s.get("bytes", 1usize << 30)?;
    s.finish()?;
    // Touch every page so the memory is resident, then hold it while tracing.
    let held = vec![1u8; bytes];
    let inner = build("bvh2", input, vec![])?;
    // Hold long enough for a memory watcher polling every 20 ms to see it.
    std::thread::sleep(std::time::Duration::from_millis(300));
    Ok(Box::new(Hog { inner, held }))
}
