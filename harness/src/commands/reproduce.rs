//! The first layout's dispatch, for the ids not yet moved to `harness/src/reproduce/`.

use super::yamauchi;
use crate::error::{input, Result};
use crate::output::{print_json, write_atomic};
use serde_json::Value;
use std::path::Path;

pub fn run(
    id: &str,
    quick: bool,
    out: &Path,
    threads: Option<usize>,
    limits: &yamauchi::Limits,
    as_json: bool,
) -> Result<()> {
    let limited = limits.size.is_some() || limits.max_pes.is_some() || limits.scenes.is_some();
    if limited && !id.starts_with("yamauchi-") {
        return Err(input(format!(
            "{id}: --size, --max-pes and --scenes are for the yamauchi-* tables only"
        )));
    }
    match id {
        "yamauchi-static-lb" => yamauchi::static_lb(id, quick, limits, out, threads, as_json),
        "yamauchi-dynamic-lb" => yamauchi::dynamic_lb(id, quick, limits, out, threads, as_json),
        "yamauchi-cfbs" => yamauchi::cfbs(id, quick, limits, out, threads, as_json),
        _ => Err(input(format!("unknown table '{id}'"))),
    }
}

/// Writes DIR/<id>.json and DIR/<id>.md, and prints one of them.
pub(super) fn write_report(
    id: &str,
    out: &Path,
    doc: &Value,
    md: &str,
    as_json: bool,
) -> Result<()> {
    std::fs::create_dir_all(out)
        .map_err(|e| input(format!("{}: cannot create: {e}", out.display())))?;
    write_atomic(&out.join(format!("{id}.json")), |w| {
        serde_json::to_writer_pretty(w, doc).map_err(std::io::Error::other)
    })?;
    write_atomic(&out.join(format!("{id}.md")), |w| {
        std::io::Write::write_all(w, md.as_bytes())
    })?;
    if as_json {
        print_json(doc);
    } else {
        print!("{md}");
    }
    Ok(())
}
