//! `report.md`: environment, one table per thread count, failed runs, plots.

use crate::document::{md_cell, Table};
use crate::summary::Summary;
use crate::table;
use std::fmt::Write;

/// The Markdown report. `plots` are the plot images (relative to the results directory) to show.
pub fn report(summary: &Summary, plots: &[String]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# rtbench report\n");
    match &summary.environment {
        Some(env) => {
            for (what, value) in table::environment_lines(env) {
                let _ = writeln!(s, "- **{what}**: {}", md_cell(&value));
            }
        }
        None => s.push_str("- environment not recorded (no `env.json`)\n"),
    }
    let _ = writeln!(
        s,
        "- **runs**: {} ({} ok, {} failed)\n",
        summary.runs,
        summary.rows.len(),
        summary.failures.len()
    );

    for t in table::run_tables(summary) {
        write_table(&mut s, &t);
    }
    if !summary.rows.is_empty() {
        let _ = writeln!(s, "{}\n", table::NOTES);
    }
    if let Some(t) = table::scaling_table(summary) {
        write_table(&mut s, &t);
        let _ = writeln!(s, "{}\n", table::SCALING_NOTES);
    }

    let failures = table::failure_lines(summary);
    if !failures.is_empty() {
        let _ = writeln!(s, "## Failed runs\n");
        for (key, why) in failures {
            let _ = writeln!(s, "- `{key}`: {}", md_cell(&why));
        }
        s.push('\n');
    }

    if !plots.is_empty() {
        let _ = writeln!(s, "## Plots\n");
        for p in plots {
            let _ = writeln!(s, "![{p}]({p})\n");
        }
    }
    s
}

fn write_table(s: &mut String, t: &Table) {
    s.push_str(&t.to_markdown());
}
