//! `nakamaru-3.2`: Table 3.2 (memory used by rayshade-ss per SF) and Figs. 3.5–3.7 (time against
//! scene data size: where the in-memory grid starts to thrash, and where the breadth-first method
//! overtakes it), seed 000 §3.5.
//!
//! Per scene and Table 3.2 size factor:
//! - **memory account** ([`RayshadeImage`]): everything rayshade-ss allocates for the scene and
//!   its grid (objects with their `Geom` and bounding box, the voxel arrays, one list node per
//!   object and voxel), from Rayshade 4.0's structs on i386, beside Table 3.2's MB (ratio per row).
//! - **in-core times** (measured): the `grid` engine (rss-r, sized on objects as Rayshade counts
//!   them, bounding-box insertion: Rayshade's grid; floor out for balls and tree) builds (p/) and
//!   traces (t/) the SPD workload on one thread; the `breadth-first` engine (32 MiB, registration
//!   ⌈r/10 + 0.5⌉ as the thesis's scaling runs) the same, p/ = store + preprocessing. Each is the
//!   CPU time of the one thread that does the work: the disk is modelled below, and a wall time
//!   measured beside other processes' load moved the two methods' order at some SFs.
//! - **paging (model)**: the preprocessing's page stream (allocating the objects, bounding them,
//!   allocating the voxels, inserting every object) and then every query of the render replayed
//!   ([`Grid::page_accesses`]) in rayshade-ss's memory image, in 4 KiB pages, through Mattson's
//!   stack algorithm: the faults of an LRU memory of 32 MiB, split p/ and t/. Modelled time =
//!   in-core time × machine factor + first-touched pages ÷ bandwidth + faults beyond first touch
//!   × fault cost. The machine factor is Table 3.1's rss-r total on the Pentium 90 over our grid's
//!   time at the same scene and SF, so compute and disk are in the thesis's proportion.
//! - **onset, as the thesis frames it**: the data-size onset is the first SF whose rayshade-ss
//!   memory exceeds physical memory (32 MB); the time onset, per phase, the first SF whose
//!   modelled time departs from its in-core trend (paging adds more than [`DEPART`] − 1 of the
//!   in-core time); crossover, the first SF where the modelled grid total exceeds breadth-first's.
//! - **validation**: the model on one case against direct simulations of the same page stream:
//!   exact LRU one frame count at a time (must equal Mattson's count) and CLOCK, the kernel's
//!   approximation of LRU (the difference is what the LRU assumption costs).

use super::published::{self, PublishedClaim, Source};
use super::{Claim, Ctx, Fidelity, Kind, Output, Param, Row, Runtime, Table, Verdict};
use crate::error::{input, Result};
use crate::measure::span::{span, Span, Workers};
use crate::source::Source as SceneSource;
use super::models::paging::Mattson;
use super::models::rayshade_memory::{Account, RayshadeImage};
use super::models::replacement::{Clock, Lru};
use crate::workload::{self, trace};
use rtbench_engines::breadth_first::config::BreadthFirstConfig;
use rtbench_engines::breadth_first::BreadthFirst;
use rtbench_engines::grid::config::GridConfig;
use rtbench_engines::grid::paging::{PageMap, PAGE};
use rtbench_engines::grid::Grid;
use rtbench_engines::{Engine, Settings};
use rtbench_reports::{Document, Table as DocTable};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// `max-sf N` (every scene), `scene=N,…` (those scenes) or `scene=LO..HI` (only those SFs).
pub const MAX_SF: Param = Param {
    key: "max-sf",
    help: "the largest SF run: N, or scene=N,scene=LO..HI (Table 3.2's SFs within)",
};
/// `fault-ms X`: one more disk, X ms per fault or seek at 100 MB/s.
pub const FAULT_MS: Param = Param {
    key: "fault-ms",
    help: "one more modelled disk: ms per page fault or seek (100 MB/s)",
};
const PAGING: Param = Param {
    key: "paging",
    help: "on (default): trace and model every SF; off: the memory account only (minutes); or scene=N,… the largest SF traced per scene (the account for all)",
};
const VALIDATE: Param = Param {
    key: "validate",
    help: "the case the model is checked on by direct simulation, sceneSF (default tetra7; tetra6 with --quick; off)",
};

/// A phase departs from its in-core trend when paging makes it this many times its in-core time.
pub const DEPART: f64 = 1.25;

