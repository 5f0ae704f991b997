//! `nakamaru-4.2`: seed 000's Table 4.2, the overhead of the two-level registration grid of §4.3.3:
//! two-level grids of upper/lower maxima 64/2 and 32/4 (128 cells per axis effective) against a
//! single-level grid capped at 128, on the largest row of each Table 4.1 scene, every other
//! improvement on (S+G+B).
//!
//! Per row the scene is written once as a split store, then traced three times out of core
//! ([`super::grid_runs`]): `grid=single cap=128`, `grid=two-level upper=64 lower=2` and
//! `upper=32 lower=4` (the two-level grid's voxel flags on disk, made subspace by subspace and
//! read block by block). The ratio is the thesis's: single-level time / two-level time; the
//! overhead its inverse, beside the text's 1.1–1.3×. The exact counters (direct registrations and
//! the range checks they cost, lower grids used) show where the overhead comes from.
//!
//! `--quick` traces one small row per scene at 128×128 with the cap scaled to 32 (16/2 and 8/4),
//! so that the small scenes' Klimaszewski resolutions exceed it as the thesis's large ones exceed
//! 128.
//! `--set rows=…`, `--set cap=N` (two-level: N/2 over 2 and N/4 over 4). Rows are saved as they
//! finish (`--resume`).

use super::grid_runs::{self, GridRun, Setup};
use super::published::{self, Source};
use super::{environment, Claim, Ctx, Fidelity, Kind, Output, Param, Row, Runtime, Table, Verdict};
use crate::error::{input, Result};
use rtbench_engines::breadth_first::spill::SpillDir;
use rtbench_reports::{Document, Table as DocTable};
use serde::{Deserialize, Serialize};
use std::path::Path;

const ROWS: Param = Param {
    key: "rows",
    help: "rows to measure, e.g. mount12,tetra12 (default: the table's 7; --quick: one small row per scene)",
};
const CAP: Param = Param {
    key: "cap",
    help: "single-level cap per axis (default 128, 32 with --quick); two-level: cap/2 over 2 and cap/4 over 4",
};
const SIZE: Param = Param {
    key: "size",
    help: "image size (default 512, 128 with --quick)",
};
const MEMORY: Param = Param {
    key: "memory",
    help: "engine memory budget (default 256MiB, the thesis's machine)",
};
const CACHE: Param = Param {
    key: "cache",
    help: "cold (default) or warm",
};
const SPILL: Param = Param {
    key: "spill",
    help: "directory for the scene stores and spill files (default the system temp dir)",
};

