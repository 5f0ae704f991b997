//! `rtbench reproduce nakamaru-3.1`: seed 000's Table 3.1, the breadth-first method against
//! Rayshade on small scenes. Published figures: `data/published/nakamaru-3.1.json`.
//!
//! Configurations, as the thesis ran them: `grid` with `preset=rss` (shadow cache and per-voxel
//! culling, Rayshade as shipped) and `preset=rss-r` (both off); `breadth-first` with
//! registration count fixed at 1, traced out of core (scene store written and preprocessed,
//! generations spilled, shading in object order: the whole of sray). For balls and tree the
//! floor is kept out of the grid in all three (§3.4: "the base plate was excluded, the rest
//! handled the same way"). One thread each: the thesis's machine had one processor, and the
//! breadth-first engine runs on one. Times are medians of the repeats; preprocessing includes
//! the scene's preparation (and for breadth-first the store's writing), not its generation.

use super::reproduce::write_report;
use crate::error::{input, Result};
use crate::source::Source;
use crate::workload::{self, out_of_core, trace};
use rtbench_engines::breadth_first::config::BreadthFirstConfig;
use rtbench_engines::breadth_first::spill::SpillDir;
use rtbench_engines::breadth_first::BreadthFirst;
use rtbench_engines::store::StoreWriter;
use rtbench_engines::Settings;
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

const NAKAMARU_31: &str = include_str!("../../../data/published/nakamaru-3.1.json");

const PHASES: [&str; 4] = ["total", "preprocess", "intersect", "shade"];

/// One timed run: seconds per phase, primitive tests, image hash.
struct Timed {
    s: [f64; 4],
    tests: u64,
    image: Vec<u8>,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

fn floor_setting(scene: &str) -> &'static str {
    if scene == "balls" || scene == "tree" {
        "out"
    } else {
        "in"
    }
}

fn grid_run(prepared: &workload::Prepared, preset: &str, floor: &str) -> Result<Timed> {
    let set = vec![
        ("preset".to_string(), preset.to_string()),
        ("floor".to_string(), floor.to_string()),
    ];
    let pool = workload::pool(Some(1))?;
    let (e, build_s) = workload::build("grid", &prepared.input, set)?;
    let r = pool.install(|| trace::render(&prepared.input.scene, e.as_ref(), 512, None));
    let pre = prepared.prepare_s + build_s;
    Ok(Timed {
        s: [pre + r.trace_s, pre, r.intersect_s, r.shade_s],
        tests: r.counters.primitive_tests,
        image: r.pixels(),
    })
}

fn breadth_first_run(prepared: &workload::Prepared, floor: &str) -> Result<Timed> {
    let t = Instant::now();
    let config = BreadthFirstConfig::from_settings(Settings::new(
        "breadth-first",
        vec![
            ("registration".into(), "fixed:1".into()),
            ("floor".into(), floor.into()),
        ],
    ))?;
    let spill = SpillDir::create(None).map_err(input)?;
    StoreWriter::create(spill.path(), "x")
        .and_then(|w| w.write_scene(&prepared.input.scene))
        .map_err(|e| input(format!("writing the scene store: {e}")))?;
    let engine = BreadthFirst::open(spill.path(), config)?;
    let pre = prepared.prepare_s + t.elapsed().as_secs_f64();
    let ooc =
        out_of_core::render(&engine, 512).map_err(|e| input(format!("out-of-core render: {e}")))?;
    let r = &ooc.render;
    Ok(Timed {
        s: [pre + r.trace_s, pre, r.intersect_s, r.shade_s],
        tests: r.counters.primitive_tests,
        image: r.pixels(),
    })
}

