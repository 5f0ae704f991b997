//! The nightly (`rtbench nightly --suite FILE --db FILE.sqlite [--out DIR]`): runs a suite (each engine × scene
//! in its own child process, as `rtbench run` does), measures instruction counts under valgrind and
//! the criterion kernels if the suite asks, compares the night with the history's baseline for the
//! same machine fingerprint (`history/detect.rs`), writes the whole night to the history in one
//! transaction, and exits 1 only when a gated metric regressed, naming it.

pub mod count;
pub mod shard;
pub mod suite;
mod tools;

use crate::cli::NightlyArgs;
use crate::error::Result;
use crate::history::{dashboard, detect, Finding, Metric};
use crate::runs::plan::{self, Common, Job, ResultsDir};
use crate::shard::ShardSpec;
use rtbench_reports::{Environment, RunRecord};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::time::Instant;
use suite::Suite;

/// The machine's fingerprint: what must match for two nights' times to be comparable (CPU model
/// and flags, cores, memory, OS, rustc, Embree version). Not the commit, not the host name.
pub fn fingerprint(env: &Environment) -> String {
    let key = serde_json::json!([
        env.cpu_model,
        env.cpu_flags,
        env.cores_logical,
        env.cores_physical,
        env.memory_bytes,
        env.os,
        env.rustc,
        env.embree_version,
    ]);
    crate::output::hex(&Sha256::digest(key.to_string().as_bytes()))
}

/// The jobs of a suite, Embree first within each (scene, SF, threads).
pub fn jobs(s: &Suite) -> Vec<Job> {
    let mut out = Vec::new();
    for p in &s.scenes {
        for &sf in &s.sf {
            for &threads in &s.threads {
                for v in &s.variants {
                    out.push(Job {
                        engine: v.engine.clone(),
                        settings: v.settings.clone(),
                        program: p.name().to_string(),
                        sf,
                        tessellate: None,
                        threads,
                        file: None,
                    });
                }
            }
        }
    }
    for f in &s.files {
        for &threads in &s.threads {
            for v in &s.variants {
                out.push(Job {
                    engine: v.engine.clone(),
                    settings: v.settings.clone(),
                    program: f.label.clone(),
                    sf: 0,
                    tessellate: None,
                    threads,
                    file: Some(f.clone()),
                });
            }
        }
    }
    out
}

fn subject(r: &RunRecord) -> String {
    let label = rtbench_reports::engine_label(&r.engine, &r.settings);
    format!("{label} {}@{}", r.scene.name, r.threads)
}

fn metric(
    name: String,
    kind: &str,
    unit: &str,
    value: f64,
    gated: bool,
    samples: Vec<f64>,
) -> Metric {
    Metric {
        name,
        kind: kind.into(),
        unit: unit.into(),
        value,
        gated,
        samples,
    }
}

/// A night's metrics from its run records: trace CPU time and build time (every repeat; not
/// gated), trace CPU time over Embree's (one ratio per repeat), every exact counter, rays.
pub fn record_metrics(s: &Suite, records: &[RunRecord]) -> Vec<Metric> {
    let mut out = Vec::new();
    for r in records.iter().filter(|r| r.ok()) {
        let subj = subject(r);
        let tr = r.time_s.trace_for_compare();
        out.push(metric(
            format!("{subj}/trace_cpu_s"),
            "time",
            "s",
            tr.median,
            false,
            tr.samples.clone(),
        ));
        out.push(metric(
            format!("{subj}/build_s"),
            "time",
            "s",
            r.time_s.build.median,
            false,
            r.time_s.build.samples.clone(),
        ));
        if r.engine != "embree" {
            let ratios = match &r.paired_ratio {
                // Pairs timed back to back in one process: every pair of every round.
                Some(p) if !p.samples.is_empty() => p.samples.clone(),
                // Otherwise one ratio per round, engine round over Embree round.
                _ => round_ratios(records, r, &tr.samples),
            };
            if !ratios.is_empty() {
                out.push(metric(
                    format!("{subj}/time_ratio"),
                    "time_ratio",
                    "ratio",
                    detect::median(&ratios),
                    s.gates("time_ratio"),
                    ratios,
                ));
            }
        }
        let gate = s.gates("counters");
        out.push(metric(
            format!("{subj}/counter.rays_total"),
            "counter",
            "count",
            r.rays_total as f64,
            gate,
            vec![],
        ));
        for (k, v) in &r.counters {
            out.push(metric(
                format!("{subj}/counter.{k}"),
                "counter",
                "count",
                *v as f64,
                gate,
                vec![],
            ));
        }
    }
    out
}

