//! The static dashboard: one HTML page (no server, no script) with the latest night's findings,
//! the trend of every gated metric over the nights of the same machine and suite with the change
//! points E-divisive finds marked, and the list of nights. Plots are drawn by the reports crate
//! (`rtbench_reports::plot`) as inline SVG; the trend charts are also written as PNG files.

use super::detect;
use super::{Finding, History, Metric};
use crate::error::{input, Result};
use rtbench_reports::plot::{self, Chart, LegendAt, Panel, Point, Series, XyPanel};
use std::collections::BTreeMap;
use std::path::Path;

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

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A named series of (night id, value).
type Trend = (String, Vec<(f64, f64)>);

/// One chart per group: each metric a series over the nights (x = night id), each change point a
/// vertical line in the series' colour.
fn chart(stem: &str, title: &str, y_label: &str, y_log: bool, group: &[Trend]) -> Chart {
    let mut series = Vec::new();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, pts) in group {
        for (_, y) in pts {
            lo = lo.min(*y);
            hi = hi.max(*y);
        }
    }
    for (i, (name, pts)) in group.iter().enumerate() {
        let color = 1 + i;
        series.push(Series {
            name: name.clone(),
            color,
            points: pts
                .iter()
                .map(|&(x, y)| Point {
                    x,
                    y,
                    y_range: None,
                })
                .collect(),
        });
        let ys: Vec<f64> = pts.iter().map(|p| p.1).collect();
        for cp in detect::change_points(&ys, 0.01, 3) {
            let x = (pts[cp - 1].0 + pts[cp].0) / 2.0;
            series.push(Series {
                name: format!("change point ({name})"),
                color,
                points: vec![
                    Point {
                        x,
                        y: lo,
                        y_range: None,
                    },
                    Point {
                        x,
                        y: hi,
                        y_range: None,
                    },
                ],
            });
        }
    }
    // Explicit x ticks (night ids, at most 12): the reports crate chooses ticks on a log scale
    // otherwise, which a range starting at 0 does not have.
    let mut xs: Vec<f64> = group
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.0))
        .collect();
    xs.sort_by(|a, b| a.total_cmp(b));
    xs.dedup();
    let step = xs.len().div_ceil(12).max(1);
    let x_ticks: Vec<f64> = xs.iter().copied().step_by(step).collect();
    Chart {
        stem: stem.to_string(),
        title: title.to_string(),
        panels: vec![Panel::Xy(XyPanel {
            title: String::new(),
            x_label: "night (history id)".into(),
            y_label: y_label.into(),
            x_log: false,
            y_log,
            x_ticks,
            lines: true,
            legend: LegendAt::UpperLeft,
            series,
        })],
    }
}

