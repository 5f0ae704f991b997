//! `spd-stats`: the SPD 3.14 README's ray statistics of the seven standard scenes against the ray counts
//! of our workload, with each engine (docs/concepts.md). The README says a
//! classical ray tracer's counts "should be within about 10%".

use super::params::{ENGINES, THREADS};
use super::published::{self, Source};
use super::{environment, Claim, Ctx, Fidelity, Image, Kind, Output, Row, Runtime, Table, Verdict};
use crate::error::Result;
use crate::source::Source as SceneSource;
use crate::workload::{self, trace};
use rtbench_reports::{Document, Table as DocTable};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

pub const TABLE: Table = Table {
    id: "spd-stats",
    seed: "SPD",
    source: "README, ray statistics",
    about: "SPD 3.14 README: ray statistics of the seven standard scenes (counts within 10%)",
    runtime: Runtime {
        quick: "minutes",
        full: "minutes",
    },
    params: &[ENGINES, THREADS],
    claims: &[Claim {
        key: "counts-within-10pct",
        fidelity: Fidelity::Faithful,
        why: "",
    }],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/spd-stats.json");
const SIZE: u32 = 512;

#[derive(Deserialize)]
struct Published {
    source: Source,
    tolerance_rel: f64,
    columns: Vec<String>,
    rows: Vec<PublishedRow>,
}

#[derive(Deserialize)]
struct PublishedRow {
    scene: String,
    sf: u32,
    #[serde(flatten)]
    counts: BTreeMap<String, serde_json::Value>,
}

impl PublishedRow {
    fn count(&self, column: &str) -> f64 {
        self.counts
            .get(column)
            .and_then(|v| v.as_f64())
            .unwrap_or_else(|| panic!("spd-stats.json: {} has no {column}", self.scene))
    }
}

/// One published count beside ours.
#[derive(Serialize)]
struct Cell {
    published: f64,
    measured: f64,
    ratio: Option<f64>,
    within: bool,
}

#[derive(Serialize)]
struct Measured {
    scene: String,
    sf: u32,
    engine: String,
    compare: BTreeMap<String, Cell>,
    within: bool,
    rays: trace::RayStats,
    time_s: BTreeMap<&'static str, f64>,
    image: String,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    measured: Vec<Measured>,
    all_within: bool,
    quick: bool,
    environment: serde_json::Value,
}

fn count_of(stats: &trace::RayStats, column: &str) -> f64 {
    (match column {
        "eye" => stats.eye,
        "eye_hit" => stats.eye_hit,
        "shadow" => stats.shadow,
        "shadow_blocked" => stats.shadow_blocked,
        "reflect" => stats.reflect,
        "refract" => stats.refract,
        "total" => stats.total,
        other => panic!("spd-stats.json: unknown column {other}"),
    }) as f64
}

/// Compares one render's counts with a published row (pure).
fn compare(p: &Published, row: &PublishedRow, stats: &trace::RayStats) -> BTreeMap<String, Cell> {
    p.columns
        .iter()
        .map(|c| {
            let (pv, m) = (row.count(c), count_of(stats, c));
            let (ratio, within) = if pv == 0.0 {
                ((m == 0.0).then_some(1.0), m == 0.0)
            } else {
                (Some(m / pv), (m / pv - 1.0).abs() <= p.tolerance_rel)
            };
            let cell = Cell {
                published: pv,
                measured: m,
                ratio,
                within,
            };
            (c.clone(), cell)
        })
        .collect()
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let engines = ctx.params.engines()?;
    if engines.is_empty() {
        return Err(crate::error::input(
            "no engine to run (see `rtbench engines`)",
        ));
    }
    let pool = crate::measure::threads::pool(ctx.params.threads()?)?;
    let mut measured = Vec::new();
    let mut images = Vec::new();
    for row in &p.rows {
        let src = SceneSource::resolve(&row.scene, Some(row.sf), None, None)?;
        let prepared = workload::prepare(&src)?;
        for engine in &engines {
            let (e, build_s) = workload::build(engine, &prepared.input, vec![])?;
            eprintln!("spd-stats: {}{} with {engine} …", row.scene, row.sf);
            let r = pool.install(|| trace::render(&prepared.input.scene, e.as_ref(), SIZE, None));
            let image = format!("{}{}-{engine}.png", row.scene, row.sf);
            images.push(Image {
                path: format!("images/{image}"),
                pixels: r.pixels().to_vec(),
                size: SIZE,
            });
            let compare = compare(&p, row, &r.stats);
            let within = compare.values().all(|c| c.within);
            measured.push(Measured {
                scene: row.scene.clone(),
                sf: row.sf,
                engine: engine.clone(),
                compare,
                within,
                rays: r.stats,
                time_s: BTreeMap::from([("build", build_s), ("trace", r.trace_s)]),
                image,
            });
        }
    }
    let rows = rows(&p, &measured);
    let doc = document(&p, &measured, ctx.quick);
    let result = Result_ {
        id: ctx.id,
        published: raw,
        all_within: measured.iter().all(|m| m.within),
        measured,
        quick: ctx.quick,
        environment: environment(pool.current_num_threads()),
    };
    let mut out = Output::new(result, rows, doc);
    out.images = images;
    Ok(out)
}

/// One row per scene and engine: every column within the tolerance.
fn rows(p: &Published, measured: &[Measured]) -> Vec<Row> {
    measured
        .iter()
        .map(|m| {
            let worst = m
                .compare
                .iter()
                .filter_map(|(c, cell)| cell.ratio.map(|r| (c, r)))
                .max_by(|a, b| (a.1 - 1.0).abs().total_cmp(&(b.1 - 1.0).abs()));
            Row::new(
                "counts-within-10pct",
                format!("{}{} {}", m.scene, m.sf, m.engine),
                format!(
                    "{} within {:.0}%",
                    p.columns.join(", "),
                    p.tolerance_rel * 100.0
                ),
                worst.map_or("-".into(), |(c, r)| format!("worst {c}: ratio {r:.3}")),
                Kind::Count,
                Verdict::of(m.within),
            )
        })
        .collect()
}

fn document(p: &Published, measured: &[Measured], quick: bool) -> Document {
    let mut doc = Document::new("spd-stats: SPD ray statistics, published vs measured");
    doc.paragraph(format!(
        "Source: {}. Published counts 'should be within about 10%' for any classical ray tracer.",
        p.source.document
    ));
    doc.paragraph(format!(
        "Measured: `rtbench reproduce spd-stats` ({}), {SIZE}×{SIZE} pixels, {}² eye rays through pixel corners, depth 5, curved primitives.",
        if quick { "--quick: same experiment, it is already small" } else { "full" },
        SIZE + 1
    ));
    let mut header = vec!["scene".to_string(), "engine".to_string()];
    for c in &p.columns {
        header.extend([format!("{c} published"), "measured".into(), "ratio".into()]);
    }
    header.push(format!("within {:.0}%", p.tolerance_rel * 100.0));
    let mut t = DocTable::new("", &header.iter().map(String::as_str).collect::<Vec<_>>());
    for m in measured {
        let mut cells = vec![format!("{}{}", m.scene, m.sf), m.engine.clone()];
        for c in &p.columns {
            let cell = &m.compare[c];
            cells.extend([
                cell.published.to_string(),
                cell.measured.to_string(),
                format!("{:.3}", cell.ratio.unwrap_or(f64::INFINITY)),
            ]);
        }
        cells.push(if m.within {
            "yes".into()
        } else {
            "**no**".into()
        });
        t.push(cells);
    }
    doc.table(t);
    doc.paragraph(format!(
        "All within {:.0}%: {}.",
        p.tolerance_rel * 100.0,
        if measured.iter().all(|m| m.within) {
            "yes"
        } else {
            "no"
        }
    ));
    doc
}