/// The engine's trace CPU time in each round over Embree's in the same round.
fn round_ratios(records: &[RunRecord], r: &RunRecord, samples: &[f64]) -> Vec<f64> {
    let yard = records.iter().find(|y| {
        y.ok()
            && y.engine == "embree"
            && y.settings.is_empty()
            && y.scene.name == r.scene.name
            && y.threads == r.threads
    });
    let Some(y) = yard else { return vec![] };
    samples
        .iter()
        .zip(&y.time_s.trace_for_compare().samples)
        .filter(|(_, b)| **b > 0.0)
        .map(|(a, b)| a / b)
        .collect()
}

/// The median of each round of a time metric: a time ratio's samples come `paired` per round
/// (one per round without pairs); a criterion estimate is one round.
fn round_medians(s: &Suite, m: &Metric) -> Vec<f64> {
    if m.kind != "time_ratio" || m.samples.is_empty() {
        return vec![m.value];
    }
    m.samples
        .chunks(s.paired.max(1) as usize)
        .map(detect::median)
        .collect()
}

/// Tonight's metrics against the baseline nights (oldest first): the findings, without the
/// `ok` rows of [`compare_all`].
pub fn compare(
    s: &Suite,
    tonight: &[Metric],
    baseline: &[Vec<Metric>],
    suspects: &std::collections::BTreeSet<String>,
) -> Vec<Finding> {
    compare_all(s, tonight, baseline, suspects)
        .into_iter()
        .filter(|f| f.verdict != "ok")
        .collect()
}

