//! One measured run (`rtbench run-one`, the child process of `run` and `sweep`): generate the
//! scene, build and trace `repeats` times, cross-check against Embree, print one [`RunRecord`].
//! Running in its own process makes the peak RSS this run's alone, and a crash costs one run.

use crate::error::Result;
use crate::measure::repeat::Repeats;
use crate::measure::span::{Sample, Workers};
use crate::source::Source;
use crate::workload::{self, crosscheck, trace};
use rtbench_reports::{run_key, CheckResult, RunRecord, SceneInfo, Spread, ThreadScaling, Timings};
use std::collections::BTreeMap;
use std::time::Instant;

/// What to run.
#[derive(Clone, Debug)]
pub struct OneSpec {
    pub engine: String,
    pub settings: Vec<(String, String)>,
    pub source: Source,
    /// `None`: all cores.
    pub threads: Option<usize>,
    pub repeats: u32,
    pub size: u32,
    /// Cross-check against Embree (skipped for Embree itself, or when it is unavailable).
    pub check: bool,
    /// Pairs of this engine's and Embree's traces to time back to back (0: none).
    pub paired: u32,
    /// Pairs of this engine's traces at one thread and at `threads` to time back to back, for
    /// the speed-up over one thread (0: none; ignored at one thread).
    pub paired_threads: u32,
    /// Exactly `paired` (and `paired_threads`) pairs, not more for fast traces.
    pub pairs_exact: bool,
    /// The wall time fast traces' pairs span at least (a round's share of
    /// [`PAIR_SPAN_S`](crate::measure::repeat::PAIR_SPAN_S)).
    pub pair_span_s: f64,
}

/// The most pairs `--paired` takes: each pair traces the whole workload twice.
pub const MAX_PAIRS: u32 = 1000;

fn embree_available() -> bool {
    rtbench_engines::registry()
        .iter()
        .any(|e| e.name == "embree" && (e.available)().is_ok())
}

/// Trace CPU time of `engine` over Embree's, back to back in this process: `pairs` = (least, most)
/// pairs, more than the least for fast traces until they span
/// [`PAIR_SPAN_S`](crate::measure::repeat::PAIR_SPAN_S). Pair i
/// traces the engine first when i is even and Embree first when it is odd, so a drift in the
/// machine's speed within a pair cancels over two pairs.
fn paired_ratios(
    pool: &rayon::ThreadPool,
    scene: &rtbench_scenes::Scene,
    engine: &dyn rtbench_engines::Engine,
    yardstick: &dyn rtbench_engines::Engine,
    size: u32,
    (pairs, most): (u32, u32),
    span_s: f64,
) -> Vec<f64> {
    let time = |e: &dyn rtbench_engines::Engine| {
        pool.install(|| trace::render(scene, e, size, None))
            .trace_cpu_s
    };
    // Embree's first render in a process is slow (cold caches, first-touch page faults), as the
    // engine's was before its untimed render above.
    time(yardstick);
    let ratios = crate::measure::repeat::pairs(pairs, most, span_s, |i| {
        let (a, b) = if i % 2 == 0 {
            let a = time(engine);
            (a, time(yardstick))
        } else {
            let b = time(yardstick);
            (time(engine), b)
        };
        Ok::<_, std::convert::Infallible>(a / b.max(1e-12))
    });
    match ratios {
        Ok(r) => r,
        Err(never) => match never {},
    }
}

