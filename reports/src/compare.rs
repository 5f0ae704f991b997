//! `compare`: did result set B regress against result set A?
//!
//! Runs are matched by key. Two signals, following the measurement rules (docs: ARCHITECTURE.md):
//! - exact counters (nodes visited, primitive tests …) are free of noise, so any change is a finding;
//! - times are compared as each engine's trace time over Embree's *within its own set*, so whatever slowed
//!   or sped up the whole machine between A and B cancels. The change of that ratio from A to B is judged
//!   on its 95 % interval ([`crate::interval`]): on the log scale, B's ratio minus A's, each the mean log
//!   of the engine's repeats minus the mean log of Embree's (or the median log of the paired ratios,
//!   [`crate::interval::LogMean::median_of`], where both sets timed pairs, `run --paired N`), with
//!   Welch–Satterthwaite degrees of freedom. Where both sets ran in rounds (`run --rounds R`), each
//!   side's figure is instead the mean of its rounds' figures, and its interval Student's t over
//!   the rounds ([`crate::rounds`]): a process's state and the minute it ran in then count as the
//!   noise they are. A regression
//!   needs the whole interval above +threshold, an improvement the whole interval below −threshold; a
//!   change whose estimate passes the threshold while its interval reaches back inside is reported as
//!   "too few samples to decide", and so is a run with fewer than two samples on a side. Sets of one
//!   process a run (`run --rounds 1`, `sweep`) decide no change of time either way: their
//!   intervals are of one process's samples, which cannot show the few percent by which two
//!   processes of one build differ (two such runs of one commit at 8² "regressed" by 11.9 %, interval
//!   [+8.9 %, +15 %]), so a change past the threshold is reported as undecided, with the rounds
//!   it needs. Embree's own times are the yardstick (ratio 1) and are not compared; its counters are;
//! - where both sets timed a run's speed-up over one thread in pairs (`run --paired-threads N`), the
//!   speed-up's change is judged the same way on its pairs (Embree's too: it measures how the harness
//!   splits the trace as much as Embree).

use crate::anchor::{Anchors, EMBREE};
use crate::interval::{self, LogMean};
use crate::number;
use crate::results::{read_environment, read_results, Environment, RunRecord};
use crate::rounds;
use crate::summary::latest_per_key;
use crate::ReportError;
use serde::Serialize;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;
use std::path::Path;

/// What kind of difference a finding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FindingKind {
    /// An exact counter changed.
    Counter,
    /// Trace time over Embree's moved past the tolerance.
    TimeRatio,
    /// Ok in A, failed in B.
    Failed,
    /// Failed in A, ok in B.
    Recovered,
    /// Failed in both.
    StillFailing,
    /// The key is in A only.
    OnlyInA,
    /// The key is in B only.
    OnlyInB,
    /// Times not compared: no Embree run beside this one in A or B.
    NoYardstick,
    /// Not compared: A and B traced other workloads under one key (another image size).
    DifferentWorkload,
    /// The speed-up over one thread (`run --paired-threads N`, in both sets) moved past the
    /// tolerance: a fall is a regression, a rise an improvement.
    ThreadSpeedup,
    /// A time ratio or speed-up whose change could not be decided: fewer than two samples on a
    /// side, an estimate past the threshold with an interval that reaches back inside it, or a
    /// change past the threshold where a side ran in one process.
    Undecided,
}

/// One difference between the two sets, about one run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    pub key: String,
    pub kind: FindingKind,
    /// The counter's name, `trace time / Embree`, or `status`.
    pub what: String,
    /// The value in A (a counter, a ratio, a status); null when absent.
    pub old: Value,
    /// The value in B.
    pub new: Value,
    /// (new − old) / old, in percent, where that means something.
    pub change_pct: Option<f64>,
    /// The change a time had to pass to count (the threshold), in percent.
    pub tolerance_pct: Option<f64>,
    /// The 95 % interval of `change_pct`, in percent, for times and speed-ups.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interval_pct: Option<[f64; 2]>,
    /// The samples behind a time or speed-up finding: A's and B's (repeats of the run and of
    /// Embree's run, or pairs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub samples: Option<[usize; 2]>,
    /// One line for people.
    pub message: String,
}

