//! What can go wrong making a report or a comparison. Every message names the file.

use crate::results::ReadError;

#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error(transparent)]
    Read(#[from] ReadError),
    #[error("{path}: no results file (expected one written by `rtbench run` or `rtbench sweep`)")]
    NoResults { path: String },
    #[error("{path}: cannot write: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}: cannot draw the plot: {message}")]
    Plot { path: String, message: String },
    #[error("{path}: cannot make the JSON document: {message}")]
    Json { path: String, message: String },
    #[error("{path}: {message}")]
    Invalid { path: String, message: String },
    #[error("threshold {0}%: must be a finite number of percent, 0 or more")]
    BadThreshold(f64),
    #[error("unknown report format `{0}` (known: md, csv, json, svg, png, html)")]
    UnknownFormat(String),
}
