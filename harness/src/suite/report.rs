//! The suites' reports: Markdown tables, one JSON document, and plots (SVG and PNG, drawn by
//! rtbench-reports), written atomically into the output folder.

use super::hard::HardResults;
use super::tessellation::TessResults;
use crate::error::{input, Result};
use crate::output::write_atomic;
use rtbench_reports::plot::{self, Bar, BarPanel, Chart, LegendAt, Panel, Point, Series, XyPanel};
use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

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

/// The hard suite as Markdown.
pub fn hard_markdown(h: &HardResults) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Hard cases, acne and speed against error\n\n{} case rays in {} sets, answers in f64; {} engine variants; {:.0} s.\n",
        h.case_rays.iter().map(|(_, n, _)| n).sum::<usize>(),
        h.case_rays.len(),
        h.results.len(),
        h.seconds
    );
    s.push_str("## Summary (all cases)\n\n| engine | leaks (of must-hit) | invalid | false hits | misses | wrong hits | coplanar: not lowest id | t err median | p99 | max | acne, 7 standard scenes | Mrays/s |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for r in &h.results {
        let t = r.total("");
        let q = t.t_err();
        let a = r.acne_standard_total();
        let _ = writeln!(
            s,
            "| {} | {} / {} | {} | {} | {} | {} | {} | {} | {} | {} | {} / {} ({}) | {} |",
            r.variant.label(),
            t.leaks,
            t.must_hit,
            t.invalid,
            t.false_hits,
            t.misses,
            t.wrong_hits,
            r.total("coplanar").ties_not_lowest,
            e(q.median),
            e(q.p99),
            e(q.max),
            a.acne,
            a.secondary,
            e(a.rate()),
            r.speed
                .map(|s| format!("{:.2}", s.mrays_per_s()))
                .unwrap_or_else(|| "-".into())
        );
    }
    s.push_str("\n## Leaks on the closed meshes (rays that must hit)\n\n| engine |");
    let meshes: Vec<&str> = h
        .case_rays
        .iter()
        .map(|(c, _, _)| c.as_str())
        .filter(|c| c.starts_with("watertight"))
        .collect();
    for m in &meshes {
        let _ = write!(s, " {} |", m.trim_start_matches("watertight-"));
    }
    s.push_str("\n|---|");
    s.push_str(&"---|".repeat(meshes.len()));
    s.push('\n');
    for r in &h.results {
        let _ = write!(s, "| {} |", r.variant.label());
        for m in &meshes {
            let t = r.total(m);
            let _ = write!(s, " {} / {} |", t.leaks, t.must_hit);
        }
        s.push('\n');
    }
    s.push_str("\n## By category: false hits / misses / wrong hits, t error p99 (ambiguous rays, whose answer hangs on rounding, are not scored)\n\n| category | rays (ambiguous) |");
    for r in &h.results {
        let _ = write!(s, " {} |", r.variant.label());
    }
    s.push_str("\n|---|---|");
    s.push_str(&"---|".repeat(h.results.len()));
    s.push('\n');
    for (c, n, amb) in &h.case_rays {
        let _ = write!(s, "| {c} | {n} ({amb}) |");
        for r in &h.results {
            let t = r.total(c);
            let _ = write!(
                s,
                " {}/{}/{}, {} |",
                t.false_hits,
                t.misses,
                t.wrong_hits,
                e(t.t_err().p99)
            );
        }
        s.push('\n');
    }
    s.push_str(
        "\n## Acne: secondary rays that hit their own surface (acne / secondary rays)\n\n| scene |",
    );
    for r in &h.results {
        let _ = write!(s, " {} |", r.variant.label());
    }
    s.push_str("\n|---|");
    s.push_str(&"---|".repeat(h.results.len()));
    s.push('\n');
    let mut rows: Vec<String> = Vec::new();
    if let Some(r0) = h.results.first() {
        rows.extend(r0.acne_standard.iter().map(|(n, _)| n.clone()));
        rows.extend(r0.acne_cases.iter().map(|(n, _)| n.clone()));
    }
    for row in &rows {
        let _ = write!(s, "| {row} |");
        for r in &h.results {
            let a = r
                .acne_standard
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
                .unwrap_or_else(|| "-".into());
            let _ = write!(s, " {a} |");
        }
        s.push('\n');
    }
    let errors: Vec<String> = h
        .results
        .iter()
        .flat_map(|r| {
            r.errors
                .iter()
                .map(move |e| format!("- {}: {e}", r.variant.label()))
        })
        .collect();
    if !errors.is_empty() {
        s.push_str("\n## Builds that failed\n\n");
        s.push_str(&errors.join("\n"));
        s.push('\n');
    }
    s
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

