//! `report.html`: one self-contained page, the same tables as `report.md` with the plots inline (SVG).

use crate::summary::Summary;
use crate::table::{self, Table};
use std::fmt::Write;

const STYLE: &str = "body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1300px;padding:0 1em;color:#222}\
table{border-collapse:collapse;margin:.5em 0 1em;font-size:14px}\
th,td{border:1px solid #ccc;padding:3px 8px}th{background:#f2f2f2}td.n{text-align:right;font-variant-numeric:tabular-nums}\
tr:nth-child(even) td{background:#fafafa}ul.env{list-style:none;padding:0}ul.env li{margin:2px 0}\
p.notes{font-size:13px;color:#555;max-width:60em}figure{margin:1em 0}svg{max-width:100%;height:auto}";

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
        let _ = writeln!(
            s,
            "<p class=\"notes\">{}</p>",
            code_spans(&escape(table::NOTES))
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
    let _ = writeln!(s, "<h2>{}</h2>\n<table>\n<thead><tr>", escape(&t.caption));
    for h in &t.header {
        let _ = write!(s, "<th>{}</th>", escape(h));
    }
    s.push_str("</tr></thead>\n<tbody>\n");
    for row in &t.rows {
        s.push_str("<tr>");
        for (cell, numeric) in row.iter().zip(&t.numeric) {
            let class = if *numeric { " class=\"n\"" } else { "" };
            let _ = write!(s, "<td{class}>{}</td>", escape(cell));
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</tbody>\n</table>\n");
}

pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `a` → <code>a</code>, for the notes written with Markdown's backticks.
fn code_spans(text: &str) -> String {
    let mut out = String::new();
    for (i, part) in text.split('`').enumerate() {
        if i % 2 == 1 {
            let _ = write!(out, "<code>{part}</code>");
        } else {
            out.push_str(part);
        }
    }
    out
}