pub fn run(id: &str, quick: bool, out: &Path, as_json: bool) -> Result<()> {
    let published: Value =
        serde_json::from_str(NAKAMARU_31).expect("data/published/nakamaru-3.1.json is valid JSON");
    let rows = published["rows"].as_array().unwrap();
    let rows: Vec<&Value> = if quick {
        rows.iter().filter(|r| r["scene"] == "tetra").collect()
    } else {
        rows.iter().collect()
    };
    let repeats = if quick { 1 } else { 3 };
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# nakamaru-3.1: breadth-first vs Rayshade-style grid on small data\n"
    );
    let _ = writeln!(
        md,
        "Published: {}, {} (machine: {}). Measured: `rtbench reproduce nakamaru-3.1{}`, one \
         thread, 512×512, median of {repeats}; `rss`/`rss-r` = `grid` presets, `bf` = \
         `breadth-first` with registration fixed:1, out of core (store, spilled generations, \
         shading in object order). Seconds; ratios are what compare.\n",
        published["source"]["document"].as_str().unwrap_or(""),
        published["source"]["sections"].as_str().unwrap_or(""),
        published["source"]["machine"].as_str().unwrap_or(""),
        if quick {
            " --quick (tetra6 only, 1 repeat)"
        } else {
            ""
        },
    );
    let _ = writeln!(
        md,
        "| scene | phase | rss | rss-r | sray | sray/rss | sray/rss-r | measured rss | rss-r | bf | bf/rss | bf/rss-r |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut measured = Vec::new();
    let mut verdicts = Vec::new();
    for row in rows {
        let scene = row["scene"].as_str().unwrap();
        let sf = row["sf"].as_u64().unwrap() as u32;
        let src = Source::resolve(scene, Some(sf), None, None)?;
        let prepared = workload::prepare(&src)?;
        let floor = floor_setting(scene);
        eprintln!("nakamaru-3.1: {scene}{sf} …");
        let mut runs: [Vec<Timed>; 3] = [Vec::new(), Vec::new(), Vec::new()];
        for _ in 0..repeats {
            runs[0].push(grid_run(&prepared, "rss", floor)?);
            runs[1].push(grid_run(&prepared, "rss-r", floor)?);
            runs[2].push(breadth_first_run(&prepared, floor)?);
        }
        let med = |c: usize, p: usize| median(runs[c].iter().map(|t| t.s[p]).collect());
        let same_image = runs[2][0].image == runs[1][0].image;
        let mut phases = serde_json::Map::new();
        for (p, phase) in PHASES.iter().enumerate() {
            let pubv: Vec<f64> = row[phase]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            let m = [med(0, p), med(1, p), med(2, p)];
            let _ = writeln!(
                md,
                "| {scene}{sf} | {phase} | {} | {} | {} | {:.2} | {:.2} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} |",
                pubv[0], pubv[1], pubv[2], pubv[2] / pubv[0], pubv[2] / pubv[1],
                m[0], m[1], m[2], m[2] / m[0], m[2] / m[1]
            );
            phases.insert(
                phase.to_string(),
                json!({"published": {"rss": pubv[0], "rss-r": pubv[1], "sray": pubv[2],
                        "sray/rss": pubv[2] / pubv[0], "sray/rss-r": pubv[2] / pubv[1]},
                       "measured": {"rss": m[0], "rss-r": m[1], "breadth-first": m[2],
                        "bf/rss": m[2] / m[0], "bf/rss-r": m[2] / m[1]}}),
            );
            if p == 0 {
                verdicts.push((
                    format!("{scene}{sf}"),
                    pubv[2] / pubv[0],
                    m[2] / m[0],
                    m[2] / m[1],
                ));
            }
        }
        let tests = [runs[0][0].tests, runs[1][0].tests, runs[2][0].tests];
        measured.push(
            json!({"scene": scene, "sf": sf, "floor": floor, "phases": phases,
            "primitive_tests": {"rss": tests[0], "rss-r": tests[1], "breadth-first": tests[2]},
            "image_equal_to_rss_r": same_image,
            "repeats": repeats}),
        );
    }
    let _ = writeln!(
        md,
        "\nOverall overhead (total time, breadth-first ÷ rss): published sray/rss beside measured; \
         the goal is a smaller overhead.\n"
    );
    let _ = writeln!(
        md,
        "| scene | published sray/rss | measured bf/rss | measured bf/rss-r | smaller |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|");
    let mut all_smaller = true;
    for (s, p, m, mr) in &verdicts {
        let smaller = m < p;
        all_smaller &= smaller;
        let _ = writeln!(
            md,
            "| {s} | {p:.2} | {m:.2} | {mr:.2} | {} |",
            if smaller { "yes" } else { "**no**" }
        );
    }
    let _ = writeln!(
        md,
        "\nPrimitive tests and image (breadth-first image equal to rss-r's):\n"
    );
    let _ = writeln!(md, "| scene | rss | rss-r | breadth-first | image equal |");
    let _ = writeln!(md, "|---|---|---|---|---|");
    for m in &measured {
        let t = &m["primitive_tests"];
        let _ = writeln!(
            md,
            "| {}{} | {} | {} | {} | {} |",
            m["scene"].as_str().unwrap(),
            m["sf"],
            t["rss"],
            t["rss-r"],
            t["breadth-first"],
            m["image_equal_to_rss_r"]
        );
    }
    let doc = json!({"id": id, "published": published, "measured": measured, "quick": quick,
        "all_smaller_overhead": all_smaller,
        "environment": {"os": std::env::consts::OS, "arch": std::env::consts::ARCH, "threads": 1}});
    write_report(id, out, &doc, &md, as_json)
}