pub const TABLE: Table = Table {
    id: "nakamaru-3.2",
    seed: "000",
    source: "Table 3.2, Figs. 3.5–3.7",
    about: "000 (Nakamaru 2002) Table 3.2, Figs. 3.5-3.7: rayshade-ss memory per SF, thrashing onset (paging model) and crossover vs breadth-first, 32 MB",
    runtime: Runtime {
        quick: "minutes",
        full: "about 20 minutes",
    },
    params: &[MAX_SF, FAULT_MS, PAGING, VALIDATE],
    claims: &[
        Claim {
            key: "table-3.2-memory",
            fidelity: Fidelity::Model,
            why: "Rayshade 4.0's structs on i386 and glibc's chunk rule applied to our scene and our Rayshade-rule grid: an account, rayshade-ss itself is not run",
        },
        Claim {
            key: "onset",
            fidelity: Fidelity::Model,
            why: "Mattson's LRU model of rayshade-ss's page stream at 32 MiB and a modelled disk, compute scaled to the Pentium 90 by Table 3.1, in place of Rayshade thrashing on the thesis's machine; the figures' curves are lost",
        },
        Claim {
            key: "in-memory-faster",
            fidelity: Fidelity::Model,
            why: "judged on the modelled times",
        },
        Claim {
            key: "breadth-first-faster-once-thrashing",
            fidelity: Fidelity::Model,
            why: "judged on the modelled times",
        },
        Claim {
            key: "scene-pattern",
            fidelity: Fidelity::Model,
            why: "judged on the modelled onsets",
        },
        Claim {
            key: "model-validation",
            fidelity: Fidelity::Model,
            why: "the model's LRU against direct simulations of the same page stream, not against a machine that pages",
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/nakamaru-3.2.json");
const TABLE_3_1: &str = include_str!("../../../data/published/nakamaru-3.1.json");

#[derive(Deserialize)]
struct Published {
    source: Source,
    memory_mb: u64,
    table_3_2: Vec<MemoryRow>,
    claims: Vec<PublishedClaim>,
}

/// Table 3.2: memory used by rayshade-ss per scene and SF (MB = 2^20 bytes, as Table 3.3's).
#[derive(Deserialize, Clone)]
struct MemoryRow {
    scene: String,
    sf: u32,
    objects: u64,
    mb: f64,
}

/// Table 3.1's rows, for the machine factor (rss-r total on the Pentium 90).
#[derive(Deserialize)]
struct Table31 {
    configs: Vec<String>,
    rows: Vec<Row31>,
}

#[derive(Deserialize)]
struct Row31 {
    scene: String,
    sf: u32,
    total: Vec<f64>,
}

/// A modelled disk: cost of a page fault and of a seek (s), sequential bandwidth (bytes/s).
struct Disk {
    name: String,
    fault_s: f64,
    bandwidth: f64,
}

/// One size factor of one scene, measured (saved as a step: `--resume` keeps it).
#[derive(Serialize, Deserialize, Clone)]
struct Point {
    sf: u32,
    /// Traced and paged (else the memory account only).
    paged: bool,
    objects: usize,
    rays: u64,
    account: Account,
    grid_res: [u32; 3],
    pre_accesses: u64,
    pre_touched: u64,
    pre_faults: u64,
    trace_accesses: u64,
    trace_touched: u64,
    trace_faults: u64,
    grid_build_s: f64,
    grid_trace_s: f64,
    bf_build_s: f64,
    bf_trace_s: f64,
    bf_pre_io_bytes: u64,
    bf_trace_io_bytes: u64,
    bf_seeks: u64,
    bf_passes: u64,
}

/// Modelled seconds of one point on one disk, p/ and t/ for both methods.
#[derive(Serialize, Clone, Copy)]
struct Modelled {
    grid_p: f64,
    grid_t: f64,
    bf_p: f64,
    bf_t: f64,
    /// The grid's in-core p/ and t/ (× machine factor, data loaded once): the trend.
    grid_p_core: f64,
    grid_t_core: f64,
}

impl Point {
    fn model(&self, d: &Disk, factor: f64) -> Modelled {
        let load = |pages: u64| (pages * PAGE) as f64 / d.bandwidth;
        let grid_p_core = self.grid_build_s * factor + load(self.pre_touched);
        let grid_t_core = self.grid_trace_s * factor + load(self.trace_touched);
        Modelled {
            grid_p: grid_p_core + self.pre_faults as f64 * d.fault_s,
            grid_t: grid_t_core + self.trace_faults as f64 * d.fault_s,
            bf_p: self.bf_build_s * factor + self.bf_pre_io_bytes as f64 / d.bandwidth,
            bf_t: self.bf_trace_s * factor
                + self.bf_trace_io_bytes as f64 / d.bandwidth
                + self.bf_seeks as f64 * d.fault_s,
            grid_p_core,
            grid_t_core,
        }
    }
}

#[derive(Serialize)]
struct SfRow {
    #[serde(flatten)]
    point: Point,
    table_3_2_mb: Option<f64>,
    table_3_2_objects: Option<u64>,
    account_mib: f64,
    model: Vec<(String, Modelled)>,
}

#[derive(Serialize, Clone)]
struct Onset {
    disk: String,
    preprocess_sf: Option<u32>,
    trace_sf: Option<u32>,
    crossover_sf: Option<u32>,
}

#[derive(Serialize)]
struct SceneResult {
    scene: String,
    sfs: Vec<u32>,
    floor: &'static str,
    machine_factor: Option<f64>,
    size_onset_sf: Option<u32>,
    rows: Vec<SfRow>,
    onsets: Vec<Onset>,
}

#[derive(Serialize, Deserialize, Clone, Copy)]
struct Validation {
    pages: u64,
    accesses: u64,
    frames: u64,
    mattson_lru: u64,
    direct_lru: u64,
    clock: u64,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    measured: Vec<SceneResult>,
    validation: Option<(String, Validation)>,
    quick: bool,
    max_sf: Option<String>,
    fault_ms: Option<f64>,
    memory_bytes: u64,
    page_bytes: u64,
    depart: f64,
    environment: serde_json::Value,
}

fn grid_config(floor: &str) -> Result<GridConfig> {
    Ok(GridConfig::from_settings(Settings::new(
        "grid",
        vec![
            ("preset".into(), "rss-r".into()),
            ("count".into(), "objects".into()),
            ("insert".into(), "bbox".into()),
            ("floor".into(), floor.into()),
        ],
    ))?)
}

/// Every query of the render replayed through rayshade-ss's image, in the order the render made them.
fn replay(
    grid: &Grid,
    map: &dyn PageMap,
    prims: usize,
    r: &trace::Render,
    rec: &trace::Recording,
    out: &mut dyn FnMut(u64),
) {
    let mut stamps = vec![0u32; prims];
    let mut ray_no = 0u32;
    let (mut ci, mut ai) = (0usize, 0usize);
    for g in &r.stats.generations {
        for (closest, n) in [(true, g.rays), (false, g.shadow)] {
            for _ in 0..n {
                let ray = if closest {
                    ci += 1;
                    rec.closest[ci - 1].0
                } else {
                    ai += 1;
                    rec.any[ai - 1].0
                };
                ray_no += 1;
                grid.page_accesses(&ray, !closest, map, &mut stamps, ray_no, out);
            }
        }
    }
}

fn grid_point(prepared: &workload::Prepared, floor: &str, frames: u64) -> Result<Point> {
    let pool = crate::measure::threads::pool(Some(1))?;
    let config = grid_config(floor)?;
    let (grid, build) = span(Workers::Caller, || Grid::build(&prepared.input, config));
    let grid = grid?;
    let grid_build_s = build.thread_cpu_s;
    let mut rec = trace::Recording::default();
    let r = pool.install(|| trace::render(&prepared.input.scene, &grid, 512, Some(&mut rec)));
    let image = RayshadeImage::new(&prepared.input.scene, &prepared.input.geometry, &grid);
    let mut m = Mattson::new(image.pages());
    image.preprocess_accesses(&mut |p| m.access(p));
    let (pre_accesses, pre_touched, pre_faults) = (m.accesses(), m.cold(), m.faults(frames) - m.cold());
    let prims = prepared.input.geometry.prims.len();
    replay(&grid, &image, prims, &r, &rec, &mut |p| m.access(p));
    Ok(Point {
        sf: 0,
        paged: true,
        objects: prepared.input.scene.objects.len(),
        rays: r.stats.total,
        account: image.account,
        grid_res: grid.cells().lattice.res,
        pre_accesses,
        pre_touched,
        pre_faults,
        trace_accesses: m.accesses() - pre_accesses,
        trace_touched: m.cold() - pre_touched,
        trace_faults: m.faults(frames) - m.cold() - pre_faults,
        grid_build_s,
        grid_trace_s: r.trace_cpu_s,
        bf_build_s: 0.0,
        bf_trace_s: 0.0,
        bf_pre_io_bytes: 0,
        bf_trace_io_bytes: 0,
        bf_seeks: 0,
        bf_passes: 0,
    })
}

/// The memory account alone: the scene and its grid, nothing traced.
fn account_point(prepared: &workload::Prepared, floor: &str) -> Result<Point> {
    let grid = Grid::build(&prepared.input, grid_config(floor)?)?;
    let image = RayshadeImage::new(&prepared.input.scene, &prepared.input.geometry, &grid);
    Ok(Point {
        sf: 0,
        paged: false,
        objects: prepared.input.scene.objects.len(),
        rays: 0,
        account: image.account,
        grid_res: grid.cells().lattice.res,
        pre_accesses: 0,
        pre_touched: 0,
        pre_faults: 0,
        trace_accesses: 0,
        trace_touched: 0,
        trace_faults: 0,
        grid_build_s: 0.0,
        grid_trace_s: 0.0,
        bf_build_s: 0.0,
        bf_trace_s: 0.0,
        bf_pre_io_bytes: 0,
        bf_trace_io_bytes: 0,
        bf_seeks: 0,
        bf_passes: 0,
    })
}

fn breadth_first_point(prepared: &workload::Prepared, floor: &str, p: &mut Point) -> Result<()> {
    let pool = crate::measure::threads::pool(Some(1))?;
    let build = Span::start(Workers::Caller);
    let config = BreadthFirstConfig::from_settings(Settings::new(
        "breadth-first",
        vec![
            ("memory".into(), "32MiB".into()),
            ("registration".into(), "thesis".into()),
            ("floor".into(), floor.into()),
            // The thesis's procedure: every ray of a generation in one breadth-first trace.
            ("batch".into(), "generation".into()),
        ],
    ))?;
    let e = BreadthFirst::from_scene(&prepared.input, config)?;
    p.bf_build_s = build.stop().thread_cpu_s;
    let r = pool.install(|| trace::render(&prepared.input.scene, &e, 512, None));
    if let Some(f) = e.failure() {
        return Err(input(f));
    }
    let s = e.build_stats();
    let get = |k: &str| r.counters.extra.get(k).copied().unwrap_or(0);
    p.bf_trace_s = r.trace_cpu_s;
    p.bf_pre_io_bytes = s.get("preprocess_bytes_read").copied().unwrap_or(0.0) as u64
        + s.get("store_bytes_written").copied().unwrap_or(0.0) as u64;
    p.bf_trace_io_bytes = get("io_bytes_read");
    p.bf_seeks = get("io_seeks");
    p.bf_passes = get("bf_passes");
    Ok(())
}

/// The model checked on one case: the trace's page stream (after the preprocessing's), in a
/// memory of half the pages it touches so that it pages, counted by Mattson, by a direct LRU
/// and by CLOCK.
fn validate(scene: &str, sf: u32) -> Result<Validation> {
    eprintln!("nakamaru-3.2: validating the model on {scene}{sf} …");
    let src = SceneSource::resolve(scene, Some(sf), None, None)?;
    let prepared = workload::prepare(&src)?;
    let grid = Grid::build(&prepared.input, grid_config(floor(scene))?)?;
    let mut rec = trace::Recording::default();
    let pool = crate::measure::threads::pool(Some(1))?;
    let r = pool.install(|| trace::render(&prepared.input.scene, &grid, 512, Some(&mut rec)));
    let image = RayshadeImage::new(&prepared.input.scene, &prepared.input.geometry, &grid);
    let mut stream: Vec<u32> = Vec::new();
    image.preprocess_accesses(&mut |p| stream.push(p as u32));
    let prims = prepared.input.geometry.prims.len();
    replay(&grid, &image, prims, &r, &rec, &mut |p| stream.push(p as u32));
    let pages = image.pages();
    let mut m = Mattson::new(pages);
    for &p in &stream {
        m.access(p as u64);
    }
    let frames = (m.cold() / 2).max(1);
    let mut lru = Lru::new(pages, frames);
    let mut clock = Clock::new(pages, frames);
    for &p in &stream {
        lru.access(p as u64);
        clock.access(p as u64);
    }
    Ok(Validation {
        pages: m.cold(),
        accesses: stream.len() as u64,
        frames,
        mattson_lru: m.faults(frames),
        direct_lru: lru.faults,
        clock: clock.faults,
    })
}

/// A limit on the SFs run: (scene or every scene, lowest, highest).
type Cap = (Option<String>, Option<u32>, u32);

/// `max-sf N` (every scene), `max-sf balls=6,tree=14` (those scenes), or with a range
/// `tree=17..18` (only those SFs of that scene): (scene, lowest, highest).
fn parse_caps(id: &str, s: Option<&str>) -> Result<Vec<Cap>> {
    let Some(s) = s else { return Ok(Vec::new()) };
    let bad = || input(format!("{id}: max-sf '{s}': expected N or scene=N,scene=LO..HI"));
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
        _ => return Err(input(format!("{id}: fault-ms '{v}': expected a number of ms above 0"))),
    };
    disks.push(Disk {
        name: format!("{ms} ms"),
        fault_s: ms * 1e-3,
        bandwidth: 100e6,
    });
    Ok((disks, Some(ms)))
}

/// The SFs of one scene to run: Table 3.2's, capped; the first two with `--quick`.
fn sf_list(scene: &str, table: &[u32], caps: &[Cap], quick: bool) -> Vec<u32> {
    let mut sfs: Vec<u32> = table.to_vec();
    if let Some(m) = caps.iter().find(|c| c.0.is_none() || c.0.as_deref() == Some(scene)) {
        sfs.retain(|&sf| sf >= m.1.unwrap_or(0) && sf <= m.2);
    }
    if quick {
        sfs.truncate(2);
    }
    sfs
}

/// 000's floor: out for balls and tree.
fn floor(scene: &str) -> &'static str {
    if scene == "balls" || scene == "tree" {
        "out"
    } else {
        "in"
    }
}

fn first(pts: &[Point], f: impl Fn(&Point) -> bool) -> Option<u32> {
    pts.iter().find(|p| f(p)).map(|p| p.sf)
}

/// The typed record of one scene: rows, the data-size onset, and per disk the p/ and t/ time
/// onsets and the crossover (pure).
fn analyse(p: &Published, scene: &str, pts: &[Point], disks: &[Disk], factor: Option<f64>, memory: u64) -> SceneResult {
    let f = factor.unwrap_or(1.0);
    let rows = pts
        .iter()
        .map(|pt| {
            let t = p.table_3_2.iter().find(|r| r.scene == scene && r.sf == pt.sf);
            SfRow {
                point: pt.clone(),
                table_3_2_mb: t.map(|r| r.mb),
                table_3_2_objects: t.map(|r| r.objects),
                account_mib: pt.account.total as f64 / 1048576.0,
                model: if pt.paged {
                    disks.iter().map(|d| (d.name.clone(), pt.model(d, f))).collect()
                } else {
                    Vec::new()
                },
            }
        })
        .collect();
    let all = pts;
    let paged: Vec<Point> = pts.iter().filter(|p| p.paged).cloned().collect();
    let pts = &paged[..];
    let onsets = disks
        .iter()
        .map(|d| Onset {
            disk: d.name.clone(),
            preprocess_sf: first(pts, |pt| {
                let m = pt.model(d, f);
                m.grid_p > DEPART * m.grid_p_core
            }),
            trace_sf: first(pts, |pt| {
                let m = pt.model(d, f);
                m.grid_t > DEPART * m.grid_t_core
            }),
            crossover_sf: first(pts, |pt| {
                let m = pt.model(d, f);
                m.grid_p + m.grid_t > m.bf_p + m.bf_t
            }),
        })
        .collect();
    SceneResult {
        scene: scene.to_string(),
        sfs: pts.iter().map(|p| p.sf).collect(),
        floor: floor(scene),
        machine_factor: factor,
        size_onset_sf: first(all, |pt| pt.account.total > memory),
        rows,
        onsets,
    }
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let (t31, _): (Table31, _) = published::load("nakamaru-3.1", TABLE_3_1);
    let max_sf = ctx.params.raw(MAX_SF.key).map(String::from);
    let caps = parse_caps(ctx.id, max_sf.as_deref())?;
    let (disks, fault_ms) = disks(ctx.id, ctx.params.raw(FAULT_MS.key))?;
    let memory = p.memory_mb << 20;
    let frames = memory / PAGE;
    let mut scenes: BTreeMap<String, Vec<u32>> = BTreeMap::new();
    for r in &p.table_3_2 {
        scenes.entry(r.scene.clone()).or_default().push(r.sf);
    }
    if let Some(c) = caps
        .iter()
        .find(|c| c.0.as_ref().is_some_and(|name| !scenes.contains_key(name)))
    {
        let known: Vec<&str> = scenes.keys().map(|s| s.as_str()).collect();
        return Err(input(format!(
            "{}: max-sf names scene '{}', which this table does not run (it runs {})",
            ctx.id,
            c.0.as_deref().unwrap_or(""),
            known.join(", ")
        )));
    }
    let validate_case = match ctx.params.raw(VALIDATE.key) {
        Some("off") => None,
        Some(v) => {
            let split = v.find(|c: char| c.is_ascii_digit());
            let parsed = split.and_then(|i| v[i..].parse::<u32>().ok().map(|sf| (v[..i].to_string(), sf)));
            match parsed {
                Some((s, sf)) if scenes.contains_key(&s) && sf >= 1 => Some((s, sf)),
                _ => return Err(input(format!("{}: validate '{v}': expected sceneSF of a Table 3.2 scene (tetra7) or off", ctx.id))),
            }
        }
        None => Some(("tetra".to_string(), if ctx.quick { 6 } else { 7 })),
    };
    // Which SFs are traced: all, none, or up to a per-scene cap.
    let paging: Vec<Cap> = match ctx.params.raw(PAGING.key) {
        None | Some("on") => Vec::new(),
        Some("off") => vec![(None, None, 0)],
        Some(v) => parse_caps(ctx.id, Some(v))
            .map_err(|_| input(format!("{}: paging '{v}': on, off or scene=N,…", ctx.id)))?,
    };
    let traced = |scene: &str, sf: u32| {
        paging
            .iter()
            .find(|c| c.0.is_none() || c.0.as_deref() == Some(scene))
            .is_none_or(|c| sf <= c.2)
    };
    let planned: Vec<(String, Vec<u32>)> = scenes
        .iter()
        .map(|(s, sfs)| (s.clone(), sf_list(s, sfs, &caps, ctx.quick)))
        .filter(|(_, sfs)| !sfs.is_empty())
        .collect();
    if planned.is_empty() {
        return Err(input(format!(
            "{}: max-sf '{}' leaves no size factor to run",
            ctx.id,
            max_sf.as_deref().unwrap_or("")
        )));
    }
    let rss_r = t31.configs.iter().position(|c| c == "rss-r").unwrap_or(1);
    let mut measured = Vec::new();
    let mut svgs = Vec::new();
    for (scene, sfs) in planned {
        let mut pts = Vec::new();
        for sf in sfs {
            let paged = traced(&scene, sf);
            // "-cpu": the times are the thread's CPU seconds (steps saved with wall times differ).
            let key = format!("{scene}{sf}{}", if paged { "-cpu" } else { "-account" });
            let pt = match ctx.checkpoint.load::<Point>(&key)? {
                Some(pt) => pt,
                None => {
                    eprintln!("nakamaru-3.2: {scene}{sf}{} …", if paged { "" } else { " (account)" });
                    let src = SceneSource::resolve(&scene, Some(sf), None, None)?;
                    let prepared = workload::prepare(&src)?;
                    let mut pt = if paged {
                        let mut pt = grid_point(&prepared, floor(&scene), frames)?;
                        breadth_first_point(&prepared, floor(&scene), &mut pt)?;
                        pt
                    } else {
                        account_point(&prepared, floor(&scene))?
                    };
                    pt.sf = sf;
                    ctx.checkpoint.save(&key, &pt)?;
                    pt
                }
            };
            pts.push(pt);
        }
        // Pentium 90 seconds per our second: Table 3.1's rss-r total at its SF over our grid's.
        let factor = t31.rows.iter().find(|r| r.scene == scene).and_then(|r| {
            let ours = pts.iter().find(|p| p.sf == r.sf && p.paged)?;
            Some(r.total[rss_r] / (ours.grid_build_s + ours.grid_trace_s).max(1e-9))
        });
        let s = analyse(&p, &scene, &pts, &disks, factor, memory);
        if s.sfs.len() >= 2 {
            svgs.push((format!("{}-{scene}", ctx.id), plot(&s, &disks[0])));
        }
        measured.push(s);
    }
    let validation = match validate_case {
        Some((scene, sf)) => {
            let key = format!("validate-{scene}{sf}");
            let v = match ctx.checkpoint.load::<Validation>(&key)? {
                Some(v) => v,
                None => {
                    let v = validate(&scene, sf)?;
                    ctx.checkpoint.save(&key, &v)?;
                    v
                }
            };
            Some((format!("{scene}{sf}"), v))
        }
        None => None,
    };
    let result = Result_ {
        id: ctx.id,
        published: raw,
        measured,
        validation,
        quick: ctx.quick,
        max_sf,
        fault_ms,
        memory_bytes: memory,
        page_bytes: PAGE,
        depart: DEPART,
        environment: super::environment(1),
    };
    let rows = rows(&p, &result);
    let doc = document(ctx, &p, &result, &disks, frames, &svgs);
    let mut out = Output::new(&result, rows, doc);
    out.svgs = svgs;
    Ok(out)
}

fn show(v: Option<u32>, last: Option<&u32>) -> String {
    v.map(|s| s.to_string())
        .unwrap_or_else(|| format!("none ≤ {}", last.map(|l| l.to_string()).unwrap_or_default()))
}

/// The thesis's per-scene explanation (§3.5), as one testable statement per scene.
fn scene_claim(scene: &str) -> &'static str {
    match scene {
        "balls" | "tree" => "many small objects in one place: page faults as soon as the data outgrows memory (time onset no later than the data-size onset)",
        "gears" => "hidden objects never referenced: the working set stays small (tracing departs later than the data-size onset, or not at all)",
        "mount" | "tetra" => "no concentration, but many objects eventually fault (a time onset exists, at or after the data-size onset)",
        "rings" => "objects overlap many voxels: preprocessing departs right after memory is exceeded (p/ onset = data-size onset), tracing like gears (t/ later or never)",
        _ => "",
    }
}