/// The result of comparing two result sets.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// The directories as given.
    pub a: String,
    pub b: String,
    /// The git commits the sets were measured at (from `env.json`), when recorded.
    pub a_commit: Option<String>,
    pub b_commit: Option<String>,
    /// What differs between the machines A and B were measured on (from their `env.json`): the
    /// CPU model, its flags, cores, memory, OS, Rust compiler, Embree. Ratios to Embree then
    /// measure the machines as well as the code (a host with AVX-512
    /// replaced an AVX2 one between two runs, and every ratio moved).
    pub machine_differences: Vec<String>,
    pub threshold_pct: f64,
    /// Keys present in both sets.
    pub matched: usize,
    /// Ratios to Embree compared.
    pub times_compared: usize,
    /// Ratios and speed-ups whose change could not be decided (see [`FindingKind::Undecided`]).
    pub undecided: usize,
    /// Counter values compared.
    pub counters_compared: usize,
    pub regressions: Vec<Finding>,
    pub improvements: Vec<Finding>,
    pub notes: Vec<Finding>,
}

impl Comparison {
    /// True when B regressed: `rtbench compare` exits 1.
    pub fn is_regression(&self) -> bool {
        !self.regressions.is_empty()
    }

    /// Runs of A that B lacks: a set that lost runs is no clean bill (`rtbench compare` exits 1).
    pub fn missing_in_b(&self) -> usize {
        self.notes
            .iter()
            .filter(|f| f.kind == FindingKind::OnlyInA)
            .count()
    }

    /// The comparison as Markdown: a verdict, then regressions, improvements and notes as tables.
    pub fn to_markdown(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "# rtbench compare\n");
        let commit = |c: &Option<String>| {
            c.as_ref()
                .map(|c| format!(" (commit {c})"))
                .unwrap_or_default()
        };
        let _ = writeln!(s, "- **A**: `{}`{}", self.a, commit(&self.a_commit));
        let _ = writeln!(s, "- **B**: `{}`{}", self.b, commit(&self.b_commit));
        if !self.machine_differences.is_empty() {
            let _ = writeln!(
                s,
                "- **different machines**: {}. Time ratios across machines measure the machines as well as the code.",
                self.machine_differences.join("; ")
            );
        }
        let _ = writeln!(
            s,
            "- **matched runs**: {}; {} trace-time ratios and {} counters compared; threshold {}%, judged on 95 % intervals ({} undecided)\n",
            self.matched,
            self.times_compared,
            self.counters_compared,
            number::short(self.threshold_pct, 3),
            self.undecided
        );
        let verdict = if self.is_regression() {
            format!(
                "**{} regression{}.**",
                self.regressions.len(),
                if self.regressions.len() == 1 { "" } else { "s" }
            )
        } else if self.matched == 0 {
            "**Nothing compared: no run of A is in B.**".to_string()
        } else if self.missing_in_b() > 0 {
            format!(
                "**No regression in the {} matched runs, but B lacks {} of A's runs.**",
                self.matched,
                self.missing_in_b()
            )
        } else {
            "**No regression.**".to_string()
        };
        let _ = writeln!(s, "{verdict}\n");
        for (title, list) in [
            ("Regressions", &self.regressions),
            ("Improvements", &self.improvements),
            ("Notes", &self.notes),
        ] {
            if list.is_empty() {
                continue;
            }
            let _ = writeln!(s, "## {title}\n");
            let _ = writeln!(
                s,
                "| run | what | A | B | change | 95 % CI | samples A/B | tolerance |"
            );
            let _ = writeln!(s, "|---|---|---:|---:|---:|---:|---:|---:|");
            for f in list {
                let pct = |p: Option<f64>| {
                    p.map(|p| format!("{}%", signed(p)))
                        .unwrap_or_else(|| "–".to_string())
                };
                let ci = f
                    .interval_pct
                    .map(|[lo, hi]| format!("[{}%, {}%]", signed(lo), signed(hi)))
                    .unwrap_or_else(|| "–".to_string());
                let n = f
                    .samples
                    .map(|[a, b]| format!("{a}/{b}"))
                    .unwrap_or_else(|| "–".to_string());
                let _ = writeln!(
                    s,
                    "| `{}` | {} | {} | {} | {} | {ci} | {n} | {} |",
                    f.key.replace('|', "\\|"),
                    f.what.replace('|', "\\|"),
                    cell(&f.old),
                    cell(&f.new),
                    pct(f.change_pct),
                    f.tolerance_pct
                        .map(|t| format!("{}%", number::short(t, 3)))
                        .unwrap_or_else(|| "–".to_string()),
                );
            }
            s.push('\n');
            // A note's row does not say why it is one (undecided, unmatched, not compared): its
            // message does.
            if title == "Notes" {
                for f in list {
                    let _ = writeln!(s, "- {}", f.message);
                }
                s.push('\n');
            }
        }
        s
    }
}

