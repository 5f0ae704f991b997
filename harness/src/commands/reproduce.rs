//! `rtbench reproduce`: published tables, remeasured. The published figures live in
//! `data/published/<id>.json` with their source; they are compiled in from there.
//!
//! `spd-stats`: the SPD README's ray statistics of the seven standard scenes, against the ray
//! counts of our workload with each engine.

use crate::error::{input, Result};
use crate::output::{print_json, write_atomic};
use crate::source::Source;
use crate::workload::{self, trace};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::Path;

const SPD_STATS: &str = include_str!("../../../data/published/spd-stats.json");

/// Every reproducible table: id, what it is.
const TABLES: &[(&str, &str)] = &[(
    "spd-stats",
    "SPD 3.14 README: ray statistics of the seven standard scenes (counts within 10%)",
)];

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
    if id != "spd-stats" {
        let ids: Vec<_> = TABLES.iter().map(|t| t.0).collect();
        return Err(input(format!(
            "unknown table '{id}' (known: {})",
            ids.join(", ")
        )));
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
    write_atomic(&out.join(format!("{id}.json")), |w| {
        serde_json::to_writer_pretty(w, &doc).map_err(std::io::Error::other)
    })?;
    write_atomic(&out.join(format!("{id}.md")), |w| {
        std::io::Write::write_all(w, md.as_bytes())
    })?;
    if as_json {
        print_json(&doc);
    } else {
        print!("{md}");
    }
    Ok(())
}