/// Tonight's metrics against the baseline nights (oldest first): the findings, and a row of
/// verdict `ok` for every gated instruction count and time metric that was compared and did not
/// move, naming what it was compared against (the baseline value, the tolerance or interval, and
/// the change). Gated counters get no `ok` row: each is compared with the last night's exact
/// value, which [`gate_findings`] names once for all.
/// `suspects`: the time metrics the last baseline night found changed on their first night
/// (verdict `suspect`); with `confirm_nights = 2` a time regression is reported only when the
/// night before was a suspect for the same metric, and a suspect night leaves that metric's
/// baseline.
pub fn compare_all(
    s: &Suite,
    tonight: &[Metric],
    baseline: &[Vec<Metric>],
    suspects: &std::collections::BTreeSet<String>,
) -> Vec<Finding> {
    let mut out = Vec::new();
    let lookup: Vec<BTreeMap<&str, &Metric>> = baseline
        .iter()
        .map(|n| n.iter().map(|m| (m.name.as_str(), m)).collect())
        .collect();
    let time_like = |m: &Metric| m.kind == "time_ratio" || m.kind == "criterion";
    let gated_times = tonight
        .iter()
        .filter(|m| m.gated && time_like(m))
        .count()
        .max(1);
    let alpha = s.false_alarm_budget / gated_times as f64;
    let tol = s
        .instructions
        .as_ref()
        .map(|i| i.tolerance_pct)
        .unwrap_or(0.1);
    for m in tonight {
        let history: Vec<&Metric> = lookup
            .iter()
            .filter_map(|n| n.get(m.name.as_str()).copied())
            .collect();
        let verdict = |dir: i32| match (dir, m.gated) {
            (1, true) => "regression",
            (-1, true) => "improvement",
            _ => "change",
        };
        match m.kind.as_str() {
            "counter" => {
                let Some(last) = history.last() else { continue };
                if last.value != m.value {
                    let pct = (m.value - last.value) / last.value.abs().max(1.0) * 100.0;
                    out.push(Finding {
                        name: m.name.clone(),
                        verdict: if m.gated { "regression" } else { "change" }.into(),
                        baseline: Some(last.value),
                        value: Some(m.value),
                        change_pct: Some(pct),
                        message: format!(
                            "{}: exact counter changed {} → {} ({pct:+.4}%)",
                            m.name, last.value, m.value
                        ),
                    });
                }
            }
            "instructions" => {
                let Some(last) = history.last() else { continue };
                let pct = (m.value - last.value) / last.value.max(1.0) * 100.0;
                if pct.abs() > tol {
                    let dir = if pct > 0.0 { 1 } else { -1 };
                    out.push(Finding {
                        name: m.name.clone(),
                        verdict: verdict(dir).into(),
                        baseline: Some(last.value),
                        value: Some(m.value),
                        change_pct: Some(pct),
                        message: format!(
                            "{}: instructions {:.0} → {:.0} ({pct:+.3}%, tolerance ±{tol}%)",
                            m.name, last.value, m.value
                        ),
                    });
                } else if m.gated {
                    out.push(Finding {
                        name: m.name.clone(),
                        verdict: "ok".into(),
                        baseline: Some(last.value),
                        value: Some(m.value),
                        change_pct: Some(pct),
                        message: format!(
                            "the last baseline night's {:.0}, tolerance ±{tol}%",
                            last.value
                        ),
                    });
                }
            }
            "time_ratio" | "criterion" => {
                let mut nights: Vec<(f64, Vec<f64>)> = history
                    .iter()
                    .map(|h| (h.value, h.samples.clone()))
                    .collect();
                let confirming = suspects.contains(&m.name);
                // The suspect night leaves the baseline; its value joins tonight's in the
                // two-night test (detect::time_verdict_over).
                let previous = if confirming {
                    nights.pop().map(|n| n.0)
                } else {
                    None
                };
                // Start the baseline after the latest change point within it (if ≥ 3 nights remain).
                let values: Vec<f64> = nights.iter().map(|n| n.0).collect();
                if let Some(&cp) = detect::change_points(&values, 0.01, 3).last() {
                    if nights.len() - cp >= 3 {
                        nights.drain(..cp);
                    }
                }
                let rounds = round_medians(s, m);
                let two_night = m.gated && s.confirm_nights > 1;
                let verdict_at = |a: f64| {
                    detect::time_verdict_over(
                        m.value,
                        previous,
                        &m.samples,
                        &rounds,
                        &nights,
                        a,
                        s.min_change_pct,
                    )
                };
                let Some(mut v) = verdict_at(alpha) else {
                    continue;
                };
                let mut used_alpha = alpha;
                // On a first night a slowdown is a suspect already at √α: the next night's
                // two-night test at α decides (the pair passes both at most at rate α).
                if two_night && !confirming && v.direction == 0 {
                    if let Some(w) = verdict_at(detect::suspect_alpha(alpha)) {
                        if w.direction == 1 {
                            v = w;
                            used_alpha = detect::suspect_alpha(alpha);
                        }
                    }
                }
                // The prediction interval tonight's value (or, confirming a suspect, the two
                // nights' mean) had to leave: the centre times e^(±threshold · width).
                let k = nights.len() as f64;
                let width = v.spread
                    * if previous.is_some() {
                        (0.5 + 1.0 / k).sqrt()
                    } else {
                        (1.0 + 1.0 / k).sqrt()
                    };
                let (lo, hi) = (
                    v.baseline * (-v.threshold * width).exp(),
                    v.baseline * (v.threshold * width).exp(),
                );
                let against = format!(
                    "{:.4} over {} nights, interval [{lo:.4}, {hi:.4}] at α = {used_alpha:.2e}",
                    v.baseline,
                    nights.len()
                );
                if v.direction != 0 {
                    let first_night = v.direction == 1 && two_night && !confirming;
                    out.push(Finding {
                        name: m.name.clone(),
                        verdict: if first_night {
                            "suspect"
                        } else {
                            verdict(v.direction)
                        }
                        .into(),
                        baseline: Some(v.baseline),
                        value: Some(m.value),
                        change_pct: Some(v.change_pct),
                        // `table` reads the comparison back from between " against " and "; ".
                        message: format!(
                            "{}: {:.4}{} against {against}; {:+.2}%, {:.1} prediction widths, threshold {:.1}; rank test p = {:.3}; every round {:+.2}% or more",
                            m.name,
                            m.value,
                            match previous {
                                Some(p) => format!(" (and {p:.4} the night before)"),
                                None => String::new(),
                            },
                            v.change_pct,
                            v.score,
                            v.threshold,
                            v.mw_p,
                            v.weakest_round_pct
                        ),
                    });
                    if let (true, Some(f)) = (first_night, out.last_mut()) {
                        f.message
                            .push_str(" — first night: a regression if the next night confirms it");
                    }
                    if let (true, Some(f)) = (confirming && v.direction == 1, out.last_mut()) {
                        f.message
                            .push_str(" — confirmed: the night before was a suspect");
                    }
                } else if m.gated {
                    out.push(Finding {
                        name: m.name.clone(),
                        verdict: "ok".into(),
                        baseline: Some(v.baseline),
                        value: Some(m.value),
                        change_pct: Some(v.change_pct),
                        message: format!(
                            "{against}{}",
                            if previous.is_some() {
                                " (the mean with the suspect night before)"
                            } else {
                                ""
                            }
                        ),
                    });
                }
            }
            _ => {}
        }
    }
    out
}