fn signed(p: f64) -> String {
    if p > 0.0 {
        format!("+{}", number::short(p, 3))
    } else {
        number::short(p, 3)
    }
}

fn cell(v: &Value) -> String {
    match v {
        Value::Null => "–".to_string(),
        Value::String(s) => s.replace('|', "\\|"),
        Value::Number(n) if n.is_f64() => n.as_f64().map(number::ratio).unwrap_or_default(),
        other => other.to_string(),
    }
}

/// What differs between the machines of two `env.json`s, one phrase each (empty: the same
/// machine as far as they record it). Memory is compared in whole GiB: the kernel's total moves
/// by a few MiB between boots.
pub fn machine_differences(a: &Environment, b: &Environment) -> Vec<String> {
    let mut out = Vec::new();
    if a.cpu_model != b.cpu_model {
        out.push(format!("CPU {} → {}", a.cpu_model, b.cpu_model));
    }
    let (fa, fb): (BTreeSet<&str>, BTreeSet<&str>) = (
        a.cpu_flags.iter().map(String::as_str).collect(),
        b.cpu_flags.iter().map(String::as_str).collect(),
    );
    let list = |v: Vec<&str>| {
        let n = v.len();
        let mut s = v.into_iter().take(8).collect::<Vec<_>>().join(" ");
        if n > 8 {
            s.push_str(&format!(" and {} more", n - 8));
        }
        s
    };
    let added: Vec<&str> = fb.difference(&fa).copied().collect();
    let removed: Vec<&str> = fa.difference(&fb).copied().collect();
    if !added.is_empty() {
        out.push(format!("CPU flags only B has: {}", list(added)));
    }
    if !removed.is_empty() {
        out.push(format!("CPU flags only A has: {}", list(removed)));
    }
    if (a.cores_logical, a.cores_physical) != (b.cores_logical, b.cores_physical) {
        let c = |e: &Environment| match e.cores_physical {
            Some(p) => format!("{} logical / {p} physical", e.cores_logical),
            None => format!("{} logical", e.cores_logical),
        };
        out.push(format!("cores {} → {}", c(a), c(b)));
    }
    let gib = |m: u64| (m as f64 / (1u64 << 30) as f64).round() as u64;
    if gib(a.memory_bytes) != gib(b.memory_bytes) {
        out.push(format!(
            "memory {} → {} GiB",
            gib(a.memory_bytes),
            gib(b.memory_bytes)
        ));
    }
    for (what, x, y) in [("OS", &a.os, &b.os), ("rustc", &a.rustc, &b.rustc)] {
        if x != y {
            out.push(format!("{what} {x} → {y}"));
        }
    }
    if a.embree_version != b.embree_version {
        let v = |e: &Option<String>| e.clone().unwrap_or_else(|| "none".to_string());
        out.push(format!(
            "Embree {} → {}",
            v(&a.embree_version),
            v(&b.embree_version)
        ));
    }
    out
}

fn read_set(dir: &Path) -> Result<(Vec<RunRecord>, Option<Environment>), ReportError> {
    let results = dir.join("results.jsonl");
    if !results.is_file() {
        return Err(ReportError::NoResults {
            path: results.display().to_string(),
        });
    }
    let records = read_results(dir)?;
    crate::summary::check_records(&records, &results.display().to_string())?;
    let records = latest_per_key(records);
    Ok((records, read_environment(dir)?))
}

