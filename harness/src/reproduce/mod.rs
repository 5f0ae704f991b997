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

mod checkpoint;
mod claims;
mod invocation;
mod models;
mod params;
mod published;
mod table;
mod writer;

mod engine_timing;
mod grid_runs;
mod load_balancing;
mod object_space_pass;
mod per_ray;

pub use checkpoint::Checkpoint;
pub use claims::{Claim, Fidelity, Kind, Row, Verdict};
pub use params::{parse_set, Param, Params};
pub use table::{environment, Ctx, Image, Output, Runtime, Table};
pub use writer::{write_charts, write_document};

use crate::error::{input, Result};
use crate::output::print_json;
use serde_json::json;
use std::path::Path;

/// Declares each table's module (named for its id) and lists its `TABLE`, in the order
/// `reproduce list` shows them: adding a table is one line here.
macro_rules! registry {
    ($($table:ident),* $(,)?) => {
        $(mod $table;)*
        /// Every table, in the order `reproduce list` shows them.
        pub const TABLES: &[Table] = &[$($table::TABLE),*];
    };
}

registry! {
    spd_stats,
    kimura_3_2,
    kimura_3_3,
    kimura_simd,
    kanamori_grid,
    nakamaru_3_1,
    nakamaru_3_2,
    nakamaru_3_3,
    nakamaru_4_1,
    nakamaru_4_2,
    nakamaru_4_3,
    nakamaru_fig4_4,
    nakamaru_fig3_2,
    nakamaru_fig3_3,
    yamauchi_static_lb,
    yamauchi_dynamic_lb,
    yamauchi_cfbs,
    yamauchi_radiosity,
}

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
    // The full runtime's head ("days", "about 1.5 CPU hours") in the column, its detail in
    // `--json`; the columns as wide as their longest entry, so that every line stays aligned.
    let head = |t: &Table| {
        let f = t.runtime.full;
        f[..f.find([';', '(']).unwrap_or(f.len())]
            .trim()
            .to_string()
    };
    let w = |f: &dyn Fn(&Table) -> String, title: &str| {
        TABLES
            .iter()
            .map(|t| f(t).chars().count())
            .max()
            .unwrap_or(0)
            .max(title.len())
    };
    let (wt, wq, wf) = (
        w(&|t| t.source.to_string(), "table"),
        w(&|t| t.runtime.quick.to_string(), "--quick"),
        w(&head, "full"),
    );
    let pad = |s: &str, n: usize| format!("{s}{}", " ".repeat(n.saturating_sub(s.chars().count())));
    println!(
        "{:<20} {:<4} {} {:>3} {:>3} {:>3} {:>3}  {} {} {:<6} about",
        "id",
        "seed",
        pad("table", wt),
        "F",
        "S",
        "M",
        "NR",
        pad("--quick", wq),
        pad("full", wf),
        "resume"
    );
    for t in TABLES {
        let n = |f: Fidelity| t.claims.iter().filter(|c| c.fidelity == f).count();
        println!(
            "{:<20} {:<4} {} {:>3} {:>3} {:>3} {:>3}  {} {} {:<6} {}",
            t.id,
            t.seed,
            pad(t.source, wt),
            n(Fidelity::Faithful),
            n(Fidelity::Substituted),
            n(Fidelity::Model),
            n(Fidelity::NotReproducible),
            pad(t.runtime.quick, wq),
            pad(&head(t), wf),
            if t.runtime.full.contains("resumable") {
                "yes"
            } else {
                "-"
            },
            t.about
        );
    }
    println!("\nF faithful, S substituted, M model, NR not reproducible: claims per table (`--json` lists them).");
    Ok(())
}

/// `rtbench reproduce <id> [--quick] --out DIR [--resume] [options]`.
pub fn run(
    id: &str,
    quick: bool,
    out: &Path,
    resume: bool,
    pairs: Vec<(String, String)>,
    as_json: bool,
) -> Result<()> {
    let table = find(id)?;
    let params = Params::new(table.id, pairs, table.params)?;
    let checkpoint = Checkpoint::open(out, table.id, resume)?;
    let ctx = Ctx {
        id: table.id,
        quick,
        params: &params,
        checkpoint: &checkpoint,
    };
    let clock = invocation::Invocation::start();
    let mut output = (table.run)(&ctx)?;
    clock.stamp(&mut output, resume);
    writer::write(table, out, output, as_json)?;
    Ok(())
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
