//! The static dashboard: one HTML file (no server, no network) with the latest night's gates and
//! findings, one plot per metric of the nights of the same machine and suite (time ratios,
//! instruction counts, counters, criterion kernels: every metric the history holds), a filter,
//! and the list of nights. The plots carry each night's 95 % interval where the history kept
//! samples, the findings of each night, the change points E-divisive finds, hover values and
//! commit links through an optional URL template.
//!
//! - `board.rs`: what is shown, as data, from the history alone;
//! - `page.rs`: the page (maud), with `dashboard.js` and uPlot inlined.
//!
//! The plots are drawn in the browser by uPlot (1.6.32, from the npm registry, MIT licence:
//! `uplot/LICENSE`), 51 kB minified: plotters' SVG would have to be re-invented for hover, held
//! cursors and hundreds of small plots that a filter shows and hides.

mod board;
mod page;

pub use board::{check_commit_url, fmt_value};

use super::History;
use crate::error::{input, Result};
use std::path::Path;

/// Writes `dir/index.html`. `commit_url`: a template holding `{commit}` that links each commit id.
pub fn write(h: &History, dir: &Path, commit_url: Option<&str>) -> Result<()> {
    let board = board::build(h, commit_url)?;
    std::fs::create_dir_all(dir).map_err(|e| input(format!("{}: {e}", dir.display())))?;
    let html = page::render(&board);
    crate::output::write_atomic(&dir.join("index.html"), |w| {
        std::io::Write::write_all(w, html.as_bytes())
    })
}