/// Compares result set `b` against `a` (see the module doc). `threshold_pct` is the smallest change of a
/// trace-time ratio, in percent, that counts; a run noisier than that raises its own bar.
pub fn compare(a: &Path, b: &Path, threshold_pct: f64) -> Result<Comparison, ReportError> {
    if !threshold_pct.is_finite() || threshold_pct < 0.0 {
        return Err(ReportError::BadThreshold(threshold_pct));
    }
    let (runs_a, env_a) = read_set(a)?;
    let (runs_b, env_b) = read_set(b)?;
    let commit = |e: &Option<Environment>| {
        e.as_ref()
            .map(|e| e.git_commit.clone())
            .filter(|c| !c.is_empty())
    };
    let mut c = Comparison {
        a: a.display().to_string(),
        b: b.display().to_string(),
        a_commit: commit(&env_a),
        b_commit: commit(&env_b),
        machine_differences: match (&env_a, &env_b) {
            (Some(x), Some(y)) => machine_differences(x, y),
            _ => Vec::new(),
        },
        threshold_pct,
        matched: 0,
        times_compared: 0,
        undecided: 0,
        counters_compared: 0,
        regressions: Vec::new(),
        improvements: Vec::new(),
        notes: Vec::new(),
    };
    compare_records(&runs_a, &runs_b, &mut c);
    Ok(c)
}

fn compare_records(runs_a: &[RunRecord], runs_b: &[RunRecord], c: &mut Comparison) {
    let anchors_a = Anchors::of(runs_a);
    let anchors_b = Anchors::of(runs_b);
    let by_key_b: BTreeMap<&str, &RunRecord> = runs_b.iter().map(|r| (r.key.as_str(), r)).collect();
    let keys_a: BTreeSet<&str> = runs_a.iter().map(|r| r.key.as_str()).collect();

    for ra in runs_a {
        let Some(rb) = by_key_b.get(ra.key.as_str()).copied() else {
            c.notes.push(finding(
                ra,
                FindingKind::OnlyInA,
                "run",
                status(ra),
                Value::Null,
                "in A only: not run in B",
            ));
            continue;
        };
        c.matched += 1;
        match (ra.ok(), rb.ok()) {
            (true, false) => {
                let why = rb
                    .reason
                    .clone()
                    .unwrap_or_else(|| "no reason recorded".to_string());
                c.regressions.push(finding(
                    ra,
                    FindingKind::Failed,
                    "status",
                    status(ra),
                    status(rb),
                    &format!("failed in B: {why}"),
                ));
                continue;
            }
            (false, true) => {
                c.improvements.push(finding(
                    ra,
                    FindingKind::Recovered,
                    "status",
                    status(ra),
                    status(rb),
                    "failed in A, ok in B",
                ));
                continue;
            }
            (false, false) => {
                let why = rb
                    .reason
                    .clone()
                    .unwrap_or_else(|| "no reason recorded".to_string());
                c.notes.push(finding(
                    ra,
                    FindingKind::StillFailing,
                    "status",
                    status(ra),
                    status(rb),
                    &format!("failed in both: {why}"),
                ));
                continue;
            }
            (true, true) => {}
        }
        if ra.size != rb.size {
            // Another image size traces other rays: its counters and times are another
            // workload's, and the run key does not hold the size.
            c.notes.push(finding(
                ra,
                FindingKind::DifferentWorkload,
                "size",
                Value::from(ra.size),
                Value::from(rb.size),
                &format!(
                    "not compared: traced at {}² in A and {}² in B",
                    ra.size, rb.size
                ),
            ));
            continue;
        }
        compare_counters(ra, rb, c);
        if ra.engine != EMBREE {
            compare_times(ra, rb, &anchors_a, &anchors_b, c);
        }
        compare_scaling(ra, rb, c);
    }
    for rb in runs_b.iter().filter(|r| !keys_a.contains(r.key.as_str())) {
        c.notes.push(finding(
            rb,
            FindingKind::OnlyInB,
            "run",
            Value::Null,
            status(rb),
            "in B only: new run",
        ));
    }
}

