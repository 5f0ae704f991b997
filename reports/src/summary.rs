//! The one result type every report format is written from (as hyperfine exports one result several
//! ways): the environment, one [`Row`] per run that finished, and the runs that failed.

use crate::anchor::{Anchors, EMBREE};
use crate::interval::Interval;
use crate::results::{CheckResult, Environment, RunRecord, SceneInfo, Spread};
use crate::scaling::ThreadScaling;
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// What `write_report` made of a results directory; also written as `summary.json`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Summary {
    /// `None` when the directory has no `env.json`.
    pub environment: Option<Environment>,
    /// Runs read (after later lines with the same key replaced earlier ones).
    pub runs: usize,
    pub rows: Vec<Row>,
    pub failures: Vec<Failure>,
    /// Files written, relative to the results directory (`report.md`, `plots/time-vs-sf-balls.svg` …).
    pub files: Vec<String>,
}

/// One run that finished, with the figures the tables and plots show.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub key: String,
    pub engine: String,
    /// The engine with its settings: `grid[mailbox=off]`. One line of a plot, one colour.
    pub label: String,
    pub settings: BTreeMap<String, String>,
    pub scene: String,
    pub program: Option<String>,
    pub sf: Option<u32>,
    pub tessellate: Option<u32>,
    /// The scene without its SF (`balls`, `mount-jenkins`, `balls-tess3`): runs of one family at several
    /// SFs make one time-vs-SF plot.
    pub family: String,
    pub primitives: u64,
    pub threads: usize,
    pub repeats: u32,
    pub rays_total: u64,
    pub build_s: Spread,
    pub trace_s: Spread,
    pub mrays_per_s: f64,
    /// Trace time over Embree's on the same scene and threads, from the same results set.
    pub ratio_to_embree: Option<f64>,
    /// The same as the quotient of the geometric means of the two runs' repeats (trace CPU time
    /// when recorded), with its 95 % interval and the repeats behind it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ratio_interval: Option<Interval>,
    /// Trace CPU time over Embree's timed in pairs in the run's process (`run --paired N`), with
    /// the interval of the pairs' median ([`crate::interval::of_ratios`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub paired_ratio: Option<Spread>,
    pub structure_bytes: u64,
    pub peak_rss_bytes: u64,
    pub check: Option<CheckResult>,
    /// Speed-up over one thread timed in pairs in the run's process (`run --paired-threads N`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thread_scaling: Option<ThreadScaling>,
    /// The machine the run (and so its ratio to Embree) was measured on, in merged shard results.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    /// Rounds the run was spread over (`run --rounds`; 1 for one process): with two or more,
    /// its intervals are over the rounds, and `n` counts rounds.
    pub rounds: usize,
}

/// A run that did not finish, and why.
#[derive(Clone, Debug, Serialize)]
pub struct Failure {
    pub key: String,
    pub engine: String,
    pub scene: String,
    pub threads: usize,
    pub status: String,
    pub reason: String,
}

/// The first record that appears twice in `records` (same key, finished at the same moment):
/// a copied line, not a re-run, which [`latest_per_key`] would otherwise count once silently or
/// a merge twice.
pub fn duplicate(records: &[RunRecord]) -> Option<&RunRecord> {
    let mut seen = std::collections::BTreeSet::new();
    records
        .iter()
        .find(|r| !seen.insert((r.key.as_str(), r.finished_at.as_str())))
}

/// What a report or a comparison needs of a results file: at least one run, no record twice
/// ([`duplicate`]), and times that are times (finite and not negative; an ok run's trace took
/// some time, or every ratio to it divides by zero).
pub fn check_records(records: &[RunRecord], path: &str) -> Result<(), crate::error::ReportError> {
    let bad = |message: String| crate::error::ReportError::Invalid {
        path: path.to_string(),
        message,
    };
    if records.is_empty() {
        return Err(bad("holds no runs".into()));
    }
    if let Some(d) = duplicate(records) {
        return Err(bad(format!(
            "run {} appears twice (the same record)",
            d.key
        )));
    }
    for r in records.iter().filter(|r| r.status == "ok") {
        let t = &r.time_s;
        let all = [&t.build, &t.trace, &t.trace_cpu];
        let wrong = all.iter().any(|s| {
            [s.min, s.median, s.max]
                .iter()
                .chain(&s.samples)
                .any(|x| !(x.is_finite() && *x >= 0.0))
        });
        // Not above zero, or NaN.
        if wrong || t.trace.median.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return Err(bad(format!(
                "run {}: a time that is negative, zero or not a number",
                r.key
            )));
        }
    }
    Ok(())
}

