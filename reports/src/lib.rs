//! rtbench-reports: tables and plots from results files, and the comparison of two result sets.
//! Knows nothing of engines: everything comes from `results.jsonl` and `env.json`.
//!
//! ```no_run
//! use rtbench_reports::{compare, write_report, Format};
//! use std::path::Path;
//!
//! // report.md, results.csv, summary.json, plots/*.svg and *.png, report.html
//! let summary = write_report(Path::new("out/nightly"), &Format::ALL)?;
//! println!("{} runs, {} files", summary.runs, summary.files.len());
//!
//! let c = compare(Path::new("out/yesterday"), Path::new("out/today"), 5.0)?;
//! print!("{}", c.to_markdown());
//! std::process::exit(if c.is_regression() { 1 } else { 0 });
//! # Ok::<(), rtbench_reports::ReportError>(())
//! ```
//!
//! One result type, several exports (as hyperfine does): [`Summary`] is built once from the records and
//! written as Markdown (`markdown.rs`), CSV (`csv.rs`), JSON, HTML (`html.rs`) and plots (`plot/`).

mod anchor;
mod atomic;
mod compare;
mod csv;
mod document;
mod error;
mod html;
pub mod interval;
mod markdown;
pub mod number;
pub mod plot;
mod report;
pub mod results;
pub mod rounds;
mod scaling;
mod summary;
mod table;

pub use anchor::{attach_ratios, EMBREE};
pub use compare::{compare, machine_differences, Comparison, Finding, FindingKind};
pub use document::{Block, Document, Table};
pub use error::ReportError;
pub use interval::Interval;
pub use report::{write_report, Format};
pub use results::{
    read_environment, read_results, run_key, CheckResult, Environment, ReadError, Round, RunRecord,
    Sample, SceneInfo, Spread, Timings,
};
pub use scaling::ThreadScaling;
pub use summary::{check_records, duplicate, engine_label, latest_per_key, Failure, Row, Summary};
