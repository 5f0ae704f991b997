//! `nakamaru-4.1`: seed 000's Table 4.1, the basic breadth-first method against the improved one
//! with S+G (separate box and geometry files, geometry read lazily) and S+G+B (and the
//! bounding-box hierarchy), 27 rows of seven SPD scenes up to 50,000,000 objects.
//!
//! Per row: the scene is streamed from its generator into a basic store (one `objects.bin`) and
//! traced by the basic method (`layout=basic`); the store is removed and the scene streamed into a
//! split store (the row's "generation": SPD plus conversion, as the thesis times it), traced with
//! S+G (`layout=split`, lazy) and S+G+B (`hierarchy=on`: the hierarchy is built at preprocessing
//! and its build counted there, as the thesis's S+G+B preprocessing includes it). Every run:
//! 512×512 SPD workload out of core, engine budget 256 MiB (the thesis's machine), page cache
//! dropped after preprocessing and every sweep (`cache=cold`: this machine could cache the
//! scene), peak RSS of the run (reset before it). Rows are saved as they finish (`--resume`).
//!
//! `--quick` traces one small row per scene at 64×64; `--set rows=balls6,mount9` picks rows.

use super::per_ray::{self, SizePoint};
use super::published::{self, Source};
use super::{environment, Claim, Ctx, Fidelity, Kind, Output, Param, Row, Runtime, Table, Verdict};
use crate::output::hex;
use crate::error::{input, Result};
use crate::source::Source as SceneSource;
use crate::workload::{self, out_of_core};
use rtbench_engines::breadth_first::config::BreadthFirstConfig;
use rtbench_engines::breadth_first::spill::SpillDir;
use rtbench_engines::breadth_first::BreadthFirst;
use rtbench_engines::store::{Codec, Layout, StoreHeader, StoreWriter};
use rtbench_engines::{Engine, Settings};
use rtbench_reports::{Document, Table as DocTable};
use rtbench_scenes::spd::MountHash;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::Path;

const ROWS: Param = Param {
    key: "rows",
    help: "rows to measure, e.g. balls6,mount9 (default: all 27; --quick: one small row per scene)",
};
const SIZE: Param = Param {
    key: "size",
    help: "image size (default 512, 64 with --quick)",
};
const MEMORY: Param = Param {
    key: "memory",
    help: "engine memory budget (default 256MiB, the thesis's machine)",
};
const CACHE: Param = Param {
    key: "cache",
    help: "cold (default: page cache dropped after preprocessing and every sweep) or warm",
};
const SPILL: Param = Param {
    key: "spill",
    help: "directory for the scene stores and spill files (default the system temp dir)",
};

pub const TABLE: Table = Table {
    id: "nakamaru-4.1",
    seed: "000",
    source: "Table 4.1",
    about: "000 (Nakamaru 2002) Table 4.1: basic breadth-first method vs S+G and S+G+B (bounding-box hierarchy), 27 rows up to 5e7 objects",
    runtime: Runtime {
        quick: "minutes",
        full: "about 80 minutes (27 rows × 3 methods out of core, and the stores' writing: 4620 s on a 2-core machine); resumable",
    },
    params: &[ROWS, SIZE, MEMORY, CACHE, SPILL],
    claims: &[
        Claim {
            key: "sg-ratio",
            fidelity: Fidelity::Substituted,
            why: "settings that are ours: the grid's shape is our reading of Klimaszewski's method (its formula is not in the thesis); our record format (f32, prepared primitives, checksums) makes balls' and gears' split stores 1.75x and 1.59x the thesis's sizes (the other scenes' within 13%); floor and backdrop polygons are tested apart from the grid in every scene (the thesis's Ch. 3 grouping did so for balls and tree only); the machine the record names (its disk read cold, page cache dropped by posix_fadvise, 256 MiB engine budget) is stated, not the reason; time ratios only",
        },
        Claim {
            key: "sgb-ratio",
            fidelity: Fidelity::Substituted,
            why: "as sg-ratio, and the hierarchy's top-level boxes share one grid here where the thesis gives each its own (balls, gears and tree have two); the test on an inner node is ours (the thesis does not give it: the leaf's box test without the per-object skips, which skips exactly)",
        },
        Claim {
            key: "sgb-over-sg",
            fidelity: Fidelity::Substituted,
            why: "as sgb-ratio",
        },
        Claim {
            key: "image-equal",
            fidelity: Fidelity::Faithful,
            why: "",
        },
        Claim {
            key: "memory",
            fidelity: Fidelity::Substituted,
            why: MEMORY_WHY,
        },
    ],
    run,
};

