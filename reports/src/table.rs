//! The report's tables as cells, shared by the Markdown and HTML writers.

use crate::document::Table;
use crate::number;
use crate::results::Environment;
use crate::summary::{Row, Summary};

const HEADER: [(&str, bool); 12] = [
    ("scene", false),
    ("engine", false),
    ("build s", true),
    ("trace s (min–max)", true),
    ("Mrays/s", true),
    ("× Embree [95 % CI] (n)", true),
    ("paired × Embree [95 % CI] (n)", true),
    ("structure MB", true),
    ("B/prim", true),
    ("peak RSS MB", true),
    ("hit agreement", true),
    ("PSNR dB", true),
];

/// What an interval's n counts: rounds where the run was spread over two or more and the interval
/// is over rounds (all of them, or those its Embree run ran too: at most the run's rounds, where
/// pooled samples are at least one a round from each side), else its samples.
fn count(r: &Row, i: &crate::interval::Interval) -> String {
    if r.rounds >= 2 && i.n >= 2 && i.n <= r.rounds {
        format!("{} rounds", i.n)
    } else {
        i.n.to_string()
    }
}

/// One table per thread count: scene × engine.
/// In results merged from shards (`rtbench merge`), a last column names the machine each row (and
/// its ratio to Embree, always measured on the same machine) comes from.
pub fn run_tables(summary: &Summary) -> Vec<Table> {
    let machines: std::collections::BTreeSet<&str> = summary
        .rows
        .iter()
        .filter_map(|r| r.machine.as_deref())
        .collect();
    let with_machine = !machines.is_empty();
    summary
        .thread_counts()
        .into_iter()
        .map(|threads| {
            let mut header: Vec<String> = HEADER.iter().map(|h| h.0.to_string()).collect();
            let mut numeric: Vec<bool> = HEADER.iter().map(|h| h.1).collect();
            if with_machine {
                header.push("machine".to_string());
                numeric.push(false);
            }
            Table {
                caption: format!("{threads} thread{}", if threads == 1 { "" } else { "s" }),
                header,
                numeric,
                rows: summary
                    .rows
                    .iter()
                    .filter(|r| r.threads == threads)
                    .map(|r| {
                        let mut c = cells(r);
                        if with_machine {
                            c.push(r.machine.clone().unwrap_or_else(|| "–".to_string()));
                        }
                        c
                    })
                    .collect(),
            }
        })
        .collect()
}

fn cells(r: &Row) -> Vec<String> {
    let t = &r.trace_s;
    vec![
        r.scene.clone(),
        r.label.clone(),
        number::seconds(r.build_s.median),
        format!(
            "{} ({}–{})",
            number::seconds(t.median),
            number::seconds(t.min),
            number::seconds(t.max)
        ),
        number::sig(r.mrays_per_s, 3),
        match (&r.ratio_interval, r.ratio_to_embree) {
            (Some(i), _) => format!("{} ({})", i.text(), count(r, i)),
            (None, Some(q)) if r.engine == crate::anchor::EMBREE => number::ratio(q),
            (None, Some(q)) => format!("{} (too few repeats for an interval)", number::ratio(q)),
            _ => "–".to_string(),
        },
        match r.paired_ratio.as_ref().and_then(|p| p.interval.as_ref()) {
            Some(i) => format!("{} ({})", i.text(), count(r, i)),
            None => match &r.paired_ratio {
                Some(p) => format!("{} ({})", number::ratio(p.median), p.samples.len()),
                None => "–".to_string(),
            },
        },
        number::megabytes(r.structure_bytes),
        bytes_per_primitive(r),
        number::megabytes(r.peak_rss_bytes),
        r.check
            .as_ref()
            .map(|c| number::agreement(c.hit_agreement))
            .unwrap_or_else(|| "–".to_string()),
        r.check
            .as_ref()
            .map(|c| number::psnr(c.image_psnr_db))
            .unwrap_or_else(|| "–".to_string()),
    ]
}

/// Structure bytes per primitive of the scene as the engine sees it (after tessellation).
fn bytes_per_primitive(r: &Row) -> String {
    if r.primitives == 0 {
        return "–".to_string();
    }
    format!("{:.1}", r.structure_bytes as f64 / r.primitives as f64)
}

