//! The suites' reports: a document (Markdown and HTML), one JSON document and plots, from the
//! measured results alone; the reproductions' writer writes them (`check --suite … --out DIR`).

use super::hard::HardResults;
use super::tessellation::TessResults;
use rtbench_reports::plot::{Bar, BarPanel, Chart, LegendAt, Panel, Point, Series, XyPanel};
use rtbench_reports::{Document, Table as DocTable};
use serde_json::{json, Value};
use std::collections::BTreeMap;

fn e(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:.1e}")
    }
}

/// Palette index per engine: 0 for Embree (as every rtbench plot), then in order.
fn colors<'a>(engines: impl Iterator<Item = &'a str>) -> BTreeMap<String, usize> {
    let mut m = BTreeMap::new();
    let mut next = 1;
    for e in engines {
        if !m.contains_key(e) {
            let c = if e == rtbench_reports::EMBREE {
                0
            } else {
                next += 1;
                next - 1
            };
            m.insert(e.to_string(), c);
        }
    }
    m
}

/// The hard suite as a document.
pub fn hard_document(h: &HardResults) -> Document {
    let mut doc = Document::new("Hard cases, acne and speed against error");
    doc.paragraph(format!(
        "{} case rays in {} sets, answers in f64; {} engine variants; {:.0} s.",
        h.case_rays.iter().map(|(_, n, _)| n).sum::<usize>(),
        h.case_rays.len(),
        h.results.len(),
        h.seconds
    ));
    let mut summary = DocTable::new(
        "Summary (all cases)",
        &[
            "engine",
            "leaks (of must-hit)",
            "invalid",
            "false hits",
            "misses",
            "wrong hits",
            "coplanar: not lowest id",
            "t err median",
            "p99",
            "max",
            "acne, 7 standard scenes",
            "Mrays/s",
        ],
    );
    for r in &h.results {
        let t = r.total("");
        let q = t.t_err();
        let a = r.acne_standard_total();
        summary.push(vec![
            r.variant.label(),
            format!("{} / {}", t.leaks, t.must_hit),
            t.invalid.to_string(),
            t.false_hits.to_string(),
            t.misses.to_string(),
            t.wrong_hits.to_string(),
            r.total("coplanar").ties_not_lowest.to_string(),
            e(q.median),
            e(q.p99),
            e(q.max),
            format!("{} / {} ({})", a.acne, a.secondary, e(a.rate())),
            r.speed
                .map(|s| format!("{:.2}", s.mrays_per_s()))
                .unwrap_or_else(|| "-".into()),
        ]);
    }
    doc.table(summary);
    let meshes: Vec<&str> = h
        .case_rays
        .iter()
        .map(|(c, _, _)| c.as_str())
        .filter(|c| c.starts_with("watertight"))
        .collect();
    let mut header = vec!["engine"];
    header.extend(meshes.iter().map(|m| m.trim_start_matches("watertight-")));
    let mut leaks = DocTable::new("Leaks on the closed meshes (rays that must hit)", &header);
    for r in &h.results {
        let mut row = vec![r.variant.label()];
        row.extend(meshes.iter().map(|m| {
            let t = r.total(m);
            format!("{} / {}", t.leaks, t.must_hit)
        }));
        leaks.push(row);
    }
    doc.table(leaks);
    let labels: Vec<String> = h.results.iter().map(|r| r.variant.label()).collect();
    let mut header = vec!["category", "rays (ambiguous)"];
    header.extend(labels.iter().map(String::as_str));
    let mut cats = DocTable::new(
        "By category: false hits / misses / wrong hits, t error p99 (ambiguous rays, whose answer hangs on rounding, are not scored)",
        &header,
    );
    for (c, n, amb) in &h.case_rays {
        let mut row = vec![c.clone(), format!("{n} ({amb})")];
        row.extend(h.results.iter().map(|r| {
            let t = r.total(c);
            format!(
                "{}/{}/{}, {}",
                t.false_hits,
                t.misses,
                t.wrong_hits,
                e(t.t_err().p99)
            )
        }));
        cats.push(row);
    }
    doc.table(cats);
    doc.table(acne_table(h, &labels));
    let errors: Vec<String> = h
        .results
        .iter()
        .flat_map(|r| {
            r.errors
                .iter()
                .map(move |e| format!("{}: {e}", r.variant.label()))
        })
        .collect();
    if !errors.is_empty() {
        doc.heading("Builds that failed");
        doc.list(errors);
    }
    doc
}

