//! `rtbench run`, `sweep`, `run-one`, `report`, `compare` (docs/concepts.md).

use crate::cli::{CompareArgs, PlanArgs, ReportArgs, RunArgs, RunOneArgs, SweepArgs};
use crate::error::{input, Failure, Result};
use crate::measure::threads::Threads;
use crate::output::print_json;
use crate::runs::one::{run_one, OneSpec};
use crate::runs::plan::{self, plan_text, run_group, Common, Job, PlanScene, ResultsDir};
use crate::shard::{group_count, Manifest, ShardSpec};
use crate::source::Source;
use crate::workload;

/// `4`, `4,5,6` or `4..8`.
pub fn parse_sf_list(s: &str) -> Result<Vec<u32>> {
    let bad = || input(format!("--sf '{s}': expected N, N,M,… or A..B"));
    let mut out = Vec::new();
    for part in s.split(',') {
        let part = part.trim();
        if let Some((a, b)) = part.split_once("..") {
            let (a, b): (u32, u32) = (
                a.trim().parse().map_err(|_| bad())?,
                b.trim().parse().map_err(|_| bad())?,
            );
            if a > b {
                return Err(bad());
            }
            out.extend(a..=b);
        } else {
            out.push(part.parse().map_err(|_| bad())?);
        }
    }
    if out.contains(&0) {
        return Err(input("--sf: size factor must be at least 1, got 0"));
    }
    Ok(out)
}

/// `1234`, `64M`, `2GiB` … → bytes.
pub fn parse_bytes(s: &str) -> Result<u64> {
    let t = s.trim();
    let split = t
        .find(|c: char| !c.is_ascii_digit() && c != '.')
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let n: f64 = num.parse().map_err(|_| {
        input(format!(
            "--max-memory '{s}': expected bytes, e.g. 512M or 2GiB"
        ))
    })?;
    let mult = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1.0,
        "k" | "kb" => 1e3,
        "m" | "mb" => 1e6,
        "g" | "gb" => 1e9,
        "kib" => 1024.0,
        "mib" => 1048576.0,
        "gib" => 1073741824.0,
        _ => return Err(input(format!("--max-memory '{s}': unknown unit '{unit}'"))),
    };
    Ok((n * mult) as u64)
}

/// An engine's name and its `key=value` settings.
type EngineSettings = (String, Vec<(String, String)>);

/// Engines of a plan with their settings, checked against the registry. An entry of `--engines`
/// may carry its own settings after colons, `bvh4:simd=off:leaf=1`, so variants of one engine run
/// side by side; `--set engine.key=value` applies to every entry of that engine.
fn plan_engines(p: &PlanArgs) -> Result<Vec<EngineSettings>> {
    let mut out: Vec<EngineSettings> = Vec::new();
    for planned in crate::select::engines(Some(&p.engines), "--engines")? {
        if out.contains(&planned) {
            return Err(input(format!("--engines: '{}' given twice", planned.0)));
        }
        out.push(planned);
    }
    for s in &p.set {
        let (lhs, v) = s
            .split_once('=')
            .ok_or_else(|| input(format!("--set '{s}': expected engine.key=value")))?;
        let (e, k) = lhs
            .split_once('.')
            .ok_or_else(|| input(format!("--set '{s}': expected engine.key=value")))?;
        let mut found = false;
        for slot in out.iter_mut().filter(|(n, _)| n == e) {
            slot.1.push((k.to_string(), v.to_string()));
            found = true;
        }
        if !found {
            return Err(input(format!(
                "--set '{s}': engine '{e}' is not in --engines"
            )));
        }
    }
    Ok(out)
}

/// `--shard K/N`, if given.
fn shard_of(p: &PlanArgs) -> Result<Option<ShardSpec>> {
    p.shard
        .as_deref()
        .map(|s| ShardSpec::parse(s, "--shard"))
        .transpose()
}

/// `--scenes`: SPD programs and scene files (OBJ, PLY, glTF, NFF), or `standard`.
pub fn plan_scenes(p: &PlanArgs) -> Result<Vec<PlanScene>> {
    PlanScene::parse_list(&p.scenes)
}

fn plan_threads(p: &PlanArgs) -> Result<Vec<Option<usize>>> {
    p.threads
        .split(',')
        .map(|t| match t.parse::<Threads>() {
            Err(_) => Err(input(format!(
                "--threads '{}': expected {}, comma-separated",
                p.threads,
                Threads::FORMS
            ))),
            Ok(Threads::Count(n)) if n > crate::measure::threads::thread_limit() => {
                Err(input(format!(
                    "--threads {n}: more than the {} this machine runs at once",
                    crate::measure::threads::thread_limit()
                )))
            }
            Ok(t) => Ok(t.count()),
        })
        .collect()
}

