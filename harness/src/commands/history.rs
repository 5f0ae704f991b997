//! `rtbench history list|show|export|replay|check|dashboard`: the nights a history holds, read
//! back, exported, replayed through the nightly's detection, checked, or drawn.

use crate::error::{input, Failure, Result};
use crate::history::{Finding, History};
use crate::nightly::{
    compare, fmt_secs, gate_findings, gates_clause, is_bad, suite, summary_markdown, suspects_of,
};
use std::collections::BTreeMap;

/// `rtbench history list|show|export|dashboard`.
pub fn run(c: &crate::cli::HistoryCommand) -> Result<()> {
    use crate::cli::HistoryCommand as H;
    match c {
        H::List { db, json } => {
            let h = History::open_read(db)?;
            let runs = h.runs(None, None)?;
            if *json {
                crate::output::print_json(&serde_json::to_value(&runs).expect("rows serialise"));
            } else {
                println!("| id | started | suite | commit | machine | metrics | regressions | wall | note |");
                println!("|---:|---|---|---|---|---:|---:|---:|---|");
                for r in runs {
                    println!(
                        "| {} | {} | {} | {}{} | {} | {} | {} | {} | {} |",
                        r.id,
                        r.started_at,
                        r.suite,
                        crate::output::head(&r.git_commit, 10),
                        if r.git_dirty { "+" } else { "" },
                        crate::output::head(&r.fingerprint, 10),
                        r.metrics,
                        r.regressions,
                        fmt_secs(r.wall_s),
                        r.note.unwrap_or_default()
                    );
                }
            }
            Ok(())
        }
        H::Show { db, run, json } => {
            let h = History::open_read(db)?;
            let id = resolve_run(&h, run.as_deref(), db)?;
            let row = h
                .run(id)?
                .ok_or_else(|| input(format!("{}: no night {id}", db.display())))?;
            let metrics = h.metrics(id)?;
            let findings = h.findings(id)?;
            if *json {
                let env: serde_json::Value = h
                    .env_json(id)?
                    .and_then(|t| serde_json::from_str(&t).ok())
                    .unwrap_or_default();
                crate::output::print_json(&serde_json::json!({
                    "run": row, "environment": env, "metrics": metrics, "findings": findings
                }));
            } else {
                print!(
                    "{}",
                    summary_markdown(
                        &row.suite,
                        &row.git_commit,
                        row.wall_s,
                        // The baseline the night had, as its gate rows recorded it (none on
                        // nights written before they were kept).
                        findings
                            .iter()
                            .find(|f| f.verdict == "gate")
                            .and_then(|f| f.baseline)
                            .map(|n| n as usize),
                        &metrics,
                        &findings
                    )
                );
            }
            Ok(())
        }
        H::Export { db, format, run } => {
            let h = History::open_read(db)?;
            match format.as_str() {
                "csv" => print!("{}", crate::history::export::csv(&h)?),
                "bmf" => {
                    let id = resolve_run(&h, run.as_deref(), db)?;
                    crate::output::print_json(&crate::history::export::bmf(&h.metrics(id)?));
                }
                f => return Err(input(format!("--format '{f}': expected csv or bmf"))),
            }
            Ok(())
        }
        H::Replay { db, suite, json } => replay(db, suite, *json),
        H::Check { db } => {
            let h = History::open_read(db)?;
            let problems = h.problems()?;
            let runs = h.runs(None, None)?;
            let metrics: usize = runs.iter().map(|r| r.metrics as usize).sum();
            if problems.is_empty() {
                println!(
                    "{}: whole (integrity_check ok, schema {}, every table and column, every night's metrics); {} nights, {metrics} metrics",
                    db.display(),
                    crate::history::SCHEMA,
                    runs.len()
                );
                return Ok(());
            }
            for p in &problems {
                println!("{}: {p}", db.display());
            }
            Err(Failure::Check(format!(
                "{}: not whole: {}",
                db.display(),
                problems[0]
            )))
        }
        H::Dashboard {
            db,
            out,
            commit_url,
        } => {
            if let Some(t) = commit_url {
                crate::history::dashboard::check_commit_url(t)?;
            }
            let h = History::open_read(db)?;
            crate::history::dashboard::write(&h, out, commit_url.as_deref())?;
            eprintln!("dashboard: {}", out.join("index.html").display());
            Ok(())
        }
    }
}

