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

/// Each seed's document, cited as a paper, and where its engines live: the rows of the paper→code map.
const PAPERS: &[(&str, &str, &str)] = &[
    (
        "SPD",
        "Eric Haines, *A Proposal for Standard Graphics Environments*, IEEE CG&A 7(11), 1987; Standard Procedural Databases 3.14, README",
        "every engine; generators in `scenes/src/spd/`",
    ),
    (
        "000",
        "Koji Nakamaru, *Ray Tracing for Massive Data* (大規模データに対するレイトレーシング), PhD thesis, Keio University, 2002",
        "`engines/src/breadth_first/`, `engines/src/store/`, `engines/src/grid/` (presets `rss`, `rss-r`)",
    ),
    (
        "001",
        "Hidetaka Kimura, *Accelerating Ray Tracing with BVHs Suited to Parallel Computation*, master's thesis, JAIST, 2007",
        "`engines/src/bvh/` (`bvh2`, `bvh4`, `bvh8`)",
    ),
    (
        "002",
        "Yoshihiro Kanamori, *Introduction to CG by Ray Tracing: a uniform grid for ray–triangle-mesh intersection*, lecture handout, University of Tsukuba, 2014",
        "`engines/src/grid/`, `engines/src/geometry/dda.rs`",
    ),
    (
        "003",
        "Hitoshi Yamauchi, *A Study of Massively Parallel Processing for Image Generation* (画像生成用超並列処理に関する研究), PhD thesis, Tohoku University, 1997",
        "`engines/src/object_space/`",
    ),
];

/// The paper→code map as Markdown, generated from the registry (README.md holds a copy that a test
/// compares with this): one row per seed, then one per table.
pub fn markdown_map() -> String {
    let mut s = String::from("| seed | paper | engines |\n|---|---|---|\n");
    for (seed, paper, engines) in PAPERS {
        s.push_str(&format!("| {seed} | {paper} | {engines} |\n"));
    }
    s.push_str(
        "\n| id | seed | where in the paper | code (`harness/src/reproduce/`) | published figures | F | S | M | NR |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for t in TABLES {
        let n = |f: Fidelity| t.claims.iter().filter(|c| c.fidelity == f).count();
        s.push_str(&format!(
            "| `{}` | {} | {} | `{}.rs` | `data/published/{}.json` | {} | {} | {} | {} |\n",
            t.id,
            t.seed,
            t.source.replace('|', "\\|"),
            t.id.replace(['-', '.'], "_"),
            t.id,
            n(Fidelity::Faithful),
            n(Fidelity::Substituted),
            n(Fidelity::Model),
            n(Fidelity::NotReproducible),
        ));
    }
    s
}

/// `rtbench reproduce list [--json | --markdown]`.
pub fn list(as_json: bool, as_markdown: bool) -> Result<()> {
    if as_markdown {
        print!("{}", markdown_map());
        return Ok(());
    }
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
    // Rows loaded from saved steps were measured by earlier invocations; say so only then.
    clock.stamp(&mut output, checkpoint.loaded() > 0);
    writer::write(table, out, output, as_json)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// README.md's paper→code map is the registry's: regenerate it with
    /// `rtbench reproduce list --markdown` when a table is added or its claims change.
    #[test]
    fn the_readme_map_is_the_registry() {
        let readme =
            std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md"))
                .expect("README.md");
        let (begin, end) = (
            "<!-- reproduce-map: rtbench reproduce list --markdown -->\n",
            "<!-- /reproduce-map -->",
        );
        let start = readme
            .find(begin)
            .expect("README.md has no reproduce-map block")
            + begin.len();
        let stop = start
            + readme[start..]
                .find(end)
                .expect("README.md's reproduce-map block is not closed");
        assert_eq!(
            readme[start..stop].trim(),
            markdown_map().trim(),
            "README.md's paper→code map differs from the registry: paste `rtbench reproduce list --markdown` between its markers"
        );
        for t in TABLES {
            assert!(
                PAPERS.iter().any(|p| p.0 == t.seed),
                "{}: seed {} has no paper",
                t.id,
                t.seed
            );
        }
    }

    /// Every result of record in docs/results/ is a document `rtbench reproduce <id>` wrote, named
    /// for its id, and says how to regenerate it: the command, commit, date and machine.
    #[test]
    fn every_result_of_record_names_its_command() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/results");
        let mut seen = 0;
        for e in std::fs::read_dir(&dir).expect("docs/results") {
            let path = e.unwrap().path();
            if path.extension().is_none_or(|x| x != "md") {
                continue;
            }
            let stem = path.file_stem().unwrap().to_str().unwrap().to_string();
            assert!(
                TABLES.iter().any(|t| t.id == stem),
                "{}: not named for a reproduce id",
                path.display()
            );
            let text = std::fs::read_to_string(&path).unwrap();
            let want = format!("Regenerate: `rtbench reproduce {stem} ");
            assert!(
                text.contains(&want),
                "{}: does not say how to regenerate it ({want}…`)",
                path.display()
            );
            assert!(
                text.contains(", commit ")
                    && (text.contains("Measured on ") || text.contains("Written on ")),
                "{}: no commit, date or machine",
                path.display()
            );
            // The folder beside the checkout the seeds once lived in (spelled so that this file
            // does not cite it).
            let outside = concat!("..", "/shared");
            assert!(
                !text.contains(outside),
                "{}: cites a file outside the repository",
                path.display()
            );
            seen += 1;
        }
        assert!(seen > 0, "no results of record in {}", dir.display());
    }

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
