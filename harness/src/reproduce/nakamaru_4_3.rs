//! `nakamaru-4.3`: seed 000's Tables 4.3 and 4.4, the massive scenes (§4.4): mount14
//! (536,870,916 objects), rings368 and rings368m (1,000,787,041 objects; rings368m is rings368
//! under a view that sees about 0.1% of them, ours in `data/views/rings368m.json`). Totals, and
//! the split into preprocessing and tracing, of the basic method, S+G and S+G+B. As the thesis
//! did here, every method uses the high-resolution grid (`grid=two-level`), so that only S, G
//! and B differ.
//!
//! A row is a chain of steps, each saved as it finishes (`--resume`), so a row of days is done
//! in sittings: the basic store (compressed with the split store's codec, so that no method
//! pays a decoder the others do not; the basic method reads it strictly forward, §3.4) and the
//! split store are written in segments (`rtbench_engines::store::segments`), each
//! segment a checkpoint; `max-seconds=S` stops the run at the first checkpoint past S seconds
//! (the report then says which steps are still to do). A scene's rows share its stores and run
//! in the order the disk allows: every row's basic steps first, the basic store removed after
//! the last, then the split store and every row's S+G and S+G+B (rings368's basic and split
//! stores, ~47 and ~24 GB, are never on disk together). Where the basic method cannot be traced
//! whole, `basic-fraction=N` traces every N-th band of image rows (a tile set, as
//! `render --tile 1/N` makes it) and extrapolates its tracing time by the rows not traced: that
//! row is labelled `model`, with the extrapolation written out. Or `basic-passes=N` runs the
//! basic method for its first N passes (the engine's `max_passes`) and extrapolates its tracing
//! part by part: the passes by the pass count of the first split run measured, S+G+B (it uses the
//! same high-resolution grid, the same rays and the same memory budget, so it makes the passes the
//! basic method would; measured on `--quick`: the report's basic-model row gives both counts), the
//! shading by the whole run's forward reads of the store (one per group of rays in memory per
//! generation, from that run's generations; rows saved before this split was kept scale all of
//! the tracing by S+G's passes). S+G+B runs before S+G: Table 4.3 compares it with the basic
//! method, and S+G at 10^9 objects takes hours. `--quick` runs small stand-ins (mount6, rings6,
//! rings6m at 64×64) with the basic method both whole and as the model (a quarter of the rows,
//! or the first N passes), which tests the model against a measurement.
//!
//! The split store is zstd-compressed by default (`split-compress`; zstd blocks with an index,
//! `rtbench_engines::store::blocks`): uncompressed, mount14's and rings368's split stores take
//! ~55 GB and ~102 GB, more than the disk's free space.

use super::per_ray::{self, SizePoint};
use super::published::{self, Source};
use super::{environment, Claim, Ctx, Fidelity, Kind, Output, Param, Row, Runtime, Table, Verdict};
use crate::output::hex;
use crate::error::{input, Result};
use crate::shard::ShardSpec;
use crate::workload::frustum::Frustum;
use crate::workload::view_file::ViewFile;
use crate::workload::{self, out_of_core, tiles};
use rtbench_engines::breadth_first::config::BreadthFirstConfig;
use rtbench_engines::breadth_first::BreadthFirst;
use rtbench_engines::store::{
    BboxReader, Codec, Layout, Outcome, SegmentLog, SegmentedWriter, StoreHeader,
};
use rtbench_engines::{Engine, Settings};
use rtbench_reports::{Document, Table as DocTable};
use rtbench_scenes::View;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

const ROWS: Param = Param {
    key: "rows",
    help: "rows, e.g. mount14,rings368m (default: the table's 3; --quick: mount6,rings6,rings6m); a trailing m is the rings368m view",
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
    help: "cold (default) or warm",
};
const STORES: Param = Param {
    key: "stores",
    help: "directory for the scene stores, kept between runs (default OUT/.partial/nakamaru-4.3/stores; removed when every row is done)",
};
const SPILL: Param = Param {
    key: "spill",
    help: "directory for spill files (default the system temp dir)",
};
const SEGMENT: Param = Param {
    key: "segment",
    help: "objects per store segment, each a checkpoint (default 16777216; --quick 1000)",
};
const MAX_SECONDS: Param = Param {
    key: "max-seconds",
    help: "stop at the first checkpoint after this many seconds (default: no limit)",
};
const PASSES: Param = Param {
    key: "basic-passes",
    help: "trace the basic method for its first N passes only (max_passes=N) and extrapolate its passes by the split runs' pass count and its shading by the whole run's store sweeps (a model; --quick: against the whole basic run)",
};
const SPLIT_COMPRESS: Param = Param {
    key: "split-compress",
    help: "the split store: zstd (default; zstd blocks, ~2-3x smaller, so that 10^9 objects fit the disk), zstd:LEVEL or none",
};
const SUBSPACES: Param = Param {
    key: "basic-subspaces",
    help: "with basic-passes: build only the first K subspaces of the basic run's on-disk grid (hrgrid_subspaces=K; the rest left empty) and extrapolate the grid's build by the subspaces in all (a model; rings368's basic build is 27 sweeps of its 35 GB store, ~4 h)",
};
const METHODS: Param = Param {
    key: "methods",
    help: "the methods this invocation measures, of basic,sgb,sg (default all three); the others keep what earlier invocations saved, so a 10^9-object row can be measured one method an invocation (e.g. methods=sgb first: the split store and S+G+B only)",
};
const FRACTION: Param = Param {
    key: "basic-fraction",
    help: "trace the basic method on every N-th band of rows only and extrapolate (a model; default 1: whole)",
};