/// Writes `dir/index.html` (and the trend charts as `dir/*.png`).
pub fn write(h: &History, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| input(format!("{}: {e}", dir.display())))?;
    let runs = h.runs(None, None)?;
    let mut body = String::new();
    let Some(last) = runs.last() else {
        return Err(input("the history holds no night: nothing to show"));
    };
    let mine: Vec<_> = runs
        .iter()
        .filter(|r| r.fingerprint == last.fingerprint && r.suite == last.suite)
        .collect();
    // name → [(night id, value)], and kinds.
    let mut trend: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    let mut kinds: BTreeMap<String, String> = BTreeMap::new();
    let mut last_metrics: Vec<Metric> = Vec::new();
    for r in &mine {
        let ms = h.metrics(r.id)?;
        for m in &ms {
            if m.gated && m.kind != "counter" || m.kind == "criterion" {
                trend
                    .entry(m.name.clone())
                    .or_default()
                    .push((r.id as f64, m.value));
                kinds.insert(m.name.clone(), m.kind.clone());
            }
        }
        if r.id == last.id {
            last_metrics = ms;
        }
    }
    let findings = h.findings(last.id)?;
    body.push_str(&format!(
        "<h1>rtbench nightly: {}</h1>\n<p>Latest night {} ({}), commit <code>{}</code>, machine <code>{}</code>: {} metrics, {} nights of this machine and suite.</p>\n",
        esc(&last.suite),
        last.id,
        esc(&last.started_at),
        esc(crate::output::head(&last.git_commit, 12)),
        esc(crate::output::head(&last.fingerprint, 12)),
        last_metrics.len(),
        mine.len()
    ));
    // What the night's gates were and what each gated metric was compared against (`gate` and
    // `ok` rows), apart from what it found.
    let gates: Vec<&Finding> = findings.iter().filter(|f| f.verdict == "gate").collect();
    body.push_str("<h2>Gates of the latest night</h2>\n");
    if gates.is_empty() {
        body.push_str("<p>Not recorded with this night.</p>\n");
    } else {
        body.push_str("<ul>\n");
        for f in &gates {
            body.push_str(&format!("<li>{}</li>\n", esc(&f.message)));
        }
        body.push_str("</ul>\n");
    }
    let compared: Vec<&Finding> = findings.iter().filter(|f| f.verdict == "ok").collect();
    let findings: Vec<Finding> = findings
        .iter()
        .filter(|f| f.verdict != "ok" && f.verdict != "gate")
        .cloned()
        .collect();
    body.push_str("<h2>Findings of the latest night</h2>\n");
    if findings.is_empty() {
        body.push_str("<p class=\"ok\">No regression, no improvement, no counter change.</p>\n");
    } else {
        body.push_str("<table><tr><th>verdict</th><th>metric</th><th>baseline</th><th>tonight</th><th>change</th></tr>\n");
        let mut sorted = findings.clone();
        sorted.sort_by_key(|f| match f.verdict.as_str() {
            "failed" | "regression" => 0,
            "improvement" => 1,
            _ => 2,
        });
        for f in &sorted {
            body.push_str(&format!(
                "<tr class=\"{}\"><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                esc(&f.verdict),
                esc(&f.verdict),
                esc(&f.name),
                f.baseline.map(fmt_value).unwrap_or_default(),
                f.value.map(fmt_value).unwrap_or_default(),
                f.change_pct
                    .map(|c| format!("{c:+.2}%"))
                    .unwrap_or_default()
            ));
        }
        body.push_str("</table>\n");
    }
    if !compared.is_empty() {
        body.push_str(&format!(
            "<details><summary>{} gated metrics compared and unchanged</summary>\n<table><tr><th>metric</th><th>tonight</th><th>compared against</th><th>change</th></tr>\n",
            compared.len()
        ));
        for f in &compared {
            body.push_str(&format!(
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                esc(&f.name),
                f.value.map(fmt_value).unwrap_or_default(),
                esc(&f.message),
                f.change_pct
                    .map(|c| format!("{c:+.3}%"))
                    .unwrap_or_default()
            ));
        }
        body.push_str("</table></details>\n");
    }
    // Groups: time ratios by scene, instruction counts, criterion kernels.
    let mut groups: BTreeMap<(u8, String), Vec<Trend>> = BTreeMap::new();
    for (name, pts) in &trend {
        let (subj, _) = name.rsplit_once('/').unwrap_or((name, ""));
        let key = match kinds.get(name).map(String::as_str) {
            Some("time_ratio") => {
                let (label, scene) = subj.split_once(' ').unwrap_or((subj, ""));
                groups
                    .entry((0, format!("trace CPU time / Embree's, {scene}")))
                    .or_default()
                    .push((label.to_string(), pts.clone()));
                continue;
            }
            Some("instructions") => (1, "instructions of the trace under callgrind".to_string()),
            Some("criterion") => (2, "criterion kernels, ns per call".to_string()),
            _ => (3, "other".to_string()),
        };
        groups
            .entry(key)
            .or_default()
            .push((subj.to_string(), pts.clone()));
    }
    body.push_str("<h2>Trends</h2>\n<p>One point per night; a vertical line in a series' colour marks a change point (E-divisive, p ≤ 0.01).</p>\n");
    for (i, ((kind, title), series)) in groups.iter().enumerate() {
        // Keep each chart legible: at most 8 series.
        for (j, part) in series.chunks(8).enumerate() {
            let stem = format!("trend-{i}-{j}");
            // Log y for all: every trend is positive, and equal ratios read as equal steps.
            let (ylab, ylog) = match kind {
                0 => ("ratio to Embree", true),
                1 => ("instructions", true),
                2 => ("ns", true),
                _ => ("value", true),
            };
            let c = chart(&stem, title, ylab, ylog, part);
            let svg = plot::svg(&c).map_err(|e| input(format!("plot {stem}: {e}")))?;
            let svg = svg.trim_start();
            let svg = if svg.starts_with("<?xml") {
                svg.split_once("?>").map(|(_, s)| s).unwrap_or(svg)
            } else {
                svg
            };
            body.push_str(&format!("<figure>{svg}</figure>\n"));
            if let Ok(png) = plot::png(&c) {
                let _ = std::fs::write(dir.join(format!("{stem}.png")), png);
            }
        }
    }
    body.push_str("<h2>Nights</h2>\n<table><tr><th>id</th><th>started</th><th>commit</th><th>machine</th><th>metrics</th><th>regressions</th><th>wall s</th><th>note</th></tr>\n");
    for r in runs.iter().rev() {
        body.push_str(&format!(
            "<tr><td>{}</td><td>{}</td><td><code>{}</code></td><td><code>{}</code></td><td>{}</td><td>{}</td><td>{:.0}</td><td>{}</td></tr>\n",
            r.id,
            esc(&r.started_at),
            esc(crate::output::head(&r.git_commit, 10)),
            esc(crate::output::head(&r.fingerprint, 10)),
            r.metrics,
            r.regressions,
            r.wall_s,
            esc(r.note.as_deref().unwrap_or(""))
        ));
    }
    body.push_str("</table>\n");
    let html = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>rtbench nightly</title>\n<style>\nbody{{font-family:sans-serif;margin:2em;max-width:1400px}}\ntable{{border-collapse:collapse;margin:1em 0}}td,th{{border:1px solid #ccc;padding:2px 8px;text-align:left}}\ntr.regression,tr.failed{{background:#fdd}}tr.improvement{{background:#dfd}}p.ok{{color:#060}}\nfigure{{display:inline-block;margin:0.5em}}svg{{max-width:100%;height:auto}}\n</style></head><body>\n{body}</body></html>\n"
    );
    crate::output::write_atomic(&dir.join("index.html"), |w| {
        std::io::Write::write_all(w, html.as_bytes())
    })
}
