//! `nakamaru-fig3.2`: seed 000's Fig. 3.2, surviving rays per pass of the breadth-first engine with
//! the registration count fixed at 1 and dynamic (inversely proportional to the rays in memory), at
//! grid resolutions 20 and 40, 65,536 initial rays.
//!
//! The thesis ran "some experimental data" (the scene is not named) and its curves are lost in the
//! text; what it states are their shapes, judged here one by one. The rays are the 256×256 pixel
//! centres of the scene's SPD camera (65,536, the figure's count), all in memory at once
//! (`rays=65536`), one intersection call: the engine's `bf_pass_NNN_rays` counts the rays in memory
//! at each pass. `nakamaru-fig3.3` (registration at voxel boundaries) shares this measurement.

use super::published::{self, Source};
use super::{Claim, Ctx, Fidelity, Kind, Output, Param, Row, Runtime, Table, Verdict};
use crate::error::{input, Result};
use crate::source::Source as SceneSource;
use crate::workload::{self, camera::Camera};
use rtbench_engines::breadth_first::config::BreadthFirstConfig;
use rtbench_engines::breadth_first::BreadthFirst;
use rtbench_engines::{Counters, Engine, Hit, Settings};
use rtbench_reports::plot::{Chart, LegendAt, Panel, Point, Series, XyPanel};
use rtbench_reports::{Document, Table as DocTable};
use serde::{Deserialize, Serialize};

pub const SCENE: Param = Param {
    key: "scene",
    help: "SPD scene traced (default rings; the thesis does not name its scene)",
};
pub const SF: Param = Param {
    key: "sf",
    help: "size factor of the scene (default: the scene's standard one)",
};