/// Acne per scene and variant: secondary rays that hit their own surface.
fn acne_table(h: &HardResults, labels: &[String]) -> DocTable {
    let mut header = vec!["scene"];
    header.extend(labels.iter().map(String::as_str));
    let mut t = DocTable::new(
        "Acne: secondary rays that hit their own surface (acne / secondary rays)",
        &header,
    );
    let mut rows: Vec<String> = Vec::new();
    if let Some(r0) = h.results.first() {
        rows.extend(r0.acne_standard.iter().map(|(n, _)| n.clone()));
        rows.extend(r0.acne_cases.iter().map(|(n, _)| n.clone()));
    }
    for row in &rows {
        let mut cells = vec![row.clone()];
        cells.extend(h.results.iter().map(|r| {
            r.acne_standard
                .iter()
                .chain(&r.acne_cases)
                .find(|(n, _)| n == row)
                .map(|(_, a)| {
                    if a.displaced > 0 {
                        format!("{} / {}, displaced {}", a.acne, a.secondary, a.displaced)
                    } else {
                        format!("{} / {}", a.acne, a.secondary)
                    }
                })
                .unwrap_or_else(|| "-".into())
        }));
        t.push(cells);
    }
    t
}

pub fn hard_json(h: &HardResults) -> Value {
    json!({
        "seconds": h.seconds,
        "case_sets": h.case_rays.iter().map(|(c, n, a)| json!({"category": c, "rays": n, "ambiguous": a})).collect::<Vec<_>>(),
        "variants": h.results.iter().map(|r| json!({
            "engine": r.variant.engine,
            "settings": r.variant.settings.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>(),
            "label": r.variant.label(),
            "total": r.total("").to_json(),
            "watertight": r.total("watertight").to_json(),
            "by_category": r.tallies.iter().map(|(c, t)| json!({"category": c, "tally": t.to_json()})).collect::<Vec<_>>(),
            "acne_standard_total": r.acne_standard_total().to_json(),
            "acne_standard": r.acne_standard.iter().map(|(n, a)| json!({"scene": n, "acne": a.to_json()})).collect::<Vec<_>>(),
            "acne_cases": r.acne_cases.iter().map(|(n, a)| json!({"category": n, "acne": a.to_json()})).collect::<Vec<_>>(),
            "speed": r.speed.map(|s| s.to_json()),
            "errors": r.errors,
            "seconds": r.seconds,
        })).collect::<Vec<_>>(),
    })
}

pub fn hard_charts(h: &HardResults) -> Vec<Chart> {
    let engine_colors = colors(h.results.iter().map(|r| r.variant.engine.as_str()));
    let leaks = Chart {
        stem: "hard-leaks".into(),
        title: "leaks and wrong answers on the hard cases".into(),
        panels: vec![
            Panel::Bars(BarPanel {
                title: "leaks on closed meshes".into(),
                value_label: "rays that passed through".into(),
                bars: h
                    .results
                    .iter()
                    .map(|r| {
                        let t = r.total("watertight");
                        Bar {
                            label: r.variant.label(),
                            value: t.leaks as f64,
                            color: engine_colors[&r.variant.engine],
                            note: format!("{} / {}", t.leaks, t.must_hit),
                            range: None,
                        }
                    })
                    .collect(),
            }),
            Panel::Bars(BarPanel {
                title: "false hits + misses + wrong hits, all cases".into(),
                value_label: "rays".into(),
                bars: h
                    .results
                    .iter()
                    .map(|r| {
                        let t = r.total("");
                        let n = t.false_hits + t.misses + t.wrong_hits;
                        Bar {
                            label: r.variant.label(),
                            value: n as f64,
                            color: engine_colors[&r.variant.engine],
                            note: n.to_string(),
                            range: None,
                        }
                    })
                    .collect(),
            }),
        ],
    };
    // Speed against error: one series per variant (a scatter), zero errors drawn at a floor.
    let with_speed: Vec<_> = h.results.iter().filter(|r| r.speed.is_some()).collect();
    let floor_rate = 0.5 / h.case_rays.iter().map(|(_, n, _)| *n).sum::<usize>().max(1) as f64;
    let t_floor = with_speed
        .iter()
        .map(|r| r.total("").t_err().p99)
        .filter(|&x| x > 0.0)
        .fold(f64::INFINITY, f64::min);
    let t_floor = if t_floor.is_finite() {
        t_floor / 10.0
    } else {
        1e-9
    };
    let labels: Vec<String> = with_speed.iter().map(|r| r.variant.label()).collect();
    let label_colors = colors(labels.iter().map(|l| l.as_str()));
    let series = |x: &dyn Fn(&super::hard::VariantResult) -> f64| -> Vec<Series> {
        with_speed
            .iter()
            .map(|r| Series {
                name: r.variant.label(),
                color: label_colors[&r.variant.label()],
                points: vec![Point {
                    x: x(r),
                    y: r.speed.map(|s| s.mrays_per_s()).unwrap_or(0.0),
                    y_range: None,
                }],
            })
            .collect()
    };
    let panel = |title: &str, x_label: &str, series: Vec<Series>| {
        Panel::Xy(XyPanel {
            title: title.into(),
            x_label: x_label.into(),
            y_label: "Mrays/s (teapot6 + gears2)".into(),
            x_log: true,
            y_log: true,
            x_ticks: Vec::new(),
            lines: false,
            legend: LegendAt::LowerRight,
            series,
        })
    };
    let speed = Chart {
        stem: "hard-speed-vs-error".into(),
        title: "speed against error, every engine and kernel variant".into(),
        panels: vec![
            panel(
                "wrong answers on the hard cases (0 drawn at 0.5/rays)",
                "fraction of case rays answered wrongly",
                series(&|r| r.total("").wrong_rate().max(floor_rate)),
            ),
            panel(
                "t error against f64 (0 drawn at the floor)",
                "relative t error, p99",
                series(&|r| r.total("").t_err().p99.max(t_floor)),
            ),
        ],
    };
    vec![leaks, speed]
}

