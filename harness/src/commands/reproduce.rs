//! `rtbench reproduce`: published tables, remeasured. The published figures live in
//! `data/published/<id>.json` with their source; they are compiled in from there.
//!
//! `spd-stats`: the SPD README's ray statistics of the seven standard scenes, against the ray
//! counts of our workload with each engine.

use crate::error::{input, Result};
use crate::output::{print_json, write_atomic};
use crate::source::Source;
use crate::workload::camera::Camera;
use crate::workload::{self, trace};
use rtbench_engines::{Counters, Hit};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

const SPD_STATS: &str = include_str!("../../../data/published/spd-stats.json");
const KIMURA_TREES: &str = include_str!("../../../data/published/kimura-3.3.json");
const KIMURA_SIMD: &str = include_str!("../../../data/published/kimura-simd.json");

/// Every reproducible table: id, what it is.
const TABLES: &[(&str, &str)] = &[
    (
        "spd-stats",
        "SPD 3.14 README: ray statistics of the seven standard scenes (counts within 10%)",
    ),
    (
        "kimura-3.3",
        "001 (Kimura 2007) §3.3-3.5: node statistics of 2/4/8-ary BVHs (orderings and ratios)",
    ),
    (
        "nakamaru-3.1",
        "000 (Nakamaru 2002) Table 3.1: breadth-first vs Rayshade (rss, rss-r) times on small data",
    ),
    (
        "nakamaru-3.2",
        "000 (Nakamaru 2002) Table 3.2, Figs. 3.5-3.7: grid thrashing onset (Mattson page model) vs breadth-first, 32 MB",
    ),
    (
        "kimura-simd",
        "001 (Kimura 2007) §4.3: SIMD 4-ary single-ray traversal speed-up (2.32-4.45x)",
    ),
];

pub fn list(as_json: bool) -> Result<()> {
    if as_json {
        print_json(&json!(TABLES
            .iter()
            .map(|(id, d)| json!({"id": id, "description": d}))
            .collect::<Vec<_>>()));
    } else {
        for (id, d) in TABLES {
            println!("{id:<12} {d}");
        }
    }
    Ok(())
}

/// Engines to run: the ones asked for, or every available engine but `reference` (brute force:
/// hours on the standard scenes).
fn engines(asked: Option<&str>) -> Result<Vec<String>> {
    match asked {
        Some(list) => Ok(list
            .split(',')
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .collect()),
        None => Ok(rtbench_engines::registry()
            .into_iter()
            .filter(|e| e.name != "reference" && (e.available)().is_ok())
            .map(|e| e.name.to_string())
            .collect()),
    }
}

