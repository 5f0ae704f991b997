//! Timing engines side by side on one ray set (closest hit, the calling thread): one warm-up, then the
//! median of several CPU and wall times; builds timed as the median wall time of several builds.
//! Shared by the tables that compare engines on the same rays (001's rendering experiments).

use crate::error::Result;
use crate::measure::repeat::{self, Repeats};
use crate::measure::span::{span, Workers};
use crate::select::median;
use crate::workload;
use rtbench_engines::{BuildInput, Counters, Hit, Ray};
use serde::Serialize;

/// One engine to time: label, engine name, settings.
pub type Timee = (
    &'static str,
    &'static str,
    &'static [(&'static str, &'static str)],
);

/// The counters a timed row keeps.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct TimedCounters {
    pub nodes_visited: u64,
    pub box_tests: u64,
    pub primitive_tests: u64,
}

/// One engine's timing on one scene.
#[derive(Clone, Debug, Serialize)]
pub struct Timed {
    pub scene: &'static str,
    pub sf: u32,
    pub engine: &'static str,
    pub engine_name: &'static str,
    pub settings: Vec<(String, String)>,
    pub build_s: f64,
    pub cpu_s: f64,
    pub wall_s: f64,
    pub repeats: usize,
    pub rays: usize,
    pub hits: usize,
    pub structure_bytes: u64,
    pub primitives: usize,
    pub counters: TimedCounters,
}

impl Timed {
    pub fn bytes_per_primitive(&self) -> f64 {
        self.structure_bytes as f64 / self.primitives.max(1) as f64
    }
}