/// Why the memory rows of Tables 4.1 and 4.3 are substituted.
pub(super) const MEMORY_WHY: &str = "the thesis's only limit was its machine's 256 MB of physical RAM, operating system included (no other cap is stated); here the engine alone is given a 256 MiB budget on a 23.5 GiB machine, and the whole process's peak RSS (engine, image, code) is checked against a bound of ours, 320 MiB, and shown beside the thesis's 256 MB";

const PUBLISHED: &str = include_str!("../../../data/published/nakamaru-4.1.json");

#[derive(Deserialize)]
struct Published {
    source: Source,
    memory_mib: u64,
    rows: Vec<PublishedRow>,
}

#[derive(Deserialize, Serialize, Clone)]
struct PublishedRow {
    scene: String,
    sf: u32,
    objects: u64,
    size_mb: u64,
    generation_s: u64,
    basic_s: u64,
    sg: f64,
    sgb: f64,
    sgb_over_sg: f64,
}

/// One method's run of one row.
#[derive(Serialize, Deserialize, Default, Clone)]
struct Run {
    preprocess_s: f64,
    trace_s: f64,
    intersect_s: f64,
    shade_s: f64,
    passes: u64,
    sha256: String,
    peak_rss_bytes: u64,
    /// The engine's reads in preprocessing, and in intersection (all calls).
    preprocess_bytes_read: u64,
    intersect_bytes_read: u64,
    intersect_read_calls: u64,
    intersect_seeks: u64,
    /// The workload's reads in shading and spill files.
    workload_bytes_read: u64,
    workload_seeks: u64,
    geometry_loads: u64,
    /// Bounding-box records read by sweeps (S+G+B; others: objects × passes).
    boxes_read: u64,
    objects_skipped: u64,
    bh_build_s: f64,
    bh_levels: Vec<u64>,
    /// `bh_level_K_skipped` per level K ≥ 1.
    bh_skipped: Vec<u64>,
    load_average: String,
    /// Rays traced, every kind (0 in rows saved by older versions, which did not keep it).
    #[serde(default)]
    rays: u64,
    /// CPU seconds of preprocessing and tracing (0 in rows saved by older versions): against
    /// the total it shows a run that did not get its core (a shared machine's times).
    #[serde(default)]
    cpu_s: f64,
}

impl Run {
    fn total_s(&self) -> f64 {
        self.preprocess_s + self.trace_s
    }

    /// CPU time over wall time, as a percentage ("-" for rows that did not keep it).
    fn cpu_share(&self) -> String {
        super::grid_runs::cpu_share(self.cpu_s, self.total_s())
    }
}

#[derive(Serialize, Deserialize, Clone)]
struct Measured {
    scene: String,
    sf: u32,
    /// A row of the table (false: a `--quick` stand-in).
    thesis_row: bool,
    objects: u64,
    basic_bytes: u64,
    split_bytes: u64,
    /// Split store written from the generator (the thesis's "generation").
    generation_s: f64,
    basic: Run,
    sg: Run,
    sgb: Run,
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

/// The small rows of `--quick`: one per scene, seconds each.
const QUICK: &[(&str, u32)] = &[
    ("balls", 3),
    ("gears", 3),
    ("mount", 5),
    ("rings", 4),
    ("teapot", 12),
    ("tetra", 5),
    ("tree", 9),
];

fn resolve(scene: &str, sf: u32) -> Result<SceneSource> {
    let hash = (scene == "mount").then_some(MountHash::Jenkins);
    SceneSource::resolve(scene, Some(sf), None, hash)
}

/// Streams the scene into a store of `layout` at `dir`; returns (header, seconds).
fn write_store(src: &SceneSource, dir: &Path, layout: Layout) -> Result<(StoreHeader, f64)> {
    let t = std::time::Instant::now();
    let mut w = StoreWriter::create_with(dir, &src.label(), layout, Codec::None)
        .map_err(|e| input(format!("{}: {e}", dir.display())))?;
    src.stream(&mut w)?;
    w.finish()
        .map_err(|e| input(format!("{}: cannot write: {e}", dir.display())))?;
    let h = StoreHeader::read(dir).map_err(|e| input(e.to_string()))?;
    Ok((h, t.elapsed().as_secs_f64()))
}

struct Setup<'a> {
    size: u32,
    memory: &'a str,
    cache: &'a str,
    spill: Option<&'a str>,
}

