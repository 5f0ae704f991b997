//! What a reproduction is, as the registry and the writer see it: a [`Table`] (id, source, claims,
//! options, `run`), the context its run gets, and the [`Output`] it returns.

use super::{Checkpoint, Claim, Param, Params, Row};
use crate::error::Result;
use rtbench_reports::plot::Chart;
use rtbench_reports::Document;
use serde_json::json;

/// How long a table takes on this machine (2 cores): with `--quick`, and in full.
#[derive(Clone, Copy, Debug)]
pub struct Runtime {
    pub quick: &'static str,
    pub full: &'static str,
}

/// One reproducible table or claim set.
pub struct Table {
    pub id: &'static str,
    /// "000" … "003", or "SPD".
    pub seed: &'static str,
    /// Where in the source: table, figure, section.
    pub source: &'static str,
    pub about: &'static str,
    pub runtime: Runtime,
    /// The options it takes (anything else is refused).
    pub params: &'static [Param],
    /// The claims its rows test, each with its fidelity label.
    pub claims: &'static [Claim],
    pub run: fn(&Ctx) -> Result<Output>,
}

/// What a table's run is given.
pub struct Ctx<'a> {
    pub id: &'static str,
    pub quick: bool,
    pub params: &'a Params,
    /// Finished steps of a long run (`--resume`); tables that take minutes ignore it.
    pub checkpoint: &'a Checkpoint,
}

/// A PNG to write: path relative to the output folder, RGB8 pixels, square size.
pub struct Image {
    pub path: String,
    pub pixels: Vec<u8>,
    pub size: u32,
}

/// What a table's run returns: its typed result (serialised), its comparison rows, its document, and
/// the plots and images the writer writes beside them.
pub struct Output {
    pub result: serde_json::Value,
    pub rows: Vec<Row>,
    pub doc: Document,
    pub charts: Vec<Chart>,
    /// Plots drawn by hand: (file stem, SVG text), written to `plots/<stem>.svg`.
    pub svgs: Vec<(String, String)>,
    pub images: Vec<Image>,
}

impl Output {
    pub fn new(result: impl serde::Serialize, rows: Vec<Row>, doc: Document) -> Output {
        Output {
            result: serde_json::to_value(result).expect("results serialise"),
            rows,
            doc,
            charts: Vec::new(),
            svgs: Vec::new(),
            images: Vec::new(),
        }
    }
}

/// The environment line every reproduction records.
pub fn environment(threads: usize) -> serde_json::Value {
    json!({"os": std::env::consts::OS, "arch": std::env::consts::ARCH, "threads": threads})
}
