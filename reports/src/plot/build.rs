//! Which plots a results set gets, and what each holds.

use super::model::{Bar, BarPanel, Chart, LegendAt, Panel, Point, Series, XyPanel};
use crate::anchor::EMBREE;
use crate::number;
use crate::summary::{Row, Summary};
use std::collections::{BTreeMap, BTreeSet};

/// Every plot of the summary: time and memory vs SF for each scene family measured at several SFs,
/// Mrays/s by engine for each scene, and speed vs error over all checked runs.
pub fn charts(summary: &Summary) -> Vec<Chart> {
    let colors = colors(summary);
    let several_threads = summary.thread_counts().len() > 1;
    let mut charts = Vec::new();

    // Scene families at several SFs, per thread count.
    let mut families: BTreeMap<(&str, usize), Vec<&Row>> = BTreeMap::new();
    for r in summary.rows.iter().filter(|r| r.sf.is_some()) {
        families
            .entry((r.family.as_str(), r.threads))
            .or_default()
            .push(r);
    }
    for ((family, threads), rows) in &families {
        let sfs: BTreeSet<u32> = rows.iter().filter_map(|r| r.sf).collect();
        if sfs.len() < 2 {
            continue;
        }
        let suffix = thread_suffix(several_threads, *threads);
        charts.push(time_vs_sf(family, &suffix, rows, &colors));
        charts.push(memory_vs_sf(family, &suffix, rows, &colors));
    }

    // Mrays/s by engine, per scene and thread count.
    let mut scenes: BTreeMap<(usize, &str, Option<u32>, &str), Vec<&Row>> = BTreeMap::new();
    for r in &summary.rows {
        scenes
            .entry((r.threads, r.family.as_str(), r.sf, r.scene.as_str()))
            .or_default()
            .push(r);
    }
    for ((threads, _, _, scene), rows) in &scenes {
        let suffix = thread_suffix(several_threads, *threads);
        charts.push(mrays_by_engine(scene, &suffix, rows, &colors));
        if let Some(c) = ratio_by_engine(scene, &suffix, rows, &colors) {
            charts.push(c);
        }
    }

    if let Some(c) = speed_vs_error(summary, &colors) {
        charts.push(c);
    }
    charts
}

/// (file-name suffix, title suffix) when the set holds several thread counts.
fn thread_suffix(several: bool, threads: usize) -> (String, String) {
    if several {
        (
            format!("-t{threads}"),
            format!(", {threads} thread{}", if threads == 1 { "" } else { "s" }),
        )
    } else {
        (String::new(), String::new())
    }
}

/// Palette index per engine label: 0 for Embree, then 1, 2 … in label order, the same in every plot.
fn colors(summary: &Summary) -> BTreeMap<String, usize> {
    let mut next = 1;
    summary
        .labels()
        .into_iter()
        .map(|l| {
            let c = if l == EMBREE {
                0
            } else {
                next += 1;
                next - 1
            };
            (l, c)
        })
        .collect()
}

/// One series per engine label, points sorted by x, only where x and y are positive (log axes).
fn series_by_label(
    rows: &[&Row],
    colors: &BTreeMap<String, usize>,
    point: impl Fn(&Row) -> Option<Point>,
) -> Vec<Series> {
    let mut by_label: BTreeMap<(usize, &str), Vec<Point>> = BTreeMap::new();
    for r in rows {
        if let Some(p) =
            point(r).filter(|p| p.x > 0.0 && p.y > 0.0 && p.x.is_finite() && p.y.is_finite())
        {
            let color = colors.get(&r.label).copied().unwrap_or(0);
            by_label
                .entry((color, r.label.as_str()))
                .or_default()
                .push(p);
        }
    }
    by_label
        .into_iter()
        .map(|((color, name), mut points)| {
            points.sort_by(|a, b| a.x.total_cmp(&b.x));
            Series {
                name: name.to_string(),
                color,
                points,
            }
        })
        .collect()
}

fn sf_panel(title: &str, y_label: &str, series: Vec<Series>) -> Panel {
    let sfs: BTreeSet<u64> = series
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.x.to_bits()))
        .collect();
    let mut x_ticks: Vec<f64> = sfs.into_iter().map(f64::from_bits).collect();
    x_ticks.sort_by(f64::total_cmp);
    Panel::Xy(XyPanel {
        x_ticks,
        title: title.to_string(),
        x_label: "SF".to_string(),
        y_label: y_label.to_string(),
        x_log: true,
        y_log: true,
        lines: true,
        legend: LegendAt::UpperLeft,
        series,
    })
}

fn time_vs_sf(
    family: &str,
    suffix: &(String, String),
    rows: &[&Row],
    colors: &BTreeMap<String, usize>,
) -> Chart {
    let trace = series_by_label(rows, colors, |r| {
        Some(Point {
            x: r.sf? as f64,
            y: r.trace_s.median,
            y_range: Some((r.trace_s.min, r.trace_s.max)),
        })
    });
    let build = series_by_label(rows, colors, |r| {
        Some(Point {
            x: r.sf? as f64,
            y: r.build_s.median,
            y_range: Some((r.build_s.min, r.build_s.max)),
        })
    });
    Chart {
        stem: file_stem(&format!("time-vs-sf-{family}{}", suffix.0)),
        title: format!("{family}: time vs SF{}", suffix.1),
        panels: vec![
            sf_panel("trace (median, min–max)", "seconds", trace),
            sf_panel("build", "seconds", build),
        ],
    }
}