fn trace(dir: &Path, s: &Setup, extra: &[(&str, &str)]) -> Result<Run> {
    crate::measure::rss::reset_peak_rss();
    let load_average = super::grid_runs::load_average();
    let mut pairs: Vec<(String, String)> = vec![
        ("memory".into(), s.memory.into()),
        ("verify".into(), "records".into()),
        ("cache".into(), s.cache.into()),
    ];
    if let Some(sp) = s.spill {
        pairs.push(("spill".into(), sp.into()));
    }
    pairs.extend(extra.iter().map(|(k, v)| (k.to_string(), v.to_string())));
    let config = BreadthFirstConfig::from_settings(Settings::new("breadth-first", pairs))?;
    let cpu0 = crate::measure::clock::process_cpu_seconds();
    let t = std::time::Instant::now();
    let engine = BreadthFirst::open(dir, config)?;
    let preprocess_s = t.elapsed().as_secs_f64();
    let ooc = out_of_core::render(&engine, s.size)
        .map_err(|e| input(format!("{}: out-of-core render: {e}", dir.display())))?;
    let r = &ooc.render;
    let x = |k: &str| r.counters.extra.get(k).copied().unwrap_or(0);
    let b = engine.build_stats();
    let levels = b.get("bh_levels").copied().unwrap_or(0.0) as usize;
    Ok(Run {
        preprocess_s,
        trace_s: r.trace_s,
        intersect_s: r.intersect_s,
        shade_s: r.shade_s,
        passes: x("bf_passes"),
        sha256: hex(&Sha256::digest(r.pixels())),
        peak_rss_bytes: crate::measure::rss::peak_rss_bytes().unwrap_or(0),
        preprocess_bytes_read: b.get("preprocess_bytes_read").copied().unwrap_or(0.0) as u64
            + b.get("bh_build_bytes_read").copied().unwrap_or(0.0) as u64,
        intersect_bytes_read: x("io_bytes_read"),
        intersect_read_calls: x("io_read_calls"),
        intersect_seeks: x("io_seeks"),
        workload_bytes_read: ooc.io.bytes_read,
        workload_seeks: ooc.io.seeks,
        geometry_loads: x("bf_geometry_loads"),
        boxes_read: if levels > 0 {
            x("bh_level_0_read")
        } else {
            engine.header().objects * x("bf_passes")
        },
        objects_skipped: x("bh_objects_skipped"),
        bh_build_s: b.get("bh_build_s").copied().unwrap_or(0.0),
        bh_levels: (1..=levels)
            .map(|k| b.get(&format!("bh_level_{k}_boxes")).copied().unwrap_or(0.0) as u64)
            .collect(),
        bh_skipped: (1..=levels)
            .map(|k| x(&format!("bh_level_{k}_skipped")))
            .collect(),
        load_average,
        rays: r.stats.total,
        cpu_s: crate::measure::clock::process_cpu_seconds() - cpu0,
    })
}

/// One method's run, saved on its own (`{key}.{method}`) as soon as it finishes, so that a row of
/// hours resumed in another invocation does not trace its finished methods again.
fn method(
    cp: &super::Checkpoint,
    key: &str,
    name: &str,
    run: impl FnOnce() -> Result<Run>,
) -> Result<Run> {
    let k = format!("{key}.{name}");
    if let Some(r) = cp.load::<Run>(&k)? {
        eprintln!("nakamaru-4.1: {key}: {name} saved by an earlier run");
        return Ok(r);
    }
    let r = run()?;
    cp.save(&k, &r)?;
    Ok(r)
}