/// The per-scene statement judged on the HDD model's onsets; None when the range shows no data-size onset.
fn judge_scene(s: &SceneResult) -> Option<bool> {
    let size = s.size_onset_sf?;
    let o = &s.onsets[0];
    let time = match (o.preprocess_sf, o.trace_sf) {
        (Some(a), Some(b)) => Some(a.min(b)),
        (a, b) => a.or(b),
    };
    Some(match s.scene.as_str() {
        "balls" | "tree" => time.is_some_and(|t| t <= size),
        "gears" => o.trace_sf.is_none_or(|t| t > size),
        "mount" | "tetra" => time.is_some_and(|t| t >= size),
        "rings" => o.preprocess_sf == Some(size) && o.trace_sf.is_none_or(|t| t > size),
        _ => return None,
    })
}

fn rows(p: &Published, r: &Result_) -> Vec<Row> {
    let mut rows = Vec::new();
    for s in &r.measured {
        for x in &s.rows {
            if let Some(mb) = x.table_3_2_mb {
                let ratio = x.account_mib / mb;
                rows.push(
                    Row::new(
                        "table-3.2-memory",
                        format!("{}{}", s.scene, x.point.sf),
                        format!("{mb} MB ({} objects)", x.table_3_2_objects.unwrap_or(0)),
                        format!("{:.1} MiB ({} objects), ratio {ratio:.2}", x.account_mib, x.point.objects),
                        Kind::Ratio,
                        Verdict::of((0.75..=1.0 / 0.75).contains(&ratio)),
                    )
                    .with_note("within 25%"),
                );
            }
        }
        let last = s.sfs.last();
        for o in s.onsets.iter().filter(|_| !s.sfs.is_empty()) {
            rows.push(Row::new(
                "onset",
                format!("{} ({})", s.scene, o.disk),
                "thrashing once rayshade-ss's memory exceeds 32 MB (no SF printed: curves lost)",
                format!(
                    "data-size onset SF {}; time onset p/ {}, t/ {}; crossover SF {}",
                    show(s.size_onset_sf, last),
                    show(o.preprocess_sf, last),
                    show(o.trace_sf, last),
                    show(o.crossover_sf, last)
                ),
                Kind::Shape,
                Verdict::Shown,
            ));
        }
        // Judged on the first disk (HDD-like, the thesis's kind of disk).
        let d: Vec<&SfRow> = s.rows.iter().filter(|x| x.point.paged).collect();
        if d.is_empty() {
            continue;
        }
        let fits: Vec<&SfRow> = d.iter().filter(|x| x.point.account.total <= r.memory_bytes).copied().collect();
        let faster_in = fits.iter().all(|x| {
            let m = &x.model[0].1;
            m.grid_p + m.grid_t < m.bf_p + m.bf_t
        });
        rows.push(
            Row::new(
                "in-memory-faster",
                &s.scene,
                "while memory suffices, rayshade-ss is faster",
                format!(
                    "{} of {} SFs that fit: grid < breadth-first (HDD model)",
                    fits.iter()
                        .filter(|x| {
                            let m = &x.model[0].1;
                            m.grid_p + m.grid_t < m.bf_p + m.bf_t
                        })
                        .count(),
                    fits.len()
                ),
                Kind::Ordering,
                if fits.is_empty() { Verdict::NotMeasured } else { Verdict::of(faster_in) },
            ),
        );
        let o = &s.onsets[0];
        let onset = match (o.preprocess_sf, o.trace_sf) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let after: Vec<&&SfRow> = d.iter().filter(|x| onset.is_some_and(|t| x.point.sf >= t)).collect();
        let bf_wins = after.iter().filter(|x| {
            let m = &x.model[0].1;
            m.bf_p + m.bf_t < m.grid_p + m.grid_t
        });
        let n_wins = bf_wins.count();
        rows.push(Row::new(
            "breadth-first-faster-once-thrashing",
            &s.scene,
            "once rayshade-ss thrashes, sray is faster",
            format!("{n_wins} of {} SFs at or past the time onset (HDD model)", after.len()),
            Kind::Ordering,
            if after.is_empty() { Verdict::NotMeasured } else { Verdict::of(n_wins == after.len()) },
        ));
        rows.push(Row::new(
            "scene-pattern",
            &s.scene,
            scene_claim(&s.scene),
            format!(
                "data-size onset {}, p/ {}, t/ {} (HDD model)",
                show(s.size_onset_sf, last),
                show(o.preprocess_sf, last),
                show(o.trace_sf, last)
            ),
            Kind::Shape,
            match judge_scene(s) {
                Some(b) => Verdict::of(b),
                None => Verdict::NotMeasured,
            },
        ));
    }
    if let Some((case, v)) = &r.validation {
        rows.push(Row::new(
            "model-validation",
            case,
            "Mattson's LRU count = a direct LRU simulation; CLOCK shown",
            format!(
                "{} frames: Mattson {} faults, direct LRU {}, CLOCK {} ({:+.1}%)",
                v.frames,
                v.mattson_lru,
                v.direct_lru,
                v.clock,
                (v.clock as f64 / v.direct_lru.max(1) as f64 - 1.0) * 100.0
            ),
            Kind::Count,
            Verdict::of(v.mattson_lru == v.direct_lru),
        ));
    }
    let _ = p;
    rows
}

