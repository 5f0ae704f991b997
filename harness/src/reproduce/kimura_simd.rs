//! `kimura-simd`: 001 (Kimura 2007) §4.3, the rendering speed-up of SIMD single-ray traversal of the 4-ary
//! SAH BVH (2.32–4.45×). 800×600 eye rays through pixel centres, one thread (the calling one), the same
//! rays for every engine; a second table runs the engines at their defaults (issue 5's side-by-side).

use super::engine_timing::{self, Timed, Timee};
use super::kimura_3_3::scenes;
use super::published::{self, Source};
use super::{environment, Claim, Ctx, Fidelity, Kind, Output, Row, Runtime, Table, Verdict};
use crate::error::Result;
use crate::source::Source as SceneSource;
use crate::workload::{self, camera::Camera};
use rtbench_reports::{Document, Table as DocTable};
use serde::{Deserialize, Serialize};

pub const TABLE: Table = Table {
    id: "kimura-simd",
    seed: "001",
    source: "§4.3, Fig. 4.5",
    about: "001 (Kimura 2007) §4.3: SIMD 4-ary single-ray traversal speed-up (2.32-4.45x)",
    runtime: Runtime {
        quick: "seconds",
        full: "minutes",
    },
    params: &[],
    claims: &[
        Claim {
            key: "simd-speedup",
            fidelity: Fidelity::Substituted,
            why: "today's CPU (AVX2) and compiler against 001's Core Duo T2050 and MSVC 2005; 001's baseline (binary or 4-ary) is not stated, so both are shown",
        },
        Claim {
            key: "engine-goal",
            fidelity: Fidelity::Faithful,
            why: "",
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/kimura-simd.json");
const IMAGE: (u32, u32) = (800, 600);

#[derive(Deserialize)]
struct Published {
    source: Source,
    speedup_simd: Range,
}
#[derive(Deserialize)]
struct Range {
    min: f64,
    max: f64,
}

/// 001's trees for the SIMD experiment: full-sweep SAH, one triangle per leaf, no packets.
const SIMD_ENGINES: &[Timee] = &[
    ("bvh2 scalar", "bvh2", &[("builder", "sah-sweep"), ("leaf", "1"), ("simd", "off"), ("packets", "off")]),
    ("bvh4 scalar", "bvh4", &[("builder", "sah-sweep"), ("wide", "direct"), ("leaf", "1"), ("simd", "off"), ("packets", "off")]),
    ("bvh4 SIMD", "bvh4", &[("builder", "sah-sweep"), ("wide", "direct"), ("leaf", "1"), ("simd", "on"), ("packets", "off")]),
    ("bvh8 SIMD", "bvh8", &[("builder", "sah-sweep"), ("wide", "direct"), ("leaf", "1"), ("simd", "on"), ("packets", "off")]),
    ("embree", "embree", &[]),
];

/// The engines as users run them (their default trees and leaves), with obvhs's two layouts.
const DEFAULT_ENGINES: &[Timee] = &[
    ("bvh2 scalar", "bvh2", &[]),
    ("bvh4 scalar", "bvh4", &[("simd", "off")]),
    ("bvh4 SIMD", "bvh4", &[]),
    ("bvh8 SIMD", "bvh8", &[]),
    ("obvhs cwbvh", "obvhs", &[]),
    ("obvhs bvh2", "obvhs", &[("layout", "bvh2")]),
    ("embree", "embree", &[]),
];

#[derive(Serialize)]
struct Speedup {
    scene: String,
    over: &'static str,
    speedup: f64,
    published_min: f64,
    published_max: f64,
    compares: &'static str,
}

#[derive(Serialize)]
struct Goal {
    scene: String,
    ratio: String,
    goal: &'static str,
    measured: f64,
    met: bool,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    measured: Vec<Timed>,
    speedups: Vec<Speedup>,
    quick: bool,
    defaults: Vec<Timed>,
    goals: Vec<Goal>,
    image: [u32; 2],
    environment: serde_json::Value,
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let repeats: usize = if ctx.quick { 3 } else { 7 };
    let (mut measured, mut defaults) = (Vec::new(), Vec::new());
    for &(scene, sf) in scenes(ctx.quick) {
        let src = SceneSource::resolve(scene, Some(sf), Some(3), None)?;
        let prepared = workload::prepare(&src)?;
        let rays = Camera::new(&prepared.input.scene.view).pixel_centre_rays(IMAGE.0, IMAGE.1);
        let on = (scene, sf);
        measured.extend(engine_timing::time_engines(SIMD_ENGINES, &prepared.input, &rays, repeats, 1, on, ctx.id)?);
        defaults.extend(engine_timing::time_engines(DEFAULT_ENGINES, &prepared.input, &rays, repeats, 3, on, ctx.id)?);
    }
    let speedups = speedups(&p, &measured);
    let goals = goals(&defaults);
    let rows = rows(&speedups, &goals);
    let doc = document(&p, &measured, &speedups, &defaults, &goals, ctx.quick, repeats);
    let result = Result_ {
        id: ctx.id,
        published: raw,
        measured,
        speedups,
        quick: ctx.quick,
        defaults,
        goals,
        image: [IMAGE.0, IMAGE.1],
        environment: environment(1),
    };
    Ok(Output::new(result, rows, doc))
}

/// The timings of one scene.
fn of_scene<'a>(times: &'a [Timed], scene: &str, sf: u32) -> impl Iterator<Item = &'a Timed> + Clone {
    let scene = scene.to_string();
    times.iter().filter(move |t| t.scene == scene && t.sf == sf)
}

/// bvh4 SIMD over each scalar baseline, per scene (pure).
fn speedups(p: &Published, measured: &[Timed]) -> Vec<Speedup> {
    let (lo, hi) = (p.speedup_simd.min, p.speedup_simd.max);
    let mut out = Vec::new();
    for &(scene, sf) in super::kimura_3_3::SCENES {
        let times = of_scene(measured, scene, sf);
        let get = |l: &str| times.clone().find(|t| t.engine == l).map(|t| t.cpu_s);
        let Some(simd) = get("bvh4 SIMD") else { continue };
        for over in ["bvh2 scalar", "bvh4 scalar"] {
            let Some(b) = get(over) else { continue };
            let s = b / simd;
            let compares = if s < lo {
                "below 001's range"
            } else if s > hi {
                "above 001's range"
            } else {
                "within 001's range"
            };
            out.push(Speedup { scene: format!("{scene}{sf}"), over, speedup: s, published_min: lo, published_max: hi, compares });
        }
    }
    out
}

/// Issue 5's goals per scene: bvh4/bvh8 SIMD at ≥ 0.8× Embree's rays per second and ≥ 1.5× the faster
/// obvhs layout's; builds ≤ 3× Embree's build time (pure).
fn goals(defaults: &[Timed]) -> Vec<Goal> {
    let mut out = Vec::new();
    for &(scene, sf) in super::kimura_3_3::SCENES {
        let times = of_scene(defaults, scene, sf);
        let get = |l: &str| times.clone().find(|t| t.engine == l);
        let obvhs = ["obvhs cwbvh", "obvhs bvh2"].iter().filter_map(|l| get(l).map(|t| t.cpu_s)).min_by(|a, b| a.total_cmp(b));
        let on = format!("{scene}{sf}");
        for l in ["bvh4 SIMD", "bvh8 SIMD"] {
            let Some(t) = get(l) else { continue };
            let mut goal = |ratio: String, goal: &'static str, measured: f64, met: bool| {
                out.push(Goal { scene: on.clone(), ratio, goal, measured, met });
            };
            if let Some(e) = get("embree") {
                let r = e.cpu_s / t.cpu_s;
                goal(format!("{l} rays/s ÷ Embree's"), "≥ 0.8", r, r >= 0.8);
                let b = t.build_s / e.build_s;
                goal(format!("{l} build s ÷ Embree's"), "≤ 3", b, b <= 3.0);
            }
            if let Some(o) = obvhs {
                let r = o / t.cpu_s;
                goal(format!("{l} rays/s ÷ fastest obvhs'"), "≥ 1.5", r, r >= 1.5);
            }
        }
    }
    out
}