fn measure_row(
    scene: &str,
    sf: u32,
    thesis_row: bool,
    s: &Setup,
    cp: &super::Checkpoint,
    key: &str,
) -> Result<Measured> {
    let src = resolve(scene, sf)?;
    let spill = SpillDir::create(s.spill.map(Path::new)).map_err(input)?;
    let basic_dir = spill.path().join("basic");
    // The basic store's size is saved with its run (`basic_bytes`), so a resumed row need not
    // write the basic store again.
    #[derive(Serialize, Deserialize)]
    struct BasicStep {
        bytes: u64,
        run: Run,
    }
    let basic_key = format!("{key}.basic");
    let basic_step = match cp.load::<BasicStep>(&basic_key)? {
        Some(b) => {
            eprintln!("nakamaru-4.1: {key}: basic saved by an earlier run");
            b
        }
        None => {
            eprintln!("nakamaru-4.1: {scene}{sf}: basic store …");
            let (hb, _) = write_store(&src, &basic_dir, Layout::Basic)?;
            eprintln!("nakamaru-4.1: {scene}{sf}: basic ({} objects) …", hb.objects);
            let run = trace(&basic_dir, s, &[("layout", "basic")])?;
            std::fs::remove_dir_all(&basic_dir).map_err(|e| input(e.to_string()))?;
            let b = BasicStep {
                bytes: hb.geometry_bytes,
                run,
            };
            cp.save(&basic_key, &b)?;
            b
        }
    };
    let split_dir = spill.path().join("split");
    let (hs, generation_s) = write_store(&src, &split_dir, Layout::Split)?;
    let sg = method(cp, key, "sg", || {
        eprintln!("nakamaru-4.1: {scene}{sf}: S+G …");
        trace(&split_dir, s, &[("layout", "split")])
    })?;
    let sgb = method(cp, key, "sgb", || {
        eprintln!("nakamaru-4.1: {scene}{sf}: S+G+B …");
        trace(&split_dir, s, &[("layout", "split"), ("hierarchy", "on")])
    })?;
    let basic = basic_step.run;
    Ok(Measured {
        scene: scene.to_string(),
        sf,
        thesis_row,
        objects: hs.objects,
        basic_bytes: basic_step.bytes,
        split_bytes: hs.bbox_bytes + hs.geometry_bytes,
        generation_s,
        basic,
        sg,
        sgb,
    })
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let size = ctx
        .params
        .number::<u32>(SIZE.key, 1)?
        .unwrap_or(if ctx.quick { 64 } else { 512 });
    workload::check_size(size)?;
    let memory = ctx.params.bytes(MEMORY.key, "256MiB")?;
    let cache = ctx.params.raw(CACHE.key).unwrap_or("cold").to_string();
    let setup = Setup {
        size,
        memory: &memory,
        cache: &cache,
        spill: ctx.params.raw(SPILL.key),
    };
    let mut todo: Vec<(String, u32, bool)> = if ctx.quick {
        QUICK.iter().map(|&(s, sf)| (s.to_string(), sf, false)).collect()
    } else {
        p.rows.iter().map(|r| (r.scene.clone(), r.sf, true)).collect()
    };
    if let Some(list) = ctx.params.list(ROWS.key)? {
        let mut picked = Vec::new();
        for item in list {
            let split = item
                .find(|c: char| c.is_ascii_digit())
                .ok_or_else(|| input(format!("{}: rows '{item}': expected scene and SF, e.g. balls6", ctx.id)))?;
            let (scene, sf) = item.split_at(split);
            let sf: u32 = sf
                .parse()
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| input(format!("{}: rows '{item}': bad size factor", ctx.id)))?;
            if !p.rows.iter().any(|r| r.scene == scene) {
                return Err(input(format!(
                    "{}: rows '{item}': the table's scenes are balls, gears, mount, rings, teapot, tetra, tree",
                    ctx.id
                )));
            }
            let thesis = p.rows.iter().any(|r| r.scene == scene && r.sf == sf);
            picked.push((scene.to_string(), sf, thesis));
        }
        todo = picked;
    }
    let mut measured = Vec::new();
    for (scene, sf, thesis) in todo {
        let key = format!("{scene}{sf}-{size}-{memory}-{cache}");
        let m = match ctx.checkpoint.load::<Measured>(&key)? {
            Some(m) => {
                eprintln!("{}: {scene}{sf}: saved by an earlier run", ctx.id);
                m
            }
            None => {
                let m = measure_row(&scene, sf, thesis, &setup, ctx.checkpoint, &key)?;
                ctx.checkpoint.save(&key, &m)?;
                m
            }
        };
        measured.push(m);
    }
    let rows = rows(&p, &measured);
    let mut doc = document(&p, &measured, &setup, ctx.quick);
    let points: Vec<SizePoint> = measured
        .iter()
        .map(|m| SizePoint {
            scene: m.scene.clone(),
            sf: m.sf,
            objects: m.objects,
            seconds: [m.basic.total_s(), m.sg.total_s(), m.sgb.total_s()],
            peak_rss: [m.basic.peak_rss_bytes, m.sg.peak_rss_bytes, m.sgb.peak_rss_bytes],
        })
        .collect();
    per_ray::table(&mut doc, &points, size);
    let charts = per_ray::charts(ctx.id, &points, size);
    let mut out = Output::new(
        Result_ {
            id: ctx.id,
            published: raw,
            measured,
            size,
            memory: memory.clone(),
            cache: cache.clone(),
            environment: environment(1),
        },
        rows,
        doc,
    );
    out.charts = charts;
    Ok(out)
}