/// The speed-up over one thread of the runs timed in pairs (`run --paired-threads N`), when any
/// was: per run, the median and range of the pairs' own ratios, the pairs' median times, how
/// much CPU time the split trace took over the one-thread trace, and beside it the speed-up from
/// two separate runs of this set (its one-thread run's median trace time over this run's), which
/// outside load moves far more.
pub fn scaling_table(summary: &Summary) -> Option<Table> {
    let rows: Vec<Vec<String>> = summary
        .rows
        .iter()
        .filter_map(|r| r.thread_scaling.as_ref().map(|s| (r, s)))
        .map(|(r, s)| {
            let separate = summary
                .rows
                .iter()
                .find(|o| o.threads == 1 && o.label == r.label && o.scene == r.scene)
                .map(|o| number::ratio(o.trace_s.median / r.trace_s.median.max(1e-12)))
                .unwrap_or_else(|| "–".to_string());
            let p = &s.speedup;
            vec![
                r.scene.clone(),
                r.label.clone(),
                s.threads.to_string(),
                match &p.interval {
                    Some(i) => format!(
                        "{} ({}–{})",
                        i.text(),
                        number::ratio(p.min),
                        number::ratio(p.max)
                    ),
                    None => format!(
                        "{} ({}–{})",
                        number::ratio(p.median),
                        number::ratio(p.min),
                        number::ratio(p.max)
                    ),
                },
                p.samples.len().to_string(),
                number::seconds(s.one_thread_s.median),
                number::seconds(s.threads_s.median),
                number::ratio(s.cpu_growth()),
                separate,
            ]
        })
        .collect();
    if rows.is_empty() {
        return None;
    }
    let header = [
        ("scene", false),
        ("engine", false),
        ("threads", true),
        ("speed-up, paired [95 % CI] (min–max)", true),
        ("pairs", true),
        ("1 thread s", true),
        ("N threads s", true),
        ("CPU s × 1 thread", true),
        ("speed-up, separate runs", true),
    ];
    Some(Table {
        caption: "Speed-up over one thread (pairs in one process)".to_string(),
        header: header.iter().map(|h| h.0.to_string()).collect(),
        numeric: header.iter().map(|h| h.1).collect(),
        rows,
    })
}

/// What the scaling table's columns mean.
pub const SCALING_NOTES: &str = "Each pair traces the same built structure at one thread and at N threads back to \
back in one process, alternating which goes first (`rtbench run --paired-threads`); the speed-up is each pair's \
one-thread wall time over its N-thread wall time: the pairs' median with its 95 % interval (on \
the logs, from their median absolute deviation), and their range; both traces must give the same image. 1 thread s and N threads s are the pairs' median wall times; CPU s × 1 thread is the CPU time of the \
pool's threads at N threads over that at one (1.00: splitting cost no extra CPU time). Speed-up, separate runs: \
this set's one-thread run's median trace time over this run's, for comparison.";

/// The failed runs: key, then why.
pub fn failure_lines(summary: &Summary) -> Vec<(String, String)> {
    summary
        .failures
        .iter()
        .map(|f| (f.key.clone(), format!("{}: {}", f.status, f.reason)))
        .collect()
}

/// The environment as (what, value) pairs.
pub fn environment_lines(env: &Environment) -> Vec<(&'static str, String)> {
    let cores = match env.cores_physical {
        Some(p) => format!("{} logical, {p} physical", env.cores_logical),
        None => format!("{} logical", env.cores_logical),
    };
    let commit = if env.git_dirty {
        format!("{} (dirty)", env.git_commit)
    } else {
        env.git_commit.clone()
    };
    vec![
        ("CPU", format!("{} ({cores})", env.cpu_model)),
        (
            "memory",
            format!("{} GB", number::sig(env.memory_bytes as f64 / 1e9, 3)),
        ),
        ("OS", format!("{} (kernel {})", env.os, env.kernel)),
        ("host", env.hostname.clone()),
        ("rustc", env.rustc.clone()),
        ("rtbench", format!("{} at {commit}", env.rtbench_version)),
        (
            "Embree",
            env.embree_version
                .clone()
                .unwrap_or_else(|| "not available".to_string()),
        ),
        ("started", env.started_at.clone()),
    ]
}

/// What the columns mean, printed under the tables.
pub const NOTES: &str = "Times are medians over the repeats, with min–max. × Embree is the trace time (CPU time of the \
pool's threads where recorded) over Embree's on the same scene and threads in this results set: the quotient of the two \
runs' geometric means over their repeats, with its 95 % interval (Welch, on the logs) and the repeats behind it (– \
without an Embree run). Paired × Embree: the ratios timed back to back in the run's own process (`run --paired N`), \
their median with its 95 % interval and the number of pairs. A run spread over rounds (`run --rounds R`, one process \
each) gives one figure per round (its pairs' median; its repeats over Embree's in the same round), and the cell is their \
mean with Student's t interval over the rounds, n counting rounds. MB are 10^6 bytes; B/prim is the \
structure's bytes per primitive (Embree: what its memory monitor reports, BVH and its copies of the geometry). Hit agreement and PSNR \
compare each engine's hits and image with Embree's (`rtbench check`); ∞ dB means identical images.";