/// Rounds of `run` when --rounds is not given: with the default three repeats, one repeat a
/// round, each job's samples from three processes.
pub const DEFAULT_ROUNDS: u32 = 3;

fn common(p: &PlanArgs) -> Result<Common> {
    workload::check_size(p.size)?;
    if p.repeat == 0 {
        return Err(input("--repeat must be at least 1"));
    }
    if let Some(s) = p.max_seconds {
        if s.is_nan() || s <= 0.0 {
            return Err(input(format!("--max-seconds {s}: must be positive")));
        }
    }
    let rounds = p.rounds.unwrap_or(DEFAULT_ROUNDS);
    if rounds == 0 {
        return Err(input("--rounds must be at least 1"));
    }
    // The rounds every job runs: never more than its repeats.
    let base = rounds.min(p.repeat);
    let max_rounds = p
        .max_rounds
        .unwrap_or(crate::runs::rounds::DEFAULT_MAX_ROUNDS.max(base));
    if max_rounds < base || max_rounds > crate::runs::rounds::MAX_ROUNDS_LIMIT {
        return Err(input(format!(
            "--max-rounds {max_rounds}: must be from the rounds every job runs ({base}) to {}",
            crate::runs::rounds::MAX_ROUNDS_LIMIT
        )));
    }
    let target_ci_pct = p
        .target_ci
        .unwrap_or(crate::runs::rounds::DEFAULT_TARGET_CI_PCT);
    if !(target_ci_pct > 0.0 && target_ci_pct < 100.0) {
        return Err(input(format!(
            "--target-ci {target_ci_pct}: must be a percentage above 0 and below 100"
        )));
    }
    Ok(Common {
        repeats: p.repeat,
        rounds,
        max_rounds,
        target_ci_pct,
        size: p.size,
        check: !p.no_check,
        paired: p.paired,
        paired_threads: p.paired_threads,
        pairs_exact: false,
        pair_span_s: crate::measure::repeat::PAIR_SPAN_S,
        max_seconds: p.max_seconds,
        max_memory: p.max_memory.as_deref().map(parse_bytes).transpose()?,
    })
}

/// The jobs of `rtbench run` in plan order (scene by scene, Embree where listed), and what they share.
pub fn run_plan(a: &RunArgs) -> Result<(Vec<Job>, Common)> {
    let engines = plan_engines(&a.plan)?;
    let scenes = plan_scenes(&a.plan)?;
    let threads = plan_threads(&a.plan)?;
    let common = common(&a.plan)?;
    let sfs = a.sf.as_deref().map(parse_sf_list).transpose()?;
    let mut jobs = Vec::new();
    for scene in &scenes {
        let p = match scene {
            PlanScene::Program(p) => p,
            // A file is traced as it is: once, whatever --sf and --tessellate say of programs.
            PlanScene::File(f) => {
                for t in &threads {
                    for (e, s) in &engines {
                        jobs.push(Job {
                            engine: e.clone(),
                            settings: s.clone(),
                            program: f.label.clone(),
                            sf: 0,
                            tessellate: None,
                            threads: *t,
                            file: Some(f.clone()),
                        });
                    }
                }
                continue;
            }
        };
        for sf in sfs.clone().unwrap_or_else(|| vec![p.standard_sf()]) {
            let opts = rtbench_scenes::spd::Options {
                size_factor: sf,
                tessellate: a.tessellate,
                ..rtbench_scenes::spd::Options::standard(*p)
            };
            rtbench_scenes::spd::validate(*p, &opts)?;
            for t in &threads {
                for (e, s) in &engines {
                    jobs.push(Job {
                        engine: e.clone(),
                        settings: s.clone(),
                        program: p.name().into(),
                        sf,
                        tessellate: a.tessellate,
                        threads: *t,
                        file: None,
                    });
                }
            }
        }
    }
    Ok((jobs, common))
}