fn document(ctx: &Ctx, p: &Published, r: &Result_, disks: &[Disk], frames: u64, svgs: &[(String, String)]) -> Document {
    let mut doc = Document::new("nakamaru-3.2: rayshade-ss's memory, thrashing onset and crossover, 32 MB");
    doc.paragraph(format!(
        "Published: {}. The figures' curves are lost; Table 3.2 (rayshade-ss memory per SF) and the per-scene explanations survive.",
        p.source.cite()
    ));
    doc.paragraph(format!("Measured: `rtbench reproduce nakamaru-3.2{}{}{}`, one thread, 512×512, Table 3.2's SFs; in-core times are the working thread's CPU seconds (the disk is modelled). Memory (model): rayshade-ss's allocation from Rayshade 4.0's structs on i386 (Geom 96 B with its box, Sphere 40, Polygon 44 + 24 B per vertex, Cone 224; voxel pointer arrays; a GeomList node of 8 B per object and voxel; glibc chunks n + 4 rounded to 8) for our scene and a grid built by Rayshade's rule (⌊n^(1/3) + 0.5⌋ cells per axis on objects, bounding-box insertion). Paging (model): that image's page stream, preprocessing then every query, through Mattson's stack algorithm at {frames} pages of 4 KiB (all 32 MiB for data; LRU); modelled time = in-core time × machine factor (Table 3.1's rss-r total / our grid's at the scene's first SF: Pentium 90 seconds) + pages first touched × 4 KiB ÷ bandwidth + faults beyond first touch × fault cost. Breadth-first: memory=32MiB, registration ⌈r/10+0.5⌉; p/ = store + preprocessing (+ bytes written ÷ bandwidth), t/ = trace (+ bytes read ÷ bandwidth + seeks × seek cost). Data-size onset: first SF with rayshade-ss memory > 32 MiB. Time onset: first SF whose modelled phase exceeds {DEPART} × its in-core time. Crossover: first SF with modelled grid total > breadth-first total.",
        if ctx.quick { " --quick" } else { "" },
        r.max_sf.as_ref().map(|m| format!(" --max-sf {m}")).unwrap_or_default(),
        r.fault_ms.map(|m| format!(" --fault-ms {m}")).unwrap_or_default()));
    let mut t = DocTable::new("Table 3.2 beside the account", &["scene", "SF", "objects (ours / table)", "Table 3.2 MB", "account MiB", "ratio", "objects+boxes MiB", "voxel arrays MiB", "list nodes", "nodes MiB", "grid res"]);
    for s in &r.measured {
        for x in &s.rows {
            let a = &x.point.account;
            t.push(vec![
                s.scene.clone(),
                x.point.sf.to_string(),
                format!("{} / {}", x.point.objects, x.table_3_2_objects.map_or("–".into(), |o| o.to_string())),
                x.table_3_2_mb.map_or("–".into(), |v| v.to_string()),
                format!("{:.1}", x.account_mib),
                x.table_3_2_mb.map_or("–".into(), |v| format!("{:.2}", x.account_mib / v)),
                format!("{:.1}", a.objects as f64 / 1048576.0),
                format!("{:.2}", a.voxel_arrays as f64 / 1048576.0),
                a.list_nodes.to_string(),
                format!("{:.1}", a.node_bytes as f64 / 1048576.0),
                format!("{}×{}×{}", x.point.grid_res[0], x.point.grid_res[1], x.point.grid_res[2]),
            ]);
        }
    }
    doc.table(t);
    for s in r.measured.iter().filter(|s| !s.sfs.is_empty()) {
        doc.heading(format!(
            "{} (machine factor {})",
            s.scene,
            s.machine_factor.map_or("none: Table 3.1's SF not run; times unscaled".into(), |f| format!("{f:.1}"))
        ));
        doc.table(scene_table(s, disks));
        let last = s.sfs.last();
        doc.list(
            s.onsets
                .iter()
                .map(|o| {
                    format!(
                        "{}: data-size onset SF {}, time onset p/ {}, t/ {}, crossover SF {}.",
                        o.disk,
                        show(s.size_onset_sf, last),
                        show(o.preprocess_sf, last),
                        show(o.trace_sf, last),
                        show(o.crossover_sf, last)
                    )
                })
                .collect(),
        );
        let stem = format!("{}-{}", ctx.id, s.scene);
        if svgs.iter().any(|(st, _)| *st == stem) {
            doc.figure(format!("plots/{stem}.svg"), &s.scene);
        }
    }
    if let Some((case, v)) = &r.validation {
        doc.heading("The model checked by direct simulation");
        doc.paragraph(format!("{case}: the preprocessing's and the render's page stream in rayshade-ss's image, {} accesses to {} pages, in a memory of {} frames (half the pages touched, so that it pages): Mattson's stack algorithm counts {} faults, a direct LRU simulation {}, CLOCK (second chance, the kernel's approximation of LRU) {} ({:+.1}% against LRU). The model assumes LRU, every frame free for the data, one disk access per fault and nothing for writing evicted pages back.",
            v.accesses, v.pages, v.frames, v.mattson_lru, v.direct_lru, v.clock, (v.clock as f64 / v.direct_lru.max(1) as f64 - 1.0) * 100.0));
    }
    let pattern = &published::claim(&p.claims, "pattern").claim;
    doc.paragraph(format!("Published pattern (000 §3.5): {pattern}"));
    doc
}