fn ratio(a: f64, b: f64) -> f64 {
    a / b.max(1e-9)
}

/// "S+G ... grows with data size as expected" (§4.4): the thesis's own S+G columns are not
/// monotone (gears 1.97 → 1.88, rings 1.85 → 1.70, teapot 2.22 → 1.99), but in every scene the largest
/// row gains more than the smallest; that is the reading its numbers bear.
fn grows_with_size(by_size: &[f64]) -> bool {
    by_size.len() >= 2 && by_size[by_size.len() - 1] > by_size[0]
}

/// The range of a ratio over each scene's largest row of the table: the text quotes S+G as
/// 1.88–2.30 and S+G+B as 1.39–4.48, but at the largest rows the table's own S+G runs from 1.38
/// (tree23) and includes rings135's 1.70, so the band judged is the table's, and the row names the
/// text's beside it.
fn largest_rows_range(p: &Published, f: impl Fn(&PublishedRow) -> f64) -> (f64, f64) {
    let mut largest: BTreeMap<&str, &PublishedRow> = BTreeMap::new();
    for r in &p.rows {
        let e = largest.entry(r.scene.as_str()).or_insert(r);
        if r.sf > e.sf {
            *e = r;
        }
    }
    largest.values().map(|r| f(r)).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    })
}