/// Baseline nights of this machine a gate needs before it can flag anything: the last night's
/// value for counters and instruction counts; three nights' spread for time metrics
/// ([`detect::time_verdict_over`]).
pub fn gate_needs(gate: &str) -> usize {
    match gate {
        "time_ratio" | "criterion" => 3,
        _ => 1,
    }
}

/// The kind of metric a gate covers.
fn gate_kind(gate: &str) -> &str {
    match gate {
        "counters" => "counter",
        g => g,
    }
}

/// One row of verdict `gate` per gate of the suite's list: whether it was active tonight, since
/// which night, and what its metrics were compared against. `earlier`: the ids of this machine's
/// earlier nights of the suite, oldest first; `window`: how many of them were tonight's baseline.
/// The row's `baseline` is `window` and its `value` the baseline nights the gate needs.
pub fn gate_findings(
    s: &Suite,
    tonight: &[Metric],
    earlier: &[i64],
    window: usize,
) -> Vec<Finding> {
    let gated_times = tonight
        .iter()
        .filter(|m| m.gated && (m.kind == "time_ratio" || m.kind == "criterion"))
        .count()
        .max(1);
    let alpha = s.false_alarm_budget / gated_times as f64;
    let mut out = Vec::new();
    for g in suite::GATES {
        let n = tonight.iter().filter(|m| m.kind == gate_kind(g)).count();
        let needs = gate_needs(g);
        let message = if !s.gates(g) {
            if n == 0 {
                continue;
            }
            format!("{g}: not gated by this suite ({n} metric(s) stored and plotted only)")
        } else if window < needs {
            format!(
                "{g}: not active yet: {window} of the {needs} baseline night(s) of this machine it \
                 needs; active from this machine's night {} of the suite ({} more)",
                needs + 1,
                needs - window
            )
        } else {
            let since = match earlier.get(needs) {
                Some(id) => format!("since night {id}"),
                None => "since this night".to_string(),
            };
            let last = earlier
                .last()
                .map(|id| format!("night {id}"))
                .unwrap_or_default();
            let against = match g {
                "counters" => format!("each against {last}'s exact value"),
                "instructions" => format!(
                    "each against {last}'s count, tolerance ±{}%",
                    s.instructions
                        .as_ref()
                        .map(|i| i.tolerance_pct)
                        .unwrap_or(0.1)
                ),
                _ => format!(
                    "each against the geometric mean of its {window} baseline nights (from the \
                     latest change point), outside a prediction interval at α = {alpha:.2e} \
                     (a budget of {} shared by {gated_times} gated time metrics) and by {}% or \
                     more{}",
                    s.false_alarm_budget,
                    s.min_change_pct,
                    if s.confirm_nights > 1 {
                        "; a slowdown is a suspect on its first night and a regression when the \
                         next night confirms it"
                    } else {
                        ""
                    }
                ),
            };
            format!("{g}: active {since}: {n} metric(s), {against}")
        };
        out.push(Finding {
            name: format!("gate/{g}"),
            verdict: "gate".into(),
            baseline: Some(window as f64),
            value: Some(needs as f64),
            change_pct: None,
            message,
        });
    }
    out
}

