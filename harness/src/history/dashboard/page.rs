//! The dashboard's page, written with maud: the latest night's gates and findings, one section per
//! metric (its plot is drawn by the page's script from the board's data), and the nights. The
//! script and uPlot (vendored from the npm registry, MIT licence in `uplot/LICENSE`) are inlined:
//! one file, no network.

use super::board::{fmt_value, Board, NightInfo, Plot};
use maud::{html, Markup, PreEscaped, DOCTYPE};

const UPLOT_JS: &str = include_str!("uplot/uPlot.iife.min.js");
const UPLOT_CSS: &str = include_str!("uplot/uPlot.min.css");
const SCRIPT: &str = include_str!("dashboard.js");
const STYLE: &str = include_str!("dashboard.css");

/// The kinds of metric, in the page's order, with what the filter calls them.
const KINDS: [(&str, &str); 5] = [
    ("time_ratio", "time ratios to Embree"),
    ("instructions", "instruction counts"),
    ("counter", "counters"),
    ("criterion", "criterion kernels"),
    ("time", "times"),
];

fn commit(n: &NightInfo) -> Markup {
    let short = crate::output::head(&n.commit, 10);
    html! {
        @match &n.url {
            Some(url) => a.commit href=(url) title=(n.commit) { code { (short) } },
            None => code title=(n.commit) { (short) },
        }
        @if n.dirty { "+" }
    }
}

fn plot(i: usize, p: &Plot) -> Markup {
    html! {
        section.plot id=(format!("plot-{i}")) data-i=(i) data-name=(p.name) data-kind=(p.kind)
            data-flag=(p.worst().unwrap_or("")) {
            h3 { a href=(format!("#plot-{i}")) { (p.name) } }
            p.tags {
                span.kind { (p.kind) }
                @if !p.unit.is_empty() { " · " (p.unit) }
                " · "
                @if p.gated {
                    span.gated title=(p.gate.as_deref().unwrap_or("")) { "gated" }
                } @else {
                    span.ungated title=(p.gate.as_deref().unwrap_or("")) { "not gated" }
                }
                @for m in &p.marks {
                    " "
                    span class={ "mark " (m.verdict) } title=(m.message) {
                        (m.verdict) " night " (m.night)
                    }
                }
            }
            @if let Some(c) = &p.compared {
                p.cmp { "Latest night: " (c) }
            }
            div.chart {}
            p.hover { "Hover a night for its values; click to hold it." }
        }
    }
}

/// The page of a board.
pub fn render(b: &Board) -> String {
    let last = &b.latest;
    let plotted = b.nights.iter().filter(|n| n.plotted).count();
    let data = serde_json::to_string(b).expect("the board serialises");
    let markup = html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                title { "rtbench nightly: " (b.suite) }
                style { (PreEscaped(UPLOT_CSS)) }
                style { (PreEscaped(STYLE)) }
            }
            body {
                h1 { "rtbench nightly: " (b.suite) }
                p.meta {
                    "Latest night " (last.id) " (" (last.started_at) "), commit " (commit(last))
                    ", machine " code { (crate::output::head(&b.fingerprint, 12)) } ": "
                    (last.metrics) " metrics, " (plotted) " nights of this machine and suite, "
                    (b.plots.len()) " plots."
                }
                section #gates {
                    h2 { "Gates of the latest night" }
                    @if b.gates.is_empty() {
                        p { "Not recorded with this night." }
                    } @else {
                        ul { @for g in &b.gates { li { (g) } } }
                    }
                }
                section #findings {
                    h2 { "Findings of the latest night" }
                    @if b.findings.is_empty() {
                        p.ok { "No regression, no improvement, no counter change." }
                    } @else {
                        table {
                            tr { th { "verdict" } th { "metric" } th { "baseline" } th { "tonight" } th { "change" } th { "what" } }
                            @for f in &b.findings {
                                tr class=(f.verdict) {
                                    td { (f.verdict) }
                                    td {
                                        @match b.plots.iter().position(|p| p.name == f.name) {
                                            Some(i) => a href=(format!("#plot-{i}")) { (f.name) },
                                            None => (f.name),
                                        }
                                    }
                                    td.n { (f.baseline.map(fmt_value).unwrap_or_default()) }
                                    td.n { (f.value.map(fmt_value).unwrap_or_default()) }
                                    td.n { (f.change_pct.map(|c| format!("{c:+.2}%")).unwrap_or_default()) }
                                    td { (f.message) }
                                }
                            }
                        }
                    }
                    @if b.compared > 0 {
                        p { (b.compared) " gated metrics compared and unchanged: each plot says what it was compared against." }
                    }
                }
                section #plots {
                    h2 { "Plots" }
                    div.controls {
                        input #filter type="search" placeholder="filter: words of a metric's name, e.g. grid tetra primitive"
                            aria-label="filter the plots by name";
                        select #kind aria-label="kind of metric" {
                            option value="" { "every kind" }
                            @for (k, what) in KINDS {
                                @let n = b.plots.iter().filter(|p| p.kind == k).count();
                                @if n > 0 { option value=(k) { (what) " (" (n) ")" } }
                            }
                        }
                        label { input #flagged type="checkbox"; " only metrics with a finding" }
                        span #shown { (b.plots.len()) " of " (b.plots.len()) " plots" }
                    }
                    p.key {
                        "One point per night (x: the night's id in the history). Bars: the 95 % interval of the night's samples. "
                        span.mark.regression { "regression" } " "
                        span.mark.improvement { "improvement" } " "
                        span.mark.change { "change or suspect" }
                        ": findings of that night. Dashed line: a change point (E-divisive, p ≤ 0.01)."
                    }
                    div.grid { @for (i, p) in b.plots.iter().enumerate() { (plot(i, p)) } }
                }
                section #nights {
                    h2 { "Nights" }
                    table {
                        tr { th { "id" } th { "started" } th { "commit" } th { "machine" } th { "metrics" } th { "regressions" } th { "wall s" } th { "note" } }
                        @for n in &b.nights {
                            tr class=[(!n.plotted).then_some("other")] {
                                td.n { (n.id) }
                                td { (n.started_at) }
                                td { (commit(n)) }
                                td { code { (crate::output::head(&n.machine, 10)) } }
                                td.n { (n.metrics) }
                                td.n { (n.regressions) }
                                td.n { (format!("{:.0}", n.wall_s)) }
                                td { (n.note) }
                            }
                        }
                    }
                }
                div #board hidden data-board=(data) {}
                script { (PreEscaped(UPLOT_JS)) }
                script { (PreEscaped(SCRIPT)) }
            }
        }
    };
    markup.into_string()
}