fn scene_table(s: &SceneResult, disks: &[Disk]) -> DocTable {
    let mut header: Vec<String> = [
        "SF", "account MiB", "pre accesses", "pre faults", "trace accesses", "trace faults", "grid p/ s", "grid t/ s", "bf p/ s", "bf t/ s", "bf passes",
    ]
    .iter()
    .map(|h| h.to_string())
    .collect();
    for d in disks {
        for w in ["grid p/", "grid t/", "bf p/", "bf t/"] {
            header.push(format!("{w} model ({})", d.name));
        }
    }
    let mut t = DocTable::new("", &header.iter().map(String::as_str).collect::<Vec<_>>());
    for x in s.rows.iter().filter(|x| x.point.paged) {
        let pt = &x.point;
        let mut cells = vec![
            pt.sf.to_string(),
            format!("{:.1}", x.account_mib),
            pt.pre_accesses.to_string(),
            pt.pre_faults.to_string(),
            pt.trace_accesses.to_string(),
            pt.trace_faults.to_string(),
            format!("{:.2}", pt.grid_build_s),
            format!("{:.2}", pt.grid_trace_s),
            format!("{:.2}", pt.bf_build_s),
            format!("{:.2}", pt.bf_trace_s),
            pt.bf_passes.to_string(),
        ];
        for (_, m) in &x.model {
            for v in [m.grid_p, m.grid_t, m.bf_p, m.bf_t] {
                cells.push(format!("{v:.1}"));
            }
        }
        t.push(cells);
    }
    t
}

