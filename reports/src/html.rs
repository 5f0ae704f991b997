//! `report.html`: one self-contained page, the same tables as `report.md` with the plots inline (SVG).

use crate::document::{page, Inline};
use crate::summary::Summary;
use crate::table;
use maud::{html, PreEscaped};

/// The page. `svgs` are the plots as (file stem, SVG text).
pub fn report(summary: &Summary, svgs: &[(String, String)]) -> String {
    let failures = table::failure_lines(summary);
    let body = html! {
        h1 { "rtbench report" }
        ul.env {
            @match &summary.environment {
                Some(env) => {
                    @for (what, value) in table::environment_lines(env) {
                        li { b { (what) } ": " (value) }
                    }
                }
                None => li { "environment not recorded (no " code { "env.json" } ")" },
            }
            li {
                b { "runs" } ": " (summary.runs) " (" (summary.rows.len()) " ok, "
                (summary.failures.len()) " failed)"
            }
        }
        @for t in table::run_tables(summary) { (t.markup()) }
        @if !summary.rows.is_empty() {
            p.notes { (Inline(table::NOTES)) }
        }
        @if let Some(t) = table::scaling_table(summary) {
            (t.markup())
            p.notes { (Inline(table::SCALING_NOTES)) }
        }
        @if !failures.is_empty() {
            h2 { "Failed runs" }
            ul { @for (key, why) in &failures { li { code { (key) } ": " (why) } } }
        }
        @if !svgs.is_empty() {
            h2 { "Plots" }
            @for (stem, svg) in svgs {
                // The SVG is the plot module's own markup, inlined as it is (from its root element on).
                figure id=(stem) { (PreEscaped(svg.find("<svg").map(|i| &svg[i..]).unwrap_or(svg))) }
            }
        }
    };
    page("rtbench report", body).into_string()
}