#[cfg(test)]
mod tests {
    use super::super::board::Mark;
    use super::*;
    use crate::history::Finding;

    fn night(id: i64, url: Option<&str>) -> NightInfo {
        NightInfo {
            id,
            started_at: "2026-01-01T00:00:00Z".into(),
            commit: "cd8e501".into(),
            dirty: false,
            machine: "m".into(),
            url: url.map(String::from),
            regressions: 1,
            metrics: 1,
            wall_s: 1.0,
            note: "<b>note</b>".into(),
            plotted: true,
        }
    }

    #[test]
    fn text_from_the_history_is_escaped_and_links_are_kept() {
        let evil = "grid <script>alert(1)</script>/counter.x\"";
        let b = Board {
            suite: "s&<".into(),
            fingerprint: "fp".into(),
            latest: night(2, Some("https://example.org/c/cd8e501")),
            nights: vec![
                night(2, Some("https://example.org/c/cd8e501")),
                night(1, None),
            ],
            gates: vec!["counters: active <since> night 2".into()],
            findings: vec![Finding {
                name: evil.into(),
                verdict: "regression".into(),
                baseline: Some(1.0),
                value: Some(2.0),
                change_pct: Some(100.0),
                message: "a <i>message</i>".into(),
            }],
            compared: 0,
            plots: vec![Plot {
                name: evil.into(),
                kind: "counter".into(),
                unit: "count".into(),
                gated: true,
                x: vec![1, 2],
                y: vec![1.0, 2.0],
                lo: vec![None, None],
                hi: vec![None, None],
                n: vec![0, 0],
                marks: vec![Mark {
                    night: 2,
                    verdict: "regression".into(),
                    message: "</section>".into(),
                }],
                change_points: vec![],
                compared: None,
                gate: None,
            }],
        };
        let html = render(&b);
        assert!(!html.contains("<script>alert"));
        assert!(!html.contains("<b>note</b>") && !html.contains("<i>message"));
        assert!(html.contains("grid &lt;script&gt;alert(1)&lt;/script&gt;/counter.x&quot;"));
        assert!(html.contains("rtbench nightly: s&amp;&lt;"));
        // The one plot's section holds its mark; the message is an attribute, not markup.
        assert_eq!(html.matches("<section class=\"plot\"").count(), 1);
        assert!(html.contains(
            "<span class=\"mark regression\" title=\"&lt;/section&gt;\">regression night 2</span>"
        ));
        assert!(html.contains("<a class=\"commit\" href=\"https://example.org/c/cd8e501\""));
        // The board travels in an attribute: its JSON is escaped there, and whole.
        let at = html.find("data-board=\"").unwrap() + "data-board=\"".len();
        let raw = &html[at..at + html[at..].find('"').unwrap()];
        assert!(!raw.contains('<'));
        assert!(raw.contains("&lt;script&gt;"));
    }
}
