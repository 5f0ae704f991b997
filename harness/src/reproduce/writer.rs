//! The one writer of reproductions: the typed result as JSON, the document as Markdown and HTML, the
//! plots (SVG and PNG) and images, each written atomically into the output folder; then the Markdown
//! (or, with `--json`, the JSON) on stdout. Also serves the `check --suite` reports.

use super::table::{Output, Table};
use super::{Fidelity, Row};
use crate::error::{input, Result};
use crate::output::{print_json, write_atomic, write_png};
use rtbench_reports::plot::{self, Chart};
use rtbench_reports::{Document, Table as DocTable};
use serde_json::{json, Value};
use std::path::Path;

/// Gives each row its claim's fidelity (a row's own label may only be lower), and fails on a row
/// naming a claim its table does not declare: a broken table, not bad input. A claim's reason is
/// stated once, in [`claims_table`]; a row's note keeps only what is particular to it.
fn label(table: &Table, rows: &mut [Row]) {
    for r in rows.iter_mut() {
        let c = table
            .claims
            .iter()
            .find(|c| c.key == r.claim)
            .unwrap_or_else(|| panic!("{}: row names undeclared claim '{}'", table.id, r.claim));
        let own = r.fidelity.unwrap_or(c.fidelity);
        let rank = |f: Fidelity| Fidelity::ALL.iter().position(|x| *x == f);
        r.fidelity = Some(if rank(own) >= rank(c.fidelity) {
            own
        } else {
            c.fidelity
        });
    }
}

/// Each claim the rows test, once: its label, why (when not faithful), and how many rows test it.
fn claims_table(table: &Table, rows: &[Row]) -> DocTable {
    let mut t = DocTable::new(
        "Claims tested: fidelity and its reason",
        &["claim", "rows", "fidelity", "why"],
    );
    for c in table.claims {
        let n = rows.iter().filter(|r| r.claim == c.key).count();
        if n == 0 {
            continue;
        }
        // Rows labelled below their claim (a stand-in scene, one scene's setting) are counted
        // here, so the claim's label never speaks for rows that do not carry it.
        let lower: Vec<(Fidelity, usize)> = Fidelity::ALL
            .iter()
            .filter(|f| **f != c.fidelity)
            .map(|f| {
                let k = rows
                    .iter()
                    .filter(|r| r.claim == c.key && r.fidelity == Some(*f))
                    .count();
                (*f, k)
            })
            .filter(|(_, k)| *k > 0)
            .collect();
        let label = if lower.is_empty() {
            c.fidelity.name().to_string()
        } else {
            let own = n - lower.iter().map(|(_, k)| k).sum::<usize>();
            let rest: Vec<String> = lower
                .iter()
                .map(|(f, k)| format!("{k} {}", f.name()))
                .collect();
            format!(
                "{} (rows: {own} {}, {}; see their notes)",
                c.fidelity.name(),
                c.fidelity.name(),
                rest.join(", ")
            )
        };
        t.push(vec![
            c.key.to_string(),
            n.to_string(),
            label,
            c.why.to_string(),
        ]);
    }
    t
}

/// The rows as the document's last table.
fn rows_table(rows: &[Row]) -> DocTable {
    let mut t = DocTable::new(
        "Claims: published vs measured",
        &[
            "claim",
            "on",
            "published",
            "measured",
            "compares",
            "verdict",
            "fidelity",
            "note",
        ],
    );
    for r in rows {
        t.push(vec![
            r.claim.to_string(),
            r.subject.clone(),
            r.published.clone(),
            r.measured.clone(),
            serde_json::to_value(r.kind)
                .ok()
                .and_then(|v| v.as_str().map(String::from))
                .unwrap_or_default(),
            if r.verdict == super::Verdict::Fails {
                format!("**{}**", r.verdict.name())
            } else {
                r.verdict.name().to_string()
            },
            r.fidelity.map(|f| f.name()).unwrap_or("").to_string(),
            r.note.clone(),
        ]);
    }
    t
}

/// Writes `DIR/<id>.json`, `.md`, `.html`, `DIR/plots/*`, images; prints one of the first two.
pub fn write(table: &Table, out: &Path, mut o: Output, as_json: bool) -> Result<()> {
    label(table, &mut o.rows);
    let mut doc = o.doc;
    if !o.rows.is_empty() {
        doc.table(claims_table(table, &o.rows));
        doc.table(rows_table(&o.rows));
    }
    let counts: serde_json::Map<String, Value> = Fidelity::ALL
        .iter()
        .map(|f| {
            let n = o.rows.iter().filter(|r| r.fidelity == Some(*f)).count();
            (f.name().to_string(), json!(n))
        })
        .collect();
    let mut result = o.result;
    if let Value::Object(m) = &mut result {
        m.insert(
            "table".into(),
            json!({"seed": table.seed, "source": table.source, "about": table.about}),
        );
        m.insert(
            "rows".into(),
            serde_json::to_value(&o.rows).expect("rows serialise"),
        );
        m.insert("fidelity".into(), Value::Object(counts));
    }
    create_dir(out)?;
    for img in &o.images {
        let path = out.join(&img.path);
        if let Some(dir) = path.parent() {
            create_dir(dir)?;
        }
        write_png(&path, &img.pixels, img.size)?;
    }
    write_charts(out, &o.charts)?;
    for (stem, svg) in &o.svgs {
        write_text(&out.join("plots").join(format!("{stem}.svg")), svg)?;
    }
    write_document(out, table.id, &doc, &result)?;
    if as_json {
        print_json(&result);
    } else {
        print!("{}", doc.to_markdown());
    }
    Ok(())
}

