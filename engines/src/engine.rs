//! The one interface every accelerator implements (docs/concepts.md, "Engines"): build from a
//! scene with a typed configuration, answer batches of closest-hit and any-hit queries, report
//! exact counters and structure memory.
//!
//! Engines are registered in [`crate::registry`]; each parses its own typed configuration from
//! the command line's `key=value` strings with [`Settings`], rejecting keys it does not know.

use crate::geometry::Geometry;
use crate::ray::{Hit, Ray};
use rtbench_scenes::Scene;
use serde::Serialize;
use std::collections::BTreeMap;
use std::str::FromStr;
use std::sync::Arc;

/// What an engine is built from: the scene as the generator gave it (f64, original primitives)
/// and the prepared `f32` geometry shared by all engines (polygons cut into triangles).
#[derive(Clone)]
pub struct BuildInput {
    pub scene: Arc<Scene>,
    pub geometry: Arc<Geometry>,
}

/// Exact, time-independent counters (SPD procedure item 14; Havran's statistics). A caller
/// gives each batch (each thread) its own `Counters` and sums them with [`Counters::add`]:
/// counting costs no atomics in hot loops. Engines fill what applies to them.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Counters {
    /// Rays answered (closest-hit and any-hit).
    pub rays: u64,
    /// Ray–primitive intersection tests, and those that hit (within the ray segment).
    pub primitive_tests: u64,
    pub primitive_hits: u64,
    /// Tree nodes visited and ray–box tests (BVH engines).
    pub nodes_visited: u64,
    pub box_tests: u64,
    /// Grid cells stepped through, and those of them that were empty (grid engines).
    pub cells_visited: u64,
    pub empty_cells_visited: u64,
    /// Tests skipped because the mailbox showed the primitive already tested for this ray.
    pub mailbox_skips: u64,
    /// Any-hit queries answered by the shadow cache.
    pub shadow_cache_hits: u64,
    /// Engine-specific counters, by name.
    pub extra: BTreeMap<String, u64>,
}

impl Counters {
    pub fn add(&mut self, o: &Counters) {
        self.rays += o.rays;
        self.primitive_tests += o.primitive_tests;
        self.primitive_hits += o.primitive_hits;
        self.nodes_visited += o.nodes_visited;
        self.box_tests += o.box_tests;
        self.cells_visited += o.cells_visited;
        self.empty_cells_visited += o.empty_cells_visited;
        self.mailbox_skips += o.mailbox_skips;
        self.shadow_cache_hits += o.shadow_cache_hits;
        for (k, v) in &o.extra {
            *self.extra.entry(k.clone()).or_insert(0) += v;
        }
    }
}

/// Rays per engine call by default: large enough to amortise the call, small enough to split
/// across threads.
pub const DEFAULT_BATCH: usize = 4096;

/// A built acceleration structure. `Send + Sync`: batches may be answered from several threads
/// at once, each with its own `Counters`.
pub trait Engine: Send + Sync {
    /// Closest hit of every ray: `hits[i]` for `rays[i]` (`Hit::MISS` when none in
    /// `(tmin, tmax)`). `hits.len() == rays.len()`.
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], counters: &mut Counters);

    /// Any hit: `occluded[i]` is true when some primitive lies in `(tmin, tmax)` of `rays[i]`.
    /// May stop at the first one found.
    fn occluded(&self, rays: &[Ray], occluded: &mut [bool], counters: &mut Counters);

    /// Bytes of the acceleration structure itself (nodes, cells, index lists; not the geometry
    /// shared by all engines unless the engine copies it).
    fn structure_bytes(&self) -> u64;

    /// Rays per call the engine wants: `Some(n)` lets the caller split a generation into calls
    /// of n rays over its threads (in-memory engines); `None` asks for the whole generation in
    /// one call (the breadth-first engine sweeps the scene once per pass for all its rays).
    fn batch_hint(&self) -> Option<usize> {
        Some(DEFAULT_BATCH)
    }

    /// Why the last calls failed, if they did: an engine that reads files (breadth-first) cannot
    /// report an I/O error through `intersect`, so it answers MISS and says so here. The caller
    /// turns it into an error instead of results.
    fn failure(&self) -> Option<String> {
        None
    }

    /// Build statistics (node counts, depths, resolution, build seconds …), by name.
    fn build_stats(&self) -> BTreeMap<String, f64> {
        BTreeMap::new()
    }
}

/// Why an engine could not be built or configured.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EngineError {
    #[error("unknown engine '{0}' (see `rtbench engines`)")]
    Unknown(String),
    #[error("engine '{engine}' is not available: {reason}")]
    Unavailable { engine: String, reason: String },
    #[error("engine '{engine}' has no setting '{key}' (known: {known})")]
    UnknownKey {
        engine: String,
        key: String,
        known: String,
    },
    #[error("engine '{engine}': bad value '{value}' for '{key}': {reason}")]
    BadValue {
        engine: String,
        key: String,
        value: String,
        reason: String,
    },
    #[error("engine '{engine}': {reason}")]
    Build { engine: String, reason: String },
}

/// `key=value` settings given to one engine. An engine reads the keys it knows with
/// [`Settings::get`] and then calls [`Settings::finish`], which rejects anything left over.
#[derive(Clone, Debug, Default)]
pub struct Settings {
    engine: String,
    pairs: Vec<(String, String)>,
    known: Vec<&'static str>,
}

impl Settings {
    pub fn new(engine: &str, pairs: Vec<(String, String)>) -> Settings {
        Settings {
            engine: engine.to_string(),
            pairs,
            known: Vec::new(),
        }
    }

    /// Reads `key` (the last occurrence wins) as a `T`, or gives `default`.
    pub fn get<T: FromStr>(&mut self, key: &'static str, default: T) -> Result<T, EngineError>
    where
        T::Err: std::fmt::Display,
    {
        self.known.push(key);
        let mut value = None;
        self.pairs.retain(|(k, v)| {
            if k == key {
                value = Some(v.clone());
                false
            } else {
                true
            }
        });
        match value {
            None => Ok(default),
            Some(v) => v.parse::<T>().map_err(|e| EngineError::BadValue {
                engine: self.engine.clone(),
                key: key.to_string(),
                value: v.clone(),
                reason: e.to_string(),
            }),
        }
    }

    /// The pairs no `get` asked for, in order: for an engine that hands unknown keys on (a
    /// plugin passes them to its library, which rejects what it does not know).
    pub fn into_rest(self) -> Vec<(String, String)> {
        self.pairs
    }

    /// Fails on the first key no `get` asked for.
    pub fn finish(self) -> Result<(), EngineError> {
        match self.pairs.into_iter().next() {
            None => Ok(()),
            Some((key, _)) => Err(EngineError::UnknownKey {
                engine: self.engine,
                key,
                known: if self.known.is_empty() {
                    "none".into()
                } else {
                    self.known.join(", ")
                },
            }),
        }
    }
}

/// One registered engine: its name, what it is, whether it can run here, how to build it.
pub struct EngineInfo {
    pub name: &'static str,
    pub description: &'static str,
    /// `Err(reason)` when a dependency is missing (e.g. Embree not installed or not built in).
    pub available: fn() -> Result<(), String>,
    pub build: BuildFn,
}

/// How an engine is built from a scene and its settings.
pub type BuildFn = fn(&BuildInput, Settings) -> Result<Box<dyn Engine>, EngineError>;
