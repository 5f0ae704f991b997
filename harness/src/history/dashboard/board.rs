//! What the dashboard shows, as data: the nights of one machine and suite, and one plot per metric
//! with its values, 95 % intervals, findings and change points. Built from the history alone;
//! the page (`page.rs`) only lays it out, and its script draws the plots from it.

use super::super::detect;
use super::super::{Finding, History, RunRow};
use crate::error::{input, Result};
use serde::Serialize;
use std::collections::BTreeMap;

/// The verdicts marked on the plots (every other one is not a finding about a value).
const MARKED: [&str; 5] = ["regression", "failed", "improvement", "change", "suspect"];

/// The placeholder a commit URL template holds.
pub const COMMIT: &str = "{commit}";

/// Refuses a commit URL template that could not make a link: it is an http(s) URL holding
/// `{commit}`.
pub fn check_commit_url(template: &str) -> Result<()> {
    let scheme = template.starts_with("https://") || template.starts_with("http://");
    if !scheme || !template.contains(COMMIT) {
        return Err(input(format!(
            "commit URL '{template}': expected an http(s) URL holding {COMMIT}, e.g. \
             https://github.com/ORG/REPO/commit/{COMMIT}"
        )));
    }
    Ok(())
}

/// A commit's link through the template; none for an id that is not plain letters and digits.
fn commit_link(template: Option<&str>, commit: &str) -> Option<String> {
    let t = template?;
    (!commit.is_empty() && commit.chars().all(|c| c.is_ascii_alphanumeric()))
        .then(|| t.replace(COMMIT, commit))
}

#[derive(Clone, Debug, Serialize)]
pub struct NightInfo {
    pub id: i64,
    pub started_at: String,
    pub commit: String,
    pub dirty: bool,
    /// The machine's fingerprint.
    pub machine: String,
    /// The commit's page, when a URL template was given.
    pub url: Option<String>,
    pub regressions: i64,
    pub metrics: i64,
    pub wall_s: f64,
    pub note: String,
    /// Another machine's or suite's night: listed, not plotted.
    pub plotted: bool,
}

/// A finding marked on a plot.
#[derive(Clone, Debug, Serialize)]
pub struct Mark {
    pub night: i64,
    pub verdict: String,
    pub message: String,
}

/// One metric over the nights.
#[derive(Clone, Debug, Serialize)]
pub struct Plot {
    pub name: String,
    pub kind: String,
    pub unit: String,
    /// Whether the latest night that holds the metric gated it.
    pub gated: bool,
    /// Night ids, ascending, and the metric's value on each.
    pub x: Vec<i64>,
    pub y: Vec<f64>,
    /// The 95 % interval of each night's samples (geometric mean, Student's t), where the night
    /// kept two or more samples of the metric.
    pub lo: Vec<Option<f64>>,
    pub hi: Vec<Option<f64>>,
    pub n: Vec<usize>,
    pub marks: Vec<Mark>,
    /// E-divisive change points (p ≤ 0.01, segments of 3 nights or more), as the x between the
    /// last night before and the first night after.
    pub change_points: Vec<f64>,
    /// What the latest night compared the metric against (its `ok` or finding row), if it did.
    pub compared: Option<String>,
    /// The state of the gate over this metric's kind on the latest night.
    pub gate: Option<String>,
}