fn status(r: &RunRecord) -> Value {
    Value::String(r.status.clone())
}

fn finding(
    r: &RunRecord,
    kind: FindingKind,
    what: &str,
    old: Value,
    new: Value,
    message: &str,
) -> Finding {
    Finding {
        key: r.key.clone(),
        kind,
        what: what.to_string(),
        old,
        new,
        change_pct: None,
        tolerance_pct: None,
        interval_pct: None,
        samples: None,
        message: format!("{}: {message}", r.key),
    }
}

/// Any change of an exact counter, including one that appeared or vanished, is a regression.
fn compare_counters(ra: &RunRecord, rb: &RunRecord, c: &mut Comparison) {
    let names: BTreeSet<&String> = ra.counters.keys().chain(rb.counters.keys()).collect();
    for name in names {
        c.counters_compared += 1;
        let (old, new) = (
            ra.counters.get(name).copied(),
            rb.counters.get(name).copied(),
        );
        if old == new {
            continue;
        }
        let show = |v: Option<u64>| {
            v.map(|v| v.to_string())
                .unwrap_or_else(|| "absent".to_string())
        };
        let change_pct = match (old, new) {
            (Some(o), Some(n)) if o > 0 => Some((n as f64 - o as f64) / o as f64 * 100.0),
            _ => None,
        };
        c.regressions.push(Finding {
            key: ra.key.clone(),
            kind: FindingKind::Counter,
            what: name.clone(),
            old: old.map(Value::from).unwrap_or(Value::Null),
            new: new.map(Value::from).unwrap_or(Value::Null),
            change_pct,
            tolerance_pct: Some(0.0),
            interval_pct: None,
            samples: None,
            message: format!("{}: counter {name}: {} → {}", ra.key, show(old), show(new)),
        });
    }
}

/// Trace time over Embree's in A against the same in B.
fn compare_times(
    ra: &RunRecord,
    rb: &RunRecord,
    anchors_a: &Anchors,
    anchors_b: &Anchors,
    c: &mut Comparison,
) {
    // Both runs timed in pairs with Embree in their own processes (`run --paired N`): those
    // ratios, each set's median log of its pairs.
    if let (Some(pa), Some(pb)) = (paired(ra), paired(rb)) {
        c.times_compared += 1;
        // Where both sides ran in rounds, the round is the unit ([`crate::rounds`]).
        if let (Some(a), Some(b)) = (rounds::paired(ra), rounds::paired(rb)) {
            let what = "trace time / Embree (paired)";
            judge(ra, by_rounds(FindingKind::TimeRatio, what, a, b, true), c);
            return;
        }
        let change = LogMean::median_of(&pb.samples)
            .zip(LogMean::median_of(&pa.samples))
            .map(|(b, a)| b.minus(&a));
        let (qa, qb) = (median_ratio(&pa.samples), median_ratio(&pb.samples));
        judge(
            ra,
            Judged {
                kind: FindingKind::TimeRatio,
                what: "trace time / Embree (paired)",
                old: qa,
                new: qb,
                change,
                samples: [pa.samples.len(), pb.samples.len()],
                unit: "samples",
                higher_is_worse: true,
                one_process: true,
            },
            c,
        );
        return;
    }
    let (Some(ya), Some(yb)) = (anchors_a.anchor(ra), anchors_b.anchor(rb)) else {
        let missing = match (
            anchors_a.anchor(ra).is_none(),
            anchors_b.anchor(rb).is_none(),
        ) {
            (true, true) => "A and B",
            (true, false) => "A",
            _ => "B",
        };
        c.notes.push(finding(
            ra,
            FindingKind::NoYardstick,
            "trace time / Embree",
            Value::Null,
            Value::Null,
            &format!(
                "times not compared: no ok Embree run on {}@{} in {missing}",
                ra.scene.name, ra.threads
            ),
        ));
        return;
    };
    c.times_compared += 1;
    if let (Some(a), Some(b)) = (rounds::quotient(ra, ya), rounds::quotient(rb, yb)) {
        let what = "trace time / Embree";
        judge(ra, by_rounds(FindingKind::TimeRatio, what, a, b, true), c);
        return;
    }
    let t = |r: &RunRecord| r.time_s.trace_for_compare().samples.clone();
    let (ea, eb, sa, sb) = (t(ra), t(rb), t(ya), t(yb));
    let change = match (
        LogMean::of(&eb),
        LogMean::of(&sb),
        LogMean::of(&ea),
        LogMean::of(&sa),
    ) {
        (Some(eb), Some(sb), Some(ea), Some(sa)) => Some(interval::combine(&[
            (1.0, eb),
            (-1.0, sb),
            (-1.0, ea),
            (1.0, sa),
        ])),
        _ => None,
    };
    judge(
        ra,
        Judged {
            kind: FindingKind::TimeRatio,
            what: "trace time / Embree",
            old: geo(&ea) / geo(&sa),
            new: geo(&eb) / geo(&sb),
            change,
            samples: [ea.len() + sa.len(), eb.len() + sb.len()],
            unit: "samples",
            higher_is_worse: true,
            one_process: true,
        },
        c,
    );
}

