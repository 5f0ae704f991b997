//! Planted regressions, to measure whether the nightly detection finds them
//! (docs/guides/nightly.md). Only the environment variable `RTBENCH_PLANT` turns one on; it
//! is meant for that measurement alone.
//!
//! - `RTBENCH_PLANT=work:ENGINE:SCENE:FRACTION`: the engine answers every query as before, then
//!   answers FRACTION of them a second time (into scratch buffers, with scratch counters): real
//!   extra work, the results and counters unchanged;
//! - `RTBENCH_PLANT=time:ENGINE:SCENE:FRACTION`: the trace runs FRACTION slower, whatever share of it
//!   the engine takes: after each query the calling thread busy-waits FRACTION of the CPU time it
//!   spent on the query and on the shading since its previous query returned, so a planted 0.10 is
//!   a trace taking 10 % more CPU time. Pauses longer than [`SHADING_GAP`] (a build, another
//!   render) are not part of the trace and are not counted. The results and counters are unchanged;
//! - `RTBENCH_PLANT=counter:ENGINE:SCENE`: one extra primitive test counted per call, no extra work.
//!
//! SCENE is the SPD program's name (`balls`); `*` matches every scene. Several plants are separated
//! by `;` (the first that matches an engine and scene applies).

use crate::measure::clock::thread_cpu_seconds;
use rtbench_engines::{Counters, Engine, Hit, Ray};
use std::cell::Cell;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

#[derive(Clone, Debug, PartialEq)]
pub enum Plant {
    Work(f64),
    Time(f64),
    Counter,
}

/// The longest pause between two queries of one thread that still counts as the shading of one
/// trace, for the `time` plant: a batch's shading takes at most about a millisecond, a build or
/// another engine's render in between far longer.
pub const SHADING_GAP: Duration = Duration::from_millis(5);

thread_local! {
    /// When this thread's previous planted query returned: wall clock and thread CPU seconds.
    static LAST_RETURN: Cell<Option<(Instant, f64)>> = const { Cell::new(None) };
}

/// The plant for this engine and scene, if `RTBENCH_PLANT` asks for one.
pub fn from_env(engine: &str, program: Option<&str>) -> Option<Plant> {
    parse(
        crate::measure::vars::values().plant.as_deref()?,
        engine,
        program,
    )
}

fn parse(spec: &str, engine: &str, program: Option<&str>) -> Option<Plant> {
    spec.split(';')
        .find_map(|one| parse_one(one.trim(), engine, program))
}

fn parse_one(spec: &str, engine: &str, program: Option<&str>) -> Option<Plant> {
    let parts: Vec<&str> = spec.split(':').collect();
    let matches = |e: &str, s: &str| e == engine && (s == "*" || Some(s) == program);
    match parts.as_slice() {
        ["work", e, s, f] if matches(e, s) => f
            .parse::<f64>()
            .ok()
            .filter(|f| f.is_finite() && *f > 0.0)
            .map(Plant::Work),
        ["time", e, s, f] if matches(e, s) => f
            .parse::<f64>()
            .ok()
            .filter(|f| f.is_finite() && *f > 0.0 && *f <= 10.0)
            .map(Plant::Time),
        ["counter", e, s] if matches(e, s) => Some(Plant::Counter),
        _ => None,
    }
}

/// An engine with a plant.
pub struct Planted {
    pub inner: Box<dyn Engine>,
    pub plant: Plant,
    /// Rays owed to the extra work, in millionths (fractions carry over between calls).
    owed: AtomicU64,
}

impl Planted {
    pub fn new(inner: Box<dyn Engine>, plant: Plant) -> Planted {
        Planted {
            inner,
            plant,
            owed: AtomicU64::new(0),
        }
    }

    /// How many of `n` rays to answer again.
    fn extra(&self, n: usize) -> usize {
        let Plant::Work(f) = self.plant else {
            return 0;
        };
        let add = (n as f64 * f * 1e6) as u64;
        let before = self.owed.fetch_add(add, Ordering::Relaxed) + add;
        let k = before / 1_000_000;
        self.owed.fetch_sub(k * 1_000_000, Ordering::Relaxed);
        (k as usize).min(n)
    }
}

