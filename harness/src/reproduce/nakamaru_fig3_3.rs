//! `nakamaru-fig3.3`: seed 000's Fig. 3.3, registration at voxel boundaries. With the
//! registration count at 1, a ray registered in every marked voxel needs a pass per voxel of an
//! object's box it crosses; registered only where it enters a voxel boundary, one pass per box
//! entered. Measured as `nakamaru-fig3.2` measures (same scene, same 65,536 rays), with the
//! engine's `boundary` switch on and off; the answers must not change.

use super::nakamaru_fig3_2::{self as fig, Published, SCENE, SF};
use super::published;
use super::{Claim, Ctx, Fidelity, Kind, Output, Row, Runtime, Table, Verdict};
use crate::error::Result;
use rtbench_reports::plot::Chart;
use rtbench_reports::{Document, Table as DocTable};
use serde::Serialize;

pub const TABLE: Table = Table {
    id: "nakamaru-fig3.3",
    seed: "000",
    source: "Fig. 3.3",
    about: "000 (Nakamaru 2002) Fig. 3.3: passes with and without registration at voxel boundaries",
    runtime: Runtime {
        quick: "seconds",
        full: "seconds",
    },
    params: &[SCENE, SF],
    claims: &[
        Claim {
            key: "fewer-passes",
            fidelity: Fidelity::Substituted,
            why: "the thesis shows a worked 2-D example, not a scene: an SPD scene of our choice (default rings7, the one of balls4, mount6, tetra6, rings7 whose dynamic runs take 3 or more passes at both resolutions), 65,536 rays as Fig. 3.2",
        },
        Claim {
            key: "example-ratio",
            fidelity: Fidelity::NotReproducible,
            why: "the 1/3 and 2/5 belong to the figure's drawn example, whose geometry is lost with the figure; a whole scene's ratio is a different quantity, shown and not judged",
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/nakamaru-fig3.3.json");

#[derive(Serialize)]
struct Pair {
    res: u32,
    with: fig::Curve,
    without: fig::Curve,
    hits_equal: bool,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    scene: String,
    published: serde_json::Value,
    pairs: Vec<Pair>,
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let (prepared, rays, scene) = fig::setup(ctx)?;
    let mut pairs = Vec::new();
    for res in [20, 40] {
        eprintln!("{}: {scene} r={res} …", ctx.id);
        let mut with = fig::curve(&prepared, &rays, res, "fixed:1", true)?;
        let mut without = fig::curve(&prepared, &rays, res, "fixed:1", false)?;
        let hits_equal = with
            .hits
            .iter()
            .zip(&without.hits)
            .all(|(a, b)| a.object == b.object && a.t == b.t);
        with.hits.clear();
        without.hits.clear();
        pairs.push(Pair {
            res,
            with,
            without,
            hits_equal,
        });
    }
    let rows = rows(&pairs);
    let mut doc = Document::new("nakamaru-fig3.3: registration at voxel boundaries");
    doc.paragraph(format!(
        "Published: {} (machine: {}). Measured: `rtbench reproduce nakamaru-fig3.3` on {scene}, 65,536 rays (256×256 pixel centres), breadth-first engine, registration fixed:1, `boundary=on` vs `off`.",
        p.source.cite(),
        p.source.machine.as_deref().unwrap_or(""),
    ));
    let mut t = DocTable::new(
        "",
        &["r", "passes with", "passes without", "with/without", "registrations with", "without", "box tests with", "without", "answers equal"],
    );
    for q in &pairs {
        t.push(vec![
            q.res.to_string(),
            q.with.passes.to_string(),
            q.without.passes.to_string(),
            format!("{:.3}", q.with.passes as f64 / q.without.passes.max(1) as f64),
            q.with.registrations.to_string(),
            q.without.registrations.to_string(),
            q.with.box_tests.to_string(),
            q.without.box_tests.to_string(),
            q.hits_equal.to_string(),
        ]);
    }
    doc.table(t);
    let chart = Chart {
        stem: ctx.id.to_string(),
        title: format!("{scene}: surviving rays per pass with and without boundary registration (000 Fig. 3.3)"),
        panels: pairs
            .iter()
            .map(|q| {
                fig::xy(
                    &format!("fixed:1, r={}", q.res),
                    true,
                    vec![fig::series(&q.with, 1), fig::series(&q.without, 2)],
                )
            })
            .collect(),
    };
    let mut out = Output::new(
        Result_ {
            id: ctx.id,
            scene,
            published: raw,
            pairs,
        },
        rows,
        doc,
    );
    out.charts = vec![chart];
    Ok(out)
}

fn rows(pairs: &[Pair]) -> Vec<Row> {
    let mut rows = Vec::new();
    for q in pairs {
        let (a, b) = (q.with.passes, q.without.passes);
        rows.push(Row::new(
            "fewer-passes",
            format!("r={}", q.res),
            "with < without (3 -> 1, 5 -> 2)",
            format!("{a} vs {b}; answers equal: {}", q.hits_equal),
            Kind::Ordering,
            Verdict::of(a < b && q.hits_equal),
        ));
        rows.push(Row::new(
            "example-ratio",
            format!("r={}", q.res),
            "1/3 and 2/5 (worked example)",
            format!("{:.3}", a as f64 / b.max(1) as f64),
            Kind::Ratio,
            Verdict::Shown,
        ));
    }
    rows
}