pub const TABLE: Table = Table {
    id: "nakamaru-fig3.2",
    seed: "000",
    source: "Fig. 3.2",
    about: "000 (Nakamaru 2002) Fig. 3.2: surviving rays per pass, registration fixed 1 vs dynamic, resolution 20 vs 40",
    runtime: Runtime {
        quick: "seconds",
        full: "seconds",
    },
    params: &[SCENE, SF],
    claims: &[
        Claim {
            key: "exponential-decay",
            fidelity: Fidelity::Substituted,
            why: "the thesis's scene is not named: an SPD scene of our choice (default rings7, the one of balls4, mount6, tetra6, rings7 whose dynamic runs take 3 or more passes at both resolutions)",
        },
        Claim {
            key: "linear-decay",
            fidelity: Fidelity::Substituted,
            why: "the thesis's scene is not named: an SPD scene of our choice (default rings7, the one of balls4, mount6, tetra6, rings7 whose dynamic runs take 3 or more passes at both resolutions)",
        },
        Claim {
            key: "more-passes-at-higher-r",
            fidelity: Fidelity::Substituted,
            why: "the thesis's scene is not named: an SPD scene of our choice (default rings7, the one of balls4, mount6, tetra6, rings7 whose dynamic runs take 3 or more passes at both resolutions)",
        },
        Claim {
            key: "passes-constant-in-r",
            fidelity: Fidelity::Substituted,
            why: "the thesis's scene is not named: an SPD scene of our choice (default rings7, the one of balls4, mount6, tetra6, rings7 whose dynamic runs take 3 or more passes at both resolutions)",
        },
        Claim {
            key: "dynamic-fewer-passes",
            fidelity: Fidelity::Substituted,
            why: "the thesis's scene is not named: an SPD scene of our choice (default rings7, the one of balls4, mount6, tetra6, rings7 whose dynamic runs take 3 or more passes at both resolutions)",
        },
        Claim {
            key: "curve-values",
            fidelity: Fidelity::NotReproducible,
            why: "the figure's curves are lost in the text extraction; only the caption and prose survive",
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/nakamaru-fig3.2.json");

#[derive(Deserialize)]
pub(super) struct Published {
    pub source: Source,
    #[serde(default)]
    rays: u32,
    #[serde(default)]
    resolutions: Vec<u32>,
}

/// One run: the rays in memory at each pass (index 0 = pass 1).
#[derive(Clone, Debug, Serialize)]
pub(super) struct Curve {
    pub label: String,
    pub res: u32,
    pub registration: String,
    pub boundary: bool,
    pub rays: u64,
    pub passes: u64,
    pub per_pass: Vec<u64>,
    pub box_tests: u64,
    pub registrations: u64,
    /// The answers, to compare runs (not serialised).
    #[serde(skip)]
    pub hits: Vec<Hit>,
}

/// The scene (from `scene`/`sf`) and its 256×256 pixel-centre rays.
pub(super) fn setup(ctx: &Ctx) -> Result<(workload::Prepared, Vec<rtbench_engines::Ray>, String)> {
    let scene = ctx.params.raw(SCENE.key).unwrap_or("rings").to_string();
    let sf = ctx.params.number::<u32>(SF.key, 1)?;
    let src = SceneSource::resolve(&scene, sf, None, None)?;
    let prepared = workload::prepare(&src)?;
    let rays = Camera::new(&prepared.input.scene.view).pixel_centre_rays(256, 256);
    Ok((prepared, rays, src.label()))
}

/// Traces `rays` once with the breadth-first engine at resolution `res`.
pub(super) fn curve(
    prepared: &workload::Prepared,
    rays: &[rtbench_engines::Ray],
    res: u32,
    registration: &str,
    boundary: bool,
) -> Result<Curve> {
    let config = BreadthFirstConfig::from_settings(Settings::new(
        "breadth-first",
        vec![
            ("res".into(), res.to_string()),
            ("registration".into(), registration.into()),
            ("rays".into(), rays.len().to_string()),
            ("boundary".into(), if boundary { "on" } else { "off" }.into()),
        ],
    ))?;
    let engine = BreadthFirst::from_scene(&prepared.input, config)?;
    let mut c = Counters::default();
    let mut hits = vec![Hit::MISS; rays.len()];
    engine.intersect(rays, &mut hits, &mut c);
    if let Some(f) = engine.failure() {
        return Err(input(f));
    }
    let passes = c.extra.get("bf_passes").copied().unwrap_or(0);
    let per_pass = (1..=passes)
        .map(|k| c.extra.get(&format!("bf_pass_{k:03}_rays")).copied().unwrap_or(0))
        .collect();
    Ok(Curve {
        label: format!(
            "{registration}, r={res}{}",
            if boundary { "" } else { ", no boundary" }
        ),
        res,
        registration: registration.into(),
        boundary,
        rays: rays.len() as u64,
        passes,
        per_pass,
        box_tests: c.box_tests,
        registrations: c.extra.get("bf_registrations").copied().unwrap_or(0),
        hits,
    })
}

/// R² of a least-squares line through (x, y).
fn r2(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    if n < 3.0 {
        return 0.0;
    }
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let syy: f64 = pts.iter().map(|p| (p.1 - my).powi(2)).sum();
    if sxx == 0.0 || syy == 0.0 {
        return 0.0;
    }
    sxy * sxy / (sxx * syy)
}

/// (R² of surviving vs pass, R² of ln surviving vs pass), over the passes run.
pub(super) fn fits(c: &Curve) -> (f64, f64) {
    let lin: Vec<(f64, f64)> = c
        .per_pass
        .iter()
        .enumerate()
        .map(|(k, &s)| ((k + 1) as f64, s as f64))
        .collect();
    let log: Vec<(f64, f64)> = lin.iter().map(|&(x, y)| (x, y.max(1.0).ln())).collect();
    (r2(&lin), r2(&log))
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    scene: String,
    published: serde_json::Value,
    curves: Vec<CurveOut>,
}

#[derive(Serialize)]
struct CurveOut {
    #[serde(flatten)]
    curve: Curve,
    r2_linear: f64,
    r2_log: f64,
    hits_equal_to_first: bool,
    /// Rays whose answer differs from the first run's, and of them those at the same distance
    /// (another object at a tie).
    hits_differ: u64,
    hits_differ_same_t: u64,
}

/// Registration at voxel boundaries, off: Fig. 3.2 precedes it in §3.2.
const BOUNDARY: bool = false;

/// Rays whose hit differs between two runs (other object, or t beyond 1e-5 relative), and how many
/// of those are ties (another object at the same t within 1e-5).
pub(super) fn differences(a: &[Hit], b: &[Hit]) -> (u64, u64) {
    let close = |x: f32, y: f32| x == y || (x - y).abs() <= 1e-5 * x.abs().max(y.abs());
    let (mut differ, mut tied) = (0, 0);
    for (x, y) in a.iter().zip(b) {
        if x.object == y.object && close(x.t, y.t) {
            continue;
        }
        differ += 1;
        if close(x.t, y.t) {
            tied += 1;
        }
    }
    (differ, tied)
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let (prepared, rays, scene) = setup(ctx)?;
    if rays.len() != p.rays as usize {
        return Err(input(format!("{}: {} rays, expected {}", ctx.id, rays.len(), p.rays)));
    }
    let mut curves = Vec::new();
    for &res in &p.resolutions {
        eprintln!("{}: {scene} r={res} …", ctx.id);
        // §3.2 measures Fig. 3.2 before it introduces registration at voxel boundaries (Fig. 3.3,
        // later in the section): every curve runs without it, as the thesis's did.
        curves.push(curve(&prepared, &rays, res, "fixed:1", BOUNDARY)?);
        // Fig. 3.2b: initial count r/20 (1 at 20, 2 at 40), then inversely proportional.
        let dynamic = format!("inverse:{}", (res / 20).max(1));
        curves.push(curve(&prepared, &rays, res, &dynamic, BOUNDARY)?);
    }
    let first = curves[0].hits.clone();
    let outs: Vec<CurveOut> = curves
        .into_iter()
        .map(|c| {
            let (l, g) = fits(&c);
            let (differ, tied) = differences(&c.hits, &first);
            let same = differ == 0;
            CurveOut {
                hits_differ: differ,
                hits_differ_same_t: tied,
                curve: Curve {
                    hits: Vec::new(),
                    ..c
                },
                r2_linear: l,
                r2_log: g,
                hits_equal_to_first: same,
            }
        })
        .collect();
    let rows = rows(&outs);
    let doc = document(&p, &scene, &outs);
    let chart = chart(ctx.id, &scene, &outs);
    let mut out = Output::new(
        Result_ {
            id: ctx.id,
            scene,
            published: raw,
            curves: outs,
        },
        rows,
        doc,
    );
    out.charts = vec![chart];
    Ok(out)
}

fn find(outs: &[CurveOut], fixed: bool, res: u32) -> Option<&CurveOut> {
    outs.iter()
        .find(|c| c.curve.res == res && c.curve.registration.starts_with("fixed") == fixed)
}

/// The thesis's stated shapes, one row each (pure).
fn rows(outs: &[CurveOut]) -> Vec<Row> {
    let mut rows = Vec::new();
    for c in outs {
        let fixed = c.curve.registration.starts_with("fixed");
        let (claim, holds, said) = if fixed {
            (
                "exponential-decay",
                c.r2_log >= 0.9 && c.r2_log > c.r2_linear,
                "exponential (p^n)",
            )
        } else {
            (
                "linear-decay",
                c.r2_linear >= 0.9 && c.r2_linear > c.r2_log,
                "linear",
            )
        };
        let measured = format!(
            "{} passes; R² linear {:.3}, R² of ln {:.3}",
            c.curve.passes, c.r2_linear, c.r2_log
        );
        rows.push(if c.curve.passes < 3 {
            Row::new(claim, c.curve.label.clone(), said, measured, Kind::Shape, Verdict::NotMeasured)
                .with_note("fewer than 3 passes: too few points to tell a shape")
        } else {
            Row::new(claim, c.curve.label.clone(), said, measured, Kind::Shape, Verdict::of(holds))
        });
    }
    let passes = |fixed, r| find(outs, fixed, r).map(|c| c.curve.passes);
    if let (Some(a), Some(b)) = (passes(true, 20), passes(true, 40)) {
        rows.push(Row::new(
            "more-passes-at-higher-r",
            "fixed:1",
            "passes(40) > passes(20)",
            format!("{b} vs {a}"),
            Kind::Ordering,
            Verdict::of(b > a),
        ));
    }
    if let (Some(a), Some(b)) = (passes(false, 20), passes(false, 40)) {
        let q = b as f64 / a.max(1) as f64;
        rows.push(Row::new(
            "passes-constant-in-r",
            "dynamic",
            "roughly constant in r",
            format!("passes(40)/passes(20) = {b}/{a} = {q:.2}"),
            Kind::Ratio,
            Verdict::of((2.0 / 3.0..=1.5).contains(&q)),
        ));
    }
    for r in [20, 40] {
        if let (Some(f), Some(d)) = (passes(true, r), passes(false, r)) {
            rows.push(Row::new(
                "dynamic-fewer-passes",
                format!("r={r}"),
                "dynamic < fixed 1",
                format!("{d} vs {f}"),
                Kind::Ordering,
                Verdict::of(d < f),
            ));
        }
    }
    rows.push(Row::new(
        "curve-values",
        "-",
        "lost (figure only)",
        "curves measured, see the plot",
        Kind::Shape,
        Verdict::NotMeasured,
    ));
    rows
}

fn document(p: &Published, scene: &str, outs: &[CurveOut]) -> Document {
    let mut doc = Document::new("nakamaru-fig3.2: surviving rays per pass");
    doc.paragraph(format!(
        "Published: {} (machine: {}). Measured: `rtbench reproduce nakamaru-fig3.2` on {scene}, 65,536 rays (256×256 pixel centres, all in memory), breadth-first engine with a cubic grid of r cells per axis, registration at voxel boundaries off (`boundary=off`: §3.2 introduces it after Fig. 3.2); fixed:1 and dynamic (inverse:N, N = 1 at r = 20, 2 at r = 40). Rays that meet no candidate voxel finish before pass 1. 'hits differ': rays whose answer differs from the first run's (fixed:1, r = 20), other object or distance; 'ties' of them: another object at the same distance.",
        p.source.cite(),
        p.source.machine.as_deref().unwrap_or(""),
    ));
    let mut t = DocTable::new(
        "",
        &["run", "passes", "pass 1", "pass 2", "pass 5", "pass 10", "R² linear", "R² ln", "box tests", "hits differ (ties)"],
    );
    for c in outs {
        let at = |k: usize| c.curve.per_pass.get(k - 1).map(|v| v.to_string()).unwrap_or("-".into());
        t.push(vec![
            c.curve.label.clone(),
            c.curve.passes.to_string(),
            at(1),
            at(2),
            at(5),
            at(10),
            format!("{:.3}", c.r2_linear),
            format!("{:.3}", c.r2_log),
            c.curve.box_tests.to_string(),
            format!("{} ({})", c.hits_differ, c.hits_differ_same_t),
        ]);
    }
    doc.table(t);
    doc
}

pub(super) fn xy(title: &str, y_log: bool, series: Vec<Series>) -> Panel {
    Panel::Xy(XyPanel {
        title: title.into(),
        x_label: "pass".into(),
        y_label: "surviving rays".into(),
        x_log: false,
        y_log,
        x_ticks: Vec::new(),
        lines: true,
        legend: LegendAt::UpperRight,
        series,
    })
}

/// The curve from pass 0 (all the rays, before rays with no candidate voxel leave).
pub(super) fn series(c: &Curve, color: usize) -> Series {
    let pts = std::iter::once(c.rays).chain(c.per_pass.iter().copied());
    Series {
        name: c.label.clone(),
        color,
        points: pts
            .enumerate()
            .map(|(k, s)| Point {
                x: k as f64,
                y: s.max(1) as f64,
                y_range: None,
            })
            .collect(),
    }
}

fn chart(id: &str, scene: &str, outs: &[CurveOut]) -> Chart {
    let pick = |fixed: bool| -> Vec<Series> {
        outs.iter()
            .filter(|c| c.curve.registration.starts_with("fixed") == fixed)
            .enumerate()
            .map(|(i, c)| series(&c.curve, i + 1))
            .collect()
    };
    Chart {
        stem: id.to_string(),
        title: format!("{scene}: surviving rays per pass (65,536 rays; 000 Fig. 3.2)"),
        panels: vec![
            xy("(a) registration fixed at 1 (log y)", true, pick(true)),
            xy("(b) dynamic registration", false, pick(false)),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(per_pass: Vec<u64>) -> Curve {
        Curve {
            label: String::new(),
            res: 20,
            registration: "fixed:1".into(),
            boundary: BOUNDARY,
            rays: 0,
            passes: per_pass.len() as u64,
            per_pass,
            box_tests: 0,
            registrations: 0,
            hits: Vec::new(),
        }
    }

    #[test]
    fn fits_tell_exponential_from_linear() {
        let exp = c((0..12).map(|k| (60000.0 * 0.6f64.powi(k)) as u64).collect());
        let (l, g) = fits(&exp);
        assert!(g > 0.99 && g > l, "{l} {g}");
        let lin = c((0..12).map(|k| 60000 - 5000 * k).collect());
        let (l, g) = fits(&lin);
        assert!(l > 0.99 && l > g, "{l} {g}");
    }
}
