//! Planted regressions, to measure whether the nightly detection finds them
//! (docs/guides/nightly.md). Only the environment variable `RTBENCH_PLANT` turns one on; it
//! is meant for that measurement alone.
//!
//! - `RTBENCH_PLANT=work:ENGINE:SCENE:FRACTION`: the engine answers every query as before, then
//!   answers FRACTION of them a second time (into scratch buffers, with scratch counters): real
//!   extra work, the results and counters unchanged;
//! - `RTBENCH_PLANT=counter:ENGINE:SCENE`: one extra primitive test counted per call, no extra work.
//!
//! SCENE is the SPD program's name (`balls`); `*` matches every scene. Several plants are separated
//! by `;` (the first that matches an engine and scene applies).

use rtbench_engines::{Counters, Engine, Hit, Ray};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};

#[derive(Clone, Debug, PartialEq)]
pub enum Plant {
    Work(f64),
    Counter,
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

impl Engine for Planted {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], counters: &mut Counters) {
        self.inner.intersect(rays, hits, counters);
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
        self.inner.occluded(rays, occluded, counters);
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
        let two = "work:bvh4:gears:0.06;counter:grid:tetra";
        assert_eq!(parse(two, "bvh4", Some("gears")), Some(Plant::Work(0.06)));
        assert_eq!(parse(two, "grid", Some("tetra")), Some(Plant::Counter));
    }
}