pub fn settings(kv: &[(&str, &str)]) -> Vec<(String, String)> {
    kv.iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

/// Whether the registry has `engine` and it can run here.
pub(super) fn available(engine: &str) -> bool {
    rtbench_engines::registry()
        .into_iter()
        .find(|e| e.name == engine)
        .is_some_and(|e| (e.available)().is_ok())
}

/// Times every available engine of `engines` on `rays`; an engine not available here is skipped
/// (said on stderr).
pub fn time_engines(
    engines: &[Timee],
    input: &BuildInput,
    rays: &[Ray],
    repeats: usize,
    builds: usize,
    (scene, sf): (&'static str, u32),
    what: &str,
) -> Result<Vec<Timed>> {
    let mut out = Vec::new();
    for &(label, engine, kv) in engines {
        if !available(engine) {
            eprintln!("{what}: {engine} is not available here; skipped");
            continue;
        }
        eprintln!("{what}: {scene}{sf} {label} …");
        let (mut e, build_s) = workload::build(engine, input, settings(kv))?;
        let mut build_times = vec![build_s];
        for _ in 1..builds {
            drop(e);
            let (again, s) = workload::build(engine, input, settings(kv))?;
            e = again;
            build_times.push(s);
        }
        let mut hits = vec![Hit::MISS; rays.len()];
        // The one repeat policy: the untimed first pass gives the counters, then each timed
        // pass is one span of this thread.
        let mut counters: Option<Counters> = None;
        let timed = Repeats::new(repeats as u32).run(Workers::Caller, |t| -> Result<()> {
            let mut c = Counters::default();
            t.span(|| e.intersect(rays, &mut hits, &mut c));
            counters.get_or_insert(c);
            Ok(())
        })?;
        let counters = counters.unwrap_or_default();
        let n_hits = hits.iter().filter(|x| x.t.is_finite()).count();
        let mut cpu: Vec<f64> = timed.iter().map(|(_, s)| s.thread_cpu_s).collect();
        let mut wall: Vec<f64> = timed.iter().map(|(_, s)| s.wall_s).collect();
        out.push(Timed {
            scene,
            sf,
            engine: label,
            engine_name: engine,
            settings: settings(kv),
            build_s: median(&mut build_times),
            cpu_s: median(&mut cpu),
            wall_s: median(&mut wall),
            repeats,
            rays: rays.len(),
            hits: n_hits,
            structure_bytes: e.structure_bytes(),
            primitives: input.geometry.prims.len(),
            counters: TimedCounters {
                nodes_visited: counters.nodes_visited,
                box_tests: counters.box_tests,
                primitive_tests: counters.primitive_tests,
            },
        });
    }
    Ok(out)
}

/// Each of `overs` against `under` in pairs on the same rays (closest hit, the calling thread):
/// the two traced back to back, which goes first alternating, at least `min` pairs and on until
/// they span [`repeat::PAIR_SPAN_S`] (at most [`repeat::PAIR_CAP_FACTOR`] × `min`), after one
/// untimed pass of each. Per `over`, each pair's CPU time of `over` ÷ `under`'s: a speed-up of
/// `under` whose interval ([`rtbench_reports::interval::of_ratios`]) a burst of load on the
/// machine touches on both sides, unlike the quotient of two separate medians.
pub fn time_pairs(
    overs: &[&Timee],
    under: &Timee,
    input: &BuildInput,
    rays: &[Ray],
    min: u32,
    what: &str,
) -> Result<Vec<Vec<f64>>> {
    let build =
        |&&(_, engine, kv): &&Timee| workload::build(engine, input, settings(kv)).map(|(e, _)| e);
    let fast = build(&under)?;
    let mut hits = vec![Hit::MISS; rays.len()];
    let cpu = |e: &dyn rtbench_engines::Engine, hits: &mut [Hit]| {
        let mut c = Counters::default();
        span(Workers::Caller, || e.intersect(rays, hits, &mut c))
            .1
            .thread_cpu_s
    };
    cpu(fast.as_ref(), &mut hits);
    let mut out = Vec::with_capacity(overs.len());
    for over in overs {
        eprintln!("{what}: {} over {} in pairs …", under.0, over.0);
        let slow = build(over)?;
        cpu(slow.as_ref(), &mut hits);
        let ratios = repeat::pairs(min, u32::MAX, repeat::PAIR_SPAN_S, |i| -> Result<f64> {
            let (a, b) = if i % 2 == 0 {
                let a = cpu(slow.as_ref(), &mut hits);
                (a, cpu(fast.as_ref(), &mut hits))
            } else {
                let b = cpu(fast.as_ref(), &mut hits);
                (cpu(slow.as_ref(), &mut hits), b)
            };
            Ok(a / b.max(1e-12))
        })?;
        out.push(ratios);
    }
    Ok(out)
}

/// A counter per ray, or "-" when the engine counts nothing (Embree).
fn per_ray(count: u64, rays: f64) -> String {
    if count == 0 {
        "-".into()
    } else {
        format!("{:.2}", count as f64 / rays)
    }
}

pub const HEADER: [&str; 10] = [
    "scene",
    "engine",
    "CPU ms (wall)",
    "nodes/ray",
    "box tests/ray",
    "tri tests/ray",
    "hits",
    "x Embree",
    "build ms",
    "B/prim",
];

/// Table rows of timed engines, with the time ratio to Embree's on the same scene and rays.
pub fn rows(times: &[Timed]) -> Vec<Vec<String>> {
    times
        .iter()
        .map(|t| {
            // Embree's row of this scene: one table holds several scenes, and a ratio to another
            // scene's Embree time says nothing (tree10's Embree read 0.59 "x Embree" so).
            let embree = times
                .iter()
                .find(|e| {
                    e.engine == "embree" && e.scene == t.scene && e.sf == t.sf && e.rays == t.rays
                })
                .map(|e| e.cpu_s);
            let n = t.rays as f64;
            vec![
                format!("{}{}", t.scene, t.sf),
                t.engine.to_string(),
                format!("{:.1} ({:.1})", t.cpu_s * 1e3, t.wall_s * 1e3),
                per_ray(t.counters.nodes_visited, n),
                per_ray(t.counters.box_tests, n),
                per_ray(t.counters.primitive_tests, n),
                t.hits.to_string(),
                embree.map_or("-".into(), |e| format!("{:.2}", t.cpu_s / e)),
                format!("{:.0}", t.build_s * 1e3),
                format!("{:.1}", t.bytes_per_primitive()),
            ]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timed(scene: &'static str, engine: &'static str, cpu_s: f64) -> Timed {
        Timed {
            scene,
            sf: 4,
            engine,
            engine_name: engine,
            settings: Vec::new(),
            build_s: 0.0,
            cpu_s,
            wall_s: cpu_s,
            repeats: 1,
            rays: 100,
            hits: 0,
            structure_bytes: 0,
            primitives: 10,
            counters: TimedCounters {
                nodes_visited: 0,
                box_tests: 0,
                primitive_tests: 0,
            },
        }
    }

    #[test]
    fn each_scene_is_held_to_its_own_embree_time() {
        let t = [
            timed("gears", "embree", 2.0),
            timed("gears", "bvh8", 3.0),
            timed("tree", "embree", 1.0),
            timed("tree", "bvh8", 0.5),
            timed("balls", "bvh4", 1.0),
        ];
        let x: Vec<String> = rows(&t).iter().map(|r| r[7].clone()).collect();
        assert_eq!(x, ["1.00", "1.50", "1.00", "0.50", "-"]);
    }
}
