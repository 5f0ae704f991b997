//! `report.html`: one self-contained page, the same tables as `report.md` with the plots inline (SVG).

use crate::document::{escape, inline_html, Table, STYLE};
use crate::summary::Summary;
use crate::table;
use std::fmt::Write;

/// The page. `svgs` are the plots as (file stem, SVG text).
pub fn report(summary: &Summary, svgs: &[(String, String)]) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>rtbench report</title>\n\
         <style>{STYLE}</style>\n</head>\n<body>\n<h1>rtbench report</h1>\n<ul class=\"env\">\n"
    );
    match &summary.environment {
        Some(env) => {
            for (what, value) in table::environment_lines(env) {
                let _ = writeln!(s, "<li><b>{what}</b>: {}</li>", escape(&value));
            }
        }
        None => s.push_str("<li>environment not recorded (no <code>env.json</code>)</li>\n"),
    }
    let _ = writeln!(
        s,
        "<li><b>runs</b>: {} ({} ok, {} failed)</li>\n</ul>",
        summary.runs,
        summary.rows.len(),
        summary.failures.len()
    );
    for t in table::run_tables(summary) {
        write_table(&mut s, &t);
    }
    if !summary.rows.is_empty() {
        let _ = writeln!(s, "<p class=\"notes\">{}</p>", inline_html(table::NOTES));
    }
    if let Some(t) = table::scaling_table(summary) {
        write_table(&mut s, &t);
        let _ = writeln!(
            s,
            "<p class=\"notes\">{}</p>",
            inline_html(table::SCALING_NOTES)
        );
    }
    let failures = table::failure_lines(summary);
    if !failures.is_empty() {
        s.push_str("<h2>Failed runs</h2>\n<ul>\n");
        for (key, why) in failures {
            let _ = writeln!(
                s,
                "<li><code>{}</code>: {}</li>",
                escape(&key),
                escape(&why)
            );
        }
        s.push_str("</ul>\n");
    }
    if !svgs.is_empty() {
        s.push_str("<h2>Plots</h2>\n");
        for (stem, svg) in svgs {
            let body = svg.find("<svg").map(|i| &svg[i..]).unwrap_or(svg);
            let _ = writeln!(s, "<figure id=\"{}\">\n{body}\n</figure>", escape(stem));
        }
    }
    s.push_str("</body>\n</html>\n");
    s
}

fn write_table(s: &mut String, t: &Table) {
    s.push_str(&t.to_html());
}