pub fn run(
    id: &str,
    quick: bool,
    out: &Path,
    asked: Option<&str>,
    threads: Option<usize>,
    as_json: bool,
) -> Result<()> {
    match id {
        "spd-stats" => {}
        "kimura-3.3" => return kimura_trees(id, quick, out, as_json),
        "kimura-simd" => return kimura_simd(id, quick, out, as_json),
        "nakamaru-3.1" => return super::reproduce_nakamaru::run(id, quick, out, as_json),
        _ => {
            let ids: Vec<_> = TABLES.iter().map(|t| t.0).collect();
            return Err(input(format!(
                "unknown table '{id}' (known: {})",
                ids.join(", ")
            )));
        }
    }
    let published: Value =
        serde_json::from_str(SPD_STATS).expect("data/published/spd-stats.json is valid JSON");
    let tol = published["tolerance_rel"].as_f64().unwrap_or(0.1);
    let columns: Vec<String> = published["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap().to_string())
        .collect();
    let engines = engines(asked)?;
    if engines.is_empty() {
        return Err(input("no engine to run (see `rtbench engines`)"));
    }
    std::fs::create_dir_all(out.join("images"))
        .map_err(|e| input(format!("{}: cannot create: {e}", out.display())))?;
    let pool = workload::pool(threads)?;
    let size = 512;
    let mut rows = Vec::new();
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# spd-stats: SPD ray statistics, published vs measured\n"
    );
    let _ = writeln!(
        md,
        "Source: {}. Published counts 'should be within about 10%' for any classical ray tracer.",
        published["source"]["document"].as_str().unwrap_or("")
    );
    let _ = writeln!(md, "Measured: `rtbench reproduce spd-stats` ({}), {size}×{size} pixels, {}² eye rays through pixel corners, depth 5, curved primitives.\n", if quick { "--quick: same experiment, it is already small" } else { "full" }, size + 1);
    let _ = writeln!(
        md,
        "| scene | engine | {} | within {:.0}% |",
        columns
            .iter()
            .map(|c| format!("{c} published | measured | ratio"))
            .collect::<Vec<_>>()
            .join(" | "),
        tol * 100.0
    );
    let _ = writeln!(md, "|---|---|{}---|", "---|---|---|".repeat(columns.len()));
    let mut all_within = true;
    for row in published["rows"].as_array().unwrap() {
        let scene = row["scene"].as_str().unwrap();
        let sf = row["sf"].as_u64().unwrap() as u32;
        let src = Source::resolve(scene, Some(sf), None, None)?;
        let prepared = workload::prepare(&src)?;
        for engine in &engines {
            let (e, build_s) = workload::build(engine, &prepared.input, vec![])?;
            eprintln!("spd-stats: {}{} with {engine} …", scene, sf);
            let r = pool.install(|| trace::render(&prepared.input.scene, e.as_ref(), size, None));
            let pixels = r.pixels();
            let png = out.join("images").join(format!("{scene}{sf}-{engine}.png"));
            write_atomic(&png, |w| {
                image::write_buffer_with_format(
                    w,
                    &pixels,
                    size,
                    size,
                    image::ExtendedColorType::Rgb8,
                    image::ImageFormat::Png,
                )
                .map_err(std::io::Error::other)
            })?;
            let measured = serde_json::to_value(&r.stats).unwrap();
            let mut cells = Vec::new();
            let mut within = true;
            let mut cmp = serde_json::Map::new();
            for c in &columns {
                let p = row[c].as_f64().unwrap();
                let m = measured[c].as_f64().unwrap();
                let (ratio, ok) = if p == 0.0 {
                    (if m == 0.0 { 1.0 } else { f64::INFINITY }, m == 0.0)
                } else {
                    (m / p, (m / p - 1.0).abs() <= tol)
                };
                within &= ok;
                cells.push(format!("{} | {} | {:.3}", p, m, ratio));
                cmp.insert(c.clone(), json!({"published": p, "measured": m, "ratio": if ratio.is_finite() { json!(ratio) } else { json!(null) }, "within": ok}));
            }
            all_within &= within;
            let _ = writeln!(
                md,
                "| {scene}{sf} | {engine} | {} | {} |",
                cells.join(" | "),
                if within { "yes" } else { "**no**" }
            );
            rows.push(json!({"scene": scene, "sf": sf, "engine": engine, "compare": cmp, "within": within,
                "rays": r.stats, "time_s": {"build": build_s, "trace": r.trace_s}, "image": png.file_name().unwrap().to_string_lossy()}));
        }
    }
    let _ = writeln!(
        md,
        "\nAll within {:.0}%: {}.",
        tol * 100.0,
        if all_within { "yes" } else { "no" }
    );
    let doc = json!({"id": id, "published": published, "measured": rows, "all_within": all_within, "quick": quick,
        "environment": {"os": std::env::consts::OS, "arch": std::env::consts::ARCH, "threads": pool.current_num_threads()}});
    write_report(id, out, &doc, &md, as_json)
}

/// Writes DIR/<id>.json and DIR/<id>.md, and prints one of them.
pub(super) fn write_report(
    id: &str,
    out: &Path,
    doc: &Value,
    md: &str,
    as_json: bool,
) -> Result<()> {
    std::fs::create_dir_all(out)
        .map_err(|e| input(format!("{}: cannot create: {e}", out.display())))?;
    write_atomic(&out.join(format!("{id}.json")), |w| {
        serde_json::to_writer_pretty(w, doc).map_err(std::io::Error::other)
    })?;
    write_atomic(&out.join(format!("{id}.md")), |w| {
        std::io::Write::write_all(w, md.as_bytes())
    })?;
    if as_json {
        print_json(doc);
    } else {
        print!("{md}");
    }
    Ok(())
}