pub const TABLE: Table = Table {
    id: "nakamaru-4.3",
    seed: "000",
    source: "Tables 4.3, 4.4",
    about: "000 (Nakamaru 2002) Tables 4.3/4.4: mount14, rings368, rings368m (5e8–1e9 objects), basic vs S+G vs S+G+B; resumable by store segment and step",
    runtime: Runtime {
        quick: "a minute",
        full: "days to weeks (10^9 objects out of core, three methods); resumable by segment and step",
    },
    params: &[
        ROWS,
        SIZE,
        MEMORY,
        CACHE,
        STORES,
        SPILL,
        SEGMENT,
        MAX_SECONDS,
        FRACTION,
        PASSES,
        SUBSPACES,
        METHODS,
        SPLIT_COMPRESS,
    ],
    claims: &[
        Claim {
            key: "sgb-ratio",
            fidelity: Fidelity::Substituted,
            why: "both stores are zstd-compressed (level 3; the thesis's Table 4.3 stores were not compressed, ours must be to fit this disk: uncompressed, mount14's and rings368's split stores take ~55 and ~102 GB), one codec for all three methods; the grid's shape is our reading of Klimaszewski's method (its formula is not in the thesis); the machine the record names (its disk read cold, page cache dropped by posix_fadvise, 256 MiB engine budget) is stated, not the reason; a row whose basic time is extrapolated is a model",
        },
        Claim {
            key: "sg-ratio",
            fidelity: Fidelity::Substituted,
            why: "as sgb-ratio",
        },
        Claim {
            key: "basic-model",
            fidelity: Fidelity::Model,
            why: "basic tracing time extrapolated from a tile set of the image rows (basic-fraction) or from its first N passes: passes by the split runs' pass count, shading by the whole run's store sweeps (basic-passes); --quick: against the whole run, measured",
        },
        Claim {
            key: "per-ray-growth-thesis",
            fidelity: Fidelity::Substituted,
            why: "ours beside the thesis's own S+G+B growth between the same rows (its time = basic time ÷ S+G+B ratio, Table 4.1 for the row near 10^6 objects, Table 4.3 for the 10^9 row; the same SPD workload at 512²), judged within 2× either way; substituted as sgb-ratio is (zstd stores, our reading of Klimaszewski's method); each growth is a ratio within one machine (ours the one the record names, the thesis's a Pentium II 450 MHz with 256 MB)",
        },
        Claim {
            key: "view",
            fidelity: Fidelity::Substituted,
            why: "the thesis does not give rings368m's camera; ours keeps rings' eye and narrows the angle (data/views/rings368m.json)",
        },
        Claim {
            key: "memory",
            fidelity: Fidelity::Substituted,
            why: super::nakamaru_4_1::MEMORY_WHY,
        },
        Claim {
            key: "image-equal",
            fidelity: Fidelity::Faithful,
            why: "",
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/nakamaru-4.3.json");
/// Table 4.1, for the thesis's own S+G+B time at the rows near 10^6 objects (per-ray-growth-thesis).
const PUBLISHED_41: &str = include_str!("../../../data/published/nakamaru-4.1.json");
const VIEW: &str = include_str!("../../../data/views/rings368m.json");

#[derive(Deserialize)]
struct Published {
    source: Source,
    improvement_range: [f64; 2],
    rows: Vec<PublishedRow>,
}

#[derive(Deserialize, Serialize, Clone)]
struct PublishedRow {
    scene: String,
    sf: u32,
    view: String,
    objects: u64,
    basic_s: u64,
    sg: f64,
    sgb: f64,
    pre_basic_s: u64,
    trace_basic_s: u64,
}

/// One method's run.
#[derive(Serialize, Deserialize, Clone, Default)]
struct Run {
    preprocess_s: f64,
    trace_s: f64,
    passes: u64,
    rays: u64,
    sha256: String,
    peak_rss_bytes: u64,
    /// The image rows traced (of size + 1) and the factor the tracing time was extrapolated by
    /// (1: the whole image, measured).
    rows_traced: u32,
    scale: f64,
    load_average: String,
    /// Stopped by the pass cap (`basic-passes`): `passes` is the cap, the image no answer, and
    /// `scale` = `passes_total` / `passes` once a split run's pass count is known (0 until then).
    #[serde(default)]
    capped: bool,
    #[serde(default)]
    passes_total: u64,
    /// The process's CPU seconds over the run (0 in rows saved before they were kept): a run
    /// that waited for a core shows CPU / wall well under 1.
    #[serde(default)]
    cpu_s: f64,
    /// Seconds of the on-disk grid's build spent by earlier invocations that were stopped
    /// (`hrgrid=resume`: rings368's basic preprocessing sweeps its 35 GB store 27 times, ~4 h,
    /// more than one sitting), counted in `preprocess_s` but not in `cpu_s`.
    #[serde(default)]
    earlier_s: f64,
    /// The tracing split: the engine's passes (`intersect_s`) and shading (`shade_s`, whose
    /// `shade_sweeps` groups of `shade_group` rays each read the store forward), and each
    /// generation's rays. 0 / empty in rows saved before they were kept.
    #[serde(default)]
    intersect_s: f64,
    #[serde(default)]
    shade_s: f64,
    #[serde(default)]
    shade_group: u64,
    #[serde(default)]
    shade_sweeps: u64,
    #[serde(default)]
    generation_rays: Vec<u64>,
    /// A capped run's shading sweeps in the whole run, once a split run's generations are known: one per
    /// group of `shade_group` rays of each generation (an upper bound: a group without a hit
    /// reads nothing).
    #[serde(default)]
    sweeps_total: u64,
    /// The run whose pass count `passes_total` is ("S+G" or "S+G+B"; empty: S+G, in rows
    /// saved before S+G+B ran first).
    #[serde(default)]
    passes_from: String,
    /// The on-disk grid's build: its seconds, and the subspaces it swept of the grid's all
    /// (fewer with `basic-subspaces`: then a model). 0 in rows saved before they were kept.
    #[serde(default)]
    hr_build_s: f64,
    #[serde(default)]
    subspaces: u64,
    #[serde(default)]
    subspaces_total: u64,
    /// The rays the engine held a pass (`rays_in_memory`), and the rays of every stream it was
    /// given, in order (each generation's rays, then its shadow rays): the engine fills a pass
    /// from one stream, so a stream of n rays takes ⌈n / rays a pass⌉ passes. 0 / empty in rows
    /// saved before they were kept.
    #[serde(default)]
    capacity: u64,
    #[serde(default)]
    stream_rays: Vec<u64>,
}

impl Run {
    /// Passes of streams of `stream_rays` rays at `capacity` rays a pass.
    fn passes_at(stream_rays: &[u64], capacity: u64) -> u64 {
        stream_rays.iter().map(|&n| n.div_ceil(capacity.max(1))).sum()
    }

    /// What the pass model's total counts ("S+G+B's passes", or a split run's streams at this
    /// run's rays a pass).
    fn passes_from(&self) -> String {
        if self.passes_from.is_empty() {
            "S+G's passes".into()
        } else if self.passes_from.contains("streams") {
            self.passes_from.clone()
        } else {
            format!("{}'s passes", self.passes_from)
        }
    }

    /// Whether the run stands in for a whole one (a tile set, the first passes, a partial grid):
    /// a model, not a measurement.
    fn is_model(&self) -> bool {
        self.scale != 1.0 || self.capped || self.partial_grid()
    }

    /// Whether the grid's build stopped short of its subspaces (`basic-subspaces`).
    fn partial_grid(&self) -> bool {
        self.subspaces > 0 && self.subspaces < self.subspaces_total
    }

    /// Preprocessing, the grid's build extrapolated by its subspaces when it stopped short:
    /// every subspace of the basic layout reads the whole store, so each costs about the same.
    fn pre_s(&self) -> f64 {
        if self.partial_grid() {
            self.preprocess_s
                + self.hr_build_s * (self.subspaces_total as f64 / self.subspaces as f64 - 1.0)
        } else {
            self.preprocess_s
        }
    }

    /// Preprocessing, written out.
    fn pre_text(&self) -> String {
        if self.partial_grid() {
            format!(
                "pre {:.1} s, of which the grid's build {:.1} s over {} of its {} subspaces, × {} / {} = {:.1} s",
                self.preprocess_s,
                self.hr_build_s,
                self.subspaces,
                self.subspaces_total,
                self.subspaces_total,
                self.subspaces,
                self.pre_s()
            )
        } else {
            format!("pre {:.1} s", self.preprocess_s)
        }
    }

    /// Preprocessing + tracing, the tracing extrapolated when only a tile set or the first
    /// passes were traced ([`Run::split_model`] when the run kept its split).
    fn total_s(&self) -> f64 {
        match self.split_model() {
            Some((passes_s, shade_s, other_s)) => self.pre_s() + passes_s + shade_s + other_s,
            None => self.pre_s() + self.trace_s * self.scale,
        }
    }

    /// A capped basic run's tracing, extrapolated part by part: its passes by a split run's pass count,
    /// its shading by the whole run's sweeps of the store, the rest (writing the eye rays) as
    /// measured. Scaling all of `trace_s` by the passes, as rows saved without the split do,
    /// scales the shading sweeps by the pass count too (seed 000 §3.4: shading is one forward
    /// read of the store per group of rays in memory, not per pass).
    fn split_model(&self) -> Option<(f64, f64, f64)> {
        let ok = self.capped
            && self.passes > 0
            && self.passes_total > 0
            && self.shade_sweeps > 0
            && self.sweeps_total > 0
            && self.intersect_s > 0.0;
        ok.then(|| {
            let passes_s = self.intersect_s * self.passes_total as f64 / self.passes as f64;
            let shade_s = self.shade_s * self.sweeps_total as f64 / self.shade_sweeps as f64;
            let other_s = (self.trace_s - self.intersect_s - self.shade_s).max(0.0);
            (passes_s, shade_s, other_s)
        })
    }
}

/// Shading groups of `group` rays over a run's generations: the forward reads of the store the
/// basic layout makes.
fn sweeps(generation_rays: &[u64], group: u64) -> u64 {
    generation_rays
        .iter()
        .map(|&n| n.div_ceil(group.max(1)))
        .sum()
}

/// A store written in segments: its seconds summed over invocations, its size.
#[derive(Serialize, Deserialize, Clone, Default)]
struct StoreStep {
    objects: u64,
    stored_bytes: u64,
    seconds: f64,
    segments: usize,
}

#[derive(Serialize, Deserialize, Clone, Default)]
struct Measured {
    row: String,
    scene: String,
    sf: u32,
    view: String,
    objects: u64,
    objects_in_view: Option<u64>,
    basic_store: Option<StoreStep>,
    split_store: Option<StoreStep>,
    basic: Option<Run>,
    /// `--quick`: the basic method on a quarter of the rows, beside the whole (the model's test).
    basic_tile: Option<Run>,
    sg: Option<Run>,
    sgb: Option<Run>,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    measured: Vec<Measured>,
    size: u32,
    memory: String,
    cache: String,
    finished: bool,
    environment: serde_json::Value,
}

struct Setup {
    size: u32,
    memory: String,
    cache: String,
    spill: Option<String>,
    stores: PathBuf,
    segment: u64,
    deadline: Option<Instant>,
    fraction: u32,
    passes: Option<u64>,
    subspaces: Option<u64>,
    split_codec: Codec,
    view: View,
    methods: Methods,
}

/// The methods one invocation measures (`methods`).
#[derive(Clone, Copy)]
struct Methods {
    basic: bool,
    sg: bool,
    sgb: bool,
}

impl Methods {
    fn parse(id: &str, list: Option<Vec<String>>) -> Result<Methods> {
        let Some(list) = list else {
            return Ok(Methods { basic: true, sg: true, sgb: true });
        };
        let mut m = Methods { basic: false, sg: false, sgb: false };
        for item in &list {
            match item.as_str() {
                "basic" => m.basic = true,
                "sg" => m.sg = true,
                "sgb" => m.sgb = true,
                other => {
                    return Err(input(format!(
                        "{id}: methods '{other}': expected basic, sg or sgb (comma-separated)"
                    )))
                }
            }
        }
        Ok(m)
    }
}

/// Writes (or goes on writing) the store at `dir`; `None` when stopped by the deadline.
fn write_store(
    src: &crate::source::Source,
    dir: &Path,
    layout: Layout,
    codec: Codec,
    s: &Setup,
) -> Result<Option<StoreStep>> {
    let cannot = |e: std::io::Error| input(format!("{}: {e}", dir.display()));
    let mut w = if SegmentLog::read(dir).map_err(cannot)?.is_some() {
        SegmentedWriter::resume(dir, &src.label()).map_err(cannot)?
    } else {
        if dir.exists() {
            std::fs::remove_dir_all(dir).map_err(cannot)?;
        }
        SegmentedWriter::start(dir, &src.label(), layout, codec, s.segment).map_err(cannot)?
    };
    if let Some(d) = s.deadline {
        w = w.with_budget(d.saturating_duration_since(Instant::now()));
    }
    src.stream(&mut w)?;
    let log = w.log().clone();
    // The last segment ends at `finish`, not at a checkpoint: its time is taken here.
    let tail = Instant::now() - Duration::from_secs_f64(w.since_checkpoint());
    match w.finish().map_err(cannot)? {
        Outcome::Stopped => Ok(None),
        Outcome::Finished(_) => {
            let h = StoreHeader::read(dir).map_err(|e| input(e.to_string()))?;
            let logged = log.done.iter().fold(0.0, |a, d| a + d.seconds);
            Ok(Some(StoreStep {
                objects: h.objects,
                stored_bytes: h.disk_bytes(),
                seconds: logged + tail.elapsed().as_secs_f64(),
                segments: log.done.len() + usize::from(h.objects > log.state.objects),
            }))
        }
    }
}

/// One method's run on the store at `dir`; a whole image (not capped, no tile) is also written
/// to `image` when given, so that a row's picture outlives the process that traced it.
fn trace(
    dir: &Path,
    s: &Setup,
    view: Option<&View>,
    tile: Option<ShardSpec>,
    extra: &[(&str, &str)],
    image: Option<&Path>,
) -> Result<Run> {
    crate::measure::rss::reset_peak_rss();
    let load_average = super::grid_runs::load_average();
    let mut pairs: Vec<(String, String)> = vec![
        ("memory".into(), s.memory.clone()),
        ("verify".into(), "records".into()),
        ("cache".into(), s.cache.clone()),
        ("grid".into(), "two-level".into()),
        // Hours per run at 10^9 objects: a line per pass on stderr.
        ("progress".into(), "on".into()),
        // A grid build of hours goes on where a stopped invocation left it.
        ("hrgrid".into(), "resume".into()),
    ];
    if let Some(sp) = &s.spill {
        pairs.push(("spill".into(), sp.clone()));
    }
    pairs.extend(extra.iter().map(|(k, v)| (k.to_string(), v.to_string())));
    let config = BreadthFirstConfig::from_settings(Settings::new("breadth-first", pairs))?;
    let cpu0 = crate::measure::clock::process_cpu_seconds();
    let t = Instant::now();
    let engine = BreadthFirst::open(dir, config)?;
    let earlier_s = engine
        .build_stats()
        .get("hr_build_prior_s")
        .copied()
        .unwrap_or(0.0);
    let preprocess_s = earlier_s + t.elapsed().as_secs_f64();
    let stat = |k: &str| engine.build_stats().get(k).copied().unwrap_or(0.0);
    let (hr_build_s, subspaces, subspaces_total) = (
        stat("hr_build_s"),
        stat("hr_subspaces") as u64,
        stat("hr_subspaces_total") as u64,
    );
    let ooc = out_of_core::render_view(&engine, s.size, tile, view)
        .map_err(|e| input(format!("{}: out-of-core render: {e}", dir.display())))?;
    let r = &ooc.render;
    let rows_traced = match tile {
        Some(t) => tiles::rows(t, s.size).len() as u32,
        None => s.size + 1,
    };
    // A run the pass cap stopped has no image and no scale until a split run's passes are known.
    let capped = crate::workload::out_of_core::pass_capped(&r.counters);
    if let (Some(path), false, None) = (image, capped, tile) {
        if let Some(d) = path.parent() {
            std::fs::create_dir_all(d).map_err(|e| input(format!("{}: {e}", d.display())))?;
        }
        crate::output::write_png(path, r.pixels(), s.size)?;
    }
    Ok(Run {
        preprocess_s,
        trace_s: r.trace_s,
        passes: r.counters.extra.get("bf_passes").copied().unwrap_or(0),
        rays: r.stats.total,
        sha256: if capped {
            String::new()
        } else {
            hex(&Sha256::digest(r.pixels()))
        },
        peak_rss_bytes: crate::measure::rss::peak_rss_bytes().unwrap_or(0),
        rows_traced,
        scale: if capped {
            0.0
        } else {
            (s.size + 1) as f64 / rows_traced.max(1) as f64
        },
        load_average,
        capped,
        passes_total: 0,
        cpu_s: crate::measure::clock::process_cpu_seconds() - cpu0,
        earlier_s,
        intersect_s: r.intersect_s,
        shade_s: r.shade_s,
        shade_group: ooc.shade_group as u64,
        shade_sweeps: ooc.shade_sweeps,
        generation_rays: r.stats.generations.iter().map(|g| g.rays).collect(),
        sweeps_total: 0,
        passes_from: String::new(),
        hr_build_s,
        subspaces,
        subspaces_total,
        capacity: stat("rays_in_memory") as u64,
        stream_rays: r
            .stats
            .generations
            .iter()
            .flat_map(|g| [g.rays, g.shadow])
            .collect(),
    })
}

/// Objects whose box reaches into `view`, read from the split store's `bbox.bin`.
fn count_in_view(dir: &Path, view: &View, size: u32) -> Result<u64> {
    let h = StoreHeader::read(dir).map_err(|e| input(e.to_string()))?;
    let f = Frustum::new(view, size);
    let mut r = BboxReader::open(dir, h.objects, 1 << 20).map_err(|e| input(e.to_string()))?;
    let mut n = 0;
    while let Some((_, b)) = r.next_record().map_err(|e| input(e.to_string()))? {
        n += u64::from(f.sees(b.lo, b.hi));
    }
    Ok(n)
}

/// Whether the time budget (`max-seconds`) is spent: no further step starts.
fn past(s: &Setup) -> bool {
    s.deadline.is_some_and(|d| Instant::now() >= d)
}

/// The codec of both stores: the basic store is written with the split store's, so that the
/// three methods read alike and the ratios compare S, G and B, not codecs.
fn codec_tag(c: Codec) -> String {
    match c {
        Codec::None => "none".into(),
        Codec::Gzip(l) => format!("gzip{l}"),
        Codec::Zstd(l) => format!("zstd{l}"),
    }
}

fn row_key(m: &Measured, s: &Setup) -> String {
    format!(
        "{}-{}-{}-{}-{}",
        m.row,
        s.size,
        s.memory,
        s.cache,
        codec_tag(s.split_codec)
    )
}

fn store_dir(m: &Measured, s: &Setup, kind: &str) -> PathBuf {
    // The basic store's folder names its codec: one written with another codec is not resumed.
    let tag = if kind == "basic" {
        format!("-{}", codec_tag(s.split_codec))
    } else {
        String::new()
    };
    s.stores.join(format!("{}{}-{kind}{tag}", m.scene, m.sf))
}

/// Where a row's S+G+B image is kept between invocations (`.partial/nakamaru-4.3/images/`).
fn image_path(ctx: &Ctx, m: &Measured) -> PathBuf {
    ctx.checkpoint.dir().join("images").join(format!("{}.png", m.row))
}

/// The basic method's steps of one row: its store (gzip, in segments) and its run (whole, a
/// tile set or the first N passes). Returns whether they are done. The store is removed after
/// the last row that needs it (`keep_basic` false), before any split store of the scene is
/// written: the disk holds a 10^9-object scene's basic and split stores only one after the
/// other (rings368's ~47 GB and ~24 GB).
fn measure_basic(ctx: &Ctx, m: &mut Measured, s: &Setup, keep_basic: bool) -> Result<bool> {
    if m.basic.is_some() {
        return Ok(true);
    }
    if past(s) || !s.methods.basic {
        return Ok(false);
    }
    let src = super::grid_runs::resolve(&m.scene, m.sf)?;
    let save = |m: &Measured| ctx.checkpoint.save(&row_key(m, s), m);
    let view = (m.view == "m").then_some(&s.view);
    let dir = store_dir(m, s, "basic");
    forget_lost_store(&mut m.basic_store, &dir, &m.row);
    if m.basic_store.is_none() {
        eprintln!(
            "nakamaru-4.3: {}: basic store ({}, in segments) …",
            m.row,
            codec_tag(s.split_codec)
        );
        match write_store(&src, &dir, Layout::Basic, s.split_codec, s)? {
            Some(st) => m.basic_store = Some(st),
            None => return Ok(false),
        }
        save(m)?;
        // A budget spent on the store stops here, so that the next invocation starts the run.
        if past(s) {
            return Ok(false);
        }
    }
    eprintln!("nakamaru-4.3: {}: basic …", m.row);
    let basic_sets = [("layout", "basic")];
    let cap = s.passes.map(|n| n.to_string());
    let subspaces = s.subspaces.map(|k| k.to_string());
    let capped_sets: Option<Vec<(&str, &str)>> = cap.as_deref().map(|n| {
        let mut v = vec![("layout", "basic"), ("max_passes", n)];
        if let Some(k) = subspaces.as_deref() {
            // A partial grid is built afresh (never resumed or left behind).
            v.extend([("hrgrid", "build"), ("hrgrid_subspaces", k)]);
        }
        v
    });
    if ctx.quick {
        // The model's test: the part beside the whole.
        m.basic_tile = Some(match &capped_sets {
            Some(sets) => trace(&dir, s, view, None, sets, None)?,
            None => trace(&dir, s, view, Some(ShardSpec { k: 1, n: 4 }), &basic_sets, None)?,
        });
        m.basic = Some(trace(&dir, s, view, None, &basic_sets, None)?);
    } else if let Some(sets) = &capped_sets {
        let mut b = trace(&dir, s, view, None, sets, None)?;
        // Split runs measured before (`methods`): the model's totals from the first of them.
        if let Some((name, r)) = [("S+G+B", &m.sgb), ("S+G", &m.sg)]
            .into_iter()
            .find_map(|(n, r)| r.as_ref().map(|r| (n, r)))
        {
            complete_model(&mut b, r, name);
        }
        m.basic = Some(b);
    } else {
        let tile = (s.fraction > 1).then_some(ShardSpec {
            k: 1,
            n: s.fraction,
        });
        m.basic = Some(trace(&dir, s, view, tile, &basic_sets, None)?);
    }
    save(m)?;
    if !keep_basic {
        let _ = std::fs::remove_dir_all(&dir);
    }
    Ok(true)
}

/// A store a saved step names but the disk no longer holds (the steps were carried to another
/// machine, or the stores removed) is written again rather than traced and failed on.
fn forget_lost_store(step: &mut Option<StoreStep>, dir: &Path, row: &str) {
    if step.is_some() && StoreHeader::read(dir).is_err() {
        eprintln!(
            "nakamaru-4.3: {row}: the store saved steps name is not at {}; writing it again",
            dir.display()
        );
        *step = None;
    }
}

/// The split store (zstd blocks by default), S+G and S+G+B of one row; returns whether done.
fn measure_split(ctx: &Ctx, m: &mut Measured, s: &Setup) -> Result<bool> {
    let src = super::grid_runs::resolve(&m.scene, m.sf)?;
    let save = |m: &Measured| ctx.checkpoint.save(&row_key(m, s), m);
    let view = (m.view == "m").then_some(&s.view);
    let mut done = true;
    // S+G+B first: it is the method Table 4.3 compares with the basic one (S+G at 10^9 objects
    // takes hours, S+G+B minutes), so a budget spent between the two leaves that row measured.
    for (name, sets) in [
        ("S+G+B", &[("layout", "split"), ("hierarchy", "on")][..]),
        ("S+G", &[("layout", "split")][..]),
    ] {
        let (slot, wanted) = if name == "S+G" {
            (&m.sg, s.methods.sg)
        } else {
            (&m.sgb, s.methods.sgb)
        };
        if slot.is_some() {
            continue;
        }
        if !wanted {
            done = false;
            continue;
        }
        if past(s) {
            return Ok(false);
        }
        let dir = store_dir(m, s, "split");
        forget_lost_store(&mut m.split_store, &dir, &m.row);
        if m.split_store.is_none() {
            eprintln!("nakamaru-4.3: {}: split store (in segments) …", m.row);
            match write_store(&src, &dir, Layout::Split, s.split_codec, s)? {
                Some(st) => m.split_store = Some(st),
                None => return Ok(false),
            }
            m.objects = m.split_store.as_ref().map_or(0, |st| st.objects);
            save(m)?;
            if past(s) {
                return Ok(false);
            }
        }
        if view.is_some() && m.objects_in_view.is_none() {
            m.objects_in_view = Some(count_in_view(&dir, &s.view, s.size)?);
            save(m)?;
        }
        eprintln!("nakamaru-4.3: {}: {name} …", m.row);
        // The row's image (docs/images): S+G+B's, the same as S+G's when the images agree.
        let png = image_path(ctx, m);
        let r = trace(&dir, s, view, None, sets, (name == "S+G+B").then_some(png.as_path()))?;
        // The pass model's total: the passes of the first split run measured (the same grid,
        // rays and memory budget; S+G and S+G+B made the same passes on every row so far).
        for b in [m.basic.as_mut(), m.basic_tile.as_mut()].into_iter().flatten() {
            complete_model(b, &r, name);
        }
        if name == "S+G" {
            m.sg = Some(r);
        } else {
            m.sgb = Some(r);
        }
        save(m)?;
    }
    Ok(done)
}

/// A capped basic run's model totals, from a split run of the same row (the same grid, rays and
/// memory budget: S+G and S+G+B made the same passes on every row so far): its pass count and
/// the whole run's shading sweeps. Left alone once set, or when the run is not capped.
///
/// Where both runs kept their rays a pass and the split run's streams account for its passes,
/// the passes are the split run's streams at the basic run's rays a pass: the methods hold different numbers of rays (at rings368 the
/// basic method 41,213, S+G+B 36,816, whose hierarchy takes part of the budget), so the split
/// run's own pass count would be another run's.
fn complete_model(b: &mut Run, r: &Run, name: &str) {
    if !(b.capped && b.passes > 0) {
        return;
    }
    // Only where the split run's own passes are its streams at its own rays a pass (a pass
    // that does not finish its rays, or a stream a pass cannot hold, would break the count).
    let streams = b.capacity > 0
        && r.capacity > 0
        && !r.stream_rays.is_empty()
        && Run::passes_at(&r.stream_rays, r.capacity) == r.passes;
    if b.passes_total == 0 || (streams && !b.passes_from.contains("streams")) {
        b.passes_total = if streams {
            Run::passes_at(&r.stream_rays, b.capacity)
        } else {
            r.passes
        };
        b.passes_from = if streams {
            format!("{name}'s streams at the basic run's {} rays a pass", b.capacity)
        } else {
            name.to_string()
        };
        b.scale = b.passes_total as f64 / b.passes as f64;
        b.sweeps_total = sweeps(&r.generation_rays, b.shade_group);
    }
}

/// A scene's rows share its stores: row `i` takes the `kind` store step of an earlier row of
/// its scene (`before`) when that store is still on disk, rather than streaming the scene's
/// 10^9 objects through the generator again only to find every segment written.
fn share_store(measured: &mut [Measured], before: &[usize], i: usize, s: &Setup, kind: &str) {
    let pick = |m: &Measured| {
        if kind == "basic" {
            m.basic_store.clone()
        } else {
            m.split_store.clone()
        }
    };
    if pick(&measured[i]).is_some() {
        return;
    }
    let Some(st) = before.iter().find_map(|&j| pick(&measured[j])) else {
        return;
    };
    if StoreHeader::read(&store_dir(&measured[i], s, kind)).is_err() {
        return;
    }
    let m = &mut measured[i];
    if kind == "basic" {
        m.basic_store = Some(st);
    } else {
        m.objects = st.objects;
        m.split_store = Some(st);
    }
}

/// The rows' steps in the order the disk allows: scene by scene (a scene's rows share its
/// stores), first every row's basic steps, the basic store removed after the last of them,
/// then every row's split steps. Returns whether all rows are done.
fn measure_rows(ctx: &Ctx, measured: &mut [Measured], s: &Setup) -> Result<bool> {
    let base = |m: &Measured| format!("{}{}", m.scene, m.sf);
    let mut scenes: Vec<String> = Vec::new();
    for m in measured.iter() {
        if !scenes.contains(&base(m)) {
            scenes.push(base(m));
        }
    }
    // A step left out by `methods` leaves its row unfinished, but the other steps go on; the
    // time budget stops everything.
    let mut all = true;
    for scene in &scenes {
        let group: Vec<usize> = (0..measured.len())
            .filter(|&i| base(&measured[i]) == *scene)
            .collect();
        for (k, &i) in group.iter().enumerate() {
            let keep_basic = group[k + 1..].iter().any(|&j| measured[j].basic.is_none());
            share_store(measured, &group[..k], i, s, "basic");
            if !measure_basic(ctx, &mut measured[i], s, keep_basic)? {
                if past(s) || s.methods.basic {
                    return Ok(false);
                }
                all = false;
            }
        }
        for (k, &i) in group.iter().enumerate() {
            share_store(measured, &group[..k], i, s, "split");
            if !measure_split(ctx, &mut measured[i], s)? {
                if past(s) {
                    return Ok(false);
                }
                all = false;
            }
        }
    }
    Ok(all)
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let size = ctx
        .params
        .number::<u32>(SIZE.key, 1)?
        .unwrap_or(if ctx.quick { 64 } else { 512 });
    workload::check_size(size)?;
    let fraction = ctx.params.number::<u32>(FRACTION.key, 1)?.unwrap_or(1);
    let passes = ctx.params.number::<u64>(PASSES.key, 1)?;
    let subspaces = ctx.params.number::<u64>(SUBSPACES.key, 1)?;
    if subspaces.is_some() && passes.is_none() {
        return Err(input(
            "nakamaru-4.3: basic-subspaces needs basic-passes: a partial grid's answers are not the scene's, so its run is a capped model",
        ));
    }
    if passes.is_some() && fraction > 1 {
        return Err(input(
            "nakamaru-4.3: basic-passes and basic-fraction are two models of one run: give one",
        ));
    }
    let split_codec = match ctx.params.raw(SPLIT_COMPRESS.key).unwrap_or("zstd") {
        c if c.starts_with("gzip") => {
            return Err(input(format!(
                "nakamaru-4.3: split-compress={c}: a split store is compressed as zstd blocks (zstd, zstd:LEVEL) or not at all (none)"
            )))
        }
        c => crate::workload::out_of_core::parse_codec(c)
            .map_err(|e| input(format!("nakamaru-4.3: split-compress={c}: {e}")))?,
    };
    let max_seconds = ctx.params.number::<f64>(MAX_SECONDS.key, 0.0)?;
    // A budget longer than an Instant reaches (1e308, inf) is no deadline.
    let deadline = max_seconds
        .and_then(|x| Duration::try_from_secs_f64(x).ok())
        .and_then(|d| Instant::now().checked_add(d));
    let segment = ctx
        .params
        .number::<u64>(SEGMENT.key, 1)?
        .unwrap_or(if ctx.quick { 1000 } else { 1 << 24 });
    let view = ViewFile::parse(VIEW, "data/views/rings368m.json")?.view;
    let out_stores = ctx
        .params
        .raw(STORES.key)
        .map(PathBuf::from)
        .unwrap_or_else(|| ctx.checkpoint.dir().join("stores"));
    let s = Setup {
        size,
        memory: ctx.params.bytes(MEMORY.key, "256MiB")?,
        cache: ctx.params.raw(CACHE.key).unwrap_or("cold").to_string(),
        spill: ctx.params.raw(SPILL.key).map(str::to_string),
        stores: out_stores,
        segment,
        deadline,
        fraction,
        passes,
        subspaces,
        split_codec,
        view,
        methods: Methods::parse(ctx.id, ctx.params.list(METHODS.key)?)?,
    };
    let names: Vec<String> = match ctx.params.list(ROWS.key)? {
        Some(l) => l,
        None if ctx.quick => vec!["mount6".into(), "rings6".into(), "rings6m".into()],
        None => p
            .rows
            .iter()
            .map(|r| format!("{}{}{}", r.scene, r.sf, r.view))
            .collect(),
    };
    let mut measured = Vec::new();
    for name in &names {
        let view = if name.ends_with('m') && name.starts_with("rings") {
            "m"
        } else {
            ""
        };
        let base = name.strip_suffix(view).unwrap_or(name);
        let rows = super::grid_runs::parse_rows(ctx.id, &[base.to_string()], &["mount", "rings"])?;
        let (scene, sf) = rows[0].clone();
        let mut m = Measured {
            row: name.clone(),
            scene,
            sf,
            view: view.to_string(),
            ..Default::default()
        };
        if let Some(saved) = ctx.checkpoint.load::<Measured>(&row_key(&m, &s))? {
            m = saved;
        }
        measured.push(m);
    }
    let finished = measure_rows(ctx, &mut measured, &s)?;
    if finished {
        // Stores no row still needs.
        let _ = std::fs::remove_dir_all(&s.stores);
    }
    let points = size_points(&measured);
    let mut rows = rows(&p, &measured, &s);
    rows.extend(growth_rows(&points, size, &ThesisSgb::new(&p)));
    let mut doc = document(&p, &measured, &s, ctx.quick, finished);
    per_ray::table(&mut doc, &points, size);
    let mut images = Vec::new();
    for m in &measured {
        let png = image_path(ctx, m);
        if m.sgb.is_none() || !png.exists() {
            continue;
        }
        let img = image::open(&png)
            .map_err(|e| input(format!("{}: {e}", png.display())))?
            .to_rgb8();
        images.push(super::Image {
            path: format!("images/{}-{}.png", ctx.id, m.row),
            size: img.width(),
            pixels: img.into_raw(),
        });
    }
    let mut out = Output::new(
        Result_ {
            id: ctx.id,
            published: raw,
            measured,
            size,
            memory: s.memory.clone(),
            cache: s.cache.clone(),
            finished,
            environment: environment(1),
        },
        rows,
        doc,
    );
    out.charts = per_ray::charts(ctx.id, &points, size);
    out.images = images;
    Ok(out)
}

/// The rows with S+G+B measured, as points of the time-per-ray benchmark, each method's seconds
/// NaN where it is not measured yet (a 10^9-object row is measured one method an invocation); the
/// rings368m view is a series of its own ("rings-view-m"): other eye rays.
fn size_points(measured: &[Measured]) -> Vec<SizePoint> {
    let nan = f64::NAN;
    measured
        .iter()
        .filter_map(|m| {
            let sgb = m.sgb.as_ref()?;
            let b = m.basic.as_ref().filter(|b| b.scale > 0.0);
            let sg = m.sg.as_ref();
            Some(SizePoint {
                scene: series_name(m),
                sf: m.sf,
                objects: m.objects,
                seconds: [
                    b.map_or(nan, |r| r.total_s()),
                    sg.map_or(nan, |r| r.total_s()),
                    sgb.total_s(),
                ],
                peak_rss: [
                    b.map_or(0, |r| r.peak_rss_bytes),
                    sg.map_or(0, |r| r.peak_rss_bytes),
                    sgb.peak_rss_bytes,
                ],
            })
        })
        .collect()
}

fn series_name(m: &Measured) -> String {
    if m.view == "m" {
        format!("{}-view-m", m.scene)
    } else {
        m.scene.clone()
    }
}

/// The thesis's own S+G+B seconds of a row (basic time ÷ S+G+B ratio) from Table 4.3, or from
/// Table 4.1 for the rows near 10^6 objects the growth starts from (the same SPD workload at
/// 512², the same machine and budget).
struct ThesisSgb {
    t43: Vec<PublishedRow>,
    t41: Vec<Published41Row>,
}

#[derive(Deserialize)]
struct Published41 {
    rows: Vec<Published41Row>,
}

#[derive(Deserialize)]
struct Published41Row {
    scene: String,
    sf: u32,
    basic_s: u64,
    sgb: f64,
}

impl ThesisSgb {
    fn new(p: &Published) -> ThesisSgb {
        let (t41, _): (Published41, _) = published::load("nakamaru-4.1", PUBLISHED_41);
        ThesisSgb {
            t43: p.rows.clone(),
            t41: t41.rows,
        }
    }

    /// `series` as [`series_name`] writes it.
    fn seconds(&self, series: &str, sf: u32) -> Option<(f64, &'static str)> {
        let (scene, view) = match series.strip_suffix("-view-m") {
            Some(s) => (s, "m"),
            None => (series, ""),
        };
        if let Some(r) = self
            .t43
            .iter()
            .find(|r| r.scene == scene && r.sf == sf && r.view == view)
        {
            return Some((r.basic_s as f64 / r.sgb, "Table 4.3"));
        }
        if view.is_empty() {
            if let Some(r) = self.t41.iter().find(|r| r.scene == scene && r.sf == sf) {
                return Some((r.basic_s as f64 / r.sgb, "Table 4.1"));
            }
        }
        None
    }
}

/// Our goal per scene (not the thesis's): S+G+B's time per eye ray from the point nearest 10^6 objects to
/// the largest, judged when those are within 3× of 10^6 and at least 5·10^8. Beside it, where
/// the thesis has both rows, the thesis's own growth between them, and ours judged against it
/// (within 2× either way): the goal asks for less growth than the thesis's own tables show.
/// Our S+G+B growth per eye ray between two rows, against the thesis's own between the same rows
/// (Tables 4.1 and 4.3 give about 38× for mount10 → mount14 and 42× for rings36 → rings368): within
/// 2× either way. Growing less than 2× is a goal of ours (docs/benchmarks.md), not the thesis's claim.
fn within_thesis_growth(ours: f64, thesis: f64) -> bool {
    ours <= 2.0 * thesis && ours >= thesis / 2.0
}

fn growth_rows(points: &[SizePoint], size: u32, thesis: &ThesisSgb) -> Vec<Row> {
    let mut scenes: Vec<&str> = points.iter().map(|p| p.scene.as_str()).collect();
    scenes.sort();
    scenes.dedup();
    let mut rows = Vec::new();
    for scene in scenes {
        let ps: Vec<&SizePoint> = points
            .iter()
            .filter(|p| p.scene == scene && p.seconds[2].is_finite())
            .collect();
        let near = |p: &&SizePoint| ((p.objects.max(1) as f64).log10() - 6.0).abs();
        let (Some(a), Some(b)) = (
            ps.iter().min_by(|x, y| near(x).total_cmp(&near(y))).copied(),
            ps.iter().max_by_key(|p| p.objects).copied(),
        ) else {
            continue;
        };
        if a.objects >= b.objects {
            continue;
        }
        let per = |p: &SizePoint| per_ray::per_eye_ray(p.seconds[2], size);
        let g = per(b) / per(a).max(1e-12);
        let ours = format!(
            "S+G+B {:.1} µs → {:.1} µs per eye ray, {} → {} objects: {g:.2}×",
            1e6 * per(a),
            1e6 * per(b),
            a.objects,
            b.objects
        );
        if let (Some((ta, sa)), Some((tb, sb))) =
            (thesis.seconds(scene, a.sf), thesis.seconds(scene, b.sf))
        {
            let gt = tb / ta;
            rows.push(Row::new(
                "per-ray-growth-thesis",
                scene.to_string(),
                format!(
                    "the thesis's S+G+B {:.0} s ({sa}, SF {}) → {:.0} s ({sb}, SF {}): {gt:.2}×",
                    ta, a.sf, tb, b.sf
                ),
                ours,
                Kind::Ratio,
                Verdict::of(within_thesis_growth(g, gt)),
            ));
        }
    }
    rows
}

fn ratio(a: f64, b: f64) -> f64 {
    a / b.max(1e-9)
}

/// The extrapolation of a basic run, written out.
fn model_text(r: &Run) -> String {
    if r.capped {
        return if r.passes_total == 0 {
            format!(
                "{} + trace {:.1} s (first {} passes) × (the split runs' passes, not yet measured)",
                r.pre_text(), r.trace_s, r.passes
            )
        } else if let Some((passes_s, shade_s, other_s)) = r.split_model() {
            format!(
                "{} + passes {:.1} s (first {}) × {} / {} ({}) + shading {:.1} s ({} sweeps of the store) × {} / {} (the whole run's groups of {} rays) + other {:.1} s = {:.1} s (passes {:.1} s, shading {:.1} s)",
                r.pre_text(),
                r.intersect_s,
                r.passes,
                r.passes_total,
                r.passes,
                r.passes_from(),
                r.shade_s,
                r.shade_sweeps,
                r.sweeps_total,
                r.shade_sweeps,
                r.shade_group,
                other_s,
                r.total_s(),
                passes_s,
                shade_s,
            )
        } else {
            format!(
                "{} + trace {:.1} s (first {} passes) × {} / {} ({}) = {:.1} s",
                r.pre_text(),
                r.trace_s,
                r.passes,
                r.passes_total,
                r.passes,
                r.passes_from(),
                r.total_s()
            )
        };
    }
    if r.scale == 1.0 {
        format!("{:.1} s measured", r.total_s())
    } else {
        format!(
            "{} + trace {:.1} s × {:.2} ({} of the rows traced) = {:.1} s",
            r.pre_text(),
            r.trace_s,
            r.scale,
            r.rows_traced,
            r.total_s()
        )
    }
}

fn rows(p: &Published, measured: &[Measured], s: &Setup) -> Vec<Row> {
    let mut rows = Vec::new();
    for m in measured {
        let pubrow = p
            .rows
            .iter()
            .find(|r| r.scene == m.scene && r.sf == m.sf && r.view == m.view);
        let note = if pubrow.is_some() {
            String::new()
        } else {
            format!("{}: a smaller stand-in, not a row of the table", m.row)
        };
        let first = rows.len();
        let shown = |f: fn(&PublishedRow) -> f64| pubrow.map_or("-".into(), |r| format!("{:.2}", f(r)));
        // Each claim as soon as the runs it compares are saved: a 10^9-object row is measured
        // one method an invocation (`methods`).
        if let Some(b) = &m.basic {
            let model = b.is_model();
            let tag = if model { " (basic: model)" } else { "" };
            for (claim, x, f) in [
                ("sg-ratio", &m.sg, (|r: &PublishedRow| r.sg) as fn(&PublishedRow) -> f64),
                ("sgb-ratio", &m.sgb, |r: &PublishedRow| r.sgb),
            ] {
                let Some(x) = x else { continue };
                let v = ratio(b.total_s(), x.total_s());
                let verdict = if claim == "sgb-ratio" && pubrow.is_some() {
                    let [lo, hi] = p.improvement_range;
                    Verdict::of((lo..=hi).contains(&v))
                } else {
                    Verdict::Shown
                };
                rows.push(
                    Row::new(
                        claim,
                        m.row.clone(),
                        if claim == "sgb-ratio" {
                            format!("{} (text: 5–14)", shown(f))
                        } else {
                            shown(f)
                        },
                        format!("{:.1} s / {:.1} s = {v:.2}{tag}", b.total_s(), x.total_s()),
                        Kind::Ratio,
                        verdict,
                    )
                    .with_note(note.clone()),
                );
                if model {
                    // A ratio over an extrapolated basic time is a model's figure, not a measurement.
                    let r = rows.pop().expect("just pushed");
                    let why = if note.is_empty() {
                        "the basic time is extrapolated (basic-model row)".to_string()
                    } else {
                        format!("the basic time is extrapolated (basic-model row); {note}")
                    };
                    rows.push(r.with_fidelity(Fidelity::Model, why));
                }
            }
            rows.push(
                Row::new(
                    "basic-model",
                    m.row.clone(),
                    pubrow.map_or("-".into(), |r| format!("{} s", r.basic_s)),
                    model_text(b),
                    Kind::Ratio,
                    Verdict::Shown,
                )
                .with_note(note.clone()),
            );
        }
        if let (Some(b), Some(sg), Some(sgb)) = (&m.basic, &m.sg, &m.sgb) {
            let model = b.is_model();
            let same = sg.sha256 == sgb.sha256 && (model || b.sha256 == sg.sha256);
            rows.push(
                Row::new(
                    "image-equal",
                    m.row.clone(),
                    "equal",
                    format!(
                        "{}{} / {} / {}",
                        if model { "(basic: a model, not compared) " } else { "" },
                        crate::output::head(&b.sha256, 12),
                        crate::output::head(&sg.sha256, 12),
                        crate::output::head(&sgb.sha256, 12)
                    ),
                    Kind::Count,
                    Verdict::of(same),
                )
                .with_note(note.clone()),
            );
        }
        let runs: Vec<(&str, &Run)> = [("basic", &m.basic), ("S+G", &m.sg), ("S+G+B", &m.sgb)]
            .into_iter()
            .filter_map(|(n, r)| r.as_ref().map(|r| (n, r)))
            .collect();
        if !runs.is_empty() {
            let peak = runs.iter().map(|(_, r)| r.peak_rss_bytes).max().unwrap_or(0);
            let of = if runs.len() < 3 {
                format!(
                    " ({} only)",
                    runs.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
                )
            } else {
                String::new()
            };
            rows.push(
                Row::new(
                    "memory",
                    m.row.clone(),
                    "256 MB machine; bound 320 MiB",
                    format!("{}{of}", super::params::peak_rss_text(peak)),
                    Kind::Ordering,
                    Verdict::of(peak <= 320 << 20),
                )
                .with_note(note.clone()),
            );
        }
        if let (Some(tile), Some(whole)) = (&m.basic_tile, &m.basic) {
            // The model against the measurement it stands in for (`--quick`).
            let e = ratio(tile.total_s(), whole.total_s());
            let (what, passes) = if tile.capped {
                (
                    format!("{}: the first {} passes against the whole", m.row, tile.passes),
                    format!(
                        " (passes: basic {}, S+G {})",
                        whole.passes,
                        m.sg.as_ref().map_or("-".into(), |r| r.passes.to_string())
                    ),
                )
            } else {
                (format!("{}: a quarter of the rows against the whole", m.row), String::new())
            };
            rows.push(
                Row::new(
                    "basic-model",
                    what,
                    "within 25% of the measured time",
                    format!("{} against {:.1} s measured: {e:.2}{passes}", model_text(tile), whole.total_s()),
                    Kind::Ratio,
                    Verdict::of((0.75..=1.25).contains(&e)),
                )
                .with_note(note.clone()),
            );
        }
        if m.view == "m" {
            let measured = match m.objects_in_view {
                Some(n) => format!(
                    "{n} of {} ({:.3}%)",
                    m.objects,
                    100.0 * n as f64 / m.objects.max(1) as f64
                ),
                None => "not counted yet".into(),
            };
            rows.push(
                Row::new(
                    "view",
                    m.row.clone(),
                    "about 1,000,000 of 10^9 (0.1%)",
                    measured,
                    Kind::Ratio,
                    match m.objects_in_view {
                        Some(n) => {
                            let f = n as f64 / m.objects.max(1) as f64;
                            Verdict::of(pubrow.is_none() || (0.0005..=0.002).contains(&f))
                        }
                        None => Verdict::NotMeasured,
                    },
                )
                .with_note(if pubrow.is_none() {
                    format!("{}: at this size the view's share is not the thesis's; shown only", m.row)
                } else {
                    String::new()
                }),
            );
        }
        if m.sgb.is_none() || m.basic.is_none() {
            rows.push(Row::new(
                "sgb-ratio",
                m.row.clone(),
                shown(|r| r.sgb),
                format!("steps still to run at {}×{}", s.size, s.size),
                Kind::Ratio,
                Verdict::NotMeasured,
            ));
        }
        if pubrow.is_none() {
            // A stand-in scene's rows are substituted whatever their claim's label (a model's
            // row stays a model: the writer keeps the lower label).
            for r in &mut rows[first..] {
                r.fidelity.get_or_insert(Fidelity::Substituted);
            }
        }
    }
    rows
}

fn document(p: &Published, measured: &[Measured], s: &Setup, quick: bool, finished: bool) -> Document {
    let mut doc = Document::new("nakamaru-4.3: massive data, basic method vs S+G and S+G+B");
    doc.paragraph(format!(
        "Published: {}. Measured: `rtbench reproduce nakamaru-4.3{}`, {}×{}, engine memory {}, cache {}, high-resolution grid for every method (as the thesis), both stores {} (the basic store in segments of {} objects, the split store in blocks).{}",
        p.source.cite(),
        if quick { " --quick" } else { "" },
        s.size,
        s.size,
        s.memory,
        s.cache,
        match s.split_codec {
            Codec::Zstd(l) => format!("zstd level {l}"),
            Codec::Gzip(l) => format!("gzip level {l}"),
            Codec::None => "uncompressed".into(),
        },
        s.segment,
        if finished { "" } else { " **Partial: stopped at a checkpoint; run again with --resume.**" }
    ));
    let mut t = DocTable::new(
        "",
        &[
            "row", "objects", "in view", "basic store MB / s", "split store MB / s", "basic s (pre + trace)",
            "S+G", "S+G+B", "thesis S+G", "thesis S+G+B", "passes", "peak RSS MiB",
        ],
    );
    let secs = |r: &Option<Run>| r.as_ref().map_or("-".into(), |r| format!("{:.1}", r.total_s()));
    for m in measured {
        let pubrow = p
            .rows
            .iter()
            .find(|r| r.scene == m.scene && r.sf == m.sf && r.view == m.view);
        let st = |x: &Option<StoreStep>| {
            x.as_ref()
                .map_or("-".into(), |x| format!("{:.1} / {:.1}", x.stored_bytes as f64 / 1e6, x.seconds))
        };
        let r = |x: &Option<Run>| match (&m.basic, x) {
            (Some(b), Some(x)) => format!("{:.2}", ratio(b.total_s(), x.total_s())),
            _ => "-".into(),
        };
        let runs = [&m.basic, &m.sg, &m.sgb];
        t.push(vec![
            m.row.clone(),
            m.objects.to_string(),
            m.objects_in_view.map_or("-".into(), |n| n.to_string()),
            st(&m.basic_store),
            st(&m.split_store),
            match &m.basic {
                Some(b) if b.is_model() => format!("{} (model)", secs(&m.basic)),
                _ => secs(&m.basic),
            },
            r(&m.sg),
            r(&m.sgb),
            pubrow.map_or("-".into(), |r| format!("{:.2}", r.sg)),
            pubrow.map_or("-".into(), |r| format!("{:.2}", r.sgb)),
            runs.iter()
                .map(|r| r.as_ref().map_or("-".into(), |r| r.passes.to_string()))
                .collect::<Vec<_>>()
                .join("/"),
            format!(
                "{:.1}",
                runs.iter()
                    .filter_map(|r| r.as_ref().map(|r| r.peak_rss_bytes))
                    .max()
                    .unwrap_or(0) as f64
                    / 1048576.0
            ),
        ]);
    }
    doc.table(t);
    let mut split = DocTable::new(
        "Preprocessing and tracing (Table 4.4's split), seconds; basic tracing extrapolated where marked",
        &["row", "method", "preprocess s", "trace s", "rows traced", "scale", "rays", "image sha256", "CPU / wall", "load avg"],
    );
    for m in measured {
        for (name, r) in [("basic", &m.basic), ("basic ¼ (quick)", &m.basic_tile), ("S+G", &m.sg), ("S+G+B", &m.sgb)] {
            if let Some(r) = r {
                split.push(vec![
                    m.row.clone(),
                    name.into(),
                    if r.partial_grid() {
                        format!(
                            "{:.2} ({} of the grid's {} subspaces; extrapolated {:.2})",
                            r.preprocess_s,
                            r.subspaces,
                            r.subspaces_total,
                            r.pre_s()
                        )
                    } else if r.earlier_s >= 0.005 {
                        format!(
                            "{:.2} (of which {:.2} by earlier, stopped invocations)",
                            r.preprocess_s, r.earlier_s
                        )
                    } else {
                        format!("{:.2}", r.preprocess_s)
                    },
                    format!("{:.2}", r.trace_s),
                    format!("{} of {}", r.rows_traced, s.size + 1),
                    format!("{:.2}", r.scale),
                    r.rays.to_string(),
                    format!("{}…", crate::output::head(&r.sha256, 12)),
                    // A run that waited for a core or for the disk shows well under 100%.
                    super::grid_runs::cpu_share(r.cpu_s, r.preprocess_s - r.earlier_s + r.trace_s),
                    r.load_average.clone(),
                ]);
            }
        }
    }
    doc.table(split);
    doc
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(scene: &str, sf: u32, objects: u64, sgb_s: f64) -> SizePoint {
        SizePoint {
            scene: scene.into(),
            sf,
            objects,
            seconds: [10.0 * sgb_s, 2.0 * sgb_s, sgb_s],
            peak_rss: [0; 3],
        }
    }

    /// Our growth per eye ray is put beside the thesis's own between the same rows (Tables 4.1 and
    /// 4.3) and judged within 2× of it; the thesis's growth fed through the check holds.
    #[test]
    fn the_per_ray_growth_is_judged_against_the_thesis_growth() {
        let (p, _): (Published, _) = published::load("nakamaru-4.3", PUBLISHED);
        let thesis = ThesisSgb::new(&p);
        let mut pts = [
            point("mount", 8, 131_076, 1.0),
            point("mount", 10, 2_097_156, 10.0),
            point("mount", 14, 536_870_916, 25.0),
            point("rings", 36, 972_361, 10.0),
            point("rings", 368, 1_000_787_041, 19.0),
            point("tetra", 10, 1_048_576, 1.0),
            point("tetra", 12, 16_777_216, 1.5),
        ];
        // rings368 with S+G+B only: still judged.
        pts[4].seconds[0] = f64::NAN;
        pts[4].seconds[1] = f64::NAN;
        let rows = growth_rows(&pts, 1, &thesis);
        let v: Vec<(&str, String, Verdict)> = rows
            .iter()
            .map(|r| (r.claim, r.subject.clone(), r.verdict))
            .collect();
        assert_eq!(v.len(), 3, "{v:?}");
        assert!(v.iter().all(|r| r.0 == "per-ray-growth-thesis"));
        // mount: 2,097,156 is the row nearest 10^6. The thesis: mount10 641 s / 1.86, mount14
        // 69,975 s / 5.33: 38.10×; ours 25 / 10 = 2.5× is more than 2× below it.
        assert_eq!(v[0], ("per-ray-growth-thesis", "mount".into(), Verdict::Fails));
        assert!(rows[0].published.contains("38.10×"), "{}", rows[0].published);
        assert!(rows[0].published.contains("Table 4.1, SF 10"), "{}", rows[0].published);
        assert!(rows[0].measured.contains("2.50×"), "{}", rows[0].measured);
        // rings36 → rings368: the thesis's about 42×.
        assert!(rows[1].published.contains("42."), "{}", rows[1].published);
        // Ours at the thesis's own growth holds: the check on the thesis's numbers.
        pts[2].seconds[2] = 10.0 * 38.10;
        let rows = growth_rows(&pts, 1, &thesis);
        assert_eq!(rows[0].verdict, Verdict::Holds);
        for gt in [38.10, 42.0, 1.5] {
            assert!(within_thesis_growth(gt, gt));
        }
    }

    /// Table 4.3's S+G+B column fed through the text's 5–14× band.
    #[test]
    fn the_improvement_band_holds_on_table_4_3() {
        let (p, _): (Published, _) = published::load("nakamaru-4.3", PUBLISHED);
        let [lo, hi] = p.improvement_range;
        assert_eq!(p.rows.len(), 3);
        assert!(p.rows.iter().all(|r| (lo..=hi).contains(&r.sgb)));
    }

    /// A capped basic run is extrapolated part by part: passes by a split run's pass count, shading by
    /// the whole run's sweeps (one per group of each S+G generation), the rest as measured; a
    /// row saved without the split keeps the old model (all of the trace by the passes).
    #[test]
    fn a_capped_basic_run_scales_its_passes_by_passes_and_its_shading_by_sweeps() {
        let mut b = Run {
            preprocess_s: 100.0,
            trace_s: 70.0,
            passes: 2,
            capped: true,
            passes_total: 10,
            scale: 5.0,
            intersect_s: 40.0,
            shade_s: 20.0,
            shade_group: 100,
            shade_sweeps: 2,
            ..Default::default()
        };
        // 250 rays in generation 1 (3 groups), 100 in 2 (1), 1 in 3 (1): 5 sweeps.
        b.sweeps_total = sweeps(&[250, 100, 1], b.shade_group);
        assert_eq!(b.sweeps_total, 5);
        let (passes_s, shade_s, other_s) = b.split_model().unwrap();
        assert_eq!((passes_s, shade_s, other_s), (200.0, 50.0, 10.0));
        assert_eq!(b.total_s(), 360.0);
        assert!(model_text(&b).contains("× 5 / 2 (the whole run's groups of 100 rays)"), "{}", model_text(&b));
        // Saved before the split was kept: the trace by the passes, 100 + 70 × 5.
        let old = Run {
            intersect_s: 0.0,
            shade_s: 0.0,
            shade_sweeps: 0,
            sweeps_total: 0,
            ..b.clone()
        };
        assert!(old.split_model().is_none());
        assert_eq!(old.total_s(), 450.0);
        // The grid built over 2 of its 27 subspaces (`basic-subspaces=2`): its 80 s of build
        // × 27 / 2, the other 20 s of preprocessing as measured.
        let partial = Run {
            hr_build_s: 80.0,
            subspaces: 2,
            subspaces_total: 27,
            ..b.clone()
        };
        assert_eq!(partial.pre_s(), 100.0 + 80.0 * 12.5);
        assert_eq!(partial.total_s(), 1100.0 + 260.0);
        let text = model_text(&partial);
        assert!(text.starts_with("pre 100.0 s, of which the grid's build 80.0 s over 2 of its 27 subspaces, × 27 / 2 = 1100.0 s + passes"), "{text}");
        // The split run's streams at the basic run's rays a pass: 250, 100, 0 and 1 rays at 40
        // a pass are 7 + 3 + 0 + 1 passes, where the split run (at 50 a pass) made 5 + 2 + 1.
        let split = Run {
            passes: 8,
            capacity: 50,
            stream_rays: vec![250, 100, 0, 1],
            generation_rays: vec![250, 1],
            ..Default::default()
        };
        assert_eq!(Run::passes_at(&split.stream_rays, split.capacity), split.passes);
        let mut c = Run {
            capacity: 40,
            passes_total: 0,
            sweeps_total: 0,
            ..b.clone()
        };
        complete_model(&mut c, &split, "S+G+B");
        assert_eq!((c.passes_total, c.sweeps_total), (11, 4));
        assert!(model_text(&c).contains("× 11 / 2 (S+G+B's streams at the basic run's 40 rays a pass)"), "{}", model_text(&c));
        // A basic run saved without its rays a pass takes the split run's passes, and keeps them.
        let mut d = Run { capacity: 0, passes_total: 0, ..b.clone() };
        complete_model(&mut d, &split, "S+G+B");
        assert_eq!(d.passes_total, 8);
        assert!(model_text(&d).contains("(S+G+B's passes)"), "{}", model_text(&d));
        // A whole build is no model.
        let whole = Run {
            subspaces: 27,
            ..partial.clone()
        };
        assert_eq!(whole.pre_s(), 100.0);
    }
}
