//! Time per ray against scene size for the three methods of seed 000 Chapter 4 (basic, S+G,
//! S+G+B), with each run's peak RSS beside it: our benchmark ("time per ray from 10^5 to
//! 10^9 objects on one plot; memory flat"). One chart per scene, from the rows a reproduction
//! measured (`nakamaru-4.1`, and `nakamaru-4.3`, whose rows reach 10^9 objects). The time is preprocessing + tracing over the eye rays, (size + 1)²
//! pixel corners, each with its whole ray tree (shadow, reflected, refracted rays): every row
//! saved by older versions kept no count of the other rays, and the eye rays are the same for the
//! three methods and every size.

use rtbench_reports::plot::{Chart, LegendAt, Panel, Point, Series, XyPanel};
use rtbench_reports::{Document, Table as DocTable};

/// One row: a scene at one size, each method's total seconds and peak RSS bytes. A method not
/// (yet) measured at this size has NaN seconds and 0 bytes: the plots leave its point out and the
/// table prints "-" (a 10^9-object row is measured one method an invocation).
pub struct SizePoint {
    pub scene: String,
    pub sf: u32,
    pub objects: u64,
    /// basic, S+G, S+G+B.
    pub seconds: [f64; 3],
    pub peak_rss: [u64; 3],
}

pub const METHODS: [&str; 3] = ["basic", "S+G", "S+G+B"];

/// Seconds per eye ray of an image of `size`.
pub fn per_eye_ray(seconds: f64, size: u32) -> f64 {
    let corners = (size as f64 + 1.0).powi(2);
    seconds / corners
}

/// The charts, one per scene with at least one point, stems `<id>-per-ray-<scene>`.
pub fn charts(id: &str, points: &[SizePoint], size: u32) -> Vec<Chart> {
    let mut scenes: Vec<&str> = points.iter().map(|p| p.scene.as_str()).collect();
    scenes.sort();
    scenes.dedup();
    scenes
        .into_iter()
        .map(|scene| {
            let mut ps: Vec<&SizePoint> = points.iter().filter(|p| p.scene == scene).collect();
            ps.sort_by_key(|p| p.objects);
            let series = |f: &dyn Fn(&SizePoint, usize) -> f64| -> Vec<Series> {
                (0..3)
                    .map(|k| Series {
                        name: METHODS[k].to_string(),
                        color: k + 1,
                        points: ps
                            .iter()
                            .filter(|p| p.seconds[k].is_finite())
                            .map(|p| Point {
                                x: p.objects as f64,
                                y: f(p, k),
                                y_range: None,
                            })
                            .collect(),
                    })
                    .collect()
            };
            Chart {
                stem: format!("{id}-per-ray-{scene}"),
                title: format!("{scene}: time per eye ray and memory against size (000 Ch.4)"),
                panels: vec![
                    Panel::Xy(XyPanel {
                        title: format!(
                            "{scene}: seconds per eye ray (with its ray tree), {size}×{size}"
                        ),
                        x_label: "objects".into(),
                        y_label: "seconds per eye ray".into(),
                        x_log: true,
                        y_log: true,
                        x_ticks: Vec::new(),
                        lines: true,
                        legend: LegendAt::UpperLeft,
                        series: series(&|p, k| per_eye_ray(p.seconds[k], size)),
                    }),
                    Panel::Xy(XyPanel {
                        title: format!("{scene}: peak RSS"),
                        x_label: "objects".into(),
                        y_label: "MiB".into(),
                        x_log: true,
                        y_log: false,
                        x_ticks: Vec::new(),
                        lines: true,
                        legend: LegendAt::LowerRight,
                        series: series(&|p, k| p.peak_rss[k] as f64 / 1048576.0),
                    }),
                ],
            }
        })
        .collect()
}

