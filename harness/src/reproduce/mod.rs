//! `rtbench reproduce`: published tables and claims, remeasured. One file per id, named for it; the
//! registry below is the only list of them.
//!
//! Each table is measure → analyse → export (as hyperfine splits a benchmark): its `run` measures into a
//! typed result, a pure function turns that into comparison [`Row`]s (published, measured, how they
//! compare, verdict, fidelity) and a [`Document`]; the one writer (`writer.rs`) renders every
//! reproduction to `DIR/<id>.md`, `.json`, `.html` (and its plots and images). Published figures live in
//! `data/published/<id>.json` with their source and are deserialised into typed structs
//! (`published.rs`).
//!
//! Adding a table: a file here, one line in [`TABLES`], its `data/published/<id>.json`.

mod claims;
mod params;
mod published;
mod writer;

mod nakamaru_3_2;
mod object_space_pass;
mod spd_stats;
mod yamauchi_cfbs;
mod yamauchi_dynamic_lb;
mod yamauchi_static_lb;

pub use claims::{Claim, Fidelity, Kind, Row, Verdict};
pub use params::{parse_set, Param, Params};

use crate::error::{input, Result};
use crate::output::print_json;
use rtbench_reports::plot::Chart;
use rtbench_reports::Document;
use serde_json::json;
use std::path::Path;

/// How long a table takes on this machine (2 cores): with `--quick`, and in full.
#[derive(Clone, Copy, Debug)]
pub struct Runtime {
    pub quick: &'static str,
    pub full: &'static str,
}

/// One reproducible table or claim set.
pub struct Table {
    pub id: &'static str,
    /// "000" … "003", or "SPD".
    pub seed: &'static str,
    /// Where in the source: table, figure, section.
    pub source: &'static str,
    pub about: &'static str,
    pub runtime: Runtime,
    /// The options it takes (anything else is refused).
    pub params: &'static [Param],
    /// The claims its rows test, each with its fidelity label.
    pub claims: &'static [Claim],
    pub run: fn(&Ctx) -> Result<Output>,
}

/// What a table's run is given.
pub struct Ctx<'a> {
    pub id: &'static str,
    pub quick: bool,
    pub params: &'a Params,
    /// The output folder (the writer fills it; a table only reads it, e.g. to resume).
    pub out: &'a Path,
}

/// A PNG to write: path relative to the output folder, RGB8 pixels, square size.
pub struct Image {
    pub path: String,
    pub pixels: Vec<u8>,
    pub size: u32,
}

/// What a table's run returns: its typed result (serialised), its comparison rows, its document, and
/// the plots and images the writer writes beside them.
pub struct Output {
    pub result: serde_json::Value,
    pub rows: Vec<Row>,
    pub doc: Document,
    pub charts: Vec<Chart>,
    /// Plots drawn by hand: (file stem, SVG text), written to `plots/<stem>.svg`.
    pub svgs: Vec<(String, String)>,
    pub images: Vec<Image>,
}

impl Output {
    pub fn new(result: impl serde::Serialize, rows: Vec<Row>, doc: Document) -> Output {
        Output {
            result: serde_json::to_value(result).expect("results serialise"),
            rows,
            doc,
            charts: Vec::new(),
            svgs: Vec::new(),
            images: Vec::new(),
        }
    }
}

/// Every table, in the order `reproduce list` shows them.
pub const TABLES: &[Table] = &[
    spd_stats::TABLE,
    nakamaru_3_2::TABLE,
    yamauchi_static_lb::TABLE,
    yamauchi_dynamic_lb::TABLE,
    yamauchi_cfbs::TABLE,
];

pub fn find(id: &str) -> Result<&'static Table> {
    TABLES.iter().find(|t| t.id == id).ok_or_else(|| {
        let ids: Vec<_> = TABLES.iter().map(|t| t.id).collect();
        input(format!("unknown table '{id}' (known: {})", ids.join(", ")))
    })
}

fn fidelity_counts(t: &Table) -> serde_json::Map<String, serde_json::Value> {
    Fidelity::ALL
        .iter()
        .map(|f| {
            let n = t.claims.iter().filter(|c| c.fidelity == *f).count();
            (f.name().to_string(), json!(n))
        })
        .collect()
}

/// `rtbench reproduce list [--json]`.
pub fn list(as_json: bool) -> Result<()> {
    if as_json {
        let rows: Vec<_> = TABLES
            .iter()
            .map(|t| {
                json!({"id": t.id, "seed": t.seed, "table": t.source, "description": t.about,
                    "fidelity": fidelity_counts(t), "quick": true,
                    "runtime": {"quick": t.runtime.quick, "full": t.runtime.full},
                    "params": t.params.iter().map(|p| json!({"key": p.key, "help": p.help})).collect::<Vec<_>>(),
                    "claims": t.claims.iter().map(|c| json!({"key": c.key, "fidelity": c.fidelity, "why": c.why})).collect::<Vec<_>>()})
            })
            .collect();
        print_json(&json!(rows));
        return Ok(());
    }
    println!(
        "{:<20} {:<4} {:<28} {:>3} {:>3} {:>3} {:>3}  {:<9} {:<9} about",
        "id", "seed", "table", "F", "S", "M", "NR", "--quick", "full"
    );
    for t in TABLES {
        let n = |f: Fidelity| t.claims.iter().filter(|c| c.fidelity == f).count();
        println!(
            "{:<20} {:<4} {:<28} {:>3} {:>3} {:>3} {:>3}  {:<9} {:<9} {}",
            t.id,
            t.seed,
            t.source,
            n(Fidelity::Faithful),
            n(Fidelity::Substituted),
            n(Fidelity::Model),
            n(Fidelity::NotReproducible),
            t.runtime.quick,
            t.runtime.full,
            t.about
        );
    }
    println!("\nF faithful, S substituted, M model, NR not reproducible: claims per table (`--json` lists them).");
    Ok(())
}

/// `rtbench reproduce <id> [--quick] --out DIR [options]`.
pub fn run(
    id: &str,
    quick: bool,
    out: &Path,
    pairs: Vec<(String, String)>,
    as_json: bool,
) -> Result<()> {
    let table = find(id)?;
    let params = Params::new(table.id, pairs, table.params)?;
    let ctx = Ctx {
        id: table.id,
        quick,
        params: &params,
        out,
    };
    let output = (table.run)(&ctx)?;
    writer::write(table, out, output, as_json)
}

/// The environment line every reproduction records.
pub fn environment(threads: usize) -> serde_json::Value {
    json!({"os": std::env::consts::OS, "arch": std::env::consts::ARCH, "threads": threads})
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_unique_and_name_their_files() {
        let mut ids: Vec<_> = TABLES.iter().map(|t| t.id).collect();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), TABLES.len());
        for t in TABLES {
            let file = format!("{}.rs", t.id.replace(['-', '.'], "_"));
            let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/reproduce");
            assert!(here.join(&file).exists(), "{} has no file {file}", t.id);
            let data = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../data/published")
                .join(format!("{}.json", t.id));
            assert!(data.exists(), "{} has no {}", t.id, data.display());
            assert!(!t.claims.is_empty(), "{} declares no claim", t.id);
            for c in t.claims {
                assert!(
                    c.fidelity == Fidelity::Faithful || !c.why.is_empty(),
                    "{}: claim {} is {} without a reason",
                    t.id,
                    c.key,
                    c.fidelity.name()
                );
            }
        }
    }
}