/// Modelled time (first disk) against rayshade-ss's memory, log–log, p/ and t/ of both methods
/// (Figs. 3.5–3.7's axes), physical memory marked.
fn plot(s: &SceneResult, d: &Disk) -> String {
    let (w, h, m) = (560.0, 340.0, 56.0);
    let rows: Vec<&SfRow> = s.rows.iter().filter(|x| x.point.paged).collect();
    let xs: Vec<f64> = rows.iter().map(|x| x.account_mib.max(1e-3).log10()).collect();
    let series: Vec<(&str, &str, Vec<f64>)> = vec![
        ("rss p/", "#e59866", rows.iter().map(|x| x.model[0].1.grid_p).collect()),
        ("rss t/", "#c0392b", rows.iter().map(|x| x.model[0].1.grid_t).collect()),
        ("sray p/", "#85c1e9", rows.iter().map(|x| x.model[0].1.bf_p).collect()),
        ("sray t/", "#2471a3", rows.iter().map(|x| x.model[0].1.bf_t).collect()),
    ];
    let ys: Vec<f64> = series.iter().flat_map(|(_, _, v)| v.iter().map(|y| y.max(1e-3).log10())).collect();
    let (x0, x1) = (
        xs.iter().cloned().fold(f64::INFINITY, f64::min).min(32f64.log10()),
        xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max).max(32f64.log10()),
    );
    let (y0, y1) = (
        ys.iter().cloned().fold(f64::INFINITY, f64::min),
        ys.iter().cloned().fold(f64::NEG_INFINITY, f64::max),
    );
    let sx = |x: f64| m + (x - x0) / (x1 - x0).max(1e-9) * (w - 2.0 * m);
    let sy = |y: f64| h - m - (y - y0) / (y1 - y0).max(1e-9) * (h - 2.0 * m);
    let mut out = format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n");
    let _ = writeln!(out, "<text x=\"{m}\" y=\"20\" font-size=\"13\">{}: modelled time (model, {}) vs rayshade-ss memory, log-log</text>", s.scene, d.name);
    let _ = writeln!(out, "<line x1=\"{m}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"black\"/><line x1=\"{m}\" y1=\"{m}\" x2=\"{m}\" y2=\"{}\" stroke=\"black\"/>", h - m, w - m, h - m, h - m);
    let xm = sx(32f64.log10());
    let _ = writeln!(out, "<line x1=\"{xm:.1}\" y1=\"{m}\" x2=\"{xm:.1}\" y2=\"{}\" stroke=\"#777\" stroke-dasharray=\"4 3\"/><text x=\"{:.1}\" y=\"{}\" fill=\"#777\">32 MiB</text>", h - m, xm + 3.0, m + 10.0);
    let _ = writeln!(out, "<text x=\"{m}\" y=\"{}\">rayshade-ss memory (MiB): {:.1} … {:.1}</text>", h - 12.0, 10f64.powf(x0), 10f64.powf(x1));
    let _ = writeln!(out, "<text x=\"4\" y=\"{}\">{:.2e}</text><text x=\"4\" y=\"{}\">{:.2e} s</text>", h - m, 10f64.powf(y0), m, 10f64.powf(y1));
    for (k, (name, colour, v)) in series.iter().enumerate() {
        let pts: Vec<String> = xs
            .iter()
            .zip(v)
            .map(|(x, y)| format!("{:.1},{:.1}", sx(*x), sy(y.max(1e-3).log10())))
            .collect();
        let _ = writeln!(out, "<polyline fill=\"none\" stroke=\"{colour}\" stroke-width=\"2\" points=\"{}\"/>", pts.join(" "));
        let _ = writeln!(out, "<text x=\"{}\" y=\"{}\" fill=\"{colour}\">{name}</text>", w - 110.0, 40.0 + 14.0 * k as f64);
    }
    for (i, x) in rows.iter().enumerate() {
        let _ = writeln!(out, "<text x=\"{:.1}\" y=\"{:.1}\" fill=\"#555\">{}</text>", sx(xs[i]) - 4.0, h - m + 14.0, x.point.sf);
    }
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_sf_caps_table_3_2s_sfs() {
        assert!(parse_caps("t", None).unwrap().is_empty());
        let all = parse_caps("t", Some("5")).unwrap();
        assert_eq!(sf_list("balls", &[4, 5, 6], &all, false), vec![4, 5]);
        let some = parse_caps("t", Some("rings=10..16,balls=5")).unwrap();
        assert_eq!(sf_list("rings", &[7, 10, 13, 16, 17], &some, false), vec![10, 13, 16]);
        assert_eq!(sf_list("gears", &[4, 5, 6], &some, true), vec![4, 5]);
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
    fn the_published_tables_parse_with_28_rows() {
        let (p, _): (Published, _) = published::load("nakamaru-3.2", PUBLISHED);
        assert_eq!(p.memory_mb, 32);
        assert_eq!(p.table_3_2.len(), 28);
        assert!(p.table_3_2.iter().any(|r| r.scene == "tree" && r.sf == 15 && r.objects == 131071));
        let (t, _): (Table31, _) = published::load("nakamaru-3.1", TABLE_3_1);
        assert!(t.configs.iter().any(|c| c == "rss-r"));
        assert_eq!(t.rows.len(), 6);
    }

    fn pt(sf: u32, mib: u64, pre_faults: u64, trace_faults: u64) -> Point {
        Point {
            sf,
            paged: true,
            objects: 1,
            rays: 1,
            account: Account {
                total: mib << 20,
                ..Account::default()
            },
            grid_res: [1, 1, 1],
            pre_accesses: 0,
            pre_touched: 0,
            pre_faults,
            trace_accesses: 0,
            trace_touched: 0,
            trace_faults,
            grid_build_s: 1.0,
            grid_trace_s: 10.0,
            bf_build_s: 2.0,
            bf_trace_s: 30.0,
            bf_pre_io_bytes: 0,
            bf_trace_io_bytes: 0,
            bf_seeks: 0,
            bf_passes: 1,
        }
    }

    #[test]
    fn onsets_follow_the_faults_and_the_crossover_the_totals() {
        let (p, _): (Published, _) = published::load("nakamaru-3.2", PUBLISHED);
        let d = disks("t", None).unwrap().0;
        // 1 s per 125 faults at 8 ms: p/ departs at 100 faults (0.8 s > 0.25 s), t/ at 10,000.
        let pts = vec![pt(1, 10, 0, 0), pt(2, 40, 100, 0), pt(3, 80, 100, 10_000)];
        let s = analyse(&p, "rings", &pts, &d, None, 32 << 20);
        assert_eq!(s.size_onset_sf, Some(2));
        assert_eq!(s.onsets[0].preprocess_sf, Some(2));
        assert_eq!(s.onsets[0].trace_sf, Some(3));
        assert_eq!(s.onsets[0].crossover_sf, Some(3));
        assert_eq!(judge_scene(&s), Some(true), "rings: p/ at the size onset, t/ later");
        let g = analyse(&p, "balls", &pts, &d, None, 32 << 20);
        assert_eq!(judge_scene(&g), Some(true), "balls: p/ departs at the size onset");
        let late = vec![pt(1, 10, 0, 0), pt(2, 40, 0, 0), pt(3, 80, 0, 10_000)];
        let b = analyse(&p, "balls", &late, &d, None, 32 << 20);
        assert_eq!(judge_scene(&b), Some(false), "balls departing after the size onset is not early");
    }
}