fn memory_vs_sf(
    family: &str,
    suffix: &(String, String),
    rows: &[&Row],
    colors: &BTreeMap<String, usize>,
) -> Chart {
    let structure = series_by_label(rows, colors, |r| {
        Some(Point {
            x: r.sf? as f64,
            y: r.structure_bytes as f64 / 1e6,
            y_range: None,
        })
    });
    let rss = series_by_label(rows, colors, |r| {
        Some(Point {
            x: r.sf? as f64,
            y: r.peak_rss_bytes as f64 / 1e6,
            y_range: None,
        })
    });
    Chart {
        stem: file_stem(&format!("memory-vs-sf-{family}{}", suffix.0)),
        title: format!("{family}: memory vs SF{}", suffix.1),
        panels: vec![
            sf_panel("structure", "MB", structure),
            sf_panel("peak RSS", "MB", rss),
        ],
    }
}

fn mrays_by_engine(
    scene: &str,
    suffix: &(String, String),
    rows: &[&Row],
    colors: &BTreeMap<String, usize>,
) -> Chart {
    let bars = rows
        .iter()
        .map(|r| Bar {
            label: r.label.clone(),
            value: r.mrays_per_s,
            color: colors.get(&r.label).copied().unwrap_or(0),
            note: match r.ratio_to_embree {
                Some(q) if r.engine != EMBREE => format!(
                    "{}  (time × {})",
                    number::sig(r.mrays_per_s, 3),
                    number::ratio(q)
                ),
                _ => number::sig(r.mrays_per_s, 3),
            },
            range: None,
        })
        .collect();
    Chart {
        stem: file_stem(&format!("mrays-{scene}{}", suffix.0)),
        title: format!("{scene}: rays per second{}", suffix.1),
        panels: vec![Panel::Bars(BarPanel {
            title: String::new(),
            value_label: "Mrays/s".to_string(),
            bars,
        })],
    }
}

/// Mrays/s against how far an engine's answers are from Embree's: 1 − hit agreement, and the 99th
/// percentile of the relative t error. A zero error cannot sit on a log axis: it is drawn at the floor
/// (half a ray in the ray count for agreement; a tenth of the smallest nonzero error for t).
fn speed_vs_error(summary: &Summary, colors: &BTreeMap<String, usize>) -> Option<Chart> {
    let checked: Vec<&Row> = summary
        .rows
        .iter()
        .filter(|r| r.check.is_some() && r.mrays_per_s > 0.0)
        .collect();
    if checked.is_empty() {
        return None;
    }
    let disagreement = series_by_label(&checked, colors, |r| {
        let c = r.check.as_ref()?;
        let floor = 0.5 / (c.rays.max(1) as f64);
        Some(Point {
            x: (1.0 - c.hit_agreement).max(floor),
            y: r.mrays_per_s,
            y_range: None,
        })
    });
    let t_floor = checked
        .iter()
        .filter_map(|r| r.check.as_ref().map(|c| c.t_rel_err_p99))
        .filter(|&e| e > 0.0)
        .fold(f64::INFINITY, f64::min);
    let t_floor = if t_floor.is_finite() {
        t_floor / 10.0
    } else {
        1e-9
    };
    let t_err = series_by_label(&checked, colors, |r| {
        let c = r.check.as_ref()?;
        Some(Point {
            x: c.t_rel_err_p99.max(t_floor),
            y: r.mrays_per_s,
            y_range: None,
        })
    });
    let panel = |title: &str, x_label: &str, series| {
        Panel::Xy(XyPanel {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: "Mrays/s".to_string(),
            x_log: true,
            y_log: true,
            x_ticks: Vec::new(),
            lines: false,
            legend: LegendAt::UpperRight,
            series,
        })
    };
    Some(Chart {
        stem: "speed-vs-error".to_string(),
        title: "speed vs error (against Embree)".to_string(),
        panels: vec![
            panel(
                "hit disagreement (0 drawn at 0.5/rays)",
                "1 − hit agreement",
                disagreement,
            ),
            panel(
                "t error (0 drawn at the floor)",
                "relative t error, p99",
                t_err,
            ),
        ],
    })
}

/// A name safe in any file system: letters, digits, `-`, `_`, `.`; anything else becomes `_`.
pub fn file_stem(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Trace time over Embree's by engine for one scene, each bar with its 95 % interval as an error
/// bar (and, where the run timed pairs, the paired ratio as a bar of its own); none without an
/// interval to draw.
fn ratio_by_engine(
    scene: &str,
    suffix: &(String, String),
    rows: &[&Row],
    colors: &BTreeMap<String, usize>,
) -> Option<Chart> {
    let mut bars = Vec::new();
    for r in rows.iter().filter(|r| r.engine != EMBREE) {
        let color = colors.get(&r.label).copied().unwrap_or(0);
        let mut push = |label: String, i: &crate::interval::Interval| {
            bars.push(Bar {
                label,
                value: i.estimate,
                color,
                note: format!("{} (n {})", i.text(), i.n),
                range: Some((i.lo, i.hi)),
            })
        };
        if let Some(i) = &r.ratio_interval {
            push(r.label.clone(), i);
        }
        if let Some(i) = r.paired_ratio.as_ref().and_then(|p| p.interval.as_ref()) {
            push(format!("{} paired", r.label), i);
        }
    }
    if bars.is_empty() {
        return None;
    }
    Some(Chart {
        stem: file_stem(&format!("ratio-{scene}{}", suffix.0)),
        title: format!("{scene}: trace time × Embree, 95 % interval{}", suffix.1),
        panels: vec![Panel::Bars(BarPanel {
            title: String::new(),
            value_label: "× Embree".to_string(),
            bars,
        })],
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn stems_are_plain() {
        assert_eq!(super::file_stem("mrays-balls4-tess3"), "mrays-balls4-tess3");
        assert_eq!(super::file_stem("mrays-my scene/x"), "mrays-my_scene_x");
    }
}