/// The same trace at one thread and on `pool`, back to back in this process, in pairs as
/// [`paired_ratios`] takes them:
/// (one-thread wall s, wall s on `pool`, one-thread pool CPU s, pool CPU s) per pair. Pair i
/// traces one thread first when i is even and `pool` first when it is odd, as
/// [`paired_ratios`] alternates. Every trace must give the image of the first: a speed-up of a
/// different answer would mean nothing.
fn paired_thread_times(
    pool: &rayon::ThreadPool,
    scene: &rtbench_scenes::Scene,
    engine: &dyn rtbench_engines::Engine,
    size: u32,
    (pairs, most): (u32, u32),
    span_s: f64,
) -> Result<Vec<(f64, f64, f64, f64)>> {
    let one = crate::measure::threads::pool(Some(1))?;
    let mut image: Option<Vec<u8>> = None;
    let mut time = |p: &rayon::ThreadPool| -> Result<(f64, f64)> {
        let r = p.install(|| trace::render(scene, engine, size, None));
        match &image {
            Some(first) if first.as_slice() != r.pixels() => Err(crate::error::input(format!(
                "--paired-threads: the image at {} thread(s) differs from the first trace's",
                p.current_num_threads()
            ))),
            Some(_) => Ok((r.trace_s, r.trace_cpu_s)),
            None => {
                image = Some(r.pixels().to_vec());
                Ok((r.trace_s, r.trace_cpu_s))
            }
        }
    };
    // The one-thread pool's first render is slow (its thread's buffers, first touch), as the
    // run's own pool was before its untimed render.
    time(&one)?;
    crate::measure::repeat::pairs(pairs, most, span_s, |i| {
        let ((w1, c1), (wn, cn)) = if i % 2 == 0 {
            let a = time(&one)?;
            (a, time(pool)?)
        } else {
            let b = time(pool)?;
            (time(&one)?, b)
        };
        Ok((w1, wn, c1, cn))
    })
}

/// Counters as a flat name → value map (common fields and the engine's own).
pub(crate) fn flatten_counters(c: &rtbench_engines::Counters) -> BTreeMap<String, u64> {
    let mut m = BTreeMap::new();
    if let Ok(serde_json::Value::Object(o)) = serde_json::to_value(c) {
        for (k, v) in o {
            match v {
                serde_json::Value::Number(n) => {
                    m.insert(k, n.as_u64().unwrap_or(0));
                }
                serde_json::Value::Object(extra) => {
                    for (k2, v2) in extra {
                        m.insert(k2, v2.as_u64().unwrap_or(0));
                    }
                }
                _ => {}
            }
        }
    }
    m
}

/// The engine with the regression `RTBENCH_PLANT` plants, if any (super::plant).
fn plant(
    engine: Box<dyn rtbench_engines::Engine>,
    spec: &OneSpec,
) -> Box<dyn rtbench_engines::Engine> {
    let program = match &spec.source {
        Source::Program(p, _) => Some(p.name()),
        Source::File(_) | Source::Room(_) => None,
    };
    match super::plant::from_env(&spec.engine, program) {
        Some(p) => Box::new(super::plant::Planted::new(engine, p)),
        None => engine,
    }
}