pub const TABLE: Table = Table {
    id: "nakamaru-4.2",
    seed: "000",
    source: "Table 4.2",
    about: "000 (Nakamaru 2002) Table 4.2: two-level ray-registration grids 64/2 and 32/4 against a single-level grid capped at 128",
    runtime: Runtime {
        quick: "minutes",
        full: "about 22 CPU minutes (7 rows up to 5e7 objects × 3 grids out of core; 37 minutes on a shared 2-core machine); resumable",
    },
    params: &[ROWS, CAP, SIZE, MEMORY, CACHE, SPILL],
    claims: &[
        Claim {
            key: "two-level-ratio",
            fidelity: Fidelity::Substituted,
            why: "settings the thesis does not give, chosen by us: the pool of lower grids (1/16 of the 256 MiB budget), the rays per pass (the same for all three grids), the grid's shape by our reading of Klimaszewski's method (its formula is not in the thesis), and the single-level grid as the basic method's in-memory grid capped at 128 (our reading of the thesis's \"-l\"), so the two-level runs' on-disk grid and block traversal (§4.3.1-4.3.2) count in the overhead too and their passes may differ at equal rays per pass; the machine the record names (its disk read cold, page cache dropped by posix_fadvise) is stated, not the reason; --quick rows are smaller scenes with the cap scaled to 32",
        },
        Claim {
            key: "overhead",
            fidelity: Fidelity::Substituted,
            why: "as two-level-ratio",
        },
        Claim {
            key: "image-equal",
            fidelity: Fidelity::Faithful,
            why: "",
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/nakamaru-4.2.json");

#[derive(Deserialize)]
struct Published {
    source: Source,
    overhead_range: [f64; 2],
    rows: Vec<PublishedRow>,
}

#[derive(Deserialize, Serialize, Clone)]
struct PublishedRow {
    scene: String,
    sf: u32,
    r64_2: f64,
    r32_4: f64,
}

#[derive(Serialize, Deserialize, Clone)]
struct Measured {
    scene: String,
    sf: u32,
    thesis_row: bool,
    objects: u64,
    cap: u32,
    single: GridRun,
    /// upper cap/2, lower 2 (64/2 at the thesis's cap).
    half: GridRun,
    /// upper cap/4, lower 4 (32/4).
    quarter: GridRun,
}

impl Measured {
    fn label(&self) -> String {
        format!("{}{}", self.scene, self.sf)
    }
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    measured: Vec<Measured>,
    size: u32,
    memory: String,
    cache: String,
    environment: serde_json::Value,
}

const SCENES: &[&str] = &["balls", "gears", "mount", "rings", "teapot", "tetra", "tree"];

/// `--quick`: one small row per scene (about 3·10^4 to 7·10^4 objects), whose Klimaszewski
/// resolution passes the quick cap of 32 along its longest axis.
const QUICK: &[(&str, u32)] = &[
    ("balls", 5),
    ("gears", 5),
    ("mount", 7),
    ("rings", 8),
    ("teapot", 30),
    ("tetra", 8),
    ("tree", 16),
];

fn measure_row(scene: &str, sf: u32, thesis_row: bool, cap: u32, s: &Setup) -> Result<Measured> {
    let src = grid_runs::resolve(scene, sf)?;
    let spill = SpillDir::create(s.spill.as_deref().map(Path::new)).map_err(input)?;
    let dir = spill.path().join("split");
    eprintln!("nakamaru-4.2: {scene}{sf}: store …");
    let h = grid_runs::write_split_store(&src, &dir)?;
    // The thesis compares the grids, not how our budget is split: the two-level grid's block
    // buffer (1/8 of the budget) and lower-grid pool (1/16) leave it room for fewer rays, hence
    // more passes. Every grid gets the same rays per pass: the fewest any of them can hold.
    let probe = |settings: &[(&str, String)]| grid_runs::rays_in_memory(&dir, s, settings);
    let single_set = vec![("grid", "single".to_string()), ("cap", cap.to_string())];
    let two_set = |upper: u32, lower: u32| {
        vec![
            ("grid", "two-level".to_string()),
            ("upper", upper.to_string()),
            ("lower", lower.to_string()),
        ]
    };
    let sets = [single_set, two_set(cap / 2, 2), two_set(cap / 4, 4)];
    let mut rays = u64::MAX;
    for set in &sets {
        rays = rays.min(probe(set)?);
    }
    let traced = |set: &[(&str, String)], what: &str| {
        eprintln!("nakamaru-4.2: {scene}{sf}: {what}, {rays} rays per pass …");
        let mut set = set.to_vec();
        set.push(("rays", rays.to_string()));
        grid_runs::trace(&dir, s, &set)
    };
    let single = traced(&sets[0], &format!("single-level, cap {cap}"))?;
    let half = traced(&sets[1], &format!("two-level {}/2", cap / 2))?;
    let quarter = traced(&sets[2], &format!("two-level {}/4", cap / 4))?;
    Ok(Measured {
        scene: scene.into(),
        sf,
        thesis_row,
        objects: h.objects,
        cap,
        single,
        half,
        quarter,
    })
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let size = ctx
        .params
        .number::<u32>(SIZE.key, 1)?
        .unwrap_or(if ctx.quick { 128 } else { 512 });
    crate::workload::check_size(size)?;
    let cap = ctx
        .params
        .number::<u32>(CAP.key, 4)?
        .unwrap_or(if ctx.quick { 32 } else { 128 });
    let setup = Setup {
        size,
        memory: ctx.params.bytes(MEMORY.key, "256MiB")?,
        cache: ctx.params.raw(CACHE.key).unwrap_or("cold").to_string(),
        spill: ctx.params.raw(SPILL.key).map(str::to_string),
    };
    let mut todo: Vec<(String, u32)> = if ctx.quick {
        QUICK.iter().map(|&(s, sf)| (s.to_string(), sf)).collect()
    } else {
        p.rows.iter().map(|r| (r.scene.clone(), r.sf)).collect()
    };
    if let Some(list) = ctx.params.list(ROWS.key)? {
        todo = grid_runs::parse_rows(ctx.id, &list, SCENES)?;
    }
    let mut measured = Vec::new();
    for (scene, sf) in todo {
        let thesis = p.rows.iter().any(|r| r.scene == scene && r.sf == sf) && cap == 128;
        // "same-rays": rows saved before every grid got the same rays per pass are not reused.
        let key = format!("{scene}{sf}-cap{cap}-{size}-{}-{}-same-rays", setup.memory, setup.cache);
        let m = match ctx.checkpoint.load::<Measured>(&key)? {
            Some(m) => {
                eprintln!("{}: {scene}{sf}: saved by an earlier run", ctx.id);
                m
            }
            None => {
                let m = measure_row(&scene, sf, thesis, cap, &setup)?;
                ctx.checkpoint.save(&key, &m)?;
                m
            }
        };
        measured.push(m);
    }
    let rows = rows(&p, &measured);
    let doc = document(&p, &measured, &setup, ctx.quick);
    Ok(Output::new(
        Result_ {
            id: ctx.id,
            published: raw,
            measured,
            size,
            memory: setup.memory.clone(),
            cache: setup.cache.clone(),
            environment: environment(1),
        },
        rows,
        doc,
    ))
}

/// The text's "1.1–1.3×" is stated to one decimal: four of the table's own fourteen cells (0.91,
/// 0.92 and twice 0.93, overheads 1.075–1.099) lie below 1.1 unrounded and round to it. The
/// overhead is judged as the text rounds it.
fn in_text_band(overhead: f64, lo: f64, hi: f64) -> bool {
    let rounded = (overhead * 10.0).round() / 10.0;
    (lo..=hi).contains(&rounded)
}

fn ratio(a: f64, b: f64) -> f64 {
    a / b.max(1e-9)
}

/// The comparison rows: per row and configuration the thesis's ratio and the overhead beside
/// 1.1–1.3×, and whether the three images are equal.
fn rows(p: &Published, measured: &[Measured]) -> Vec<Row> {
    let mut rows = Vec::new();
    let [lo, hi] = p.overhead_range;
    for m in measured {
        let pub_row = p.rows.iter().find(|r| r.scene == m.scene && r.sf == m.sf);
        let note = if m.thesis_row {
            String::new()
        } else {
            format!(
                "{}: a smaller stand-in for the table's {}{}, cap {} (two-level {}/2 and {}/4)",
                m.label(),
                m.scene,
                p.rows.iter().find(|r| r.scene == m.scene).map_or(0, |r| r.sf),
                m.cap,
                m.cap / 2,
                m.cap / 4
            )
        };
        // A stand-in scene's rows are substituted whatever their claim's label.
        let mark = |r: Row| {
            if m.thesis_row {
                r.with_note(note.clone())
            } else {
                r.with_fidelity(Fidelity::Substituted, note.clone())
            }
        };
        let s = m.single.total_s();
        for (name, run, published) in [
            (format!("{}/2", m.cap / 2), &m.half, pub_row.map(|r| r.r64_2)),
            (format!("{}/4", m.cap / 4), &m.quarter, pub_row.map(|r| r.r32_4)),
        ] {
            let t = run.total_s();
            rows.push(mark(
                Row::new(
                    "two-level-ratio",
                    format!("{} {name}", m.label()),
                    published.map_or("-".into(), |v| format!("{v:.2}")),
                    format!("{s:.2} s / {t:.2} s = {:.2}", ratio(s, t)),
                    Kind::Ratio,
                    Verdict::Shown,
                ),
            ));
            let over = ratio(t, s);
            let per_pass = ratio(
                t / run.passes.max(1) as f64,
                s / m.single.passes.max(1) as f64,
            );
            rows.push(mark(
                Row::new(
                    "overhead",
                    format!("{} {name}", m.label()),
                    format!("{lo}–{hi}× (to one decimal, as the text states it)"),
                    format!(
                        "{over:.2}× ({} rays per pass; passes {} vs {}; per pass {per_pass:.2}×; direct registrations {} of {}, range checks turned away {})",
                        run.rays_in_memory, run.passes, m.single.passes,
                        run.direct_registrations, run.registrations, run.direct_misses
                    ),
                    Kind::Range,
                    Verdict::of(in_text_band(over, lo, hi)),
                ),
            ));
        }
        let same = m.single.sha256 == m.half.sha256 && m.half.sha256 == m.quarter.sha256;
        rows.push(mark(
            Row::new(
                "image-equal",
                m.label(),
                "equal",
                format!(
                    "{}… / {}… / {}…",
                    crate::output::head(&m.single.sha256, 12),
                    crate::output::head(&m.half.sha256, 12),
                    crate::output::head(&m.quarter.sha256, 12)
                ),
                Kind::Count,
                Verdict::of(same),
            ),
        ));
    }
    rows
}

fn document(p: &Published, measured: &[Measured], s: &Setup, quick: bool) -> Document {
    let mut doc = Document::new("nakamaru-4.2: overhead of the two-level grid");
    doc.paragraph(format!(
        "Published: {} (machine: {}). Measured: `rtbench reproduce nakamaru-4.2{}`, {}×{}, breadth-first engine with S+G+B, memory {}, cache {}, one thread; times are preprocessing (with the hierarchy's and the on-disk grid's build) + tracing. Every grid of a row traces the same rays per pass (`rays=`: the fewest any of the three can hold in the budget; the two-level grid's block buffer and lower-grid pool would otherwise leave it fewer rays and more passes, a difference of our memory split, not of the grids). Ratio = single-level time / two-level time (the thesis's); overhead = its inverse, and per pass (time per pass over the single-level grid's).",
        p.source.cite(),
        p.source.machine.as_deref().unwrap_or(""),
        if quick { " --quick" } else { "" },
        s.size,
        s.size,
        s.memory,
        s.cache,
    ));
    let mut t = DocTable::new(
        "",
        &[
            "row", "objects", "grid", "cells per axis", "upper/lower", "total s", "ratio", "thesis",
            "cells visited", "box tests", "lower / direct registrations", "direct turned away",
            "lower grids used", "grid MiB read", "passes", "peak RSS MiB", "CPU / wall", "load avg",
        ],
    );
    for m in measured {
        let r = p.rows.iter().find(|r| r.scene == m.scene && r.sf == m.sf);
        let s = m.single.total_s();
        for (name, run, published) in [
            (format!("single ≤ {}", m.cap), &m.single, None),
            (format!("two-level {}/2", m.cap / 2), &m.half, r.map(|r| r.r64_2)),
            (format!("two-level {}/4", m.cap / 4), &m.quarter, r.map(|r| r.r32_4)),
        ] {
            t.push(vec![
                m.label(),
                m.objects.to_string(),
                name,
                format!("{}×{}×{}", run.res[0], run.res[1], run.res[2]),
                format!(
                    "{}×{}×{} / {}",
                    run.upper[0], run.upper[1], run.upper[2], run.lower
                ),
                format!("{:.2}", run.total_s()),
                format!("{:.2}", ratio(s, run.total_s())),
                published.map_or("-".into(), |v| format!("{v:.2}")),
                run.cells_visited.to_string(),
                run.box_tests.to_string(),
                format!("{} / {}", run.lower_registrations, run.direct_registrations),
                run.direct_misses.to_string(),
                run.lower_grids_used.to_string(),
                format!("{:.1}", run.grid_bytes_read as f64 / 1048576.0),
                run.passes.to_string(),
                format!("{:.1}", run.peak_rss_bytes as f64 / 1048576.0),
                run.cpu_share(),
                run.load_average.clone(),
            ]);
        }
    }
    doc.table(t);
    doc
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(total: f64, sha: &str) -> GridRun {
        GridRun {
            trace_s: total,
            sha256: sha.repeat(12),
            ..Default::default()
        }
    }

    #[test]
    fn the_text_band_holds_on_every_cell_of_the_table() {
        let (p, _): (Published, _) = published::load("nakamaru-4.2", PUBLISHED);
        let [lo, hi] = p.overhead_range;
        let cells: Vec<f64> = p.rows.iter().flat_map(|r| [r.r64_2, r.r32_4]).collect();
        assert_eq!(cells.len(), 14);
        for c in &cells {
            assert!(in_text_band(1.0 / c, lo, hi), "cell {c}: overhead {}", 1.0 / c);
        }
        // Unrounded, four cells fall below the text's band.
        let below = cells.iter().filter(|c| !(lo..=hi).contains(&(1.0 / *c))).count();
        assert_eq!(below, 4);
        assert!(!in_text_band(1.04, lo, hi));
        assert!(!in_text_band(1.36, lo, hi));
    }

    #[test]
    fn the_overhead_is_judged_against_the_text() {
        let (p, _): (Published, _) = published::load("nakamaru-4.2", PUBLISHED);
        let m = Measured {
            scene: "mount".into(),
            sf: 12,
            thesis_row: true,
            objects: 1,
            cap: 128,
            single: run(10.0, "a"),
            half: run(12.0, "a"),
            quarter: run(20.0, "b"),
        };
        let rows = rows(&p, &[m]);
        let over: Vec<_> = rows.iter().filter(|r| r.claim == "overhead").collect();
        assert_eq!(over[0].verdict, Verdict::Holds);
        assert_eq!(over[1].verdict, Verdict::Fails);
        let ratio = rows.iter().find(|r| r.claim == "two-level-ratio").unwrap();
        assert_eq!(ratio.published, "0.81");
        let img = rows.iter().find(|r| r.claim == "image-equal").unwrap();
        assert_eq!(img.verdict, Verdict::Fails);
    }
}
