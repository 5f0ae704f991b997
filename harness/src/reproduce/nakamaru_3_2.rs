//! `nakamaru-3.2`: where the in-memory grid starts to thrash, measured so that any machine gives
//! the same answer (seed 000 §3.4, Table 3.2, Figs. 3.5–3.7; digest §2.2).
//!
//! Per scene and size factor:
//! - the `grid` engine (rss-r: no shadow cache, no per-voxel culling; floor out for balls and
//!   tree as in the thesis) traces the SPD workload on one thread, recording every query; its
//!   compute time is measured (build + trace). Every query is then replayed through
//!   [`Grid::page_accesses`] in the order the render made them, and Mattson's stack algorithm
//!   ([`Mattson`]) gives the page faults of an LRU memory of 32 MiB (000's machine) in 4 KiB
//!   pages. Modelled time = compute time + every page touched loaded once at the disk's
//!   bandwidth (the scene must be read in any case) + each fault beyond that × fault cost.
//! - the `breadth-first` engine (memory budget 32 MiB, registration ⌈r/10 + 0.5⌉ as in 000's
//!   scaling runs) traces the same workload; its measured time (store writing, preprocessing,
//!   trace) beside the modelled time = measured + (bytes read and written) ÷ bandwidth + seeks ×
//!   seek cost, on the same disk. Its shading here uses the in-memory scene (the out-of-core
//!   shading is `rtbench render --scene STORE`): only intersection and preprocessing I/O count.
//! - onset: the smallest SF whose modelled grid time per ray exceeds twice its in-core (measured)
//!   time per ray, i.e. where paging costs more than the work itself; crossover: the smallest SF
//!   whose modelled grid time exceeds the breadth-first engine's modelled time.
//!
//! Disks: HDD-like (8 ms per fault or seek, 100 MB/s), SSD-like (0.1 ms, 500 MB/s), and with
//! `fault-ms X` one more (X ms, 100 MB/s).

use super::published::{self, PublishedClaim, Source};
use super::{Claim, Ctx, Fidelity, Kind, Output, Param, Row, Runtime, Table, Verdict};
use crate::error::{input, Result};
use crate::source::Source as SceneSource;
use crate::workload::paging::Mattson;
use crate::workload::{self, trace};
use rtbench_engines::breadth_first::config::BreadthFirstConfig;
use rtbench_engines::breadth_first::BreadthFirst;
use rtbench_engines::grid::config::GridConfig;
use rtbench_engines::grid::paging::PAGE;
use rtbench_engines::grid::Grid;
use rtbench_engines::{Engine, Settings};
use rtbench_reports::{Document, Table as DocTable};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::time::Instant;

/// `max-sf N` (every scene), `scene=N,…` (those scenes) or `scene=LO..HI` (only those SFs).
pub const MAX_SF: Param = Param {
    key: "max-sf",
    help: "the largest SF run: N, or scene=N,scene=LO..HI",
};
/// `fault-ms X`: one more disk, X ms per fault or seek at 100 MB/s.
pub const FAULT_MS: Param = Param {
    key: "fault-ms",
    help: "one more modelled disk: ms per page fault or seek (100 MB/s)",
};