pub fn run(a: &RunArgs) -> Result<()> {
    let (mut jobs, common) = run_plan(a)?;
    let shard = shard_of(&a.plan)?;
    let manifest = match shard {
        Some(spec) => {
            let plan_jobs: Vec<String> = jobs.iter().map(Job::key).collect();
            let groups = group_count(&jobs, run_group);
            let mine = spec.select(&jobs, run_group);
            let m = Manifest::new(
                "run",
                spec,
                &plan_text("run", &common, &plan_jobs),
                plan_jobs,
                mine.iter().map(Job::key).collect(),
            );
            m.write(&a.plan.out)?;
            eprintln!(
                "run: shard {}/{}: {} of {} runs, {} of {groups} scene groups",
                spec.k,
                spec.n,
                mine.len(),
                jobs.len(),
                group_count(&mine, run_group)
            );
            jobs = mine;
            Some(m)
        }
        None => None,
    };
    let mut out = ResultsDir::open(&a.plan.out, a.plan.resume)?;
    let failures = plan::run(&jobs, &common, &mut out, a.plan.resume)?;
    if let Some(mut m) = manifest {
        m.finished_at = Some(crate::measure::environment::now_utc());
        m.write(&a.plan.out)?;
    }
    eprintln!(
        "{} runs, {failures} failed: {}",
        jobs.len(),
        a.plan.out.join("results.jsonl").display()
    );
    if failures > 0 {
        return Err(Failure::Check(format!(
            "{failures} of {} runs failed (see {})",
            jobs.len(),
            a.plan.out.join("results.jsonl").display()
        )));
    }
    Ok(())
}

pub fn sweep(a: &SweepArgs) -> Result<()> {
    let engines = plan_engines(&a.plan)?;
    let programs = plan_scenes(&a.plan)?;
    let threads = plan_threads(&a.plan)?;
    if threads.len() != 1 {
        return Err(input("sweep: give one --threads value"));
    }
    if a.plan.rounds.is_some_and(|r| r != 1) || a.plan.max_rounds.is_some_and(|r| r != 1) {
        return Err(input(
            "sweep: --rounds and --max-rounds are for run (a sweep runs each size factor once, in one process)",
        ));
    }
    let common = Common {
        rounds: 1,
        max_rounds: 1,
        ..common(&a.plan)?
    };
    if common.max_seconds.is_none() && common.max_memory.is_none() {
        return Err(input(
            "sweep: give --max-seconds or --max-memory (the limit that ends each scene's sweep)",
        ));
    }
    if a.sf_start == 0 || a.sf_start > a.sf_max {
        return Err(input(format!(
            "sweep: --sf-start {} must be from 1 to --sf-max {}",
            a.sf_start, a.sf_max
        )));
    }
    // A sweep's unit of work is (engine, scene): its SFs rise until the limit. Shards take whole
    // scenes, so the stop rule holds per scene.
    let units = |ps: &[PlanScene]| -> Vec<String> {
        ps.iter()
            .map(PlanScene::name)
            .flat_map(|p| {
                engines.iter().map(move |(e, s)| {
                    format!(
                        "{}/{p}",
                        rtbench_reports::engine_label(
                            e,
                            &s.iter()
                                .cloned()
                                .collect::<std::collections::BTreeMap<_, _>>()
                        )
                    )
                })
            })
            .collect()
    };
    let shard = shard_of(&a.plan)?;
    let mut programs = programs;
    let manifest = match shard {
        Some(spec) => {
            let plan_units = units(&programs);
            let mine = spec.select(&programs, PlanScene::name);
            let text = format!(
                "{}\nsf {}..{} threads {:?}",
                plan_text("sweep", &common, &plan_units),
                a.sf_start,
                a.sf_max,
                threads[0]
            );
            let m = Manifest::new("sweep", spec, &text, plan_units, units(&mine));
            m.write(&a.plan.out)?;
            eprintln!(
                "sweep: shard {}/{}: scenes {} of {}",
                spec.k,
                spec.n,
                if mine.is_empty() {
                    "none".to_string()
                } else {
                    mine.iter()
                        .map(PlanScene::name)
                        .collect::<Vec<_>>()
                        .join(",")
                },
                programs.len()
            );
            programs = mine;
            Some(m)
        }
        None => None,
    };
    let mut out = ResultsDir::open(&a.plan.out, a.plan.resume)?;
    let n = plan::sweep(
        &engines,
        &programs,
        a.sf_start,
        a.sf_max,
        threads[0],
        &common,
        &mut out,
        a.plan.resume,
    )?;
    if let Some(mut m) = manifest {
        m.finished_at = Some(crate::measure::environment::now_utc());
        m.write(&a.plan.out)?;
    }
    eprintln!(
        "sweep: {n} runs: {}",
        a.plan.out.join("results.jsonl").display()
    );
    Ok(())
}

