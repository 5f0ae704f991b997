//! `rtbench scene store … --segment N [--resume] [--max-seconds S]`: a store written in segments
//! of N objects, across processes (`rtbench_engines::store::segments`), for the 10^8–10^9-object
//! scenes of seed 000 Table 4.3 that take longer to write than one sitting. Unlike a store
//! written in one go (a temporary directory renamed when complete), the directory is written in
//! place: until the last segment it holds `segments.json` and no `header.json`, which readers
//! refuse, and `--resume` goes on from its last checkpoint.

use crate::error::{input, Result};
use crate::output::print_json;
use crate::source::Source;
use crate::workload::out_of_core::parse_codec;
use rtbench_engines::store::{Layout, Outcome, SegmentLog, SegmentedWriter, StoreHeader};
use serde_json::json;
use std::path::Path;
use std::time::{Duration, Instant};

pub struct SegmentArgs<'a> {
    pub layout: &'a str,
    pub compress: &'a str,
    pub segment: u64,
    pub resume: bool,
    pub max_seconds: Option<f64>,
    pub max_bytes: u64,
    pub as_json: bool,
}

pub fn store(src: &Source, out: &Path, a: &SegmentArgs) -> Result<()> {
    let layout: Layout = a
        .layout
        .parse()
        .map_err(|e| input(format!("--layout {}: {e}", a.layout)))?;
    let codec =
        parse_codec(a.compress).map_err(|e| input(format!("--compress {}: {e}", a.compress)))?;
    if codec.name() == "gzip" && layout == Layout::Split {
        return Err(input(format!(
            "--compress {}: a split store is read with seeks, so it is compressed as zstd blocks: use --compress zstd[:LEVEL] or --layout basic",
            a.compress
        )));
    }
    if a.segment == 0 {
        return Err(input("--segment 0: a segment holds at least one object"));
    }
    let budget = match a.max_seconds {
        // Not above zero, or NaN.
        Some(s) if s.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) => {
            return Err(input(format!("--max-seconds {s}: expected seconds > 0")))
        }
        // Longer than a Duration holds (1e308, inf): no limit.
        s => s.map(|s| Duration::try_from_secs_f64(s).unwrap_or(Duration::MAX)),
    };
    super::scene::check_output_bound(
        src,
        a.max_bytes,
        "store records",
        super::scene::STORE_PER_OBJECT,
        super::scene::STORE_PER_VERTEX,
    )?;
    let label = src.label();
    let cannot = |e: std::io::Error| input(format!("{}: {e}", out.display()));
    let before = SegmentLog::read(out).map_err(cannot)?;
    let start = Instant::now();
    let mut w = match (&before, a.resume) {
        (Some(_), true) => SegmentedWriter::resume(out, &label).map_err(cannot)?,
        (Some(_), false) => {
            return Err(input(format!(
                "{}: a store is being written here; add --resume to go on with it",
                out.display()
            )))
        }
        (None, _) => {
            if out.exists()
                && std::fs::read_dir(out)
                    .map(|mut d| d.next().is_some())
                    .unwrap_or(true)
            {
                return Err(input(format!(
                    "{}: exists and is neither empty nor a store being written",
                    out.display()
                )));
            }
            SegmentedWriter::start(out, &label, layout, codec, a.segment).map_err(cannot)?
        }
    };
    if let Some(b) = budget {
        w = w.with_budget(b);
    }
    let objects_before = w.objects_done();
    let segments_before = w.log().done.len();
    // Stream through a copy of the log's view of progress: the writer owns the log.
    let result = src.stream(&mut w);
    let log = w.log().clone();
    result?;
    let outcome = w.finish().map_err(cannot)?;
    let secs = start.elapsed().as_secs_f64();
    let new = &log.done[segments_before.min(log.done.len())..];
    let written = log.state.objects - objects_before;
    let seg_seconds: f64 = new.iter().map(|d| d.seconds).sum();
    let (finished, objects, stored) = match &outcome {
        Outcome::Finished(_) => {
            let h = StoreHeader::read(out).map_err(|e| input(e.to_string()))?;
            (true, h.objects, h.disk_bytes())
        }
        Outcome::Stopped => (
            false,
            log.state.objects,
            log.state.geometry.stored + log.state.bbox.map_or(0, |b| b.stored),
        ),
    };
    let v = json!({
        "store": out.display().to_string(),
        "scene": label,
        "layout": log.layout,
        "codec": log.codec,
        "segment": log.segment,
        "finished": finished,
        "objects_on_disk": objects,
        "stored_bytes": stored,
        "segments_done": log.done.len(),
        "this_run": {
            "objects_written": written,
            "segments": new.len(),
            "segment_seconds": seg_seconds,
            "objects_per_s": written as f64 / seg_seconds.max(1e-9),
            "time_s": secs,
            "skipped_objects": objects_before,
        },
        "peak_rss_bytes": crate::measure::rss::peak_rss_bytes(),
    });
    if a.as_json {
        print_json(&v);
    } else if finished {
        eprintln!(
            "wrote {} ({objects} objects, {:.1} MB on disk) in {} segments; this run {secs:.1} s",
            out.display(),
            stored as f64 / 1e6,
            log.done.len()
        );
    } else {
        eprintln!(
            "{}: stopped after segment {} ({objects} objects, {:.1} MB on disk); run again with --resume to go on",
            out.display(),
            log.done.len(),
            stored as f64 / 1e6
        );
    }
    Ok(())
}