pub fn run_one(spec: &OneSpec) -> Result<RunRecord> {
    let start = Instant::now();
    workload::check_size(spec.size)?;
    if spec.paired > MAX_PAIRS {
        return Err(crate::error::input(format!(
            "--paired {}: at most {MAX_PAIRS} pairs",
            spec.paired
        )));
    }
    if spec.paired_threads > MAX_PAIRS {
        return Err(crate::error::input(format!(
            "--paired-threads {}: at most {MAX_PAIRS} pairs",
            spec.paired_threads
        )));
    }
    let pool = crate::measure::threads::pool(spec.threads)?;
    let prepared = workload::prepare(&spec.source)?;
    let scene = &prepared.input.scene;
    let mut last = None;
    // The one repeat policy: an untimed render first, then the timed repeats, each engine built
    // afresh and its trace measured by the render's span.
    let passes = Repeats::new(spec.repeats).run(Workers::Pool, |t| -> Result<_> {
        let (engine, build_s) =
            workload::build(&spec.engine, &prepared.input, spec.settings.clone())?;
        let engine = plant(engine, spec);
        let r = pool.install(|| trace::render(scene, engine.as_ref(), spec.size, None));
        if let Some(f) = engine.failure() {
            return Err(crate::error::input(f));
        }
        t.record(r.sample.clone());
        let phases = (prepared.prepare_s + build_s, r.intersect_s, r.shade_s);
        last = Some((engine, r));
        Ok(phases)
    })?;
    let samples: Vec<Sample> = passes.iter().map(|(_, s)| s.clone()).collect();
    let col = |f: fn(&(f64, f64, f64)) -> f64| passes.iter().map(|(p, _)| f(p)).collect::<Vec<_>>();
    let (build, is, sh) = (col(|p| p.0), col(|p| p.1), col(|p| p.2));
    let tr: Vec<f64> = samples.iter().map(|s| s.wall_s).collect();
    let cpu: Vec<f64> = samples.iter().map(|s| s.thread_cpu_s).collect();
    let (engine, render) = last.expect("at least one repeat");
    // Before the cross-check builds Embree too.
    let peak_rss_bytes = crate::measure::rss::peak_rss_bytes().unwrap_or(0);
    let wants_yardstick = (spec.check || spec.paired > 0) && spec.engine != "embree";
    let yardstick = if wants_yardstick && embree_available() {
        Some(workload::build("embree", &prepared.input, vec![])?.0)
    } else {
        None
    };
    // The most pairs a run takes: the least asked for when they must be exact.
    let most = |n: u32| if spec.pairs_exact { n } else { MAX_PAIRS };
    let paired_ratio = match (&yardstick, spec.paired) {
        (Some(y), n) if n > 0 => Some(Spread::of_ratios(&paired_ratios(
            &pool,
            scene,
            engine.as_ref(),
            y.as_ref(),
            spec.size,
            (n, most(n)),
            spec.pair_span_s,
        ))),
        _ => None,
    };
    let thread_scaling = if spec.paired_threads > 0 && pool.current_num_threads() > 1 {
        let pairs = paired_thread_times(
            &pool,
            scene,
            engine.as_ref(),
            spec.size,
            (spec.paired_threads, most(spec.paired_threads)),
            spec.pair_span_s,
        )?;
        Some(ThreadScaling::of(pool.current_num_threads(), &pairs))
    } else {
        None
    };
    let check = if let (true, Some(yardstick)) = (spec.check, &yardstick) {
        let c = pool.install(|| {
            crosscheck::cross_check(scene, engine.as_ref(), yardstick.as_ref(), spec.size)
        });
        Some(CheckResult {
            against: "embree".into(),
            rays: c.rays(),
            hit_agreement: c.agreement(),
            primitive_agreement: Some(c.primitive_agreement()),
            t_rel_err_median: c.t_rel_err.median,
            t_rel_err_p99: c.t_rel_err.p99,
            t_rel_err_max: c.t_rel_err.max,
            image_psnr_db: c.image_psnr_db,
        })
    } else {
        None
    };
    let trace = Spread::of(&tr);
    let settings: BTreeMap<String, String> = spec.settings.iter().cloned().collect();
    let threads = pool.current_num_threads();
    let (program, sf, tessellate) = match &spec.source {
        Source::Program(p, o) => (
            Some(p.name().to_string()),
            Some(o.size_factor),
            o.tessellate,
        ),
        Source::File(_) | Source::Room(_) => (None, None, None),
    };
    let pixels = render.pixels();
    let name = spec.source.run_label()?;
    use sha2::Digest;
    Ok(RunRecord {
        key: run_key(&spec.engine, &settings, &name, threads),
        status: "ok".into(),
        reason: None,
        engine: spec.engine.clone(),
        settings,
        scene: SceneInfo {
            name,
            program,
            sf,
            tessellate,
            objects: scene.objects.len() as u64,
            primitives: prepared.input.geometry.prims.len() as u64,
            file: match &spec.source {
                Source::File(p) => Some(p.display().to_string()),
                _ => None,
            },
            sha256: spec.source.file_sha256()?,
        },
        threads,
        repeats: spec.repeats.max(1),
        size: spec.size,
        rays: serde_json::to_value(&render.stats).ok(),
        rays_total: render.stats.total,
        mrays_per_s: render.stats.total as f64 / trace.median.max(1e-12) / 1e6,
        time_s: Timings {
            generate: prepared.generate_s,
            build: Spread::of(&build),
            trace,
            intersect: Spread::of(&is),
            shade: Spread::of(&sh),
            trace_cpu: Spread::of(&cpu),
        },
        structure_bytes: engine.structure_bytes(),
        peak_rss_bytes,
        counters: flatten_counters(&render.counters),
        build_stats: engine.build_stats(),
        check,
        paired_ratio,
        thread_scaling,
        image_sha256: Some(crate::output::hex(&sha2::Sha256::digest(pixels))),
        samples,
        ratio_to_embree: None,
        rounds: Vec::new(),
        wall_s: start.elapsed().as_secs_f64(),
        finished_at: crate::measure::environment::now_utc(),
        machine: None,
    })
}