/// `DIR/<stem>.json`, `.md` and `.html`.
pub fn write_document(out: &Path, stem: &str, doc: &Document, json: &Value) -> Result<()> {
    create_dir(out)?;
    write_atomic(&out.join(format!("{stem}.json")), |w| {
        serde_json::to_writer_pretty(&mut *w, json).map_err(std::io::Error::other)?;
        std::io::Write::write_all(w, b"\n")
    })?;
    write_text(&out.join(format!("{stem}.md")), &doc.to_markdown())?;
    write_text(&out.join(format!("{stem}.html")), &doc.to_html())
}

/// Each chart as `DIR/plots/<stem>.svg` and `.png`; returns the stems.
pub fn write_charts(out: &Path, charts: &[Chart]) -> Result<Vec<String>> {
    if charts.is_empty() {
        return Ok(Vec::new());
    }
    let dir = out.join("plots");
    create_dir(&dir)?;
    let mut stems = Vec::new();
    for chart in charts {
        let svg = plot::svg(chart).map_err(input)?;
        write_text(&dir.join(format!("{}.svg", chart.stem)), &svg)?;
        let png = plot::png(chart).map_err(input)?;
        write_atomic(&dir.join(format!("{}.png", chart.stem)), |w| {
            std::io::Write::write_all(w, &png)
        })?;
        stems.push(chart.stem.clone());
    }
    Ok(stems)
}

fn write_text(path: &Path, text: &str) -> Result<()> {
    if let Some(dir) = path.parent() {
        create_dir(dir)?;
    }
    write_atomic(path, |w| std::io::Write::write_all(w, text.as_bytes()))
}

fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| input(format!("{}: cannot create: {e}", dir.display())))
}

#[cfg(test)]
mod tests {
    use super::super::{find, Kind, Verdict};
    use super::*;

    /// A table's first claim that `pick` accepts, and a row of it named `s{i}`.
    fn claim_rows(
        id: &str,
        pick: fn(&super::super::Claim) -> bool,
        kind: Kind,
        verdict: Verdict,
    ) -> (
        &'static Table,
        &'static super::super::Claim,
        impl Fn(usize) -> Row,
    ) {
        let table = find(id).unwrap();
        let c = table.claims.iter().find(|c| pick(c)).unwrap();
        let row = move |i: usize| Row::new(c.key, format!("s{i}"), "p", "m", kind, verdict);
        (table, c, row)
    }

    #[test]
    fn a_claims_reason_is_stated_once_not_on_every_row() {
        let (table, c, row) = claim_rows(
            "yamauchi-cfbs",
            |c| c.fidelity != Fidelity::Faithful,
            Kind::Ratio,
            Verdict::Shown,
        );
        let mut rows: Vec<Row> = (0..3).map(row).collect();
        label(table, &mut rows);
        assert!(rows
            .iter()
            .all(|r| r.note.is_empty() && r.fidelity == Some(c.fidelity)));
        let md = {
            let mut d = Document::new("t");
            d.table(claims_table(table, &rows));
            d.table(rows_table(&rows));
            d.to_markdown()
        };
        assert_eq!(md.matches(c.why).count(), 1, "{md}");
    }

    #[test]
    fn a_claims_label_counts_the_rows_that_carry_a_lower_one() {
        let (table, _, row) = claim_rows(
            "nakamaru-4.2",
            |c| c.fidelity == Fidelity::Faithful,
            Kind::Count,
            Verdict::Holds,
        );
        let mut rows = vec![
            row(0),
            row(1).with_fidelity(Fidelity::Substituted, "a stand-in scene"),
            row(2).with_fidelity(Fidelity::Substituted, "a stand-in scene"),
        ];
        label(table, &mut rows);
        let t = claims_table(table, &rows);
        let md = {
            let mut d = Document::new("t");
            d.table(t);
            d.to_markdown()
        };
        assert!(
            md.contains("faithful (rows: 1 faithful, 2 substituted; see their notes)"),
            "{md}"
        );
    }
}