/// The speed-up over one thread in A against B's, when both timed it in pairs: each set's mean
/// log of its pairs' speed-ups. Embree's own speed-up is compared too: it is a figure of the
/// harness (how it splits the trace), not only of Embree.
fn compare_scaling(ra: &RunRecord, rb: &RunRecord, c: &mut Comparison) {
    let (Some(sa), Some(sb)) = (&ra.thread_scaling, &rb.thread_scaling) else {
        return;
    };
    if let (Some(a), Some(b)) = (rounds::speedup(ra), rounds::speedup(rb)) {
        let what = "speed-up over 1 thread";
        judge(
            ra,
            by_rounds(FindingKind::ThreadSpeedup, what, a, b, false),
            c,
        );
        return;
    }
    let (pa, pb) = (&sa.speedup, &sb.speedup);
    let change = LogMean::median_of(&pb.samples)
        .zip(LogMean::median_of(&pa.samples))
        .map(|(b, a)| b.minus(&a));
    judge(
        ra,
        Judged {
            kind: FindingKind::ThreadSpeedup,
            what: "speed-up over 1 thread",
            old: median_ratio(&pa.samples),
            new: median_ratio(&pb.samples),
            change,
            samples: [pa.samples.len(), pb.samples.len()],
            unit: "samples",
            higher_is_worse: false,
            one_process: true,
        },
        c,
    );
}

/// A figure both sides measured over rounds: A's and B's mean log over their rounds.
fn by_rounds(
    kind: FindingKind,
    what: &str,
    a: LogMean,
    b: LogMean,
    higher_is_worse: bool,
) -> Judged<'_> {
    Judged {
        kind,
        what,
        old: a.mean.exp(),
        new: b.mean.exp(),
        change: Some(b.minus(&a)),
        samples: [a.n, b.n],
        unit: "rounds",
        higher_is_worse,
        one_process: false,
    }
}

/// Geometric mean (0 for no sample).
fn geo(x: &[f64]) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    (x.iter().map(|v| v.max(1e-300).ln()).sum::<f64>() / x.len() as f64).exp()
}

/// The figure of ratios measured in pairs: the exponential of their median log (0 for none).
fn median_ratio(x: &[f64]) -> f64 {
    LogMean::median_of(x).map_or_else(|| geo(x), |m| m.mean.exp())
}

/// A run's paired ratios to Embree, when it has some.
fn paired(r: &RunRecord) -> Option<&crate::results::Spread> {
    r.paired_ratio
        .as_ref()
        .filter(|p| r.ok() && !p.samples.is_empty())
}

/// A figure of A and B and the log-scale change between them.
struct Judged<'a> {
    kind: FindingKind,
    what: &'a str,
    old: f64,
    new: f64,
    /// B's log figure minus A's; `None` when a side has fewer than two samples.
    change: Option<LogMean>,
    samples: [usize; 2],
    /// What `samples` counts: "samples", or "rounds" where each side's figure is over rounds.
    unit: &'a str,
    /// A rise is a regression (a time ratio), else a fall is (a speed-up).
    higher_is_worse: bool,
    /// A side's samples are of one process (it has no rounds): a change past the threshold is not
    /// decided.
    one_process: bool,
}

