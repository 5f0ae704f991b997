//! `nakamaru-fig4.4`: seed 000's Figures 4.4–4.7, the effect of the high-resolution grid of §4.3:
//! time against scene size for a single-level grid capped at 128 cells per axis (the thesis's
//! "-l" curves) and for the high-resolution grid (Klimaszewski's resolution, uncapped, through
//! the rule R_u = 256, R_l = 4: on disk, made subspace by subspace, read block by block, rays in
//! the two-level grid), every other improvement on (S+G+B).
//!
//! The figures' points were lost, so what is compared is their text: the capped grid's time grows
//! linearly from some point on, the high-resolution grid's gently. Judged per scene by the slope
//! of log time against log objects (1: linear), over the whole curve and between its last two
//! sizes, with the exact ray–box tests' slope beside it (noise-free).
//!
//! Per size the scene is written once as a split store and traced by both grids
//! ([`super::grid_runs`]). `--quick` runs three small sizes per scene at 128×128 with the cap scaled to 16.
//! `--set scenes=mount,tetra`, `--set sizes=mount:9,10,11` (one scene per `sizes`), `--set cap=N`.
//! Sizes are saved as they finish (`--resume`).

use super::grid_runs::{self, log_slope, GridRun, Setup};
use super::published::{self, Source};
use super::{environment, Claim, Ctx, Fidelity, Kind, Output, Param, Row, Runtime, Table, Verdict};
use crate::error::{input, Result};
use rtbench_engines::breadth_first::spill::SpillDir;
use rtbench_reports::plot::{Chart, LegendAt, Panel, Point, Series, XyPanel};
use rtbench_reports::{Document, Table as DocTable};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