/// The gates' states in a few words (`history replay`): `counters, instructions active;
/// time_ratio 2/3 nights`.
pub fn gates_clause(findings: &[Finding]) -> String {
    let mut active = Vec::new();
    let mut waiting = Vec::new();
    for f in findings.iter().filter(|f| f.verdict == "gate") {
        let g = f.name.trim_start_matches("gate/");
        if f.message.contains(": active ") {
            active.push(g.to_string());
        } else if f.message.contains(": not active yet") {
            waiting.push(format!(
                "{g} {}/{} nights",
                f.baseline.unwrap_or(0.0),
                f.value.unwrap_or(0.0)
            ));
        }
    }
    let mut parts = Vec::new();
    if !active.is_empty() {
        parts.push(format!("{} active", active.join(", ")));
    }
    if !waiting.is_empty() {
        parts.push(format!("waiting: {}", waiting.join(", ")));
    }
    if parts.is_empty() {
        "no gate".into()
    } else {
        parts.join("; ")
    }
}

pub use crate::output::fmt_secs;

/// The metrics a night found changed for the first time (verdict `suspect`).
pub fn suspects_of(findings: &[Finding]) -> std::collections::BTreeSet<String> {
    findings
        .iter()
        .filter(|f| f.verdict == "suspect")
        .map(|f| f.name.clone())
        .collect()
}

pub fn is_bad(f: &Finding) -> bool {
    f.verdict == "regression" || f.verdict == "failed"
}

