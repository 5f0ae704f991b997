//! `kimura-3.2`: 001 (Kimura 2007) Table 3.2, the leaf slots B^D of an N-ary tree whose leaves all sit at
//! depth D, and the prose that reads it: the smallest B^D that holds cloister's 81,410 triangles is
//! 10^5, so B = 10 wastes the fewest slots. Exact arithmetic; the printed 12^6 is an erratum.

use super::published::{self, Source};
use super::{environment, Claim, Ctx, Fidelity, Kind, Output, Row, Runtime, Table, Verdict};
use crate::error::Result;
use rtbench_reports::{Document, Table as DocTable};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

pub const TABLE: Table = Table {
    id: "kimura-3.2",
    seed: "001",
    source: "Table 3.2",
    about: "001 (Kimura 2007) Table 3.2: leaf slots B^D per branching factor and depth (exact counts)",
    runtime: Runtime { quick: "seconds", full: "seconds" },
    params: &[],
    claims: &[
        Claim { key: "cell", fidelity: Fidelity::Faithful, why: "" },
        Claim { key: "smallest-sufficient", fidelity: Fidelity::Faithful, why: "" },
        Claim { key: "b10-fewest-slots", fidelity: Fidelity::Faithful, why: "" },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/kimura-3.2.json");

#[derive(Deserialize)]
struct Published {
    source: Source,
    triangles: u64,
    rows: Vec<PublishedRow>,
    smallest_sufficient: Vec<Sufficient>,
}
#[derive(Deserialize)]
struct PublishedRow {
    branching: u64,
    /// Depth (as a string key) → printed leaf count.
    leaves: BTreeMap<String, u64>,
}
#[derive(Deserialize, Serialize, Clone, Copy, PartialEq)]
struct Sufficient {
    branching: u64,
    depth: u32,
    leaves: u64,
}

#[derive(Serialize)]
struct Cell {
    branching: u64,
    depth: u32,
    printed: u64,
    computed: u64,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    cells: Vec<Cell>,
    smallest_sufficient: Vec<Sufficient>,
    quick: bool,
    environment: serde_json::Value,
}

/// The smallest depth D with B^D ≥ n.
fn smallest_sufficient(b: u64, n: u64) -> Sufficient {
    let (mut depth, mut leaves) = (0, 1u64);
    while leaves < n {
        depth += 1;
        leaves = leaves.saturating_mul(b);
    }
    Sufficient { branching: b, depth, leaves }
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let cells: Vec<Cell> = p
        .rows
        .iter()
        .flat_map(|r| {
            r.leaves.iter().map(move |(d, &printed)| {
                let depth: u32 = d.parse().expect("kimura-3.2.json: depth keys are numbers");
                Cell { branching: r.branching, depth, printed, computed: r.branching.pow(depth) }
            })
        })
        .collect();
    let ours: Vec<Sufficient> = p.rows.iter().map(|r| smallest_sufficient(r.branching, p.triangles)).collect();
    let rows = rows(&p, &cells, &ours);
    let doc = document(&p, &cells, &ours);
    let result = Result_ { id: ctx.id, published: raw, cells, smallest_sufficient: ours, quick: ctx.quick, environment: environment(1) };
    Ok(Output::new(result, rows, doc))
}

/// Every printed cell against B^D, the bold cells, and the argmin (pure).
fn rows(p: &Published, cells: &[Cell], ours: &[Sufficient]) -> Vec<Row> {
    let mut rows: Vec<Row> = cells
        .iter()
        .map(|c| {
            let r = Row::new("cell", format!("B={} D={}", c.branching, c.depth), c.printed.to_string(), c.computed.to_string(), Kind::Count, Verdict::of(c.printed == c.computed));
            if c.printed == c.computed { r } else { r.with_note("printed value is an erratum") }
        })
        .collect();
    for (o, pb) in ours.iter().zip(&p.smallest_sufficient) {
        rows.push(Row::new(
            "smallest-sufficient",
            format!("B={}", o.branching),
            format!("D={} ({})", pb.depth, pb.leaves),
            format!("D={} ({})", o.depth, o.leaves),
            Kind::Count,
            Verdict::of(o == pb),
        ));
    }
    let best = ours.iter().min_by_key(|s| s.leaves).map_or(0, |s| s.branching);
    rows.push(Row::new("b10-fewest-slots", format!("{} triangles", p.triangles), "B=10", format!("B={best}"), Kind::Ordering, Verdict::of(best == 10)));
    rows
}

fn document(p: &Published, cells: &[Cell], ours: &[Sufficient]) -> Document {
    let mut doc = Document::new("kimura-3.2: leaf slots B^D, 001 Table 3.2 vs computed");
    doc.paragraph(format!("Source: {}. {}", p.source.cite(), p.source.note.as_deref().unwrap_or("")));
    doc.paragraph("Measured: `rtbench reproduce kimura-3.2`: B^D in exact integer arithmetic, and per B the smallest depth whose B^D holds the triangle count.");
    let mut t = DocTable::new("", &["B", "D", "printed", "B^D", "equal"]).numeric(&[true, true, true, true, false]);
    for c in cells {
        t.push(vec![c.branching.to_string(), c.depth.to_string(), c.printed.to_string(), c.computed.to_string(), if c.printed == c.computed { "yes".into() } else { "**no (erratum)**".into() }]);
    }
    doc.table(t);
    let mut s = DocTable::new("", &["B", "smallest D", "B^D", "wasted slots"]).numeric(&[true, true, true, true]);
    for o in ours {
        s.push(vec![o.branching.to_string(), o.depth.to_string(), o.leaves.to_string(), (o.leaves - p.triangles).to_string()]);
    }
    doc.table(s);
    doc
}