const SCENES_P: Param = Param {
    key: "scenes",
    help: "scenes to measure, e.g. mount,tetra (default all seven)",
};
const SIZES: Param = Param {
    key: "sizes",
    help: "size factors of one scene, e.g. mount:9,10,11 (default: Table 4.1's; --quick: three small ones)",
};
const CAP: Param = Param {
    key: "cap",
    help: "the single-level grid's cap per axis (default 128, 16 with --quick)",
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
    id: "nakamaru-fig4.4",
    seed: "000",
    source: "Figs 4.4–4.7",
    about: "000 (Nakamaru 2002) Figs 4.4–4.7: time vs scene size, single-level grid capped at 128 (\"-l\") vs the high-resolution grid",
    runtime: Runtime {
        quick: "minutes",
        full: "about 40 minutes (27 sizes up to 5e7 objects × 2 grids out of core; 2426 s on a 2-core machine); resumable",
    },
    params: &[SCENES_P, SIZES, CAP, SIZE, MEMORY, CACHE, SPILL],
    claims: &[
        Claim {
            key: "growth",
            fidelity: Fidelity::Substituted,
            why: "the grid's shape is our reading of Klimaszewski's method (its formula is not in the thesis); the figures' points are lost, so their text is judged by slopes of our curves; the machine the record names (its disk read cold) is stated, not the reason; --quick uses small scenes with the cap scaled to 16",
        },
        Claim {
            key: "image-equal",
            fidelity: Fidelity::Faithful,
            why: "",
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/nakamaru-fig4.4.json");

#[derive(Deserialize)]
struct Published {
    source: Source,
    cap: u32,
    claims: Vec<String>,
    sizes: BTreeMap<String, Vec<u32>>,
}

/// One size of one scene, traced by both grids.
#[derive(Serialize, Deserialize, Clone)]
struct Point_ {
    scene: String,
    sf: u32,
    objects: u64,
    cap: u32,
    capped: GridRun,
    high_res: GridRun,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    measured: Vec<Point_>,
    slopes: Vec<Slopes>,
    size: u32,
    memory: String,
    cache: String,
    environment: serde_json::Value,
}

/// The analysis of one scene's two curves.
#[derive(Serialize, Clone, Debug, PartialEq)]
struct Slopes {
    scene: String,
    sizes: Vec<u32>,
    /// log–log slopes of total time: whole curve, and the last two sizes.
    capped: Option<f64>,
    high_res: Option<f64>,
    capped_last: Option<f64>,
    high_res_last: Option<f64>,
    /// log–log slopes of the ray–box tests (exact).
    capped_box_tests: Option<f64>,
    high_res_box_tests: Option<f64>,
}

/// `--quick`: three sizes per scene, about 10^3·4 to 7·10^4 objects, past the quick cap of 16.
const QUICK: &[(&str, &[u32])] = &[
    ("balls", &[3, 4, 5]),
    ("gears", &[3, 4, 5]),
    ("mount", &[5, 6, 7]),
    ("rings", &[4, 6, 8]),
    ("teapot", &[12, 20, 30]),
    ("tetra", &[6, 7, 8]),
    ("tree", &[12, 14, 16]),
];

fn measure(scene: &str, sf: u32, cap: u32, s: &Setup) -> Result<Point_> {
    let src = grid_runs::resolve(scene, sf)?;
    let spill = SpillDir::create(s.spill.as_deref().map(Path::new)).map_err(input)?;
    let dir = spill.path().join("split");
    eprintln!("nakamaru-fig4.4: {scene}{sf}: store …");
    let h = grid_runs::write_split_store(&src, &dir)?;
    eprintln!("nakamaru-fig4.4: {scene}{sf}: single-level, cap {cap} …");
    let capped = grid_runs::trace(
        &dir,
        s,
        &[("grid", "single".to_string()), ("cap", cap.to_string())],
    )?;
    eprintln!("nakamaru-fig4.4: {scene}{sf}: high-resolution grid …");
    let high_res = grid_runs::trace(&dir, s, &[("grid", "two-level".to_string())])?;
    Ok(Point_ {
        scene: scene.into(),
        sf,
        objects: h.objects,
        cap,
        capped,
        high_res,
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
        .number::<u32>(CAP.key, 1)?
        .unwrap_or(if ctx.quick { 16 } else { p.cap });
    let setup = Setup {
        size,
        memory: ctx.params.bytes(MEMORY.key, "256MiB")?,
        cache: ctx.params.raw(CACHE.key).unwrap_or("cold").to_string(),
        spill: ctx.params.raw(SPILL.key).map(str::to_string),
    };
    let mut plan: Vec<(String, Vec<u32>)> = if ctx.quick {
        QUICK
            .iter()
            .map(|(s, v)| (s.to_string(), v.to_vec()))
            .collect()
    } else {
        p.sizes.iter().map(|(s, v)| (s.clone(), v.clone())).collect()
    };
    if let Some(list) = ctx.params.list(SCENES_P.key)? {
        for s in &list {
            if !p.sizes.contains_key(s) {
                return Err(input(format!("{}: scenes '{s}': not a scene of the figures", ctx.id)));
            }
        }
        plan.retain(|(s, _)| list.contains(s));
    }
    if let Some(spec) = ctx.params.raw(SIZES.key) {
        let (scene, sfs) = spec.split_once(':').ok_or_else(|| {
            input(format!("{}: sizes '{spec}': expected scene:SF,SF,…", ctx.id))
        })?;
        if !p.sizes.contains_key(scene) {
            return Err(input(format!("{}: sizes '{spec}': unknown scene", ctx.id)));
        }
        let sfs = sfs
            .split(',')
            .map(|v| v.trim().parse::<u32>().ok().filter(|&n| n >= 1))
            .collect::<Option<Vec<u32>>>()
            .ok_or_else(|| input(format!("{}: sizes '{spec}': bad size factor", ctx.id)))?;
        plan = vec![(scene.to_string(), sfs)];
    }
    let mut measured = Vec::new();
    for (scene, sfs) in &plan {
        for &sf in sfs {
            let key = format!("{scene}{sf}-cap{cap}-{size}-{}-{}", setup.memory, setup.cache);
            let m = match ctx.checkpoint.load::<Point_>(&key)? {
                Some(m) => {
                    eprintln!("{}: {scene}{sf}: saved by an earlier run", ctx.id);
                    m
                }
                None => {
                    let m = measure(scene, sf, cap, &setup)?;
                    ctx.checkpoint.save(&key, &m)?;
                    m
                }
            };
            measured.push(m);
        }
    }
    let slopes = analyse(&measured);
    let rows = rows(&p, &measured, &slopes);
    let doc = document(&p, &measured, &slopes, &setup, cap, ctx.quick);
    let charts = slopes
        .iter()
        .map(|s| chart(ctx.id, &s.scene, &measured, cap))
        .collect();
    let mut out = Output::new(
        Result_ {
            id: ctx.id,
            published: raw,
            measured,
            slopes,
            size,
            memory: setup.memory.clone(),
            cache: setup.cache.clone(),
            environment: environment(1),
        },
        rows,
        doc,
    );
    out.charts = charts;
    Ok(out)
}

/// Per scene, the slopes of both curves (pure).
fn analyse(measured: &[Point_]) -> Vec<Slopes> {
    let mut scenes: BTreeMap<&str, Vec<&Point_>> = BTreeMap::new();
    for m in measured {
        scenes.entry(m.scene.as_str()).or_default().push(m);
    }
    scenes
        .into_iter()
        .map(|(scene, mut ps)| {
            ps.sort_by_key(|p| p.objects);
            let curve = |f: &dyn Fn(&Point_) -> f64| -> Vec<(f64, f64)> {
                ps.iter().map(|p| (p.objects as f64, f(p))).collect()
            };
            let last = |v: Vec<(f64, f64)>| log_slope(&v[v.len().saturating_sub(2)..]);
            Slopes {
                scene: scene.to_string(),
                sizes: ps.iter().map(|p| p.sf).collect(),
                capped: log_slope(&curve(&|p| p.capped.total_s())),
                high_res: log_slope(&curve(&|p| p.high_res.total_s())),
                capped_last: last(curve(&|p| p.capped.total_s())),
                high_res_last: last(curve(&|p| p.high_res.total_s())),
                capped_box_tests: log_slope(&curve(&|p| p.capped.box_tests as f64)),
                high_res_box_tests: log_slope(&curve(&|p| p.high_res.box_tests as f64)),
            }
        })
        .collect()
}

fn f2(v: Option<f64>) -> String {
    v.map_or("-".into(), |v| format!("{v:.2}"))
}

fn rows(p: &Published, measured: &[Point_], slopes: &[Slopes]) -> Vec<Row> {
    let mut rows = Vec::new();
    for s in slopes {
        let table_sizes = p.sizes.get(&s.scene).cloned().unwrap_or_default();
        let note = if s.sizes == table_sizes {
            String::new()
        } else {
            format!(
                "sizes {:?}, not the table's {:?}: smaller stand-ins",
                s.sizes, table_sizes
            )
        };
        let verdict = match (s.capped, s.high_res) {
            (Some(c), Some(h)) => Verdict::of(h < c),
            _ => Verdict::NotMeasured,
        };
        rows.push(
            Row::new(
                "growth",
                format!("{}: whole curve", s.scene),
                "capped grows linearly, high-res gently (high-res slope below capped)",
                format!(
                    "time slope capped {} / high-res {} (box tests: {} / {})",
                    f2(s.capped),
                    f2(s.high_res),
                    f2(s.capped_box_tests),
                    f2(s.high_res_box_tests)
                ),
                Kind::Shape,
                verdict,
            )
            .with_note(note.clone()),
        );
        let verdict = match (s.capped_last, s.high_res_last) {
            (Some(c), Some(h)) => Verdict::of(h < c),
            _ => Verdict::NotMeasured,
        };
        rows.push(
            Row::new(
                "growth",
                format!("{}: last two sizes", s.scene),
                "capped linear from some point on (slope near 1), high-res below it",
                format!(
                    "time slope capped {} / high-res {}",
                    f2(s.capped_last),
                    f2(s.high_res_last)
                ),
                Kind::Shape,
                verdict,
            )
            .with_note(note.clone()),
        );
    }
    for m in measured {
        rows.push(Row::new(
            "image-equal",
            format!("{}{}", m.scene, m.sf),
            "equal",
            format!("{}… / {}…", crate::output::head(&m.capped.sha256, 12), crate::output::head(&m.high_res.sha256, 12)),
            Kind::Count,
            Verdict::of(m.capped.sha256 == m.high_res.sha256),
        ));
    }
    rows
}

fn chart(id: &str, scene: &str, measured: &[Point_], cap: u32) -> Chart {
    let mut ps: Vec<&Point_> = measured.iter().filter(|m| m.scene == scene).collect();
    ps.sort_by_key(|p| p.objects);
    let series = |name: String, color: usize, f: &dyn Fn(&Point_) -> f64| Series {
        name,
        color,
        points: ps
            .iter()
            .map(|p| Point {
                x: p.objects as f64,
                y: f(p),
                y_range: None,
            })
            .collect(),
    };
    Chart {
        stem: format!("{id}-{scene}"),
        title: format!("{scene}: time against size (000 Figs 4.4–4.7)"),
        panels: vec![Panel::Xy(XyPanel {
            title: format!("{scene}: S+G+B, preprocessing + tracing"),
            x_label: "objects".into(),
            y_label: "seconds".into(),
            x_log: true,
            y_log: true,
            x_ticks: Vec::new(),
            lines: true,
            legend: LegendAt::UpperLeft,
            series: vec![
                series(format!("{scene}-l (single, cap {cap})"), 1, &|p| p.capped.total_s()),
                series(format!("{scene} (high-resolution)"), 2, &|p| p.high_res.total_s()),
            ],
        })],
    }
}

fn document(
    p: &Published,
    measured: &[Point_],
    slopes: &[Slopes],
    s: &Setup,
    cap: u32,
    quick: bool,
) -> Document {
    let mut doc = Document::new("nakamaru-fig4.4: time against size, capped grid vs high-resolution grid");
    doc.paragraph(format!(
        "Published: {} (machine: {}); the figures' text: {} Measured: `rtbench reproduce nakamaru-fig4.4{}`, {}×{}, breadth-first engine with S+G+B, memory {}, cache {}, one thread; capped = `grid=single cap={cap}`, high-res = `grid=two-level` (R_u 256, R_l 4). Times are preprocessing (with the hierarchy's and the on-disk grid's build) + tracing. Slopes are of log time against log objects (1 = linear).",
        p.source.cite(),
        p.source.machine.as_deref().unwrap_or(""),
        p.claims.join(" "),
        if quick { " --quick" } else { "" },
        s.size,
        s.size,
        s.memory,
        s.cache,
    ));
    let mut t = DocTable::new(
        "Slopes per scene",
        &[
            "scene", "sizes", "capped slope", "high-res slope", "capped last", "high-res last",
            "capped box-test slope", "high-res box-test slope",
        ],
    );
    for sl in slopes {
        t.push(vec![
            sl.scene.clone(),
            format!("{:?}", sl.sizes),
            f2(sl.capped),
            f2(sl.high_res),
            f2(sl.capped_last),
            f2(sl.high_res_last),
            f2(sl.capped_box_tests),
            f2(sl.high_res_box_tests),
        ]);
    }
    doc.table(t);
    let mut t = DocTable::new(
        "Points",
        &[
            "row", "objects", "capped cells", "capped s", "high-res cells", "upper/lower",
            "high-res s", "capped box tests", "high-res box tests", "subspaces", "grid MiB read",
            "peak RSS MiB", "CPU / wall capped, high-res", "load avg",
        ],
    );
    for m in measured {
        let (c, h) = (&m.capped, &m.high_res);
        t.push(vec![
            format!("{}{}", m.scene, m.sf),
            m.objects.to_string(),
            format!("{}×{}×{}", c.res[0], c.res[1], c.res[2]),
            format!("{:.2}", c.total_s()),
            format!("{}×{}×{}", h.res[0], h.res[1], h.res[2]),
            format!("{}×{}×{} / {}", h.upper[0], h.upper[1], h.upper[2], h.lower),
            format!("{:.2}", h.total_s()),
            c.box_tests.to_string(),
            h.box_tests.to_string(),
            h.subspaces.to_string(),
            format!("{:.1}", h.grid_bytes_read as f64 / 1048576.0),
            format!(
                "{:.1}",
                c.peak_rss_bytes.max(h.peak_rss_bytes) as f64 / 1048576.0
            ),
            format!("{}, {}", c.cpu_share(), h.cpu_share()),
            h.load_average.clone(),
        ]);
    }
    doc.table(t);
    doc
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(sf: u32, objects: u64, capped: f64, high: f64) -> Point_ {
        let run = |t: f64| GridRun {
            trace_s: t,
            box_tests: (t * 1000.0) as u64,
            sha256: "ab".repeat(32),
            ..Default::default()
        };
        Point_ {
            scene: "mount".into(),
            sf,
            objects,
            cap: 128,
            capped: run(capped),
            high_res: run(high),
        }
    }

    #[test]
    fn slopes_tell_linear_from_gentle_growth() {
        let ms = vec![
            point(9, 1_000, 1.0, 1.0),
            point(10, 10_000, 5.0, 2.0),
            point(11, 100_000, 50.0, 4.0),
        ];
        let s = analyse(&ms);
        assert_eq!(s.len(), 1);
        assert!((s[0].capped_last.unwrap() - 1.0).abs() < 1e-9);
        assert!((s[0].high_res_last.unwrap() - 2f64.log10()).abs() < 1e-9);
        let (p, _): (Published, _) = published::load("nakamaru-fig4.4", PUBLISHED);
        let rows = rows(&p, &ms, &s);
        assert!(rows
            .iter()
            .filter(|r| r.claim == "growth")
            .all(|r| r.verdict == Verdict::Holds));
        // Reversed: the high-resolution grid growing faster does not hold.
        let rev: Vec<Point_> = ms
            .iter()
            .map(|m| point(m.sf, m.objects, m.high_res.trace_s, m.capped.trace_s))
            .collect();
        let rows = super::rows(&p, &rev, &analyse(&rev));
        assert!(rows
            .iter()
            .filter(|r| r.claim == "growth")
            .all(|r| r.verdict == Verdict::Fails));
    }
}