fn rows(p: &Published, measured: &[Measured]) -> Vec<Row> {
    let mut rows = Vec::new();
    let find = |m: &Measured| p.rows.iter().find(|r| r.scene == m.scene && r.sf == m.sf);
    let note = |m: &Measured| {
        if m.thesis_row {
            String::new()
        } else {
            format!("{}: not a row of the table (a smaller stand-in)", m.label())
        }
    };
    for m in measured {
        let first = rows.len();
        let pub_row = find(m);
        let (b, sg, sgb) = (m.basic.total_s(), m.sg.total_s(), m.sgb.total_s());
        let shown = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2}"));
        rows.push(
            Row::new(
                "sg-ratio",
                m.label(),
                shown(pub_row.map(|r| r.sg)),
                format!("{b:.1} s / {sg:.1} s = {:.2}", ratio(b, sg)),
                Kind::Ratio,
                Verdict::Shown,
            )
            .with_note(note(m)),
        );
        rows.push(
            Row::new(
                "sgb-ratio",
                m.label(),
                shown(pub_row.map(|r| r.sgb)),
                format!("{b:.1} s / {sgb:.1} s = {:.2}", ratio(b, sgb)),
                Kind::Ratio,
                Verdict::Shown,
            )
            .with_note(note(m)),
        );
        rows.push(
            Row::new(
                "sgb-over-sg",
                m.label(),
                format!("{} (worst 0.99)", shown(pub_row.map(|r| r.sgb_over_sg))),
                format!("{:.2}", ratio(sg, sgb)),
                Kind::Ratio,
                Verdict::of(ratio(sg, sgb) >= 0.95),
            )
            .with_note(note(m)),
        );
        let same = m.basic.sha256 == m.sg.sha256 && m.sg.sha256 == m.sgb.sha256;
        rows.push(
            Row::new(
                "image-equal",
                m.label(),
                "equal",
                format!(
                    "{}… / {}… / {}…",
                    crate::output::head(&m.basic.sha256, 12),
                    crate::output::head(&m.sg.sha256, 12),
                    crate::output::head(&m.sgb.sha256, 12)
                ),
                Kind::Count,
                Verdict::of(same),
            )
            .with_note(note(m)),
        );
        let peak = m
            .basic
            .peak_rss_bytes
            .max(m.sg.peak_rss_bytes)
            .max(m.sgb.peak_rss_bytes);
        rows.push(
            Row::new(
                "memory",
                m.label(),
                format!("{} MB machine; bound 320 MiB", p.memory_mib),
                super::params::peak_rss_text(peak),
                Kind::Ordering,
                Verdict::of(peak <= 320 << 20),
            )
            .with_note(note(m)),
        );
        if !m.thesis_row {
            // A stand-in scene's rows are substituted whatever their claim's label.
            for r in &mut rows[first..] {
                r.fidelity.get_or_insert(Fidelity::Substituted);
            }
        }
    }
    // Per scene: S+G growing with size, and the ratios at the largest row measured.
    let mut scenes: BTreeMap<&str, Vec<&Measured>> = BTreeMap::new();
    for m in measured.iter().filter(|m| m.thesis_row) {
        scenes.entry(m.scene.as_str()).or_default().push(m);
    }
    for (scene, mut ms) in scenes {
        ms.sort_by_key(|m| m.sf);
        let largest_pub = p.rows.iter().filter(|r| r.scene == scene).map(|r| r.sf).max();
        let last = ms[ms.len() - 1];
        let at_largest = Some(last.sf) == largest_pub;
        let partial = if at_largest {
            String::new()
        } else {
            format!("partial: largest row measured {} (the table's: {scene}{})", last.label(), largest_pub.unwrap_or(0))
        };
        let sgs: Vec<f64> = ms.iter().map(|m| ratio(m.basic.total_s(), m.sg.total_s())).collect();
        if sgs.len() >= 2 {
            let thesis: Vec<String> = p
                .rows
                .iter()
                .filter(|r| r.scene == scene)
                .map(|r| format!("{}{} {:.2}", r.scene, r.sf, r.sg))
                .collect();
            rows.push(
                Row::new(
                    "sg-ratio",
                    format!("{scene}: growth with size"),
                    format!(
                        "grows with data size (§4.4): largest row above smallest; thesis {}",
                        thesis.join(", ")
                    ),
                    ms.iter()
                        .zip(&sgs)
                        .map(|(m, r)| format!("{} {r:.2}", m.label()))
                        .collect::<Vec<_>>()
                        .join(", "),
                    Kind::Shape,
                    Verdict::of(grows_with_size(&sgs)),
                )
                .with_note(partial.clone()),
            );
        }
        let sg = sgs[sgs.len() - 1];
        let (sg_lo, sg_hi) = largest_rows_range(p, |r| r.sg);
        rows.push(
            Row::new(
                "sg-ratio",
                format!("{scene}: at the largest row"),
                format!("{sg_lo:.2}–{sg_hi:.2} (the table's largest rows; the text says 1.88–2.30)"),
                format!("{} {sg:.2}", last.label()),
                Kind::Range,
                if at_largest {
                    Verdict::of((sg_lo..=sg_hi).contains(&sg))
                } else {
                    Verdict::NotMeasured
                },
            )
            .with_note(partial.clone()),
        );
        let sgb = ratio(last.basic.total_s(), last.sgb.total_s());
        let (sgb_lo, sgb_hi) = largest_rows_range(p, |r| r.sgb);
        rows.push(
            Row::new(
                "sgb-ratio",
                format!("{scene}: at the largest row"),
                format!("{sgb_lo:.2}–{sgb_hi:.2} (the table's largest rows; the text says 1.39–4.48)"),
                format!("{} {sgb:.2}", last.label()),
                Kind::Range,
                if at_largest {
                    Verdict::of((sgb_lo..=sgb_hi).contains(&sgb))
                } else {
                    Verdict::NotMeasured
                },
            )
            .with_note(partial),
        );
    }
    rows
}