impl Plot {
    /// The verdict of the worst mark on the plot (regression first), for the page's filters.
    pub fn worst(&self) -> Option<&str> {
        MARKED
            .iter()
            .find(|v| self.marks.iter().any(|m| m.verdict == **v))
            .copied()
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Board {
    pub suite: String,
    pub fingerprint: String,
    pub latest: NightInfo,
    /// Every night of the history, newest first.
    pub nights: Vec<NightInfo>,
    /// The gates of the latest night, one line each.
    pub gates: Vec<String>,
    /// The latest night's findings (not `ok` nor `gate` rows), worst first.
    pub findings: Vec<Finding>,
    /// The latest night's gated metrics compared and unchanged.
    pub compared: usize,
    /// Plots in the page's order: time ratios, instruction counts, counters, criterion, the rest.
    pub plots: Vec<Plot>,
}

fn kind_order(kind: &str) -> u8 {
    match kind {
        "time_ratio" => 0,
        "instructions" => 1,
        "counter" => 2,
        "criterion" => 3,
        _ => 4,
    }
}

fn verdict_order(verdict: &str) -> u8 {
    match verdict {
        "failed" | "regression" => 0,
        "improvement" => 1,
        _ => 2,
    }
}

/// The gate named `gate/<g>` governs the metrics of kind `counter` (`counters`) or of kind `g`.
fn governs(gate: &str, kind: &str) -> bool {
    gate == kind || gate == format!("{kind}s")
}

fn night_info(r: &RunRow, template: Option<&str>, plotted: bool) -> NightInfo {
    NightInfo {
        id: r.id,
        started_at: r.started_at.clone(),
        commit: r.git_commit.clone(),
        dirty: r.git_dirty,
        machine: r.fingerprint.clone(),
        url: commit_link(template, &r.git_commit),
        regressions: r.regressions,
        metrics: r.metrics,
        wall_s: r.wall_s,
        note: r.note.clone().unwrap_or_default(),
        plotted,
    }
}

/// The board of the latest night's machine and suite.
pub fn build(h: &History, commit_url: Option<&str>) -> Result<Board> {
    if let Some(t) = commit_url {
        check_commit_url(t)?;
    }
    let runs = h.runs(None, None)?;
    let Some(last) = runs.last() else {
        return Err(input("the history holds no night: nothing to show"));
    };
    let mine = |r: &RunRow| r.fingerprint == last.fingerprint && r.suite == last.suite;
    let mut plots: BTreeMap<String, Plot> = BTreeMap::new();
    let mut last_findings = Vec::new();
    for r in runs.iter().filter(|r| mine(r)) {
        for m in h.metrics(r.id)? {
            let interval = if m.samples.len() >= 2 {
                rtbench_reports::interval::of_ratios(&m.samples)
            } else {
                None
            };
            let p = plots.entry(m.name.clone()).or_insert_with(|| Plot {
                name: m.name.clone(),
                kind: m.kind.clone(),
                unit: m.unit.clone(),
                gated: m.gated,
                x: Vec::new(),
                y: Vec::new(),
                lo: Vec::new(),
                hi: Vec::new(),
                n: Vec::new(),
                marks: Vec::new(),
                change_points: Vec::new(),
                compared: None,
                gate: None,
            });
            p.kind = m.kind.clone();
            p.unit = m.unit.clone();
            p.gated = m.gated;
            p.x.push(r.id);
            p.y.push(m.value);
            p.lo.push(interval.as_ref().map(|i| i.lo));
            p.hi.push(interval.as_ref().map(|i| i.hi));
            p.n.push(m.samples.len());
        }
        let findings = h.findings(r.id)?;
        for f in &findings {
            if let Some(p) = plots.get_mut(&f.name) {
                if MARKED.contains(&f.verdict.as_str()) {
                    p.marks.push(Mark {
                        night: r.id,
                        verdict: f.verdict.clone(),
                        message: f.message.clone(),
                    });
                }
            }
        }
        if r.id == last.id {
            last_findings = findings;
        }
    }
    // A counter that is 0 on every night is one the engine does not keep (a BVH visits no grid
    // cells): no plot for it. It is still recorded and gated, so a night it moves is marked.
    plots.retain(|_, p| !(p.kind == "counter" && p.y.iter().all(|v| *v == 0.0)));
    let gates: Vec<&Finding> = last_findings
        .iter()
        .filter(|f| f.verdict == "gate")
        .collect();
    for p in plots.values_mut() {
        p.gate = gates
            .iter()
            .find(|g| governs(g.name.trim_start_matches("gate/"), &p.kind))
            .map(|g| g.message.clone());
        p.compared = last_findings
            .iter()
            .filter(|f| f.name == p.name && f.verdict != "gate")
            .min_by_key(|f| verdict_order(&f.verdict))
            .map(|f| format!("{}: {}", f.verdict, f.message));
        // A constant series has no change point: skip the permutation test.
        if p.y.iter().any(|v| *v != p.y[0]) {
            p.change_points = detect::change_points(&p.y, 0.01, 3)
                .into_iter()
                .map(|i| (p.x[i - 1] + p.x[i]) as f64 / 2.0)
                .collect();
        }
    }
    let mut plots: Vec<Plot> = plots.into_values().collect();
    plots.sort_by(|a, b| (kind_order(&a.kind), &a.name).cmp(&(kind_order(&b.kind), &b.name)));
    let mut findings: Vec<Finding> = last_findings
        .iter()
        .filter(|f| f.verdict != "ok" && f.verdict != "gate")
        .cloned()
        .collect();
    findings.sort_by_key(|f| verdict_order(&f.verdict));
    Ok(Board {
        suite: last.suite.clone(),
        fingerprint: last.fingerprint.clone(),
        latest: night_info(last, commit_url, true),
        nights: runs
            .iter()
            .rev()
            .map(|r| night_info(r, commit_url, mine(r)))
            .collect(),
        gates: gates.iter().map(|g| g.message.clone()).collect(),
        compared: last_findings.iter().filter(|f| f.verdict == "ok").count(),
        findings,
        plots,
    })
}

/// A value as the tables print it: counts whole, small values with four significant digits.
pub fn fmt_value(v: f64) -> String {
    if v.abs() >= 1e4 && v.fract() == 0.0 {
        format!("{v:.0}")
    } else if v.abs() >= 100.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.4}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commit_links_need_a_template_and_a_plain_id() {
        let t = "https://example.org/r/commit/{commit}";
        assert!(check_commit_url(t).is_ok());
        assert!(check_commit_url("https://example.org/r/commit/").is_err());
        assert!(check_commit_url("javascript:alert({commit})").is_err());
        assert_eq!(
            commit_link(Some(t), "cd8e501").as_deref(),
            Some("https://example.org/r/commit/cd8e501")
        );
        assert_eq!(commit_link(None, "cd8e501"), None);
        assert_eq!(commit_link(Some(t), "unknown?x=1"), None);
        assert_eq!(commit_link(Some(t), ""), None);
    }

    #[test]
    fn a_gate_governs_its_kind() {
        assert!(governs("counters", "counter"));
        assert!(governs("time_ratio", "time_ratio"));
        assert!(governs("instructions", "instructions"));
        assert!(!governs("counters", "time_ratio"));
    }
}
