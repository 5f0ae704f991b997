//! `write_report`: a results directory in, report files out, each written atomically.

use crate::atomic::write_atomic;
use crate::results::{read_environment, read_results};
use crate::summary::{latest_per_key, Summary};
use crate::{csv, html, markdown, plot, ReportError};
use serde::Serialize;
use std::path::Path;
use std::str::FromStr;

/// A kind of report file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// `report.md`
    Md,
    /// `results.csv`
    Csv,
    /// `summary.json`
    Json,
    /// `plots/*.svg`
    Svg,
    /// `plots/*.png`
    Png,
    /// `report.html` (plots inline)
    Html,
}

impl Format {
    pub const ALL: [Format; 6] = [
        Format::Md,
        Format::Csv,
        Format::Json,
        Format::Svg,
        Format::Png,
        Format::Html,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Format::Md => "md",
            Format::Csv => "csv",
            Format::Json => "json",
            Format::Svg => "svg",
            Format::Png => "png",
            Format::Html => "html",
        }
    }

    /// A comma-separated list as `--format` takes it: `md,csv,svg`.
    pub fn parse_list(list: &str) -> Result<Vec<Format>, ReportError> {
        let mut out = Vec::new();
        for f in list.split(',').map(str::trim).filter(|f| !f.is_empty()) {
            let f = f.parse()?;
            if !out.contains(&f) {
                out.push(f);
            }
        }
        Ok(out)
    }
}

impl FromStr for Format {
    type Err = ReportError;
    fn from_str(s: &str) -> Result<Format, ReportError> {
        match s.to_ascii_lowercase().as_str() {
            "md" | "markdown" => Ok(Format::Md),
            "csv" => Ok(Format::Csv),
            "json" => Ok(Format::Json),
            "svg" => Ok(Format::Svg),
            "png" => Ok(Format::Png),
            "html" => Ok(Format::Html),
            _ => Err(ReportError::UnknownFormat(s.to_string())),
        }
    }
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Reads `dir/results.jsonl` (and `dir/env.json` if there) and writes the reports asked for (all of them
/// when `formats` is empty): `report.md`, `results.csv`, `summary.json`, `plots/*.svg`, `plots/*.png`,
/// `report.html`. Returns the summary the files were made from, with `files` listing what was written.
pub fn write_report(dir: &Path, formats: &[Format]) -> Result<Summary, ReportError> {
    let results = dir.join("results.jsonl");
    if !results.is_file() {
        return Err(ReportError::NoResults {
            path: results.display().to_string(),
        });
    }
    let wants = |f: Format| formats.is_empty() || formats.contains(&f);
    let environment = read_environment(dir)?;
    let records = read_results(dir)?;
    crate::summary::check_records(&records, &dir.join("results.jsonl").display().to_string())?;
    let records = latest_per_key(records);
    let mut summary = Summary::of(environment, records.clone());
    let mut files: Vec<String> = Vec::new();

    let charts = if wants(Format::Svg) || wants(Format::Png) || wants(Format::Html) {
        plot::charts(&summary)
    } else {
        Vec::new()
    };
    let plots_dir = dir.join("plots");
    if !charts.is_empty() && (wants(Format::Svg) || wants(Format::Png)) {
        std::fs::create_dir_all(&plots_dir).map_err(|e| ReportError::Io {
            path: plots_dir.display().to_string(),
            source: e,
        })?;
    }
    let plot_error = |path: &Path, message: String| ReportError::Plot {
        path: path.display().to_string(),
        message,
    };

    let mut svgs: Vec<(String, String)> = Vec::new();
    let mut shown: Vec<String> = Vec::new();
    for chart in &charts {
        if wants(Format::Svg) || wants(Format::Html) {
            let path = plots_dir.join(format!("{}.svg", chart.stem));
            let svg = plot::svg(chart).map_err(|m| plot_error(&path, m))?;
            if wants(Format::Svg) {
                write_atomic(&path, svg.as_bytes())?;
                files.push(format!("plots/{}.svg", chart.stem));
                shown.push(format!("plots/{}.svg", chart.stem));
            }
            svgs.push((chart.stem.clone(), svg));
        }
        if wants(Format::Png) {
            let path = plots_dir.join(format!("{}.png", chart.stem));
            let png = plot::png(chart).map_err(|m| plot_error(&path, m))?;
            write_atomic(&path, &png)?;
            files.push(format!("plots/{}.png", chart.stem));
            if !wants(Format::Svg) {
                shown.push(format!("plots/{}.png", chart.stem));
            }
        }
    }

    if wants(Format::Md) {
        write_atomic(
            &dir.join("report.md"),
            markdown::report(&summary, &shown).as_bytes(),
        )?;
        files.push("report.md".to_string());
    }
    if wants(Format::Csv) {
        write_atomic(&dir.join("results.csv"), csv::results(&records).as_bytes())?;
        files.push("results.csv".to_string());
    }
    if wants(Format::Html) {
        write_atomic(
            &dir.join("report.html"),
            html::report(&summary, &svgs).as_bytes(),
        )?;
        files.push("report.html".to_string());
    }
    if wants(Format::Json) {
        files.push("summary.json".to_string());
    }
    summary.files = files;
    if wants(Format::Json) {
        let path = dir.join("summary.json");
        let mut text = serde_json::to_string_pretty(&summary).map_err(|e| ReportError::Json {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        text.push('\n');
        write_atomic(&path, text.as_bytes())?;
    }
    Ok(summary)
}