fn document(p: &Published, measured: &[Measured], s: &Setup, quick: bool) -> Document {
    let mut doc = Document::new("nakamaru-4.1: basic method vs S+G and S+G+B");
    doc.paragraph(format!(
        "Published: {} (machine: {}). Measured: `rtbench reproduce nakamaru-4.1{}`, {}×{}, breadth-first engine memory {}, cache {}, one thread; totals = preprocessing (S+G+B: with the hierarchy's build) + tracing (intersection and shading, out of core). Ratios are basic / method. MiB = 2^20 bytes. CPU / wall: the process's CPU time over its wall time per method; well below 100% the run waited for its core (a shared machine) or the disk, and its time says less.",
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
            "row", "objects", "split MiB", "generation s", "basic s", "S+G", "S+G+B", "(S+G+B / S+G)",
            "thesis S+G", "thesis S+G+B", "passes", "hierarchy boxes", "boxes read S+G+B / S+G",
            "geometry loads", "bh build s", "peak RSS MiB", "images equal", "CPU / wall basic, S+G, S+G+B",
            "load avg",
        ],
    );
    for m in measured {
        let r = p.rows.iter().find(|r| r.scene == m.scene && r.sf == m.sf);
        let (b, sg, sgb) = (m.basic.total_s(), m.sg.total_s(), m.sgb.total_s());
        let peak = m.basic.peak_rss_bytes.max(m.sg.peak_rss_bytes).max(m.sgb.peak_rss_bytes);
        t.push(vec![
            m.label(),
            m.objects.to_string(),
            format!("{:.1}", m.split_bytes as f64 / 1048576.0),
            format!("{:.1}", m.generation_s),
            format!("{b:.1}"),
            format!("{:.2}", ratio(b, sg)),
            format!("{:.2}", ratio(b, sgb)),
            format!("({:.2})", ratio(sg, sgb)),
            r.map_or("-".into(), |r| format!("{:.2}", r.sg)),
            r.map_or("-".into(), |r| format!("{:.2}", r.sgb)),
            format!("{}/{}/{}", m.basic.passes, m.sg.passes, m.sgb.passes),
            m.sgb
                .bh_levels
                .iter()
                .map(|n| n.to_string())
                .collect::<Vec<_>>()
                .join("/"),
            format!("{}/{}", m.sgb.boxes_read, m.sg.boxes_read),
            format!("{}/{}", m.sgb.geometry_loads, m.sg.geometry_loads),
            format!("{:.2}", m.sgb.bh_build_s),
            format!("{:.1}", peak as f64 / 1048576.0),
            (m.basic.sha256 == m.sg.sha256 && m.sg.sha256 == m.sgb.sha256).to_string(),
            format!("{}, {}, {}", m.basic.cpu_share(), m.sg.cpu_share(), m.sgb.cpu_share()),
            m.sgb.load_average.clone(),
        ]);
    }
    doc.table(t);
    // The table's cost: what a full run takes, summed over rows measured in different runs.
    let sum = |f: &dyn Fn(&Measured) -> f64| measured.iter().map(f).fold(0.0, |a, x| a + x);
    let (g, b, sg, sgb) = (
        sum(&|m| m.generation_s),
        sum(&|m| m.basic.total_s()),
        sum(&|m| m.sg.total_s()),
        sum(&|m| m.sgb.total_s()),
    );
    doc.paragraph(format!(
        "Measured time over these {} rows: split-store generation {g:.0} s, basic {b:.0} s, S+G {sg:.0} s, S+G+B {sgb:.0} s; {:.0} s = {:.2} h in all (the basic stores' writing and the cache drops between runs not included).",
        measured.len(),
        g + b + sg + sgb,
        (g + b + sg + sgb) / 3600.0
    ));
    let mut io = DocTable::new(
        "Bytes read and seeks per stage (engine: preprocessing and intersection; workload: shading and spill files)",
        &[
            "row", "method", "preprocess s", "intersect s", "shade s", "preprocess bytes", "intersect bytes",
            "intersect seeks", "workload bytes", "workload seeks",
        ],
    );
    for m in measured {
        for (name, r) in [("basic", &m.basic), ("S+G", &m.sg), ("S+G+B", &m.sgb)] {
            io.push(vec![
                m.label(),
                name.into(),
                format!("{:.2}", r.preprocess_s),
                format!("{:.2}", r.intersect_s),
                format!("{:.2}", r.shade_s),
                r.preprocess_bytes_read.to_string(),
                r.intersect_bytes_read.to_string(),
                r.intersect_seeks.to_string(),
                r.workload_bytes_read.to_string(),
                r.workload_seeks.to_string(),
            ]);
        }
    }
    doc.table(io);
    doc
}