/// One record per key: a later line replaces an earlier one (a re-run after `--resume`).
pub fn latest_per_key(records: Vec<RunRecord>) -> Vec<RunRecord> {
    let mut index: BTreeMap<String, usize> = BTreeMap::new();
    let mut out: Vec<RunRecord> = Vec::with_capacity(records.len());
    for r in records {
        match index.get(&r.key) {
            Some(&i) => out[i] = r,
            None => {
                index.insert(r.key.clone(), out.len());
                out.push(r);
            }
        }
    }
    out
}

/// The engine and its settings, as a plot legend names it.
pub fn label(r: &RunRecord) -> String {
    engine_label(&r.engine, &r.settings)
}

/// An engine with its settings, as every report names it: `bvh4` or `bvh4[leaf=1,simd=off]`.
pub fn engine_label<'a, K, V>(engine: &str, settings: impl IntoIterator<Item = (K, V)>) -> String
where
    K: std::fmt::Display + 'a,
    V: std::fmt::Display + 'a,
{
    let s: Vec<String> = settings
        .into_iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect();
    if s.is_empty() {
        engine.to_string()
    } else {
        format!("{engine}[{}]", s.join(","))
    }
}

/// The scene's name without its SF: `balls4` → `balls`, `mount6-jenkins` → `mount-jenkins`.
pub fn family(scene: &SceneInfo) -> String {
    if let (Some(p), Some(sf)) = (&scene.program, scene.sf) {
        if let Some(rest) = scene.name.strip_prefix(&format!("{p}{sf}")) {
            return format!("{p}{rest}");
        }
    }
    scene.name.clone()
}

impl Summary {
    /// Builds the summary of one results set: rows sorted by threads, scene (program, SF, tessellation),
    /// Embree first, then engine label.
    pub fn of(environment: Option<Environment>, records: Vec<RunRecord>) -> Summary {
        let records = latest_per_key(records);
        let anchors = Anchors::of(&records);
        let mut rows: Vec<Row> = records
            .iter()
            .filter(|r| r.ok())
            .map(|r| Row {
                key: r.key.clone(),
                engine: r.engine.clone(),
                label: label(r),
                settings: r.settings.clone(),
                scene: r.scene.name.clone(),
                program: r.scene.program.clone(),
                sf: r.scene.sf,
                tessellate: r.scene.tessellate,
                family: family(&r.scene),
                primitives: r.scene.primitives,
                threads: r.threads,
                repeats: r.repeats,
                rays_total: r.rays_total,
                build_s: r.time_s.build.clone(),
                trace_s: r.time_s.trace.clone(),
                mrays_per_s: r.mrays_per_s,
                ratio_to_embree: anchors.ratio(r),
                ratio_interval: r.ratio_to_embree.clone().or_else(|| {
                    let a = anchors.anchor(r).filter(|_| r.engine != EMBREE)?;
                    crate::interval::of_quotient(
                        &r.time_s.trace_for_compare().samples,
                        &a.time_s.trace_for_compare().samples,
                    )
                }),
                paired_ratio: r.paired_ratio.clone(),
                structure_bytes: r.structure_bytes,
                peak_rss_bytes: r.peak_rss_bytes,
                check: r.check.clone(),
                thread_scaling: r.thread_scaling.clone(),
                machine: r.machine.clone(),
                rounds: r.rounds.len().max(1),
            })
            .collect();
        rows.sort_by(|a, b| {
            (
                a.threads,
                &a.family,
                a.sf,
                a.tessellate,
                &a.scene,
                a.engine != EMBREE,
                &a.label,
            )
                .cmp(&(
                    b.threads,
                    &b.family,
                    b.sf,
                    b.tessellate,
                    &b.scene,
                    b.engine != EMBREE,
                    &b.label,
                ))
        });
        let failures = records
            .iter()
            .filter(|r| !r.ok())
            .map(|r| Failure {
                key: r.key.clone(),
                engine: r.engine.clone(),
                scene: r.scene.name.clone(),
                threads: r.threads,
                status: r.status.clone(),
                reason: r
                    .reason
                    .clone()
                    .unwrap_or_else(|| "no reason recorded".to_string()),
            })
            .collect();
        Summary {
            environment,
            runs: records.len(),
            rows,
            failures,
            files: Vec::new(),
        }
    }

    /// The thread counts the rows were measured with, ascending.
    pub fn thread_counts(&self) -> Vec<usize> {
        self.rows
            .iter()
            .map(|r| r.threads)
            .collect::<BTreeSet<_>>()
            .into_iter()
            .collect()
    }

    /// Every engine label, Embree first, then by name: the order of legends and colours.
    pub fn labels(&self) -> Vec<String> {
        let set: BTreeSet<(bool, &str)> = self
            .rows
            .iter()
            .map(|r| (r.engine != EMBREE, r.label.as_str()))
            .collect();
        set.into_iter().map(|(_, l)| l.to_string()).collect()
    }
}