fn hard_charts(h: &HardResults) -> Vec<Chart> {
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

fn write_charts(dir: &Path, charts: &[Chart]) -> Result<Vec<String>> {
    let plots = dir.join("plots");
    std::fs::create_dir_all(&plots)
        .map_err(|e| input(format!("{}: cannot create: {e}", plots.display())))?;
    let mut files = Vec::new();
    for c in charts {
        let svg = plot::svg(c).map_err(|e| input(format!("plot {}: {e}", c.stem)))?;
        let png = plot::png(c).map_err(|e| input(format!("plot {}: {e}", c.stem)))?;
        write_atomic(&plots.join(format!("{}.svg", c.stem)), |w| {
            w.write_all(svg.as_bytes())
        })?;
        write_atomic(&plots.join(format!("{}.png", c.stem)), |w| {
            w.write_all(&png)
        })?;
        files.push(format!("plots/{}.png", c.stem));
    }
    Ok(files)
}

fn write_doc(dir: &Path, stem: &str, md: &str, json: &Value, charts: &[Chart]) -> Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| input(format!("{}: cannot create: {e}", dir.display())))?;
    let files = write_charts(dir, charts)?;
    let mut md = md.to_string();
    md.push_str("\n## Plots\n\n");
    for f in files {
        let _ = writeln!(md, "![{f}]({f})");
    }
    write_atomic(&dir.join(format!("{stem}.md")), |w| {
        w.write_all(md.as_bytes())
    })?;
    let text = serde_json::to_string_pretty(json).expect("JSON values serialise");
    write_atomic(&dir.join(format!("{stem}.json")), |w| {
        w.write_all(text.as_bytes())
    })
}

/// DIR/hard.md, DIR/hard.json, DIR/plots/hard-*.svg and .png.
pub fn write_hard(dir: &Path, h: &HardResults) -> Result<()> {
    write_doc(
        dir,
        "hard",
        &hard_markdown(h),
        &hard_json(h),
        &hard_charts(h),
    )
}

/// The tessellation curves as Markdown.
pub fn tess_markdown(t: &TessResults) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Tessellation: curved primitives against `--tessellate RES`\n\nImage RMSE (colour channels 0…1, all {}² pixel corners) of each tessellated render against the same engine's curved render, and trace time (queries) relative to the curved render's; {:.0} s.\n",
        t.size + 1,
        t.seconds
    );
    s.push_str("| scene | engine | curved query s | RES: RMSE (query time ×) | first RES under 1e-3 RMSE | its time × | RES for 1e-3 by a power-law fit |\n|---|---|---|---|---|---|---|\n");
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
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {}{} | {} | {} | {} |",
            c.scene,
            c.engine,
            c.curved_s,
            pts.join("; "),
            c.stopped
                .as_ref()
                .map(|r| format!("; stopped: {r}"))
                .unwrap_or_default(),
            under
                .map(|p| p.res.to_string())
                .unwrap_or_else(|| "none ≤ 8".into()),
            under
                .map(|p| format!("{:.2}×", p.time_s / c.curved_s.max(1e-12)))
                .unwrap_or_else(|| "-".into()),
            super::tessellation::extrapolate(&c.points, 1e-3)
                .map(|r| format!("{r:.0}"))
                .unwrap_or_else(|| "-".into())
        );
    }
    s
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

fn tess_charts(t: &TessResults) -> Vec<Chart> {
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

/// DIR/tessellation.md, .json and plots/tessellation-*.
pub fn write_tessellation(dir: &Path, t: &TessResults) -> Result<()> {
    write_doc(
        dir,
        "tessellation",
        &tess_markdown(t),
        &tess_json(t),
        &tess_charts(t),
    )
}