pub fn run_one_cmd(a: &RunOneArgs) -> Result<()> {
    let spec = OneSpec {
        engine: a.engine.clone(),
        settings: workload::parse_settings(&a.set)?,
        source: Source::resolve(
            &a.scene.scene,
            a.scene.opts.sf,
            a.scene.opts.tessellate,
            a.scene.opts.hash,
        )?,
        threads: a.threads.count(),
        repeats: a.repeat,
        size: a.size,
        check: !a.no_check,
        paired: a.paired,
        paired_threads: a.paired_threads,
        pairs_exact: a.pairs_exact,
        pair_span_s: if a.pair_span.is_finite() {
            a.pair_span.max(0.0)
        } else {
            return Err(input(format!(
                "--pair-span {}: not a number of seconds",
                a.pair_span
            )));
        },
    };
    let rec = run_one(&spec)?;
    println!(
        "{}",
        serde_json::to_string(&rec).expect("record serialises")
    );
    Ok(())
}

pub fn report(a: &ReportArgs) -> Result<()> {
    let formats = a
        .format
        .split(',')
        .map(|f| {
            f.trim()
                .parse::<rtbench_reports::Format>()
                .map_err(|e| input(format!("--format: {e}")))
        })
        .collect::<Result<Vec<_>>>()?;
    if !a.dir.join("results.jsonl").is_file() {
        return Err(input(format!("{}: no results.jsonl here", a.dir.display())));
    }
    let summary =
        rtbench_reports::write_report(&a.dir, &formats).map_err(|e| input(e.to_string()))?;
    eprintln!(
        "report: {} files in {}",
        summary.files.len(),
        a.dir.display()
    );
    Ok(())
}

pub fn compare(a: &CompareArgs) -> Result<()> {
    for d in [&a.a, &a.b] {
        if !d.join("results.jsonl").is_file() {
            return Err(input(format!("{}: no results.jsonl here", d.display())));
        }
    }
    if a.threshold.is_nan() || a.threshold < 0.0 {
        return Err(input(format!(
            "--threshold {}: must be a percentage ≥ 0",
            a.threshold
        )));
    }
    let c = rtbench_reports::compare(&a.a, &a.b, a.threshold).map_err(|e| input(e.to_string()))?;
    if c.matched == 0 {
        return Err(input(format!(
            "{} and {}: no run of A is in B, nothing compared{}",
            a.a.display(),
            a.b.display(),
            changed_files(&a.a, &a.b)
        )));
    }
    let other_workload = c
        .notes
        .iter()
        .filter(|f| f.kind == rtbench_reports::FindingKind::DifferentWorkload)
        .count();
    if other_workload == c.matched {
        let f = &c
            .notes
            .iter()
            .find(|f| f.kind == rtbench_reports::FindingKind::DifferentWorkload);
        return Err(input(format!(
            "{} and {}: nothing compared, every matched run traced another workload ({})",
            a.a.display(),
            a.b.display(),
            f.map(|f| f.message.clone()).unwrap_or_default()
        )));
    }
    if a.json {
        print_json(&serde_json::to_value(&c).expect("comparison serialises"));
    } else {
        print!("{}", c.to_markdown());
    }
    if c.is_regression() {
        let names: Vec<String> = c.regressions.iter().map(|f| f.message.clone()).collect();
        return Err(Failure::Check(format!("regression: {}", names.join("; "))));
    }
    if c.missing_in_b() > 0 {
        return Err(Failure::Check(format!(
            "B lacks {} of A's runs (see the notes)",
            c.missing_in_b()
        )));
    }
    Ok(())
}

/// `; FILE changed (…)` for each scene file both sides ran whose content differs: a changed file
/// is another scene, so its runs are never matched.
fn changed_files(a: &std::path::Path, b: &std::path::Path) -> String {
    let files = |d: &std::path::Path| -> std::collections::BTreeMap<String, String> {
        rtbench_reports::read_results(d)
            .unwrap_or_default()
            .into_iter()
            .filter_map(|r| Some((r.scene.file?, r.scene.sha256?)))
            .collect()
    };
    let (fa, fb) = (files(a), files(b));
    fa.iter()
        .filter_map(|(f, ha)| {
            let hb = fb.get(f).filter(|hb| *hb != ha)?;
            Some(format!(
                "; {f} changed (content {} in A, {} in B): a changed file is another scene",
                crate::output::head(ha, crate::source::FILE_HASH_DIGITS),
                crate::output::head(hb, crate::source::FILE_HASH_DIGITS)
            ))
        })
        .collect()
}