fn rows(speedups: &[Speedup], goals: &[Goal]) -> Vec<Row> {
    let mut rows: Vec<Row> = speedups
        .iter()
        .map(|s| {
            Row::new(
                "simd-speedup",
                format!("{} over {}", s.scene, s.over),
                format!("{}-{}", s.published_min, s.published_max),
                format!("{:.2}", s.speedup),
                Kind::Range,
                Verdict::of(s.compares == "within 001's range"),
            )
        })
        .collect();
    rows.extend(goals.iter().map(|g| {
        Row::new("engine-goal", format!("{} {}", g.scene, g.ratio), g.goal, format!("{:.2}", g.measured), Kind::Ratio, Verdict::of(g.met))
            .with_fidelity(Fidelity::Faithful, "issue 5's goal for our engines, not a claim of 001")
    }));
    rows
}

fn timed_table(times: &[Timed]) -> DocTable {
    let mut t = DocTable::new("", &engine_timing::HEADER);
    for r in engine_timing::rows(times) {
        t.push(r);
    }
    t
}

fn document(p: &Published, measured: &[Timed], speedups: &[Speedup], defaults: &[Timed], goals: &[Goal], quick: bool, repeats: usize) -> Document {
    let (lo, hi) = (p.speedup_simd.min, p.speedup_simd.max);
    let (w, h) = IMAGE;
    let mut doc = Document::new("kimura-simd: SIMD 4-ary single-ray traversal, 001 vs measured");
    doc.paragraph(format!("Source: {}.", p.source.cite()));
    doc.paragraph(format!("Published: SIMD made rendering {lo}-{hi}x faster (Core Duo T2050, 4 scenes incl. cloister; baseline 'without SIMD', binary or 4-ary tree not stated)."));
    doc.paragraph(format!("Measured: `rtbench reproduce kimura-simd` ({}), {w}x{h} eye rays through pixel centres (NFF angle vertical, square pixels), intersect only (no shading), one thread, trees `builder=sah-sweep leaf=1 packets=off` (`wide=direct` for bvh4/bvh8), Embree with its defaults. Times: median of {repeats} repeats after one warm-up, CPU time of the calling thread (wall in brackets). Absolute times are not compared with 2006's.", if quick { "--quick: gears4 only, fewer repeats" } else { "full" }));
    doc.table(timed_table(measured));
    let mut s = DocTable::new("", &["scene", "bvh4 SIMD over", "speed-up (CPU time)", "001", "how it compares"]);
    for x in speedups {
        s.push(vec![x.scene.clone(), x.over.into(), format!("{:.2}", x.speedup), format!("{lo}-{hi}"), x.compares.into()]);
    }
    doc.table(s);
    doc.heading("The engines at their defaults, same rays (issue 5's side-by-side)");
    doc.paragraph("Default trees and leaves (bvh2: binned SAH, leaf 1; bvh4/bvh8: binned SAH collapsed, leaf 4, triangle packets; obvhs: PLOC, `medium` preset), one thread, same rays and timing as above; build: median wall time of 3 builds (Embree builds with its own threads).");
    doc.table(timed_table(defaults));
    let mut g = DocTable::new("", &["scene", "ratio", "goal", "measured", "met"]);
    for x in goals {
        g.push(vec![x.scene.clone(), x.ratio.clone(), x.goal.into(), format!("{:.2}", x.measured), if x.met { "yes" } else { "no" }.into()]);
    }
    doc.table(g);
    doc
}