/// Runs `query`, then, for a `time` plant, busy-waits the planted fraction of the CPU time this
/// thread spent on the query and on the shading since its previous query (see the module doc).
/// CPU time, not wall time: on a loaded machine a thread's wall time includes the time others had
/// the core, and a plant scaled by it would plant a larger slowdown the busier the machine.
fn timed(plant: &Plant, query: impl FnOnce()) {
    let Plant::Time(f) = *plant else {
        query();
        return;
    };
    let (wall0, cpu0) = (Instant::now(), thread_cpu_seconds());
    query();
    let cpu1 = thread_cpu_seconds();
    let mut spent = cpu1 - cpu0;
    if let Some((wall, cpu)) = LAST_RETURN.get() {
        if wall0.saturating_duration_since(wall) <= SHADING_GAP {
            spent += cpu0 - cpu;
        }
    }
    let until = cpu1 + spent.max(0.0) * f;
    while thread_cpu_seconds() < until {
        std::hint::spin_loop();
    }
    LAST_RETURN.set(Some((Instant::now(), thread_cpu_seconds())));
}

impl Engine for Planted {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], counters: &mut Counters) {
        timed(&self.plant, || self.inner.intersect(rays, hits, counters));
        let k = self.extra(rays.len());
        if k > 0 {
            let mut scratch = vec![Hit::MISS; k];
            self.inner
                .intersect(&rays[..k], &mut scratch, &mut Counters::default());
            std::hint::black_box(&scratch);
        }
        if self.plant == Plant::Counter {
            counters.primitive_tests += 1;
        }
    }

    fn occluded(&self, rays: &[Ray], occluded: &mut [bool], counters: &mut Counters) {
        timed(&self.plant, || {
            self.inner.occluded(rays, occluded, counters)
        });
        let k = self.extra(rays.len());
        if k > 0 {
            let mut scratch = vec![false; k];
            self.inner
                .occluded(&rays[..k], &mut scratch, &mut Counters::default());
            std::hint::black_box(&scratch);
        }
        if self.plant == Plant::Counter {
            counters.primitive_tests += 1;
        }
    }

    fn structure_bytes(&self) -> u64 {
        self.inner.structure_bytes()
    }

    fn batch_hint(&self) -> Option<usize> {
        self.inner.batch_hint()
    }

    fn failure(&self) -> Option<String> {
        self.inner.failure()
    }

    fn build_stats(&self) -> BTreeMap<String, f64> {
        self.inner.build_stats()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plants_match_their_engine_and_scene_only() {
        assert_eq!(
            parse("work:grid:balls:0.05", "grid", Some("balls")),
            Some(Plant::Work(0.05))
        );
        assert_eq!(parse("work:grid:balls:0.05", "bvh4", Some("balls")), None);
        assert_eq!(parse("work:grid:balls:0.05", "grid", Some("tetra")), None);
        assert_eq!(
            parse("counter:grid:*", "grid", Some("tetra")),
            Some(Plant::Counter)
        );
        assert_eq!(parse("work:grid:balls:x", "grid", Some("balls")), None);
        assert_eq!(
            parse("time:bvh8:*:0.1", "bvh8", Some("mount")),
            Some(Plant::Time(0.1))
        );
        assert_eq!(parse("time:bvh8:*:-1", "bvh8", Some("mount")), None);
        let two = "work:bvh4:gears:0.06;counter:grid:tetra";
        assert_eq!(parse(two, "bvh4", Some("gears")), Some(Plant::Work(0.06)));
        assert_eq!(parse(two, "grid", Some("tetra")), Some(Plant::Counter));
    }
}

#[cfg(test)]
mod time_plant_tests {
    use super::*;

    #[test]
    fn a_time_plant_slows_a_query_by_its_fraction() {
        let work = || {
            let t = thread_cpu_seconds();
            while thread_cpu_seconds() < t + 0.002 {
                std::hint::spin_loop();
            }
        };
        let t = thread_cpu_seconds();
        for _ in 0..10 {
            timed(&Plant::Time(0.5), work);
        }
        let s = thread_cpu_seconds() - t;
        // 20 ms of CPU in queries and at least half of that planted.
        assert!(s >= 0.030, "{s}");
    }
}