/// The Markdown summary for a CI job page: regressions first, then improvements, then the table.
pub fn summary_markdown(
    suite: &str,
    commit: &str,
    wall_s: f64,
    baseline_nights: Option<usize>,
    metrics: &[Metric],
    findings: &[Finding],
) -> String {
    let mut s = String::new();
    let gated = metrics.iter().filter(|m| m.gated).count();
    let bad: Vec<&Finding> = findings.iter().filter(|f| is_bad(f)).collect();
    s.push_str(&format!(
        "# Nightly `{suite}` at `{}`: {}\n\n{} metrics ({gated} gated), {}, {}.\n\n",
        crate::output::head(commit, 12),
        if bad.is_empty() {
            "no regression".to_string()
        } else {
            format!("{} regression(s)", bad.len())
        },
        metrics.len(),
        match baseline_nights {
            Some(n) => format!("{n} baseline nights of this machine"),
            None => "baseline nights not recorded with this night".to_string(),
        },
        fmt_secs(wall_s)
    ));
    s.push_str("## Gates\n\n");
    let gates: Vec<&Finding> = findings.iter().filter(|f| f.verdict == "gate").collect();
    if gates.is_empty() {
        s.push_str("Not recorded with this night.\n");
    }
    for f in gates {
        s.push_str(&format!("- {}\n", f.message));
    }
    s.push_str("\n## Regressions\n\n");
    if bad.is_empty() {
        s.push_str("None.\n");
    }
    for f in &bad {
        s.push_str(&format!("- **{}** {}\n", f.verdict, f.message));
    }
    s.push_str("\n## Improvements\n\n");
    let good: Vec<&Finding> = findings
        .iter()
        .filter(|f| f.verdict == "improvement")
        .collect();
    if good.is_empty() {
        s.push_str("None.\n");
    }
    for f in good {
        s.push_str(&format!("- {}\n", f.message));
    }
    let watch: Vec<&Finding> = findings.iter().filter(|f| f.verdict == "suspect").collect();
    if !watch.is_empty() {
        s.push_str("\n## Watch: time changes on their first night\n\n");
        for f in watch {
            s.push_str(&format!("- {}\n", f.message));
        }
    }
    let other: Vec<&Finding> = findings.iter().filter(|f| f.verdict == "change").collect();
    if !other.is_empty() {
        s.push_str("\n## Ungated changes\n\n");
        for f in other {
            s.push_str(&format!("- {}\n", f.message));
        }
    }
    s.push_str("\n## Table\n\n| metric | tonight | compared against | change | verdict |\n|---|---:|---|---:|---|\n");
    let by_name: BTreeMap<&str, &Finding> = findings.iter().map(|f| (f.name.as_str(), f)).collect();
    let counters = metrics.iter().filter(|m| m.kind == "counter").count();
    for m in metrics.iter().filter(|m| m.gated && m.kind != "counter") {
        let f = by_name.get(m.name.as_str());
        let against = match f {
            Some(f) if f.verdict == "ok" => f.message.clone(),
            // A flagged time metric's message names its comparison between " against " and "; ".
            Some(f) => match f
                .message
                .split_once(" against ")
                .and_then(|(_, rest)| rest.split_once("; "))
            {
                Some((against, _)) => against.to_string(),
                None => f
                    .baseline
                    .map(|b| format!("{} (above)", dashboard::fmt_value(b)))
                    .unwrap_or_default(),
            },
            None => "not compared (see Gates)".to_string(),
        };
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} |\n",
            m.name,
            dashboard::fmt_value(m.value),
            against,
            f.and_then(|f| f.change_pct)
                .map(|c| format!("{c:+.3}%"))
                .unwrap_or_default(),
            f.map(|f| f.verdict.as_str()).unwrap_or("not compared"),
        ));
    }
    let changed = findings
        .iter()
        .filter(|f| f.name.contains("/counter."))
        .count();
    s.push_str(&format!(
        "\n{counters} exact counters, {changed} changed.\n"
    ));
    s
}

/// What a night (or a shard of one) measured, before it is compared and recorded.
pub struct Measured {
    pub env: Environment,
    pub fingerprint: String,
    pub started_at: String,
    pub metrics: Vec<Metric>,
    pub findings: Vec<Finding>,
    /// Wall seconds of the measuring (the slowest shard's, for merged shards).
    pub wall_s: f64,
}