fn environment(threads: usize) -> Value {
    json!({"os": std::env::consts::OS, "arch": std::env::consts::ARCH, "threads": threads})
}

/// 001's three SPD scenes (Table 3.1), tessellated as 001 did (patch resolution 3).
const KIMURA_SCENES: &[(&str, u32)] = &[("gears", 4), ("tree", 10), ("balls", 4)];

fn kimura_scenes(quick: bool) -> &'static [(&'static str, u32)] {
    if quick {
        &KIMURA_SCENES[..1]
    } else {
        KIMURA_SCENES
    }
}

fn settings(kv: &[(&str, &str)]) -> Vec<(String, String)> {
    kv.iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

/// How a measured ratio compares with a published one: "matches" within `tol` (relative).
fn near(measured: f64, published: f64, tol: f64) -> &'static str {
    if (measured / published - 1.0).abs() <= tol {
        "matches"
    } else {
        "differs"
    }
}

/// `kimura-3.3`: 001's trees (object median and full-sweep SAH, 001's own N-ary builders, one
/// triangle per leaf) on 001's SPD scenes, for the widths the engines have (2, 4, 8).
fn kimura_trees(id: &str, quick: bool, out: &Path, as_json: bool) -> Result<()> {
    let published: Value =
        serde_json::from_str(KIMURA_TREES).expect("data/published/kimura-3.3.json is valid JSON");
    let table_tris: Vec<&Value> = published["scenes"]["rows"]
        .as_array()
        .unwrap()
        .iter()
        .collect();
    let widths = [("bvh2", 2u32), ("bvh4", 4), ("bvh8", 8)];
    let builders = [
        ("median", "object median"),
        ("sah-sweep", "SAH (full sweep)"),
    ];
    let mut rows = Vec::new();
    let mut checks = Vec::new();
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# kimura-3.3: node statistics of 2/4/8-ary BVHs, 001 vs measured\n"
    );
    let _ = writeln!(
        md,
        "Source: {}; {}.",
        published["source"]["document"].as_str().unwrap_or(""),
        published["source"]["sections"].as_str().unwrap_or("")
    );
    let _ = writeln!(md, "001's plotted values (Figs. 3.12-3.19) are lost; what compares is its orderings and ratios, not absolute values. Widths 6, 10, 12, 14 and 16 are not built (the engines have 2, 4 and 8); cloister is not reproduced (no source).");
    let _ = writeln!(md, "Measured: `rtbench reproduce kimura-3.3` ({}), engines bvh2/bvh4/bvh8 with `wide=direct leaf=1 packets=off` and `builder=median` or `builder=sah-sweep`. Depth: root = 0. Memory: 001 Eq. 3.3 (empty nodes not counted | counted).\n", if quick { "--quick: gears4 only" } else { "full: gears4, tree10, balls4" });
    let _ = writeln!(md, "| scene | builder | N | triangles (Table 3.1) | internal | leaves | empty | avg leaf depth | with empty | max depth | Eq. 3.3 bytes | with empty | actual bytes | build s |");
    let _ = writeln!(
        md,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for &(scene, sf) in kimura_scenes(quick) {
        let src = Source::resolve(scene, Some(sf), Some(3), None)?;
        let prepared = workload::prepare(&src)?;
        let tris = prepared.input.geometry.prims.len() as u64;
        let published_tris = table_tris
            .iter()
            .find(|r| r["scene"] == scene && r["sf"] == sf)
            .and_then(|r| r["triangles"].as_u64());
        let mut depth = std::collections::BTreeMap::new();
        for (builder, builder_name) in builders {
            let mut by_width = std::collections::BTreeMap::new();
            for (engine, width) in widths {
                eprintln!("kimura-3.3: {scene}{sf} {builder} N={width} …");
                let (e, build_s) = workload::build(
                    engine,
                    &prepared.input,
                    settings(&[
                        ("builder", builder),
                        ("wide", "direct"),
                        ("leaf", "1"),
                        ("packets", "off"),
                    ]),
                )?;
                let st = e.build_stats();
                let g = |k: &str| st.get(k).copied().unwrap_or(f64::NAN);
                let _ = writeln!(
                    md,
                    "| {scene}{sf} | {builder_name} | {width} | {tris} ({}) | {} | {} | {} | {:.3} | {:.3} | {} | {} | {} | {} | {:.2} |",
                    published_tris.map_or("-".into(), |p| p.to_string()),
                    g("internal_nodes"), g("leaf_nodes"), g("empty_nodes"), g("avg_leaf_depth"),
                    g("avg_leaf_depth_with_empty"), g("max_leaf_depth"), g("model_bytes"),
                    g("model_bytes_with_empty"), g("node_bytes"), build_s
                );
                by_width.insert(
                    width,
                    (
                        g("avg_leaf_depth"),
                        g("internal_nodes"),
                        g("leaf_nodes"),
                        g("empty_nodes"),
                        g("model_bytes"),
                    ),
                );
                rows.push(json!({"scene": scene, "sf": sf, "builder": builder, "width": width, "engine": engine,
                    "triangles": tris, "triangles_published": published_tris, "build_s": build_s, "stats": st}));
            }
            depth.insert(builder, by_width);
        }
        // 001's claims, for this scene.
        let mut check = |claim: &str, published: String, measured: String, verdict: &str| {
            checks.push(json!({"scene": format!("{scene}{sf}"), "claim": claim, "published": published, "measured": measured, "compares": verdict}));
        };
        if let Some(p) = published_tris {
            check(
                "Table 3.1 triangle count",
                p.to_string(),
                tris.to_string(),
                if p == tris {
                    "count matches"
                } else {
                    "count differs"
                },
            );
        }
        for (builder, _) in builders {
            let w = &depth[builder];
            let r42 = w[&4].0 / w[&2].0;
            check(
                &format!("{builder}: avg leaf depth N=4 / N=2"),
                "about 0.5 (Fig. 3.12/3.16 prose)".into(),
                format!("{r42:.3}"),
                near(r42, 0.5, 0.1),
            );
            let r84 = w[&8].0 / w[&4].0;
            check(
                &format!("{builder}: avg leaf depth N=8 / N=4"),
                "between 0.5 and 1 (not halved)".into(),
                format!("{r84:.3}"),
                if r84 > 0.5 && r84 < 1.0 {
                    "ordering matches"
                } else {
                    "ordering differs"
                },
            );
            let (_, i2, l2, e2, _) = w[&2];
            check(
                &format!("{builder}: N=2 leaves = internal + 1, no empty nodes"),
                "exact (Fig. 3.13 prose)".into(),
                format!("leaves {l2}, internal {i2}, empty {e2}"),
                if l2 == i2 + 1.0 && e2 == 0.0 {
                    "count matches"
                } else {
                    "count differs"
                },
            );
            for n in [4, 8] {
                let r = w[&n].4 / w[&2].4;
                check(
                    &format!("{builder}: Eq. 3.3 memory N={n} / N=2"),
                    "below 1 (Figs. 3.14, 3.19 prose)".into(),
                    format!("{r:.3}"),
                    if r < 1.0 {
                        "ordering matches"
                    } else {
                        "ordering differs"
                    },
                );
            }
        }
        let r = depth["sah-sweep"][&2].0 / depth["median"][&2].0;
        check(
            "N=2 avg leaf depth SAH / median",
            "about 1.1 (Fig. 3.16 prose)".into(),
            format!("{r:.3}"),
            near(r, 1.1, 0.05),
        );
    }
    let _ = writeln!(md, "\n001 §3.3's worked example (16 primitives): balanced depth 4 (N=2) vs 2 (N=4), 15 vs 5 internal nodes; Table 3.3's internal-node bytes 36, 44, 60 for N = 2, 4, 8 are Eq. 3.1 and are what the Eq. 3.3 columns use.\n");
    let _ = writeln!(
        md,
        "| scene | claim | published | measured | how it compares |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|");
    for c in &checks {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} |",
            c["scene"].as_str().unwrap(),
            c["claim"].as_str().unwrap(),
            c["published"].as_str().unwrap(),
            c["measured"].as_str().unwrap(),
            c["compares"].as_str().unwrap()
        );
    }
    let doc = json!({"id": id, "published": published, "measured": rows, "compare": checks, "quick": quick,
        "not_built": "widths 6, 10, 12, 14, 16 (engines have 2, 4, 8); cloister (no source)", "environment": environment(1)});
    write_report(id, out, &doc, &md, as_json)
}