#[cfg(test)]
mod tests {
    use super::*;

    fn published() -> Published {
        published::load::<Published>("nakamaru-4.1", PUBLISHED).0
    }

    fn by_scene(p: &Published) -> BTreeMap<&str, Vec<&PublishedRow>> {
        let mut m: BTreeMap<&str, Vec<&PublishedRow>> = BTreeMap::new();
        for r in &p.rows {
            m.entry(r.scene.as_str()).or_default().push(r);
        }
        for v in m.values_mut() {
            v.sort_by_key(|r| r.sf);
        }
        m
    }

    #[test]
    fn growth_with_size_holds_on_the_thesis_table() {
        let p = published();
        let scenes = by_scene(&p);
        assert_eq!(scenes.len(), 7);
        let mut not_monotone = Vec::new();
        for (scene, rs) in &scenes {
            let sgs: Vec<f64> = rs.iter().map(|r| r.sg).collect();
            assert!(grows_with_size(&sgs), "{scene}: {sgs:?}");
            if !sgs.windows(2).all(|w| w[1] >= w[0]) {
                not_monotone.push(*scene);
            }
        }
        // Why the check is not "monotone": three of the thesis's own scenes are not.
        assert_eq!(not_monotone, ["gears", "rings", "teapot"]);
        assert!(!grows_with_size(&[2.0, 1.9]));
    }

    #[test]
    fn the_bands_judged_are_the_tables_own_largest_rows() {
        let p = published();
        let (lo, hi) = largest_rows_range(&p, |r| r.sg);
        assert_eq!((lo, hi), (1.38, 2.30));
        let (blo, bhi) = largest_rows_range(&p, |r| r.sgb);
        assert_eq!((blo, bhi), (1.39, 4.48));
        for rs in by_scene(&p).values() {
            let last = rs[rs.len() - 1];
            assert!((lo..=hi).contains(&last.sg));
            assert!((blo..=bhi).contains(&last.sgb));
        }
        // The text's 1.88–2.30 leaves out two of the table's own largest rows.
        let outside: Vec<String> = by_scene(&p)
            .values()
            .map(|rs| rs[rs.len() - 1])
            .filter(|r| !(1.88..=2.30).contains(&r.sg))
            .map(|r| format!("{}{}", r.scene, r.sf))
            .collect();
        assert_eq!(outside, ["rings135", "tree23"]);
    }

    #[test]
    fn hierarchy_never_costs_more_than_the_thesis_worst() {
        let p = published();
        assert!(p.rows.iter().all(|r| r.sgb_over_sg >= 0.95));
        assert_eq!(
            p.rows.iter().map(|r| r.sgb_over_sg).fold(f64::INFINITY, f64::min),
            0.99
        );
    }
}