/// The benchmark in numbers: per scene, the time per eye ray at its smallest and largest
/// row and the growth between them, per method (the plots are `plots/<id>-per-ray-<scene>.svg`).
pub fn table(doc: &mut Document, points: &[SizePoint], size: u32) {
    let mut t = DocTable::new(
        "Time per eye ray (preprocessing + tracing over the (size+1)² eye rays, each with its ray tree): smallest and largest row per scene, growth = largest / smallest",
        &["scene", "objects", "basic µs", "S+G µs", "S+G+B µs", "growth basic / S+G / S+G+B"],
    );
    let mut scenes: Vec<&str> = points.iter().map(|p| p.scene.as_str()).collect();
    scenes.sort();
    scenes.dedup();
    for scene in scenes {
        let mut ps: Vec<&SizePoint> = points.iter().filter(|p| p.scene == scene).collect();
        ps.sort_by_key(|p| p.objects);
        let us = |p: &SizePoint, k: usize| {
            let s = p.seconds[k];
            if s.is_finite() {
                format!("{:.0}", 1e6 * per_eye_ray(s, size))
            } else {
                "-".into()
            }
        };
        let (a, b) = (ps[0], ps[ps.len() - 1]);
        let g = growth(points, scene);
        t.push(vec![
            scene.to_string(),
            if ps.len() > 1 {
                format!("{} → {}", a.objects, b.objects)
            } else {
                a.objects.to_string()
            },
            format!("{} → {}", us(a, 0), us(b, 0)),
            format!("{} → {}", us(a, 1), us(b, 1)),
            format!("{} → {}", us(a, 2), us(b, 2)),
            g.map_or("-".into(), |(_, _, g)| {
                g.map(|x| {
                    if x.is_finite() {
                        format!("{x:.2}")
                    } else {
                        "-".into()
                    }
                })
                .join(" / ")
            }),
        ]);
    }
    doc.table(t);
}

/// Growth of the time per ray between the smallest and largest size of a scene, per method (NaN
/// for a method missing at either end).
pub fn growth(points: &[SizePoint], scene: &str) -> Option<(u64, u64, [f64; 3])> {
    let mut ps: Vec<&SizePoint> = points.iter().filter(|p| p.scene == scene).collect();
    ps.sort_by_key(|p| p.objects);
    let (a, b) = (ps.first()?, ps.last()?);
    if a.objects == b.objects {
        return None;
    }
    Some((
        a.objects,
        b.objects,
        [0, 1, 2].map(|k| b.seconds[k] / a.seconds[k].max(1e-12)),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_chart_per_scene_with_three_methods_in_size_order() {
        let p = |scene: &str, objects, s: f64| SizePoint {
            scene: scene.into(),
            sf: 1,
            objects,
            seconds: [s, s / 2.0, s / 4.0],
            peak_rss: [1 << 20, 2 << 20, 3 << 20],
        };
        let pts = [
            p("mount", 100, 8.0),
            p("tetra", 10, 1.0),
            p("mount", 10, 2.0),
        ];
        let c = charts("x", &pts, 1);
        assert_eq!(c.len(), 2);
        assert_eq!(c[0].stem, "x-per-ray-mount");
        let Panel::Xy(t) = &c[0].panels[0] else {
            panic!()
        };
        assert_eq!(t.series.len(), 3);
        // 2×2 corners: 2 s over 4 eye rays, then 8 s.
        assert_eq!(t.series[0].points[0].x, 10.0);
        assert_eq!(t.series[0].points[0].y, 0.5);
        assert_eq!(t.series[2].points[1].y, 0.5);
        assert_eq!(growth(&pts, "mount"), Some((10, 100, [4.0, 4.0, 4.0])));
        assert_eq!(growth(&pts, "tetra"), None);
        // A size with S+G+B only: its other methods' points are left out, their growth NaN.
        let mut pts = pts;
        pts[0].seconds = [f64::NAN, f64::NAN, 2.0];
        let c = charts("x", &pts, 1);
        let Panel::Xy(t) = &c[0].panels[0] else {
            panic!()
        };
        assert_eq!(t.series[0].points.len(), 1);
        assert_eq!(t.series[2].points.len(), 2);
        let g = growth(&pts, "mount").unwrap().2;
        assert!(g[0].is_nan() && g[1].is_nan() && g[2] == 4.0, "{g:?}");
        let mut doc = Document::new("t");
        table(&mut doc, &pts, 1);
        let md = doc.to_markdown();
        assert!(md.contains("- / - / 4.00"), "{md}");
    }
}
