//! `rtbench reproduce`: published tables, remeasured. The published figures live in
//! `data/published/<id>.json` with their source; they are compiled in from there.
//!
//! `spd-stats`: the SPD README's ray statistics of the seven standard scenes, against the ray
//! counts of our workload with each engine.

use crate::error::{input, Result};
use crate::output::{print_json, write_atomic, write_png};
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
        "001 (Kimura 2007) §3.3-3.5: node statistics of N-ary BVHs, N = 2…16 (orderings and ratios)",
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
    (
        "yamauchi-static-lb",
        "003 (Yamauchi 1997) §4.2.2: (Mπ)² speed-up/efficiency vs PEs, 3 allocations, 1D/2D/3D",
    ),
    (
        "yamauchi-dynamic-lb",
        "003 (Yamauchi 1997) §4.2.2: (Mπ)² efficiency vs RP blocks per PE (2D skewed)",
    ),
    (
        "yamauchi-cfbs",
        "003 (Yamauchi 1997) §3.4, §4.3: cached frame buffer, queueing model vs simulation",
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
            println!("{id:<20} {d}");
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
            write_png(&png, &pixels, size)?;
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

/// 001's branching factors: object median 2–16 in steps of 2, SAH (halving) 2, 4, 8, 16.
const KIMURA_MEDIAN_WIDTHS: [usize; 8] = [2, 4, 6, 8, 10, 12, 14, 16];
const KIMURA_SAH_WIDTHS: [usize; 4] = [2, 4, 8, 16];

/// `kimura-3.3`: 001's trees (object median and full-sweep SAH, 001's own N-ary builders, one
/// triangle per leaf) on 001's SPD scenes, for every branching factor 001 tabulates (2–16),
/// built with [`rtbench_engines::bvh::tree_statistics`] (the engines traverse 2, 4, 8 only).
fn kimura_trees(id: &str, quick: bool, out: &Path, as_json: bool) -> Result<()> {
    use rtbench_engines::bvh::{config::Config, stats::TreeStats, tree_statistics};
    let published: Value =
        serde_json::from_str(KIMURA_TREES).expect("data/published/kimura-3.3.json is valid JSON");
    let table_tris: Vec<&Value> = published["scenes"]["rows"]
        .as_array()
        .unwrap()
        .iter()
        .collect();
    let builders: [(&str, &str, &[usize]); 2] = [
        ("median", "object median", &KIMURA_MEDIAN_WIDTHS),
        ("sah-sweep", "SAH (full sweep)", &KIMURA_SAH_WIDTHS),
    ];
    let mut rows = Vec::new();
    let mut checks = Vec::new();
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# kimura-3.3: node statistics of N-ary BVHs (N = 2…16), 001 vs measured\n"
    );
    let _ = writeln!(
        md,
        "Source: {}; {}.",
        published["source"]["document"].as_str().unwrap_or(""),
        published["source"]["sections"].as_str().unwrap_or("")
    );
    let _ = writeln!(md, "001's plotted values (Figs. 3.12-3.19) are lost; what compares is its orderings and ratios, not absolute values. Cloister is not reproduced (no source).");
    let _ = writeln!(md, "Measured: `rtbench reproduce kimura-3.3` ({}): 001's own N-ary builders (`wide=direct leaf=1`), object median for N = 2, 4, …, 16 and full-sweep SAH for N = 2, 4, 8, 16 (001's SAH halves, so powers of two), built with the library call behind `rtbench tree-stats` (no traversal). Depth: root = 0. Memory: 001 Eq. 3.3 (empty nodes not counted | counted); actual bytes: our N-wide node array (boxes side by side, 64-byte aligned).\n", if quick { "--quick: gears4 only" } else { "full: gears4, tree10, balls4" });
    let _ = writeln!(md, "| scene | builder | N | triangles (Table 3.1) | internal | leaves | empty | avg leaf depth | with empty | max depth | Eq. 3.3 bytes | with empty | actual bytes | build s |");
    let _ = writeln!(
        md,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    // Table 3.3: the internal-node bytes of Eq. 3.1, against the published table.
    let t33_w: Vec<u64> = serde_json::from_value(published["internal_node_bytes"]["width"].clone())
        .expect("kimura-3.3.json: internal_node_bytes.width");
    let t33_b: Vec<u64> = serde_json::from_value(published["internal_node_bytes"]["bytes"].clone())
        .expect("kimura-3.3.json: internal_node_bytes.bytes");
    let ours: Vec<u64> = t33_w
        .iter()
        .map(|&w| TreeStats::internal_node_model_bytes(w as usize))
        .collect();
    checks.push(json!({"scene": "-", "claim": "Table 3.3 internal-node bytes, N = 2…16", "published": format!("{t33_b:?}"),
        "measured": format!("{ours:?}"), "compares": if ours == t33_b { "count matches" } else { "count differs" }}));
    for &(scene, sf) in kimura_scenes(quick) {
        let src = Source::resolve(scene, Some(sf), Some(3), None)?;
        let prepared = workload::prepare(&src)?;
        let geometry = &prepared.input.geometry;
        let tris = geometry.prims.len() as u64;
        let published_tris = table_tris
            .iter()
            .find(|r| r["scene"] == scene && r["sf"] == sf)
            .and_then(|r| r["triangles"].as_u64());
        let mut stats_of = std::collections::BTreeMap::new();
        for (builder, builder_name, widths) in builders {
            let mut by_width = std::collections::BTreeMap::new();
            for &width in widths {
                eprintln!("kimura-3.3: {scene}{sf} {builder} N={width} …");
                let pairs = settings(&[
                    ("builder", builder),
                    ("wide", "direct"),
                    ("leaf", "1"),
                    ("packets", "off"),
                    ("simd", "off"),
                ]);
                let config = Config::parse(width, rtbench_engines::Settings::new("bvh", pairs))?;
                let (t, build_s) = tree_statistics(geometry, &config);
                let _ = writeln!(
                    md,
                    "| {scene}{sf} | {builder_name} | {width} | {tris} ({}) | {} | {} | {} | {:.3} | {:.3} | {} | {} | {} | {} | {:.2} |",
                    published_tris.map_or("-".into(), |p| p.to_string()),
                    t.internal_nodes, t.leaf_nodes, t.empty_nodes, t.avg_leaf_depth,
                    t.avg_leaf_depth_with_empty, t.max_leaf_depth, t.model_bytes(),
                    t.model_bytes_with_empty(), t.node_bytes, build_s
                );
                let mut st = std::collections::BTreeMap::new();
                t.insert_into(&mut st);
                rows.push(json!({"scene": scene, "sf": sf, "builder": builder, "width": width,
                    "triangles": tris, "triangles_published": published_tris, "build_s": build_s, "stats": st}));
                by_width.insert(width, t);
            }
            stats_of.insert(builder, by_width);
        }
        // 001's claims, for this scene.
        let mut check = |claim: &str, published: String, measured: String, verdict: &str| {
            checks.push(json!({"scene": format!("{scene}{sf}"), "claim": claim, "published": published, "measured": measured, "compares": verdict}));
        };
        let ordering = |ok: bool| {
            if ok {
                "ordering matches"
            } else {
                "ordering differs"
            }
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
        for (builder, _, widths) in builders {
            let w = &stats_of[builder];
            let depth = |n: usize| w[&n].avg_leaf_depth;
            let r42 = depth(4) / depth(2);
            check(
                &format!("{builder}: avg leaf depth N=4 / N=2"),
                "about 0.5 (Fig. 3.12/3.16 prose)".into(),
                format!("{r42:.3}"),
                near(r42, 0.5, 0.1),
            );
            let r84 = depth(8) / depth(4);
            check(
                &format!("{builder}: avg leaf depth N=8 / N=4"),
                "between 0.5 and 1 (not halved)".into(),
                format!("{r84:.3}"),
                ordering(r84 > 0.5 && r84 < 1.0),
            );
            let t2 = &w[&2];
            check(
                &format!("{builder}: N=2 leaves = internal + 1, no empty nodes"),
                "exact (Fig. 3.13 prose)".into(),
                format!(
                    "leaves {}, internal {}, empty {}",
                    t2.leaf_nodes, t2.internal_nodes, t2.empty_nodes
                ),
                if t2.leaf_nodes == t2.internal_nodes + 1 && t2.empty_nodes == 0 {
                    "count matches"
                } else {
                    "count differs"
                },
            );
            let m2 = t2.model_bytes() as f64;
            let ratios: Vec<String> = widths[1..]
                .iter()
                .map(|n| format!("{n}: {:.3}", w[n].model_bytes() as f64 / m2))
                .collect();
            let below = widths[1..]
                .iter()
                .filter(|n| (w[*n].model_bytes() as f64) < m2)
                .count();
            check(
                &format!("{builder}: Eq. 3.3 memory N / N=2, every N > 2"),
                "below 1 for almost every N (Figs. 3.14, 3.19 prose)".into(),
                format!(
                    "{} ({below} of {} below 1)",
                    ratios.join(", "),
                    widths.len() - 1
                ),
                ordering(below + 1 >= widths.len() - 1),
            );
        }
        let sah = &stats_of["sah-sweep"];
        let mem = |n: usize| sah[&n].model_bytes();
        let lowest = [2, 4, 8, 16].into_iter().min_by_key(|&n| mem(n)).unwrap();
        check(
            "sah-sweep: Eq. 3.3 memory lowest at N=4 and 8, slightly higher at 16",
            "lowest at 4 and 8; 16 slightly higher (Fig. 3.19 prose)".into(),
            format!(
                "lowest at N={lowest}; N=16 / min(4, 8) = {:.3}",
                mem(16) as f64 / mem(4).min(mem(8)) as f64
            ),
            ordering((lowest == 4 || lowest == 8) && mem(16) > mem(4).min(mem(8))),
        );
        let r = stats_of["sah-sweep"][&2].avg_leaf_depth / stats_of["median"][&2].avg_leaf_depth;
        check(
            "N=2 avg leaf depth SAH / median",
            "about 1.1 (Fig. 3.16 prose)".into(),
            format!("{r:.3}"),
            near(r, 1.1, 0.05),
        );
    }
    let _ = writeln!(md, "\n001 §3.3's worked example (16 primitives): balanced depth 4 (N=2) vs 2 (N=4), 15 vs 5 internal nodes (a unit test builds it); Table 3.3's internal-node bytes 28 + 4N are what the Eq. 3.3 columns use.\n");
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
        "not_built": "cloister (no source)", "environment": environment(1)});
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

/// The second table of `kimura-simd`: the engines as users run them (their default trees and
/// leaves), with obvhs's two layouts, on 001's rays: issue 5's side-by-side benchmark.
const DEFAULT_ENGINES: &[SimdEngine] = &[
    ("bvh2 scalar", "bvh2", &[]),
    ("bvh4 scalar", "bvh4", &[("simd", "off")]),
    ("bvh4 SIMD", "bvh4", &[]),
    ("bvh8 SIMD", "bvh8", &[]),
    ("obvhs cwbvh", "obvhs", &[]),
    ("obvhs bvh2", "obvhs", &[("layout", "bvh2")]),
    ("embree", "embree", &[]),
];

/// One engine's result: label, median CPU seconds, median wall seconds, counters, hits, build
/// seconds, structure bytes per primitive.
type Timed = (&'static str, f64, f64, Counters, usize, f64, f64);

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

/// Times every available engine of `engines` on `rays` (closest hit, the calling thread): one
/// warm-up, then the median of `repeats` CPU and wall times; the build time is the median wall
/// time of `builds` builds. Appends a JSON row per engine.
fn time_engines(
    engines: &[SimdEngine],
    input: &rtbench_engines::BuildInput,
    rays: &[rtbench_engines::Ray],
    repeats: usize,
    builds: usize,
    (scene, sf): (&str, u32),
    rows: &mut Vec<Value>,
) -> Result<Vec<Timed>> {
    let mut times: Vec<Timed> = Vec::new();
    for &(label, engine, kv) in engines {
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
        let (mut e, build_s) = workload::build(engine, input, settings(kv))?;
        let mut build_times = vec![build_s];
        for _ in 1..builds {
            drop(e);
            let (again, s) = workload::build(engine, input, settings(kv))?;
            e = again;
            build_times.push(s);
        }
        let build_s = median(&mut build_times);
        let mut hits = vec![Hit::MISS; rays.len()];
        let mut counters = Counters::default();
        e.intersect(rays, &mut hits, &mut counters);
        let n_hits = hits.iter().filter(|x| x.t.is_finite()).count();
        let (mut cpu, mut wall) = (Vec::new(), Vec::new());
        for _ in 0..repeats {
            let mut c = Counters::default();
            let t = Instant::now();
            let c0 = workload::thread_cpu_seconds();
            e.intersect(rays, &mut hits, &mut c);
            cpu.push(workload::thread_cpu_seconds() - c0);
            wall.push(t.elapsed().as_secs_f64());
        }
        let (cpu, wall) = (median(&mut cpu), median(&mut wall));
        rows.push(json!({"scene": scene, "sf": sf, "engine": label, "engine_name": engine, "settings": settings(kv),
            "build_s": build_s, "cpu_s": cpu, "wall_s": wall, "repeats": repeats, "rays": rays.len(), "hits": n_hits,
            "structure_bytes": e.structure_bytes(), "primitives": input.geometry.prims.len(),
            "counters": {"nodes_visited": counters.nodes_visited, "box_tests": counters.box_tests, "primitive_tests": counters.primitive_tests}}));
        let bytes_per_prim = e.structure_bytes() as f64 / input.geometry.prims.len().max(1) as f64;
        times.push((label, cpu, wall, counters, n_hits, build_s, bytes_per_prim));
    }
    Ok(times)
}

/// Table rows of timed engines, with the time ratio to Embree's.
fn write_timed(md: &mut String, scene: &str, times: &[Timed], n: f64) {
    let embree = times.iter().find(|t| t.0 == "embree").map(|t| t.1);
    for (label, cpu, wall, c, n_hits, build_s, bpp) in times {
        let _ = writeln!(
            md,
            "| {scene} | {label} | {:.1} ({:.1}) | {} | {} | {} | {n_hits} | {} | {:.0} | {bpp:.1} |",
            cpu * 1e3,
            wall * 1e3,
            per_ray(c.nodes_visited, n),
            per_ray(c.box_tests, n),
            per_ray(c.primitive_tests, n),
            embree.map_or("-".into(), |e| format!("{:.2}", cpu / e)),
            build_s * 1e3
        );
    }
}

/// Issue 5's goals on one scene: bvh4/bvh8 SIMD at ≥ 0.8× Embree's rays per second and ≥ 1.5×
/// the faster obvhs layout's; builds ≤ 3× Embree's build time.
fn engine_goals(scene: &str, times: &[Timed]) -> Vec<Value> {
    let get = |l: &str| times.iter().find(|t| t.0 == l);
    let mut out = Vec::new();
    let obvhs = ["obvhs cwbvh", "obvhs bvh2"]
        .iter()
        .filter_map(|l| get(l).map(|t| t.1))
        .min_by(|a, b| a.total_cmp(b));
    for l in ["bvh4 SIMD", "bvh8 SIMD"] {
        let Some(t) = get(l) else { continue };
        let mut goal = |ratio: String, goal: &str, measured: f64, met: bool| {
            out.push(json!({"scene": scene, "ratio": ratio, "goal": goal, "measured": measured, "met": met}));
        };
        if let Some(e) = get("embree") {
            let r = e.1 / t.1;
            goal(format!("{l} rays/s ÷ Embree's"), "≥ 0.8", r, r >= 0.8);
            let b = t.5 / e.5;
            goal(format!("{l} build s ÷ Embree's"), "≤ 3", b, b <= 3.0);
        }
        if let Some(o) = obvhs {
            let r = o / t.1;
            goal(format!("{l} rays/s ÷ fastest obvhs'"), "≥ 1.5", r, r >= 1.5);
        }
    }
    out
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
    let repeats: usize = if quick { 3 } else { 7 };
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
    let _ = writeln!(md, "| scene | engine | CPU ms (wall) | nodes/ray | box tests/ray | tri tests/ray | hits | x Embree | build ms | B/prim |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    let mut rows = Vec::new();
    let mut speedups = Vec::new();
    let (mut default_rows, mut default_md, mut goals) = (Vec::new(), String::new(), Vec::new());
    for &(scene, sf) in kimura_scenes(quick) {
        let src = Source::resolve(scene, Some(sf), Some(3), None)?;
        let prepared = workload::prepare(&src)?;
        let camera = Camera::new(&prepared.input.scene.view);
        let rays = camera.pixel_centre_rays(w, h);
        let times = time_engines(
            SIMD_ENGINES,
            &prepared.input,
            &rays,
            repeats,
            1,
            (scene, sf),
            &mut rows,
        )?;
        write_timed(&mut md, &format!("{scene}{sf}"), &times, rays.len() as f64);
        let defaults = time_engines(
            DEFAULT_ENGINES,
            &prepared.input,
            &rays,
            repeats,
            3,
            (scene, sf),
            &mut default_rows,
        )?;
        write_timed(
            &mut default_md,
            &format!("{scene}{sf}"),
            &defaults,
            rays.len() as f64,
        );
        goals.extend(engine_goals(&format!("{scene}{sf}"), &defaults));
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
    let _ = writeln!(
        md,
        "\n## The engines at their defaults, same rays (issue 5's side-by-side)\n"
    );
    let _ = writeln!(md, "Default trees and leaves (bvh2: binned SAH, leaf 1; bvh4/bvh8: binned SAH collapsed, leaf 4, triangle packets; obvhs: PLOC, `medium` preset), one thread, same rays and timing as above; build: median wall time of 3 builds (Embree builds with its own threads).\n");
    let _ = writeln!(md, "| scene | engine | CPU ms (wall) | nodes/ray | box tests/ray | tri tests/ray | hits | x Embree | build ms | B/prim |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    md.push_str(&default_md);
    let _ = writeln!(md, "\n| scene | ratio | goal | measured | met |");
    let _ = writeln!(md, "|---|---|---|---|---|");
    for g in &goals {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.2} | {} |",
            g["scene"].as_str().unwrap(),
            g["ratio"].as_str().unwrap(),
            g["goal"].as_str().unwrap(),
            g["measured"].as_f64().unwrap(),
            if g["met"].as_bool().unwrap() {
                "yes"
            } else {
                "no"
            }
        );
    }
    let doc = json!({"id": id, "published": published, "measured": rows, "speedups": speedups, "quick": quick,
        "defaults": default_rows, "goals": goals, "image": [w, h], "environment": environment(1)});
    write_report(id, out, &doc, &md, as_json)
}