/// Runs the suite's jobs (those of `spec`'s shard only, when given), its instruction counts and
/// its criterion benchmarks (shard 1 only), writing the runs into `out` as they finish.
pub fn measure(
    suite: &Suite,
    a: &NightlyArgs,
    spec: Option<ShardSpec>,
    out: Option<&std::path::Path>,
) -> Result<Measured> {
    let start = Instant::now();
    let env = crate::measure::environment::capture();
    let fp = fingerprint(&env);
    let started_at = crate::measure::environment::now_utc();
    let mut results = match out {
        Some(d) => Some(ResultsDir::open(d, false)?),
        None => None,
    };
    let mut jobs = jobs(suite);
    if let Some(spec) = spec {
        jobs = spec.select(&jobs, crate::runs::plan::run_group);
    }
    // Rounds: every job once per round, one timed repeat each, so that an engine's i-th sample
    // and Embree's i-th sample are minutes apart at most and a burst of load on a shared machine
    // touches one sample of many metrics rather than every sample of one.
    let common = Common {
        repeats: 1,
        rounds: 1,
        max_rounds: 1,
        target_ci_pct: crate::runs::rounds::DEFAULT_TARGET_CI_PCT,
        size: suite.size,
        check: false,
        paired: suite.paired,
        paired_threads: 0,
        // A fixed number of pairs a round: each round's median is taken over `paired` samples.
        pairs_exact: true,
        pair_span_s: crate::measure::repeat::PAIR_SPAN_S,
        max_seconds: suite.max_seconds,
        max_memory: None,
    };
    eprintln!(
        "nightly: suite '{}': {} runs × {} rounds, machine {}{}",
        suite.name,
        jobs.len(),
        suite.repeats,
        crate::output::head(&fp, 12),
        spec.map(|s| format!(", shard {}/{}", s.k, s.n))
            .unwrap_or_default()
    );
    let mut progress = plan::Progress::new(jobs.len() * suite.repeats as usize);
    let mut merged: Vec<Option<RunRecord>> = vec![None; jobs.len()];
    for _ in 0..suite.repeats {
        for (job, slot) in jobs.iter().zip(merged.iter_mut()) {
            if slot.as_ref().is_some_and(|r| !r.ok()) {
                continue;
            }
            let rec = plan::run_child(job, &common);
            progress.finish(job, &rec, false);
            *slot = Some(match slot.take() {
                Some(prev) => crate::runs::rounds::absorb(prev, rec),
                None => rec,
            });
        }
    }
    let records: Vec<RunRecord> = merged.into_iter().flatten().collect();
    if let Some(r) = results.as_mut() {
        for rec in &records {
            r.put(rec.clone())?;
        }
    }
    let mut metrics = record_metrics(suite, &records);
    let mut findings: Vec<Finding> = records
        .iter()
        .filter(|r| !r.ok())
        .map(|r| Finding {
            name: r.key.clone(),
            verdict: "failed".into(),
            baseline: None,
            value: None,
            change_pct: None,
            message: format!(
                "{}: run failed: {}",
                r.key,
                r.reason.as_deref().unwrap_or("")
            ),
        })
        .collect();
    let scratch = match out {
        Some(d) => d.to_path_buf(),
        None => std::env::temp_dir(),
    };
    if let Some(ins) = &suite.instructions {
        let t = Instant::now();
        for v in &ins.variants {
            for (i, &p) in ins.scenes.iter().enumerate() {
                // Shards split the instruction counts by scene, as they split the runs.
                if spec.is_some_and(|s| !s.owns_group(i)) {
                    continue;
                }
                let subj = format!("{} {}{}", v.label(), p.name(), ins.sf);
                match tools::instructions(v, p, ins.sf, ins.size, &scratch) {
                    Ok((ir, wall)) => {
                        eprintln!(
                            "nightly: instructions {subj}: {ir} ({wall:.1} s under valgrind)"
                        );
                        metrics.push(metric(
                            format!("{subj}/instructions"),
                            "instructions",
                            "Ir",
                            ir as f64,
                            suite.gates("instructions"),
                            vec![],
                        ));
                        metrics.push(metric(
                            format!("{subj}/valgrind_s"),
                            "time",
                            "s",
                            wall,
                            false,
                            vec![wall],
                        ));
                    }
                    Err(e) => findings.push(Finding {
                        name: format!("{subj}/instructions"),
                        verdict: "failed".into(),
                        baseline: None,
                        value: None,
                        change_pct: None,
                        message: format!("{subj}: {e}"),
                    }),
                }
            }
        }
        eprintln!(
            "nightly: instruction counts took {}",
            fmt_secs(t.elapsed().as_secs_f64())
        );
    }
    let criterion_here = spec.is_none_or(|s| s.k == 1);
    if let Some(c) = suite
        .criterion
        .as_ref()
        .filter(|_| !a.skip_criterion && criterion_here)
    {
        let home = scratch.join(format!("criterion-{}", std::process::id()));
        match tools::criterion(c, &home, suite.gates("criterion")) {
            Ok((m, wall)) => {
                eprintln!(
                    "nightly: criterion: {} benchmarks in {}",
                    m.len(),
                    fmt_secs(wall)
                );
                metrics.extend(m);
            }
            Err(e) => findings.push(Finding {
                name: "criterion".into(),
                verdict: "failed".into(),
                baseline: None,
                value: None,
                change_pct: None,
                message: e,
            }),
        }
        if out.is_none() {
            let _ = std::fs::remove_dir_all(&home);
        }
    }
    Ok(Measured {
        env,
        fingerprint: fp,
        started_at,
        metrics,
        findings,
        wall_s: start.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ratio(value: f64) -> Metric {
        Metric {
            name: "grid tetra3@1/time_ratio".into(),
            kind: "time_ratio".into(),
            unit: "ratio".into(),
            value,
            gated: true,
            samples: vec![value * 0.999, value, value * 1.001],
        }
    }

    #[test]
    fn a_change_too_small_for_one_night_is_caught_by_two() {
        let text = |confirm: u32| {
            format!(
                "engines = [\"embree\", \"grid\"]\nscenes = [\"tetra\"]\nsf = [3]\n\
                 gate = [\"time_ratio\"]\nconfirm_nights = {confirm}\nfalse_alarm_budget = 0.0015\n"
            )
        };
        let two = suite::parse("s.toml", &text(2)).unwrap();
        let one = suite::parse("s.toml", &text(1)).unwrap();
        let baseline: Vec<Vec<Metric>> = [1.0, 1.02, 0.98, 1.01, 0.99, 1.02, 0.98, 1.0, 1.01, 0.99]
            .iter()
            .map(|&v| vec![ratio(v)])
            .collect();
        let none = Default::default();
        let slow = [ratio(1.055)];
        // One night alone: inside α's prediction interval (no finding with one-night rules) …
        assert!(compare(&one, &slow, &baseline, &none).is_empty());
        // … but past √α's: a suspect.
        let f = compare(&two, &slow, &baseline, &none);
        assert_eq!(f.len(), 1, "{f:?}");
        assert_eq!(f[0].verdict, "suspect", "{}", f[0].message);
        // Two such nights: their mean is past α's interval for a mean of two.
        let mut with_suspect = baseline.clone();
        with_suspect.push(vec![ratio(1.055)]);
        let f2 = compare(&two, &slow, &with_suspect, &suspects_of(&f));
        assert_eq!(f2.len(), 1, "{f2:?}");
        assert_eq!(f2[0].verdict, "regression", "{}", f2[0].message);
        assert!(
            f2[0].message.contains("the night before"),
            "{}",
            f2[0].message
        );
        // A suspect night followed by an ordinary one is nothing.
        assert!(compare(&two, &[ratio(1.0)], &with_suspect, &suspects_of(&f)).is_empty());
    }

    #[test]
    fn a_time_change_is_a_suspect_first_and_a_regression_when_the_next_night_confirms() {
        let text = |confirm: u32| {
            format!(
                "engines = [\"embree\", \"grid\"]\nscenes = [\"tetra\"]\nsf = [3]\n\
                 gate = [\"time_ratio\"]\nconfirm_nights = {confirm}\n"
            )
        };
        let two = suite::parse("s.toml", &text(2)).unwrap();
        let one = suite::parse("s.toml", &text(1)).unwrap();
        let baseline: Vec<Vec<Metric>> = [1.0, 1.004, 0.997, 1.002, 0.999, 1.001]
            .iter()
            .map(|&v| vec![ratio(v)])
            .collect();
        let none = Default::default();
        let slow = [ratio(1.10)];
        let f = compare(&two, &slow, &baseline, &none);
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].verdict, "suspect", "{}", f[0].message);
        assert!(!is_bad(&f[0]));
        assert_eq!(
            compare(&one, &slow, &baseline, &none)[0].verdict,
            "regression"
        );
        // The next night: the suspect night (the last of the baseline) is left out of the
        // baseline, and the change confirmed is a regression.
        let mut with_suspect = baseline.clone();
        with_suspect.push(vec![ratio(1.10)]);
        let f = compare(&two, &slow, &with_suspect, &suspects_of(&f));
        assert_eq!(f[0].verdict, "regression", "{}", f[0].message);
        assert!(f[0].message.contains("confirmed"));
        // A suspect the next night does not confirm is nothing.
        let f = compare(
            &two,
            &[ratio(1.0)],
            &with_suspect,
            &["grid tetra3@1/time_ratio".to_string()].into(),
        );
        assert!(f.is_empty(), "{f:?}");
        assert!(suite::parse("s.toml", &text(3))
            .err()
            .unwrap()
            .to_string()
            .contains("confirm_nights = 3: 1 or 2"));
    }
}
