//! `rtbench reproduce nakamaru-3.2`: where the in-memory grid starts to thrash, measured so that
//! any machine gives the same answer (seed 000 §3.4, Table 3.2, Figs. 3.5–3.7).
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
//! `--fault-ms X` one more (X ms, 100 MB/s).

use super::reproduce::write_report;
use crate::error::{input, Result};
use crate::output::write_atomic;
use crate::source::Source;
use crate::workload::paging::Mattson;
use crate::workload::{self, trace};
use rtbench_engines::breadth_first::config::BreadthFirstConfig;
use rtbench_engines::breadth_first::BreadthFirst;
use rtbench_engines::grid::config::GridConfig;
use rtbench_engines::grid::paging::PAGE;
use rtbench_engines::grid::Grid;
use rtbench_engines::{Engine, Settings};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

const PUBLISHED: &str = include_str!("../../../data/published/nakamaru-3.2.json");

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

/// A limit on the SFs run: (scene or every scene, lowest, highest).
type Cap = (Option<String>, Option<u32>, u32);

/// `--max-sf N` (every scene), `--max-sf balls=6,tree=14` (those scenes), or with a range
/// `tree=17..18` (only those SFs of that scene): (scene, lowest, highest).
fn parse_caps(s: Option<&str>) -> Result<Vec<Cap>> {
    let Some(s) = s else { return Ok(Vec::new()) };
    let bad = || {
        input(format!(
            "--max-sf '{s}': expected N or scene=N,scene=LO..HI"
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

pub fn run(
    id: &str,
    quick: bool,
    out: &Path,
    max_sf: Option<&str>,
    fault_ms: Option<f64>,
    as_json: bool,
) -> Result<()> {
    let caps = parse_caps(max_sf)?;
    let published: Value = serde_json::from_str(PUBLISHED).expect("nakamaru-3.2.json is valid");
    let memory = published["memory_mb"].as_u64().unwrap() << 20;
    let frames = memory / PAGE;
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
    if let Some(ms) = fault_ms {
        if !(ms.is_finite() && ms > 0.0) {
            return Err(input(format!(
                "--fault-ms {ms}: expected a number of ms above 0"
            )));
        }
        disks.push(Disk {
            name: format!("{ms} ms"),
            fault_s: ms * 1e-3,
            bandwidth: 100e6,
        });
    }
    std::fs::create_dir_all(out.join("plots"))
        .map_err(|e| input(format!("{}: cannot create: {e}", out.display())))?;
    let ranges = published["sf_ranges"].as_object().unwrap();
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# nakamaru-3.2: thrashing onset of the in-memory grid, 32 MiB\n"
    );
    let _ = writeln!(md, "Published: {}, {}. The figures' curves are lost; Table 3.2 (rayshade-ss memory per SF) survives and is shown beside ours.\n", published["source"]["document"].as_str().unwrap_or(""), published["source"]["sections"].as_str().unwrap_or(""));
    let _ = writeln!(md, "Measured: `rtbench reproduce nakamaru-3.2{}{}{}`, one thread, 512×512. Grid: `grid` rss-r, its page stream (cell offsets, references, primitives, primitive→object, mailbox; 4 KiB pages) through Mattson's stack algorithm at {} pages; modelled = measured compute + pages touched × 4 KiB ÷ bandwidth (loading the data once) + faults beyond first touch × fault cost. Breadth-first: memory=32MiB, registration ⌈r/10+0.5⌉; modelled = measured + I/O bytes ÷ bandwidth + seeks × seek cost. Onset: smallest SF with modelled grid time per ray > 2 × its in-core time per ray. Crossover: smallest SF with modelled grid time > modelled breadth-first time.\n",
        if quick { " --quick" } else { "" }, max_sf.map(|m| format!(" --max-sf {m}")).unwrap_or_default(), fault_ms.map(|m| format!(" --fault-ms {m}")).unwrap_or_default(), frames);
    let mut scenes_json = Vec::new();
    let mut summary = Vec::new();
    for (scene, range) in ranges {
        let mut lo = range[0].as_u64().unwrap() as u32;
        let mut hi = range[1].as_u64().unwrap() as u32;
        if let Some(m) = caps
            .iter()
            .find(|c| c.0.is_none() || c.0.as_deref() == Some(scene.as_str()))
        {
            lo = lo.max(m.1.unwrap_or(0));
            hi = hi.min(m.2);
        }
        if quick {
            hi = hi.min(lo + 1);
        }
        if lo > hi {
            continue;
        }
        let floor = if scene == "balls" || scene == "tree" {
            "out"
        } else {
            "in"
        };
        let mut pts = Vec::new();
        for sf in lo..=hi {
            eprintln!("nakamaru-3.2: {scene}{sf} …");
            let src = Source::resolve(scene, Some(sf), None, None)?;
            let prepared = workload::prepare(&src)?;
            let mut p = grid_point(&prepared, floor, frames)?;
            p.sf = sf;
            breadth_first_point(&prepared, floor, &mut p)?;
            pts.push(p);
        }
        let _ = writeln!(md, "## {scene} (SF {lo}–{hi})\n");
        let _ = writeln!(md, "| SF | objects | Table 3.2 MB | grid MB (model) | page accesses | pages touched | faults @32 MiB beyond first touch | grid compute s | bf measured s | bf I/O MB | bf seeks | bf passes | {} |",
            disks.iter().map(|d| format!("grid model s ({0}) | bf model s ({0})", d.name)).collect::<Vec<_>>().join(" | "));
        let _ = writeln!(
            md,
            "|---|---|---|---|---|---|---|---|---|---|---|{}",
            "---|---|".repeat(disks.len())
        );
        let mut rows = Vec::new();
        for p in &pts {
            let t32 = published["table_3_2"]
                .as_array()
                .unwrap()
                .iter()
                .find(|r| r["scene"] == scene.as_str() && r["sf"] == p.sf)
                .and_then(|r| r["mb"].as_f64());
            let models: Vec<String> = disks
                .iter()
                .map(|d| format!("{:.2} | {:.2}", p.grid_model(d), p.bf_model(d)))
                .collect();
            let _ = writeln!(
                md,
                "| {} | {} | {} | {:.1} | {} | {} | {} | {:.2} | {:.2} | {:.1} | {} | {} | {} |",
                p.sf,
                p.objects,
                t32.map(|v| v.to_string()).unwrap_or("–".into()),
                p.grid_bytes as f64 / 1e6,
                p.accesses,
                p.distinct,
                p.faults,
                p.grid_s,
                p.bf_s,
                p.bf_io_bytes as f64 / 1e6,
                p.bf_seeks,
                p.bf_passes,
                models.join(" | ")
            );
            rows.push(json!({"sf": p.sf, "objects": p.objects, "rays": p.rays, "table_3_2_mb": t32,
                "grid_bytes": p.grid_bytes, "page_accesses": p.accesses, "pages_touched": p.distinct, "faults_beyond_first_touch": p.faults,
                "grid_compute_s": p.grid_s, "bf_measured_s": p.bf_s, "bf_io_bytes": p.bf_io_bytes,
                "bf_seeks": p.bf_seeks, "bf_passes": p.bf_passes,
                "model": disks.iter().map(|d| json!({"disk": d.name, "grid_s": p.grid_model(d), "bf_s": p.bf_model(d)})).collect::<Vec<_>>()}));
        }
        let mut per_disk = Vec::new();
        for (k, d) in disks.iter().enumerate() {
            let onset = pts
                .iter()
                .find(|p| p.grid_model(d) / p.rays as f64 > 2.0 * p.grid_s / p.rays as f64)
                .map(|p| p.sf);
            let cross = pts
                .iter()
                .find(|p| p.grid_model(d) > p.bf_model(d))
                .map(|p| p.sf);
            let show = |v: Option<u32>| {
                v.map(|s| s.to_string())
                    .unwrap_or_else(|| format!("none ≤ {hi}"))
            };
            let _ = writeln!(
                md,
                "\n{}: onset SF {}, crossover SF {}.",
                d.name,
                show(onset),
                show(cross)
            );
            summary.push((scene.clone(), d.name.clone(), show(onset), show(cross)));
            per_disk.push(json!({"disk": d.name, "onset_sf": onset, "crossover_sf": cross}));
            if k == 0 && pts.len() >= 2 {
                let svg = plot(scene, &pts, d, onset);
                let f = out.join("plots").join(format!("nakamaru-3.2-{scene}.svg"));
                write_atomic(&f, |w| std::io::Write::write_all(w, svg.as_bytes()))?;
                let _ = writeln!(md, "\n![{scene}](plots/nakamaru-3.2-{scene}.svg)");
            }
        }
        let _ = writeln!(md);
        scenes_json.push(json!({"scene": scene, "sf": [lo, hi], "floor": floor, "rows": rows, "result": per_disk}));
    }
    let _ = writeln!(
        md,
        "## Summary\n\n| scene | disk | onset SF | crossover SF |\n|---|---|---|---|"
    );
    for (s, d, o, c) in &summary {
        let _ = writeln!(md, "| {s} | {d} | {o} | {c} |");
    }
    let _ = writeln!(
        md,
        "\nPublished pattern (000 §3.4): {}",
        published["claims"][0]["claim"].as_str().unwrap_or("")
    );
    let doc = json!({"id": id, "published": published, "measured": scenes_json, "quick": quick, "max_sf": max_sf,
        "memory_bytes": memory, "page_bytes": PAGE,
        "environment": {"os": std::env::consts::OS, "arch": std::env::consts::ARCH, "threads": 1}});
    write_report(id, out, &doc, &md, as_json)
}