pub const TABLE: Table = Table {
    id: "nakamaru-3.2",
    seed: "000",
    source: "Table 3.2, Figs. 3.5–3.7",
    about: "000 (Nakamaru 2002) Table 3.2, Figs. 3.5-3.7: grid thrashing onset (Mattson page model) vs breadth-first, 32 MB",
    runtime: Runtime {
        quick: "minutes",
        full: "hours",
    },
    params: &[MAX_SF, FAULT_MS],
    claims: &[
        Claim {
            key: "onset",
            fidelity: Fidelity::Model,
            why: "Mattson's LRU stack model of the grid's page stream at 32 MiB and a modelled disk, in place of Rayshade thrashing on a 32 MB Pentium 90; 000's curves are lost, so no onset SF is published",
        },
        Claim {
            key: "table-3.2-memory",
            fidelity: Fidelity::Substituted,
            why: "the memory of our grid's page layout (rss-r), not rayshade-ss's allocation",
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/nakamaru-3.2.json");

#[derive(Deserialize)]
struct Published {
    source: Source,
    memory_mb: u64,
    table_3_2: Vec<MemoryRow>,
    sf_ranges: BTreeMap<String, [u32; 2]>,
    claims: Vec<PublishedClaim>,
}

/// Table 3.2: memory used by rayshade-ss per scene and SF.
#[derive(Deserialize)]
struct MemoryRow {
    scene: String,
    sf: u32,
    mb: f64,
}

/// A modelled disk: cost of a page fault and of a seek (s), sequential bandwidth (bytes/s).
struct Disk {
    name: String,
    fault_s: f64,
    bandwidth: f64,
}

/// One size factor of one scene, measured.
struct Point {
    sf: u32,
    objects: usize,
    rays: u64,
    grid_bytes: u64,
    accesses: u64,
    /// Pages touched at all (first-touch loads), and faults beyond those at 32 MiB.
    distinct: u64,
    faults: u64,
    grid_s: f64,
    bf_s: f64,
    bf_io_bytes: u64,
    bf_seeks: u64,
    bf_passes: u64,
}

impl Point {
    /// Compute, plus loading every page once at the disk's bandwidth (as reading the scene
    /// file), plus a random access per fault beyond that.
    fn grid_model(&self, d: &Disk) -> f64 {
        self.grid_s + (self.distinct * PAGE) as f64 / d.bandwidth + self.faults as f64 * d.fault_s
    }
    fn bf_model(&self, d: &Disk) -> f64 {
        self.bf_s + self.bf_io_bytes as f64 / d.bandwidth + self.bf_seeks as f64 * d.fault_s
    }
}

#[derive(Serialize)]
struct DiskModel {
    disk: String,
    grid_s: f64,
    bf_s: f64,
}

#[derive(Serialize)]
struct SfRow {
    sf: u32,
    objects: usize,
    rays: u64,
    table_3_2_mb: Option<f64>,
    grid_bytes: u64,
    page_accesses: u64,
    pages_touched: u64,
    faults_beyond_first_touch: u64,
    grid_compute_s: f64,
    bf_measured_s: f64,
    bf_io_bytes: u64,
    bf_seeks: u64,
    bf_passes: u64,
    model: Vec<DiskModel>,
}

#[derive(Serialize)]
struct Onset {
    disk: String,
    onset_sf: Option<u32>,
    crossover_sf: Option<u32>,
}

#[derive(Serialize)]
struct SceneResult {
    scene: String,
    sf: [u32; 2],
    floor: &'static str,
    rows: Vec<SfRow>,
    result: Vec<Onset>,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    measured: Vec<SceneResult>,
    quick: bool,
    max_sf: Option<String>,
    fault_ms: Option<f64>,
    memory_bytes: u64,
    page_bytes: u64,
    environment: serde_json::Value,
}

fn grid_point(prepared: &workload::Prepared, floor: &str, frames: u64) -> Result<Point> {
    let pool = workload::pool(Some(1))?;
    let t = Instant::now();
    let config = GridConfig::from_settings(Settings::new(
        "grid",
        vec![
            ("preset".into(), "rss-r".into()),
            ("floor".into(), floor.into()),
        ],
    ))?;
    let grid = Grid::build(&prepared.input, config)?;
    let build_s = t.elapsed().as_secs_f64();
    let mut rec = trace::Recording::default();
    let r = pool.install(|| trace::render(&prepared.input.scene, &grid, 512, Some(&mut rec)));
    let layout = grid.layout();
    let mut m = Mattson::new(layout.bytes / PAGE + 1);
    let mut stamps = vec![0u32; prepared.input.geometry.prims.len()];
    let mut ray_no = 0u32;
    let (mut ci, mut ai) = (0usize, 0usize);
    for g in &r.stats.generations {
        for (list, n, any) in [(0, g.rays, false), (1, g.shadow, true)] {
            for _ in 0..n {
                let ray = if list == 0 {
                    ci += 1;
                    rec.closest[ci - 1].0
                } else {
                    ai += 1;
                    rec.any[ai - 1].0
                };
                ray_no += 1;
                grid.page_accesses(&ray, any, &layout, &mut stamps, ray_no, &mut |p| {
                    m.access(p)
                });
            }
        }
    }
    Ok(Point {
        sf: 0,
        objects: prepared.input.scene.objects.len(),
        rays: r.stats.total,
        grid_bytes: layout.bytes,
        accesses: m.accesses(),
        distinct: m.cold(),
        faults: m.faults(frames) - m.cold(),
        grid_s: build_s + r.trace_s,
        bf_s: 0.0,
        bf_io_bytes: 0,
        bf_seeks: 0,
        bf_passes: 0,
    })
}

fn breadth_first_point(prepared: &workload::Prepared, floor: &str, p: &mut Point) -> Result<()> {
    let pool = workload::pool(Some(1))?;
    let t = Instant::now();
    let config = BreadthFirstConfig::from_settings(Settings::new(
        "breadth-first",
        vec![
            ("memory".into(), "32MiB".into()),
            ("registration".into(), "thesis".into()),
            ("floor".into(), floor.into()),
        ],
    ))?;
    let e = BreadthFirst::from_scene(&prepared.input, config)?;
    let build_s = t.elapsed().as_secs_f64();
    let r = pool.install(|| trace::render(&prepared.input.scene, &e, 512, None));
    if let Some(f) = e.failure() {
        return Err(input(f));
    }
    let s = e.build_stats();
    let x = &r.counters.extra;
    let get = |k: &str| x.get(k).copied().unwrap_or(0);
    p.bf_s = build_s + r.trace_s;
    p.bf_io_bytes = get("io_bytes_read")
        + s.get("preprocess_bytes_read").copied().unwrap_or(0.0) as u64
        + s.get("store_bytes_written").copied().unwrap_or(0.0) as u64;
    p.bf_seeks = get("io_seeks");
    p.bf_passes = get("bf_passes");
    Ok(())
}

/// A limit on the SFs run: (scene or every scene, lowest, highest).
type Cap = (Option<String>, Option<u32>, u32);

/// `max-sf N` (every scene), `max-sf balls=6,tree=14` (those scenes), or with a range
/// `tree=17..18` (only those SFs of that scene): (scene, lowest, highest).
fn parse_caps(id: &str, s: Option<&str>) -> Result<Vec<Cap>> {
    let Some(s) = s else { return Ok(Vec::new()) };
    let bad = || {
        input(format!(
            "{id}: max-sf '{s}': expected N or scene=N,scene=LO..HI"
        ))
    };
    if let Ok(n) = s.parse::<u32>() {
        return Ok(vec![(None, None, n)]);
    }
    s.split(',')
        .map(|kv| {
            let (k, v) = kv.split_once('=').ok_or_else(bad)?;
            let num = |t: &str| t.trim().parse::<u32>().map_err(|_| bad());
            let (lo, hi) = match v.split_once("..") {
                Some((a, b)) => (Some(num(a)?), num(b)?),
                None => (None, num(v)?),
            };
            Ok((Some(k.trim().to_string()), lo, hi))
        })
        .collect()
}

/// The modelled disks: HDD-like, SSD-like, and `fault-ms` if given (above 0).
fn disks(id: &str, fault_ms: Option<&str>) -> Result<(Vec<Disk>, Option<f64>)> {
    let mut disks = vec![
        Disk {
            name: "HDD 8 ms".into(),
            fault_s: 8e-3,
            bandwidth: 100e6,
        },
        Disk {
            name: "SSD 0.1 ms".into(),
            fault_s: 1e-4,
            bandwidth: 500e6,
        },
    ];
    let Some(v) = fault_ms else {
        return Ok((disks, None));
    };
    let ms = match v.trim().parse::<f64>() {
        Ok(ms) if ms.is_finite() && ms > 0.0 => ms,
        _ => {
            return Err(input(format!(
                "{id}: fault-ms '{v}': expected a number of ms above 0"
            )))
        }
    };
    disks.push(Disk {
        name: format!("{ms} ms"),
        fault_s: ms * 1e-3,
        bandwidth: 100e6,
    });
    Ok((disks, Some(ms)))
}

/// The SFs of one scene to run: its published range, capped, two SFs with `--quick`.
fn sf_range(scene: &str, range: [u32; 2], caps: &[Cap], quick: bool) -> (u32, u32) {
    let (mut lo, mut hi) = (range[0], range[1]);
    if let Some(m) = caps
        .iter()
        .find(|c| c.0.is_none() || c.0.as_deref() == Some(scene))
    {
        lo = lo.max(m.1.unwrap_or(0));
        hi = hi.min(m.2);
    }
    if quick {
        hi = hi.min(lo + 1);
    }
    (lo, hi)
}

/// Measures every SF of one scene with both engines.
fn measure_scene(scene: &str, lo: u32, hi: u32, frames: u64) -> Result<Vec<Point>> {
    let floor = floor(scene);
    let mut pts = Vec::new();
    for sf in lo..=hi {
        eprintln!("nakamaru-3.2: {scene}{sf} …");
        let src = SceneSource::resolve(scene, Some(sf), None, None)?;
        let prepared = workload::prepare(&src)?;
        let mut p = grid_point(&prepared, floor, frames)?;
        p.sf = sf;
        breadth_first_point(&prepared, floor, &mut p)?;
        pts.push(p);
    }
    Ok(pts)
}

/// 000's floor: out for balls and tree.
fn floor(scene: &str) -> &'static str {
    if scene == "balls" || scene == "tree" {
        "out"
    } else {
        "in"
    }
}

/// The typed record of one scene: its rows, and onset and crossover per disk (pure).
fn analyse(
    p: &Published,
    scene: &str,
    lo: u32,
    hi: u32,
    pts: &[Point],
    disks: &[Disk],
) -> SceneResult {
    let rows = pts
        .iter()
        .map(|pt| SfRow {
            sf: pt.sf,
            objects: pt.objects,
            rays: pt.rays,
            table_3_2_mb: p
                .table_3_2
                .iter()
                .find(|r| r.scene == scene && r.sf == pt.sf)
                .map(|r| r.mb),
            grid_bytes: pt.grid_bytes,
            page_accesses: pt.accesses,
            pages_touched: pt.distinct,
            faults_beyond_first_touch: pt.faults,
            grid_compute_s: pt.grid_s,
            bf_measured_s: pt.bf_s,
            bf_io_bytes: pt.bf_io_bytes,
            bf_seeks: pt.bf_seeks,
            bf_passes: pt.bf_passes,
            model: disks
                .iter()
                .map(|d| DiskModel {
                    disk: d.name.clone(),
                    grid_s: pt.grid_model(d),
                    bf_s: pt.bf_model(d),
                })
                .collect(),
        })
        .collect();
    let result = disks
        .iter()
        .map(|d| Onset {
            disk: d.name.clone(),
            onset_sf: pts
                .iter()
                .find(|p| p.grid_model(d) / p.rays as f64 > 2.0 * p.grid_s / p.rays as f64)
                .map(|p| p.sf),
            crossover_sf: pts
                .iter()
                .find(|p| p.grid_model(d) > p.bf_model(d))
                .map(|p| p.sf),
        })
        .collect();
    SceneResult {
        scene: scene.to_string(),
        sf: [lo, hi],
        floor: floor(scene),
        rows,
        result,
    }
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let max_sf = ctx.params.raw(MAX_SF.key).map(String::from);
    let caps = parse_caps(ctx.id, max_sf.as_deref())?;
    let (disks, fault_ms) = disks(ctx.id, ctx.params.raw(FAULT_MS.key))?;
    let memory = p.memory_mb << 20;
    let frames = memory / PAGE;
    if let Some(c) = caps.iter().find(|c| {
        c.0.as_ref()
            .is_some_and(|name| !p.sf_ranges.contains_key(name))
    }) {
        let known: Vec<&str> = p.sf_ranges.keys().map(|s| s.as_str()).collect();
        return Err(input(format!(
            "{}: max-sf names scene '{}', which this table does not run (it runs {})",
            ctx.id,
            c.0.as_deref().unwrap_or(""),
            known.join(", ")
        )));
    }
    let planned: Vec<(&String, u32, u32)> = p
        .sf_ranges
        .iter()
        .map(|(scene, range)| {
            let (lo, hi) = sf_range(scene, *range, &caps, ctx.quick);
            (scene, lo, hi)
        })
        .filter(|(_, lo, hi)| lo <= hi)
        .collect();
    if planned.is_empty() {
        return Err(input(format!(
            "{}: max-sf '{}' leaves no size factor to run",
            ctx.id,
            max_sf.as_deref().unwrap_or("")
        )));
    }
    let mut measured = Vec::new();
    let mut svgs = Vec::new();
    for (scene, lo, hi) in planned {
        let pts = measure_scene(scene, lo, hi, frames)?;
        let s = analyse(&p, scene, lo, hi, &pts, &disks);
        if pts.len() >= 2 {
            let svg = plot(scene, &pts, &disks[0], s.result[0].onset_sf);
            svgs.push((format!("{}-{scene}", ctx.id), svg));
        }
        measured.push(s);
    }
    let result = Result_ {
        id: ctx.id,
        published: raw,
        measured,
        quick: ctx.quick,
        max_sf,
        fault_ms,
        memory_bytes: memory,
        page_bytes: PAGE,
        environment: super::environment(1),
    };
    let rows = rows(&result);
    let doc = document(ctx, &p, &result, &disks, frames, &svgs);
    let mut out = Output::new(&result, rows, doc);
    out.svgs = svgs;
    Ok(out)
}

fn show(v: Option<u32>, hi: u32) -> String {
    v.map(|s| s.to_string())
        .unwrap_or_else(|| format!("none ≤ {hi}"))
}

/// Onset and crossover per scene and disk (model), and our memory beside Table 3.2's
/// (substituted): shown, not judged, as 000 prints no onset and a different program's memory.
fn rows(r: &Result_) -> Vec<Row> {
    let mut rows = Vec::new();
    for s in &r.measured {
        for o in &s.result {
            rows.push(Row::new(
                "onset",
                format!("{} ({})", s.scene, o.disk),
                "balls, tree: early; gears: late; sray faster once Rayshade thrashes (no SF printed)",
                format!("onset SF {}, crossover SF {}", show(o.onset_sf, s.sf[1]), show(o.crossover_sf, s.sf[1])),
                Kind::Shape,
                Verdict::Shown,
            ));
        }
        for x in &s.rows {
            if let Some(mb) = x.table_3_2_mb {
                let ours = x.grid_bytes as f64 / 1e6;
                rows.push(Row::new(
                    "table-3.2-memory",
                    format!("{}{}", s.scene, x.sf),
                    format!("{mb} MB (rayshade-ss)"),
                    format!("{ours:.1} MB (grid), ratio {:.2}", ours / mb),
                    Kind::Ratio,
                    Verdict::Shown,
                ));
            }
        }
    }
    rows
}

fn document(
    ctx: &Ctx,
    p: &Published,
    r: &Result_,
    disks: &[Disk],
    frames: u64,
    svgs: &[(String, String)],
) -> Document {
    let mut doc = Document::new("nakamaru-3.2: thrashing onset of the in-memory grid, 32 MiB");
    doc.paragraph(format!("Published: {}, {}. The figures' curves are lost; Table 3.2 (rayshade-ss memory per SF) survives and is shown beside ours.", p.source.document, p.source.sections.as_deref().unwrap_or("")));
    doc.paragraph(format!("Measured: `rtbench reproduce nakamaru-3.2{}{}{}`, one thread, 512×512. Grid: `grid` rss-r, its page stream (cell offsets, references, primitives, primitive→object, mailbox; 4 KiB pages) through Mattson's stack algorithm at {frames} pages; modelled = measured compute + pages touched × 4 KiB ÷ bandwidth (loading the data once) + faults beyond first touch × fault cost. Breadth-first: memory=32MiB, registration ⌈r/10+0.5⌉; modelled = measured + I/O bytes ÷ bandwidth + seeks × seek cost. Onset: smallest SF with modelled grid time per ray > 2 × its in-core time per ray. Crossover: smallest SF with modelled grid time > modelled breadth-first time.",
        if ctx.quick { " --quick" } else { "" }, r.max_sf.as_ref().map(|m| format!(" --max-sf {m}")).unwrap_or_default(), r.fault_ms.map(|m| format!(" --fault-ms {m}")).unwrap_or_default()));
    for s in &r.measured {
        doc.heading(format!("{} (SF {}–{})", s.scene, s.sf[0], s.sf[1]));
        doc.table(scene_table(s, disks));
        doc.list(
            s.result
                .iter()
                .map(|o| {
                    format!(
                        "{}: onset SF {}, crossover SF {}.",
                        o.disk,
                        show(o.onset_sf, s.sf[1]),
                        show(o.crossover_sf, s.sf[1])
                    )
                })
                .collect(),
        );
        let stem = format!("{}-{}", ctx.id, s.scene);
        if svgs.iter().any(|(st, _)| *st == stem) {
            doc.figure(format!("plots/{stem}.svg"), &s.scene);
        }
    }
    doc.heading("Summary");
    let mut t = DocTable::new("", &["scene", "disk", "onset SF", "crossover SF"]);
    for s in &r.measured {
        for o in &s.result {
            t.push(vec![
                s.scene.clone(),
                o.disk.clone(),
                show(o.onset_sf, s.sf[1]),
                show(o.crossover_sf, s.sf[1]),
            ]);
        }
    }
    doc.table(t);
    let pattern = &published::claim(&p.claims, "pattern").claim;
    doc.paragraph(format!("Published pattern (000 §3.4): {pattern}"));
    doc
}

fn scene_table(s: &SceneResult, disks: &[Disk]) -> DocTable {
    let mut header: Vec<String> = [
        "SF",
        "objects",
        "Table 3.2 MB",
        "grid MB (model)",
        "page accesses",
        "pages touched",
        "faults @32 MiB beyond first touch",
        "grid compute s",
        "bf measured s",
        "bf I/O MB",
        "bf seeks",
        "bf passes",
    ]
    .iter()
    .map(|h| h.to_string())
    .collect();
    for d in disks {
        header.push(format!("grid model s ({})", d.name));
        header.push(format!("bf model s ({})", d.name));
    }
    let mut t = DocTable::new("", &header.iter().map(String::as_str).collect::<Vec<_>>());
    for x in &s.rows {
        let mut cells = vec![
            x.sf.to_string(),
            x.objects.to_string(),
            x.table_3_2_mb.map_or("–".into(), |v| v.to_string()),
            format!("{:.1}", x.grid_bytes as f64 / 1e6),
            x.page_accesses.to_string(),
            x.pages_touched.to_string(),
            x.faults_beyond_first_touch.to_string(),
            format!("{:.2}", x.grid_compute_s),
            format!("{:.2}", x.bf_measured_s),
            format!("{:.1}", x.bf_io_bytes as f64 / 1e6),
            x.bf_seeks.to_string(),
            x.bf_passes.to_string(),
        ];
        for m in &x.model {
            cells.push(format!("{:.2}", m.grid_s));
            cells.push(format!("{:.2}", m.bf_s));
        }
        t.push(cells);
    }
    t
}

/// A small SVG: modelled time per ray against grid memory (log–log), grid and breadth-first on
/// one disk, the onset marked.
fn plot(scene: &str, pts: &[Point], d: &Disk, onset: Option<u32>) -> String {
    let (w, h, m) = (520.0, 320.0, 50.0);
    let xs: Vec<f64> = pts
        .iter()
        .map(|p| (p.grid_bytes as f64 / 1e6).log10())
        .collect();
    let g: Vec<f64> = pts
        .iter()
        .map(|p| (p.grid_model(d) / p.rays as f64).log10())
        .collect();
    let b: Vec<f64> = pts
        .iter()
        .map(|p| (p.bf_model(d) / p.rays as f64).log10())
        .collect();
    let (x0, x1) = (
        xs.iter().cloned().fold(f64::INFINITY, f64::min),
        xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
    );
    let ys = g.iter().chain(&b);
    let (y0, y1) = (
        ys.clone().cloned().fold(f64::INFINITY, f64::min),
        ys.cloned().fold(f64::NEG_INFINITY, f64::max),
    );
    let sx = |x: f64| m + (x - x0) / (x1 - x0).max(1e-9) * (w - 2.0 * m);
    let sy = |y: f64| h - m - (y - y0) / (y1 - y0).max(1e-9) * (h - 2.0 * m);
    let line = |v: &[f64], c: &str| {
        let pts: Vec<String> = xs
            .iter()
            .zip(v)
            .map(|(x, y)| format!("{:.1},{:.1}", sx(*x), sy(*y)))
            .collect();
        format!(
            "<polyline fill=\"none\" stroke=\"{c}\" stroke-width=\"2\" points=\"{}\"/>",
            pts.join(" ")
        )
    };
    let mut s = format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n");
    let _ = writeln!(s, "<text x=\"{m}\" y=\"20\" font-size=\"13\">{scene}: modelled time per ray ({}), log-log</text>", d.name);
    let _ = writeln!(s, "<line x1=\"{m}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"black\"/><line x1=\"{m}\" y1=\"{m}\" x2=\"{m}\" y2=\"{}\" stroke=\"black\"/>", h - m, w - m, h - m, h - m);
    let _ = writeln!(
        s,
        "<text x=\"{}\" y=\"{}\">grid memory (MB): {:.1} … {:.1}</text>",
        m,
        h - 15.0,
        10f64.powf(x0),
        10f64.powf(x1)
    );
    let _ = writeln!(
        s,
        "<text x=\"5\" y=\"{}\">{:.2e}</text><text x=\"5\" y=\"{}\">{:.2e} s</text>",
        h - m,
        10f64.powf(y0),
        m,
        10f64.powf(y1)
    );
    s.push_str(&line(&g, "#c0392b"));
    s.push_str(&line(&b, "#2471a3"));
    for (i, p) in pts.iter().enumerate() {
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" fill=\"#555\">{}</text>",
            sx(xs[i]) - 4.0,
            h - m + 14.0,
            p.sf
        );
    }
    if let Some(o) = onset {
        if let Some(i) = pts.iter().position(|p| p.sf == o) {
            let _ = writeln!(s, "<line x1=\"{x:.1}\" y1=\"{m}\" x2=\"{x:.1}\" y2=\"{}\" stroke=\"#c0392b\" stroke-dasharray=\"4 3\"/><text x=\"{:.1}\" y=\"{}\" fill=\"#c0392b\">onset SF {o}</text>", h - m, sx(xs[i]) + 3.0, m + 12.0, x = sx(xs[i]));
        }
    }
    let _ = writeln!(s, "<text x=\"{}\" y=\"40\" fill=\"#c0392b\">grid (rss-r)</text><text x=\"{}\" y=\"54\" fill=\"#2471a3\">breadth-first</text>", w - 150.0, w - 150.0);
    s.push_str("</svg>\n");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_sf_caps_every_scene_or_named_ones() {
        assert!(parse_caps("t", None).unwrap().is_empty());
        let all = parse_caps("t", Some("6")).unwrap();
        assert_eq!(sf_range("balls", [4, 7], &all, false), (4, 6));
        let some = parse_caps("t", Some("tree=17..18,balls=5")).unwrap();
        assert_eq!(sf_range("tree", [11, 18], &some, false), (17, 18));
        assert_eq!(sf_range("balls", [4, 7], &some, false), (4, 5));
        assert_eq!(sf_range("gears", [4, 12], &some, true), (4, 5));
        for bad in ["x", "tree=", "tree=a..b", "tree=3..", "4,5"] {
            let e = parse_caps("t", Some(bad)).err().map(|e| e.to_string());
            assert!(e.is_some_and(|e| e.starts_with("t: max-sf")), "{bad}");
        }
    }

    #[test]
    fn fault_ms_must_be_a_positive_finite_number() {
        assert_eq!(disks("t", None).unwrap().0.len(), 2);
        let (d, ms) = disks("t", Some("2.5")).unwrap();
        assert_eq!((d.len(), ms), (3, Some(2.5)));
        for bad in ["0", "-1", "inf", "NaN", "x"] {
            assert!(disks("t", Some(bad)).is_err(), "{bad}");
        }
    }

    #[test]
    fn the_published_table_parses() {
        let (p, _): (Published, _) = published::load("nakamaru-3.2", PUBLISHED);
        assert_eq!(p.memory_mb, 32);
        assert_eq!(p.sf_ranges.len(), 6);
        assert!(p.table_3_2.iter().any(|r| r.scene == "tree" && r.sf == 15));
    }
}