/// One timed engine of `kimura-simd`: label, engine, settings.
type SimdEngine = (
    &'static str,
    &'static str,
    &'static [(&'static str, &'static str)],
);
const SIMD_ENGINES: &[SimdEngine] = &[
    (
        "bvh2 scalar",
        "bvh2",
        &[
            ("builder", "sah-sweep"),
            ("leaf", "1"),
            ("simd", "off"),
            ("packets", "off"),
        ],
    ),
    (
        "bvh4 scalar",
        "bvh4",
        &[
            ("builder", "sah-sweep"),
            ("wide", "direct"),
            ("leaf", "1"),
            ("simd", "off"),
            ("packets", "off"),
        ],
    ),
    (
        "bvh4 SIMD",
        "bvh4",
        &[
            ("builder", "sah-sweep"),
            ("wide", "direct"),
            ("leaf", "1"),
            ("simd", "on"),
            ("packets", "off"),
        ],
    ),
    (
        "bvh8 SIMD",
        "bvh8",
        &[
            ("builder", "sah-sweep"),
            ("wide", "direct"),
            ("leaf", "1"),
            ("simd", "on"),
            ("packets", "off"),
        ],
    ),
    ("embree", "embree", &[]),
];

/// One engine's result: label, median CPU seconds, median wall seconds, counters, hits.
type Timed = (&'static str, f64, f64, Counters, usize);

/// A counter per ray, or "-" when the engine counts nothing (Embree).
fn per_ray(count: u64, rays: f64) -> String {
    if count == 0 {
        "-".into()
    } else {
        format!("{:.2}", count as f64 / rays)
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

/// `kimura-simd`: 001 §4.3's experiment. 800×600 eye rays through pixel centres, one thread
/// (the calling one), the same rays for every engine; median of several timed repeats.
fn kimura_simd(id: &str, quick: bool, out: &Path, as_json: bool) -> Result<()> {
    let published: Value =
        serde_json::from_str(KIMURA_SIMD).expect("data/published/kimura-simd.json is valid JSON");
    let (lo, hi) = (
        published["speedup_simd"]["min"].as_f64().unwrap(),
        published["speedup_simd"]["max"].as_f64().unwrap(),
    );
    let repeats = if quick { 3 } else { 7 };
    let (w, h) = (800u32, 600u32);
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# kimura-simd: SIMD 4-ary single-ray traversal, 001 vs measured\n"
    );
    let _ = writeln!(
        md,
        "Source: {}; {}.",
        published["source"]["document"].as_str().unwrap_or(""),
        published["source"]["section"].as_str().unwrap_or("")
    );
    let _ = writeln!(md, "Published: SIMD made rendering {lo}-{hi}x faster (Core Duo T2050, 4 scenes incl. cloister; baseline 'without SIMD', binary or 4-ary tree not stated).");
    let _ = writeln!(md, "Measured: `rtbench reproduce kimura-simd` ({}), {w}x{h} eye rays through pixel centres (NFF angle vertical, square pixels), intersect only (no shading), one thread, trees `builder=sah-sweep leaf=1 packets=off` (`wide=direct` for bvh4/bvh8), Embree with its defaults. Times: median of {repeats} repeats after one warm-up, CPU time of the calling thread (wall in brackets). Absolute times are not compared with 2006's.\n", if quick { "--quick: gears4 only, fewer repeats" } else { "full" });
    let _ = writeln!(md, "| scene | engine | CPU ms (wall) | nodes/ray | box tests/ray | tri tests/ray | hits | x Embree |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|");
    let mut rows = Vec::new();
    let mut speedups = Vec::new();
    for &(scene, sf) in kimura_scenes(quick) {
        let src = Source::resolve(scene, Some(sf), Some(3), None)?;
        let prepared = workload::prepare(&src)?;
        let camera = Camera::new(&prepared.input.scene.view);
        let rays = camera.pixel_centre_rays(w, h);
        let mut times: Vec<Timed> = Vec::new();
        for &(label, engine, kv) in SIMD_ENGINES {
            let available = rtbench_engines::registry()
                .into_iter()
                .find(|e| e.name == engine)
                .map(|e| (e.available)().is_ok())
                .unwrap_or(false);
            if !available {
                eprintln!("kimura-simd: {engine} is not available here; skipped");
                continue;
            }
            eprintln!("kimura-simd: {scene}{sf} {label} …");
            let (e, build_s) = workload::build(engine, &prepared.input, settings(kv))?;
            let mut hits = vec![Hit::MISS; rays.len()];
            let mut counters = Counters::default();
            e.intersect(&rays, &mut hits, &mut counters);
            let n_hits = hits.iter().filter(|x| x.t.is_finite()).count();
            let (mut cpu, mut wall) = (Vec::new(), Vec::new());
            for _ in 0..repeats {
                let mut c = Counters::default();
                let t = Instant::now();
                let c0 = workload::thread_cpu_seconds();
                e.intersect(&rays, &mut hits, &mut c);
                cpu.push(workload::thread_cpu_seconds() - c0);
                wall.push(t.elapsed().as_secs_f64());
            }
            let (cpu, wall) = (median(&mut cpu), median(&mut wall));
            rows.push(json!({"scene": scene, "sf": sf, "engine": label, "engine_name": engine, "settings": settings(kv),
                "build_s": build_s, "cpu_s": cpu, "wall_s": wall, "repeats": repeats, "rays": rays.len(), "hits": n_hits,
                "counters": {"nodes_visited": counters.nodes_visited, "box_tests": counters.box_tests, "primitive_tests": counters.primitive_tests}}));
            times.push((label, cpu, wall, counters, n_hits));
        }
        let embree = times.iter().find(|t| t.0 == "embree").map(|t| t.1);
        let n = rays.len() as f64;
        for (label, cpu, wall, c, n_hits) in &times {
            let _ = writeln!(
                md,
                "| {scene}{sf} | {label} | {:.1} ({:.1}) | {} | {} | {} | {n_hits} | {} |",
                cpu * 1e3,
                wall * 1e3,
                per_ray(c.nodes_visited, n),
                per_ray(c.box_tests, n),
                per_ray(c.primitive_tests, n),
                embree.map_or("-".into(), |e| format!("{:.2}", cpu / e))
            );
        }
        let get = |l: &str| times.iter().find(|t| t.0 == l).map(|t| t.1);
        if let Some(simd) = get("bvh4 SIMD") {
            for base in ["bvh2 scalar", "bvh4 scalar"] {
                if let Some(b) = get(base) {
                    let s = b / simd;
                    let verdict = if s < lo {
                        "below 001's range"
                    } else if s > hi {
                        "above 001's range"
                    } else {
                        "within 001's range"
                    };
                    speedups.push(json!({"scene": format!("{scene}{sf}"), "over": base, "speedup": s, "published_min": lo, "published_max": hi, "compares": verdict}));
                }
            }
        }
    }
    let _ = writeln!(
        md,
        "\n| scene | bvh4 SIMD over | speed-up (CPU time) | 001 | how it compares |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|");
    for s in &speedups {
        let _ = writeln!(
            md,
            "| {} | {} | {:.2} | {lo}-{hi} | {} |",
            s["scene"].as_str().unwrap(),
            s["over"].as_str().unwrap(),
            s["speedup"].as_f64().unwrap(),
            s["compares"].as_str().unwrap()
        );
    }
    let doc = json!({"id": id, "published": published, "measured": rows, "speedups": speedups, "quick": quick,
        "image": [w, h], "environment": environment(1)});
    write_report(id, out, &doc, &md, as_json)
}