/// Decides on the interval of the change: a regression or improvement only when the whole 95 %
/// interval lies past ±threshold and both sides ran in rounds; undecided when a side has fewer
/// than two samples, when the estimate passes the threshold but the interval reaches back
/// inside, or when the interval passes it but a side ran in one process.
fn judge(ra: &RunRecord, j: Judged, c: &mut Comparison) {
    let thr = c.threshold_pct;
    let [na, nb] = j.samples;
    let Some(change) = j.change else {
        c.undecided += 1;
        c.notes.push(Finding {
            key: ra.key.clone(),
            kind: FindingKind::Undecided,
            what: j.what.to_string(),
            old: Value::from(j.old),
            new: Value::from(j.new),
            change_pct: (j.old > 0.0).then(|| (j.new / j.old - 1.0) * 100.0),
            tolerance_pct: Some(thr),
            interval_pct: None,
            samples: Some(j.samples),
            message: format!(
                "{}: {} {} → {}: too few samples to decide ({na} {} in A, {nb} in B; at least 2 a side)",
                ra.key,
                j.what,
                number::ratio(j.old),
                number::ratio(j.new),
                j.unit
            ),
        });
        return;
    };
    let ci = change.interval();
    let pct = |x: f64| (x - 1.0) * 100.0;
    let (est, lo, hi) = (pct(ci.estimate), pct(ci.lo), pct(ci.hi));
    let worse = |x: f64| if j.higher_is_worse { x } else { -x };
    // Past the threshold towards worse, towards better, or neither, for the whole interval.
    let (w_lo, w_hi) = {
        let (a, b) = (worse(lo), worse(hi));
        (a.min(b), a.max(b))
    };
    let verdict = if w_lo > thr {
        Some(true)
    } else if w_hi < -thr {
        Some(false)
    } else {
        None
    };
    let interval_text = format!("95 % CI [{}%, {}%]", signed(lo), signed(hi));
    let n_text = format!("{na} {} in A, {nb} in B", j.unit);
    let mut f = Finding {
        key: ra.key.clone(),
        kind: j.kind,
        what: j.what.to_string(),
        old: Value::from(j.old),
        new: Value::from(j.new),
        change_pct: Some(est),
        tolerance_pct: Some(thr),
        interval_pct: Some([lo, hi]),
        samples: Some(j.samples),
        message: String::new(),
    };
    let head = format!(
        "{}: {} {} → {}",
        ra.key,
        j.what,
        number::ratio(j.old),
        number::ratio(j.new)
    );
    let (est_text, thr_text) = (signed(est), number::short(thr, 3));
    let undecided = match verdict {
        Some(_) if j.one_process => Some(format!(
            "{head} ({est_text}%; {interval_text}, past the threshold {thr_text}%): not decided: a side ran in one process, whose samples cannot show how far two processes of one build differ; run both with --rounds 2 or more, and as many repeats ({n_text})"
        )),
        None if est.abs() > thr => Some(format!(
            "{head} ({est_text}%; {interval_text} reaches inside the threshold {thr_text}%): too few samples to decide ({n_text})"
        )),
        _ => None,
    };
    if let Some(message) = undecided {
        c.undecided += 1;
        f.kind = FindingKind::Undecided;
        f.message = message;
        c.notes.push(f);
        return;
    }
    let Some(regressed) = verdict else {
        return;
    };
    let word = match (j.higher_is_worse, est > 0.0) {
        (true, true) => "slower relative to Embree",
        (true, false) => "faster relative to Embree",
        (false, true) => "rose",
        (false, false) => "fell",
    };
    f.message = format!(
        "{head} ({est_text}% {word}; {interval_text}, beyond the threshold {thr_text}%; {n_text})"
    );
    if regressed {
        c.regressions.push(f);
    } else {
        c.improvements.push(f);
    }
}