/// `rtbench history replay`: every night of the suite, in order, compared (by [`compare`], as
/// `rtbench nightly` compares) with the nights of the same machine before it.
fn replay(db: &std::path::Path, suite_file: &std::path::Path, json: bool) -> Result<()> {
    let s = suite::load(suite_file)?;
    let h = History::open_read(db)?;
    let runs = h.runs(None, Some(&s.name))?;
    if runs.is_empty() {
        return Err(input(format!(
            "{}: no night of suite '{}' in the history",
            db.display(),
            s.name
        )));
    }
    let mut rows = Vec::new();
    let mut alarmed = 0;
    let mut previous: BTreeMap<i64, std::collections::BTreeSet<String>> = BTreeMap::new();
    for (i, r) in runs.iter().enumerate() {
        let prev: Vec<_> = runs[..i]
            .iter()
            .filter(|p| p.fingerprint == r.fingerprint)
            .collect();
        let window = &prev[prev.len().saturating_sub(s.baseline_nights)..];
        let baseline = window
            .iter()
            .map(|p| h.metrics(p.id))
            .collect::<Result<Vec<_>>>()?;
        // The suspects of the night before, as this replay found them (the live run read them
        // from the history the same way).
        let suspects = match window.last() {
            Some(p) => previous.get(&p.id).cloned().unwrap_or_default(),
            None => Default::default(),
        };
        let metrics = h.metrics(r.id)?;
        let findings = compare(&s, &metrics, &baseline, &suspects);
        previous.insert(r.id, suspects_of(&findings));
        let earlier: Vec<i64> = prev.iter().map(|p| p.id).collect();
        let gates = gate_findings(&s, &metrics, &earlier, window.len());
        let bad: Vec<&Finding> = findings.iter().filter(|f| is_bad(f)).collect();
        if !bad.is_empty() {
            alarmed += 1;
        }
        if !json {
            println!(
                "night {} ({}{} baseline nights; {}): {}",
                r.id,
                r.note
                    .as_deref()
                    .filter(|n| !n.is_empty())
                    .map(|n| format!("{n}, "))
                    .unwrap_or_default(),
                window.len(),
                gates_clause(&gates),
                if bad.is_empty() {
                    "no regression".to_string()
                } else {
                    bad.iter()
                        .map(|f| f.message.as_str())
                        .collect::<Vec<_>>()
                        .join("; ")
                }
            );
        }
        rows.push(serde_json::json!({
            "id": r.id,
            "note": r.note,
            "baseline_nights": window.len(),
            "gates": gates.iter().map(|f| &f.message).collect::<Vec<_>>(),
            "recorded_regressions": r.regressions,
            "regressions": bad.iter().map(|f| &f.message).collect::<Vec<_>>(),
            "suspects": findings.iter().filter(|f| f.verdict == "suspect").map(|f| &f.message).collect::<Vec<_>>(),
        }));
    }
    let recorded = runs.iter().filter(|r| r.regressions > 0).count();
    if json {
        crate::output::print_json(&serde_json::json!({
            "suite": s.name,
            "nights": runs.len(),
            "nights_with_regression": alarmed,
            "nights_with_regression_recorded": recorded,
            "nights_detail": rows,
        }));
    } else {
        println!(
            "replay: {} nights of suite '{}': {alarmed} with a reported regression ({recorded} when they ran)",
            runs.len(),
            s.name
        );
    }
    Ok(())
}

fn resolve_run(h: &History, run: Option<&str>, db: &std::path::Path) -> Result<i64> {
    match run {
        None | Some("latest") => h
            .runs(None, None)?
            .last()
            .map(|r| r.id)
            .ok_or_else(|| input(format!("{}: the history holds no night", db.display()))),
        Some(s) => {
            let id = s
                .parse::<i64>()
                .map_err(|_| input(format!("--run '{s}': expected a night's id or 'latest'")))?;
            // A night that is not there is an error, not an empty answer.
            h.run(id)?
                .map(|r| r.id)
                .ok_or_else(|| input(format!("{}: no night {id}", db.display())))
        }
    }
}