/// The tessellation curves as a document.
pub fn tess_document(t: &TessResults) -> Document {
    let mut doc = Document::new("Tessellation: curved primitives against `--tessellate RES`");
    doc.paragraph(format!(
        "Image RMSE (colour channels 0…1, all {}² pixel corners) of each tessellated render against the same engine's curved render, and trace time (queries) relative to the curved render's; {:.0} s.",
        t.size + 1,
        t.seconds
    ));
    let mut table = DocTable::new(
        "",
        &[
            "scene",
            "engine",
            "curved query s",
            "RES: RMSE (query time ×)",
            "first RES under 1e-3 RMSE",
            "its time ×",
            "RES for 1e-3 by a power-law fit",
        ],
    );
    for c in &t.curves {
        let pts: Vec<String> = c
            .points
            .iter()
            .map(|p| {
                format!(
                    "{}: {} ({:.2}×)",
                    p.res,
                    e(p.rmse),
                    p.time_s / c.curved_s.max(1e-12)
                )
            })
            .collect();
        let under = c.points.iter().find(|p| p.rmse < 1e-3);
        table.push(vec![
            c.scene.clone(),
            c.engine.clone(),
            format!("{:.3}", c.curved_s),
            format!(
                "{}{}",
                pts.join("; "),
                c.stopped
                    .as_ref()
                    .map(|r| format!("; stopped: {r}"))
                    .unwrap_or_default()
            ),
            under
                .map(|p| p.res.to_string())
                .unwrap_or_else(|| "none ≤ 8".into()),
            under
                .map(|p| format!("{:.2}×", p.time_s / c.curved_s.max(1e-12)))
                .unwrap_or_else(|| "-".into()),
            super::tessellation::extrapolate(&c.points, 1e-3)
                .map(|r| format!("{r:.0}"))
                .unwrap_or_else(|| "-".into()),
        ]);
    }
    doc.table(table);
    doc
}

pub fn tess_json(t: &TessResults) -> Value {
    json!({
        "size": t.size,
        "seconds": t.seconds,
        "curves": t.curves.iter().map(|c| json!({
            "scene": c.scene, "engine": c.engine, "curved_trace_s": c.curved_s,
            "points": c.points.iter().map(|p| json!({"res": p.res, "rmse": p.rmse, "trace_s": p.time_s, "triangles": p.triangles})).collect::<Vec<_>>(),
            "first_res_under_1e-3": c.points.iter().find(|p| p.rmse < 1e-3).map(|p| p.res),
            "res_for_1e-3_power_law": super::tessellation::extrapolate(&c.points, 1e-3),
            "stopped": c.stopped,
        })).collect::<Vec<_>>(),
    })
}

pub fn tess_charts(t: &TessResults) -> Vec<Chart> {
    let colors = colors(t.curves.iter().map(|c| c.engine.as_str()));
    let mut scenes: Vec<&str> = t.curves.iter().map(|c| c.scene.as_str()).collect();
    scenes.dedup();
    let panel =
        |scene: &str, y_label: &str, y: &dyn Fn(&super::tessellation::TessPoint, f64) -> f64| {
            Panel::Xy(XyPanel {
                title: scene.into(),
                x_label: "RES".into(),
                y_label: y_label.into(),
                x_log: false,
                y_log: true,
                x_ticks: (1..=8).map(f64::from).collect(),
                lines: true,
                legend: LegendAt::UpperRight,
                series: t
                    .curves
                    .iter()
                    .filter(|c| c.scene == scene)
                    .map(|c| Series {
                        name: c.engine.clone(),
                        color: colors[&c.engine],
                        points: c
                            .points
                            .iter()
                            .map(|p| Point {
                                x: p.res as f64,
                                y: y(p, c.curved_s).max(1e-9),
                                y_range: None,
                            })
                            .collect(),
                    })
                    .collect(),
            })
        };
    vec![
        Chart {
            stem: "tessellation-rmse".into(),
            title: "image RMSE of --tessellate RES against the curved render".into(),
            panels: scenes
                .iter()
                .map(|s| panel(s, "RMSE", &|p, _| p.rmse))
                .collect(),
        },
        Chart {
            stem: "tessellation-time".into(),
            title: "trace time of --tessellate RES relative to the curved render".into(),
            panels: scenes
                .iter()
                .map(|s| panel(s, "time / curved time", &|p, c| p.time_s / c.max(1e-12)))
                .collect(),
        },
    ]
}
