//! `rtbench reproduce yamauchi-static-lb | yamauchi-dynamic-lb | yamauchi-cfbs`: seed 003's
//! (Mπ)² evaluation (Yamauchi 1997, ch. 4) on SPD scenes. 003's own ray-tracing pass
//! ([`crate::workload::yamauchi`]) is executed once per scene on the object-space engine and
//! timed on every machine configuration by the engine's event simulation. The published figures
//! (prose only: 003's plots are lost) are in `data/published/yamauchi-*.json`.

use crate::error::{input, Result};
use crate::output::{write_atomic, write_png};
use crate::source::Source;
use crate::workload::{self, yamauchi};
use rayon::prelude::*;
use rtbench_engines::object_space::config::{Costs, FrameBuffer, ObjectSpaceConfig};
use rtbench_engines::object_space::machine::{Allocation, Machine};
use rtbench_engines::object_space::queueing::{self, Model};
use rtbench_engines::object_space::sim::{simulate, SimResult};
use rtbench_engines::object_space::ObjectSpace;
use rtbench_reports::plot::{self, Chart, LegendAt, Panel, Point, Series, XyPanel};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

const STATIC_LB: &str = include_str!("../../../data/published/yamauchi-static-lb.json");
const DYNAMIC_LB: &str = include_str!("../../../data/published/yamauchi-dynamic-lb.json");
const CFBS: &str = include_str!("../../../data/published/yamauchi-cfbs.json");

/// Limits a user may put on the experiments (the full ones take long on a small machine).
#[derive(Clone, Debug, Default)]
pub struct Limits {
    pub size: Option<u32>,
    pub max_pes: Option<u32>,
    pub scenes: Option<String>,
}

/// One scene, executed once: the engine (its subspaces and primitives) and 003's pass on it.
struct Traced {
    label: String,
    os: ObjectSpace,
    pass: yamauchi::Pass,
    trace_s: f64,
}

fn trace_scenes(scenes: &[String], size: u32, out: &Path) -> Result<Vec<Traced>> {
    trace_scenes_with(scenes, size, out, Costs::default())
}

/// As [`trace_scenes`], with the engine's unit costs (the per-test clocks enter the record).
fn trace_scenes_with(
    scenes: &[String],
    size: u32,
    out: &Path,
    costs: Costs,
) -> Result<Vec<Traced>> {
    std::fs::create_dir_all(out.join("images"))
        .map_err(|e| input(format!("{}: cannot create: {e}", out.display())))?;
    let mut v = Vec::new();
    for s in scenes {
        let src = Source::resolve(s, None, None, None)?;
        let prepared = workload::prepare(&src)?;
        let label = prepared.input.scene.name.clone();
        let config = ObjectSpaceConfig {
            costs,
            ..ObjectSpaceConfig::default()
        };
        let os = ObjectSpace::build(&prepared.input, config).map_err(|e| input(e.to_string()))?;
        eprintln!("{label}: tracing 003's pass at {size}x{size} …");
        let t = Instant::now();
        let pass = yamauchi::trace_pass(&os, &prepared.input.scene, size);
        let trace_s = t.elapsed().as_secs_f64();
        let png = out.join("images").join(format!("{label}-yamauchi.png"));
        let pixels = pass.pixels();
        write_png(&png, &pixels, size)?;
        v.push(Traced {
            label,
            os,
            pass,
            trace_s,
        });
    }
    Ok(v)
}

/// PEs per axis for `pes` (a power of two) on a `dims`-dimensional torus, as even as possible,
/// the larger counts first.
fn shape(pes: u32, dims: u8) -> [u32; 3] {
    let k = pes.trailing_zeros();
    let mut s = [1u32; 3];
    for i in 0..dims as u32 {
        let bits = k / dims as u32 + u32::from(i < k % dims as u32);
        s[i as usize] = 1 << bits;
    }
    s
}

fn machine(pes: u32, dims: u8, allocation: Allocation, rp_blocks: u32) -> Machine {
    Machine {
        pes: shape(pes, dims),
        dims,
        allocation,
        rp_blocks,
    }
}

/// Simulates each machine on `t` (in parallel over machines) with the given frame buffer.
fn run_all(t: &Traced, machines: &[(Machine, FrameBuffer)]) -> Vec<(SimResult, f64)> {
    let s = t.os.config().subspaces;
    machines
        .par_iter()
        .map(|(m, fb)| {
            let start = Instant::now();
            let r = simulate(
                &t.pass.trace,
                m,
                &m.owner_map(s),
                &t.os.config().costs,
                *fb,
                t.pass.size,
            );
            (r, start.elapsed().as_secs_f64())
        })
        .collect()
}

fn scenes_of(limits: &Limits, default: &[&str]) -> Vec<String> {
    match &limits.scenes {
        Some(l) => l
            .split(',')
            .map(|s| s.trim().to_string())
            .filter(|s| !s.is_empty())
            .collect(),
        None => default.iter().map(|s| s.to_string()).collect(),
    }
}

fn size_of(limits: &Limits, quick: bool) -> Result<u32> {
    let size = limits.size.unwrap_or(if quick { 128 } else { 512 });
    workload::check_size(size)?;
    Ok(size)
}

fn powers(max: u32) -> Vec<u32> {
    (0..=12).map(|k| 1u32 << k).filter(|&p| p <= max).collect()
}

fn write_plot(out: &Path, chart: &Chart) -> Result<()> {
    let dir = out.join("plots");
    std::fs::create_dir_all(&dir)
        .map_err(|e| input(format!("{}: cannot create: {e}", dir.display())))?;
    let svg = plot::svg(chart).map_err(input)?;
    write_atomic(&dir.join(format!("{}.svg", chart.stem)), |w| {
        std::io::Write::write_all(w, svg.as_bytes())
    })?;
    let png = plot::png(chart).map_err(input)?;
    write_atomic(&dir.join(format!("{}.png", chart.stem)), |w| {
        std::io::Write::write_all(w, &png)
    })
}

fn panel(title: &str, x: &str, y: &str, series: Vec<Series>, legend: LegendAt) -> Panel {
    Panel::Xy(XyPanel {
        title: title.into(),
        x_label: x.into(),
        y_label: y.into(),
        x_log: true,
        y_log: false,
        x_ticks: Vec::new(),
        lines: true,
        legend,
        series,
    })
}

fn series(name: &str, color: usize, pts: &[(f64, f64)]) -> Series {
    Series {
        name: name.into(),
        color,
        points: pts
            .iter()
            .map(|&(x, y)| Point {
                x,
                y,
                y_range: None,
            })
            .collect(),
    }
}

fn pass_json(t: &Traced) -> Value {
    json!({"scene": t.label, "size": t.pass.size, "primary": t.pass.primary, "secondary": t.pass.secondary,
        "intensity_packets": t.pass.intensity_packets, "subspace_visits": t.pass.trace.segs.len(),
        "primitive_tests": t.pass.counters.primitive_tests, "trace_s": t.trace_s,
        "image": format!("images/{}-yamauchi.png", t.label)})
}

fn sim_json(r: &SimResult, t1: u64, blocks: u64, wall: f64) -> Value {
    let speedup = t1 as f64 / r.clocks as f64;
    json!({"clocks": r.clocks, "speedup": speedup, "efficiency": speedup / blocks as f64,
        "utilisation": r.utilisation(), "imbalance": r.imbalance(), "frgu_clocks": r.frgu_clocks, "events": r.events,
        "packets": r.packets, "hops": r.hops, "frame_buffer": r.frame_buffer, "wall_s": wall,
        "events_per_s": r.events as f64 / wall.max(1e-9)})
}

/// `yamauchi-static-lb`: speed-up and efficiency vs PEs, three allocations, 1D/2D/3D, 1 RP block.
pub fn static_lb(
    id: &str,
    quick: bool,
    limits: &Limits,
    out: &Path,
    threads: Option<usize>,
    as_json: bool,
) -> Result<()> {
    let published: Value = serde_json::from_str(STATIC_LB).expect("valid JSON");
    let size = size_of(limits, quick)?;
    let max_pes = limits.max_pes.unwrap_or(if quick { 256 } else { 1024 });
    if max_pes == 0 {
        return Err(input("--max-pes must be at least 1"));
    }
    let scenes = scenes_of(
        limits,
        if quick {
            &["tetra"]
        } else {
            &["balls", "rings", "tetra"]
        },
    );
    let pool = workload::pool(threads)?;
    let traced = trace_scenes(&scenes, size, out)?;
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# yamauchi-static-lb: (Mπ)² static load balancing on SPD scenes\n"
    );
    let _ = writeln!(
        md,
        "Source: {}; {}. {}\n",
        published["source"]["document"].as_str().unwrap_or(""),
        published["source"]["sections"].as_str().unwrap_or(""),
        published["source"]["note"].as_str().unwrap_or("")
    );
    let _ = writeln!(md, "Measured: `rtbench reproduce {id}{}` — 003's ray-tracing pass (1 primary ray per pixel centre, ≤ 3 reflections, no shadow rays) at {size}×{size}, 32³ subspaces, 1 RP block per PE, Table 4 costs, direct frame buffer; PEs up to {max_pes} (a 1D machine's PE count must divide the 32 subspaces of its axis, so 1D stops at 32; 3D has no skewed allocation in 003). Efficiency = T(1 PE) / (T × PEs).\n", if quick { " --quick" } else { "" });
    let mut rows = Vec::new();
    let mut findings = Vec::new();
    for t in &traced {
        let mut machines = vec![(machine(1, 1, Allocation::Block, 1), FrameBuffer::Direct)];
        let mut keys = vec![(1u8, Allocation::Block, 1u32)];
        for dims in 1..=3u8 {
            let cap = if dims == 1 {
                max_pes.min(32)
            } else {
                max_pes.min(1024)
            };
            for alloc in [
                Allocation::Block,
                Allocation::Distributed,
                Allocation::Skewed,
            ] {
                if dims == 3 && alloc == Allocation::Skewed {
                    continue;
                }
                for p in powers(cap).into_iter().filter(|&p| p > 1) {
                    machines.push((machine(p, dims, alloc, 1), FrameBuffer::Direct));
                    keys.push((dims, alloc, p));
                }
            }
        }
        eprintln!("{}: simulating {} machines …", t.label, machines.len());
        let results = pool.install(|| run_all(t, &machines));
        let t1 = results[0].0.clocks;
        let eff = |dims: u8, alloc: Allocation, p: u32| -> Option<f64> {
            if p == 1 {
                return Some(1.0);
            }
            keys.iter()
                .position(|k| *k == (dims, alloc, p))
                .map(|i| t1 as f64 / (results[i].0.clocks as f64 * p as f64))
        };
        // Table and JSON.
        let _ = writeln!(
            md,
            "## {} (T(1 PE) = {t1} clocks; {} rays, {} subspace visits)\n",
            t.label,
            t.pass.primary + t.pass.secondary,
            t.pass.trace.segs.len()
        );
        let _ = writeln!(md, "| PEs | 1D block | 1D distributed | 1D skewed | 2D block | 2D distributed | 2D skewed | 3D block | 3D distributed |");
        let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|");
        for p in powers(max_pes.min(1024)) {
            let mut cells = Vec::new();
            for (d, a) in [
                (1, Allocation::Block),
                (1, Allocation::Distributed),
                (1, Allocation::Skewed),
                (2, Allocation::Block),
                (2, Allocation::Distributed),
                (2, Allocation::Skewed),
                (3, Allocation::Block),
                (3, Allocation::Distributed),
            ] {
                cells.push(eff(d, a, p).map_or("–".to_string(), |e| format!("{:.1}%", e * 100.0)));
            }
            let _ = writeln!(md, "| {p} | {} |", cells.join(" | "));
        }
        let mut sims = Vec::new();
        for (k, (r, wall)) in keys.iter().zip(&results) {
            let mut v = sim_json(r, t1, k.2 as u64, *wall);
            v["dims"] = json!(k.0);
            v["allocation"] = json!(k.1.name());
            v["pes"] = json!(k.2);
            v["shape"] = json!(machine(k.2, k.0, k.1, 1).pes_label());
            sims.push(v);
        }
        // Findings.
        let mut order = serde_json::Map::new();
        let mut order_md = Vec::new();
        let mut ordering_holds = true;
        for dims in 1..=3u8 {
            let cap = if dims == 1 {
                max_pes.min(32)
            } else {
                max_pes.min(1024)
            };
            let ps: Vec<u32> = powers(cap).into_iter().filter(|&p| p > 1).collect();
            let count = |a: Allocation, b: Allocation| {
                ps.iter()
                    .filter(|&&p| eff(dims, a, p) < eff(dims, b, p))
                    .count()
            };
            let bd = count(Allocation::Block, Allocation::Distributed);
            if dims < 3 {
                let ds = count(Allocation::Distributed, Allocation::Skewed);
                let bs = count(Allocation::Block, Allocation::Skewed);
                ordering_holds &= ds == ps.len() && bs == ps.len();
                order_md.push(format!("{dims}D: block < distributed at {bd}/{n}, distributed < skewed at {ds}/{n}, block < skewed at {bs}/{n} PE counts", n = ps.len()));
                order.insert(format!("{dims}d"), json!({"pe_counts": ps, "block_lt_distributed": bd, "distributed_lt_skewed": ds, "block_lt_skewed": bs}));
            } else {
                order_md.push(format!(
                    "3D: block < distributed at {bd}/{} PE counts",
                    ps.len()
                ));
                order.insert(
                    "3d".into(),
                    json!({"pe_counts": ps, "block_lt_distributed": bd}),
                );
            }
        }
        let ps23: Vec<u32> = powers(max_pes.min(1024))
            .into_iter()
            .filter(|&p| p > 1)
            .collect();
        let skew_ge = ps23
            .iter()
            .filter(|&&p| eff(2, Allocation::Skewed, p) >= eff(3, Allocation::Distributed, p))
            .count();
        let e256 = eff(2, Allocation::Skewed, 256);
        let b256 = eff(2, Allocation::Block, 256);
        let verdict = |b: bool| if b { "holds" } else { "does not hold" };
        let _ = writeln!(md, "\nFindings on {}:\n", t.label);
        let _ = writeln!(
            md,
            "- Ordering block < distributed < skewed: skewed above both {}; {}.",
            verdict(ordering_holds),
            order_md.join("; ")
        );
        let _ = writeln!(
            md,
            "- 2D skewed ≥ 3D distributed: at {skew_ge}/{} PE counts ({}).",
            ps23.len(),
            verdict(skew_ge == ps23.len())
        );
        match e256 {
            Some(e) => {
                let _ = writeln!(md, "- 2D, 256 PEs, skewed above 60%: {:.1}% ({}); 2D block at 256 PEs: {:.1}% (003, radiosity: about 20%).\n", e * 100.0, verdict(e > 0.6), b256.unwrap_or(0.0) * 100.0);
            }
            None => {
                let _ = writeln!(md, "- 2D, 256 PEs: not run (--max-pes below 256).\n");
            }
        }
        findings.push(
            json!({"scene": t.label, "ordering": order, "skewed_above_both": ordering_holds,
            "2d_skewed_ge_3d_distributed": {"pe_counts": ps23.len(), "holds_at": skew_ge},
            "2d_skewed_256_efficiency": e256, "2d_block_256_efficiency": b256,
            "2d_256_above_60": e256.map(|e| e > 0.6)}),
        );
        rows.push(json!({"pass": pass_json(t), "t1_clocks": t1, "runs": sims}));
        // Plots: efficiency and speed-up vs PEs, a panel per dimension, and 2D skewed vs 3D distributed.
        let pts = |dims: u8, a: Allocation, speed: bool| -> Vec<(f64, f64)> {
            let cap = if dims == 1 {
                max_pes.min(32)
            } else {
                max_pes.min(1024)
            };
            powers(cap)
                .into_iter()
                .filter_map(|p| {
                    eff(dims, a, p).map(|e| (p as f64, if speed { e * p as f64 } else { e }))
                })
                .collect()
        };
        for (what, speed, legend) in [
            ("efficiency", false, LegendAt::UpperRight),
            ("speedup", true, LegendAt::UpperLeft),
        ] {
            let panels = (1..=3u8)
                .map(|d| {
                    let mut s = vec![
                        series("block", 1, &pts(d, Allocation::Block, speed)),
                        series("distributed", 2, &pts(d, Allocation::Distributed, speed)),
                    ];
                    if d < 3 {
                        s.push(series("skewed", 3, &pts(d, Allocation::Skewed, speed)));
                    }
                    panel(&format!("{d}D torus"), "PEs", what, s, legend)
                })
                .collect();
            write_plot(
                out,
                &Chart {
                    stem: format!("{id}-{}-{what}", t.label),
                    title: format!(
                        "{}: {what} vs PEs (003's pass, {size}x{size}, 1 RP block)",
                        t.label
                    ),
                    panels,
                },
            )?;
        }
        write_plot(
            out,
            &Chart {
                stem: format!("{id}-{}-2d-skewed-vs-3d-distributed", t.label),
                title: format!("{}: 2D skewed vs 3D distributed (003 Fig. 34)", t.label),
                panels: vec![panel(
                    "efficiency",
                    "PEs",
                    "efficiency",
                    vec![
                        series("2D skewed", 3, &pts(2, Allocation::Skewed, false)),
                        series("3D distributed", 2, &pts(3, Allocation::Distributed, false)),
                    ],
                    LegendAt::UpperRight,
                )],
            },
        )?;
    }
    let doc = json!({"id": id, "published": published, "quick": quick, "size": size, "max_pes": max_pes,
        "measured": rows, "findings": findings,
        "environment": {"os": std::env::consts::OS, "arch": std::env::consts::ARCH, "threads": pool.current_num_threads()}});
    super::reproduce::write_report(id, out, &doc, &md, as_json)
}

/// `yamauchi-dynamic-lb`: efficiency vs RP blocks per PE on the 2D torus with skewed allocation.
pub fn dynamic_lb(
    id: &str,
    quick: bool,
    limits: &Limits,
    out: &Path,
    threads: Option<usize>,
    as_json: bool,
) -> Result<()> {
    let published: Value = serde_json::from_str(DYNAMIC_LB).expect("valid JSON");
    let size = size_of(limits, quick)?;
    let max_pes = limits.max_pes.unwrap_or(if quick { 256 } else { 1024 });
    let scenes = scenes_of(
        limits,
        if quick {
            &["tetra"]
        } else {
            &["balls", "rings", "tetra"]
        },
    );
    let pe_counts: Vec<u32> = [16u32, 64, 256, 1024]
        .into_iter()
        .filter(|&p| p <= max_pes)
        .collect();
    if pe_counts.is_empty() {
        return Err(input(
            "--max-pes must be at least 16 for yamauchi-dynamic-lb",
        ));
    }
    let blocks: Vec<u32> = if quick {
        vec![1, 2, 4, 8, 16]
    } else {
        vec![1, 2, 4, 8, 16, 32]
    };
    let pool = workload::pool(threads)?;
    let traced = trace_scenes(&scenes, size, out)?;
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# yamauchi-dynamic-lb: (Mπ)² dynamic load balancing on SPD scenes\n"
    );
    let _ = writeln!(
        md,
        "Source: {}; {}. {}\n",
        published["source"]["document"].as_str().unwrap_or(""),
        published["source"]["sections"].as_str().unwrap_or(""),
        published["source"]["note"].as_str().unwrap_or("")
    );
    let _ = writeln!(md, "Measured: `rtbench reproduce {id}{}` — 003's pass at {size}×{size}, 32³ subspaces, 2D torus, skewed allocation, least-loaded dispatch to R RP blocks per PE, direct frame buffer. Efficiency = T(1 PE, 1 RP block) / (T × PEs × R) (003 eq. 25).\n", if quick { " --quick" } else { "" });
    let mut rows = Vec::new();
    let mut findings = Vec::new();
    for t in &traced {
        let mut machines = vec![(machine(1, 1, Allocation::Block, 1), FrameBuffer::Direct)];
        let mut keys = vec![(1u32, 1u32)];
        for &p in &pe_counts {
            for &r in &blocks {
                machines.push((machine(p, 2, Allocation::Skewed, r), FrameBuffer::Direct));
                keys.push((p, r));
            }
        }
        eprintln!("{}: simulating {} machines …", t.label, machines.len());
        let results = pool.install(|| run_all(t, &machines));
        let t1 = results[0].0.clocks;
        let get = |p: u32, r: u32| {
            keys.iter()
                .position(|k| *k == (p, r))
                .map(|i| &results[i].0)
        };
        let speed = |p: u32, r: u32| get(p, r).map(|s| t1 as f64 / s.clocks as f64);
        let eff = |p: u32, r: u32| speed(p, r).map(|s| s / (p * r) as f64);
        let _ = writeln!(md, "## {} (T(1 PE, 1 RP block) = {t1} clocks)\n", t.label);
        let _ = writeln!(md, "Efficiency (speed-up) by PEs × RP blocks per PE:\n");
        let _ = writeln!(
            md,
            "| PEs | {} |",
            blocks
                .iter()
                .map(|r| format!("R = {r}"))
                .collect::<Vec<_>>()
                .join(" | ")
        );
        let _ = writeln!(md, "|---|{}", "---|".repeat(blocks.len()));
        let mut stops = serde_json::Map::new();
        for &p in &pe_counts {
            let cells: Vec<String> = blocks
                .iter()
                .map(|&r| {
                    format!(
                        "{:.1}% ({:.0}×)",
                        eff(p, r).unwrap() * 100.0,
                        speed(p, r).unwrap()
                    )
                })
                .collect();
            let _ = writeln!(md, "| {p} | {} |", cells.join(" | "));
            // Where gains stop: the first R whose doubling gains under 10% speed-up.
            let stop = blocks
                .windows(2)
                .find(|w| speed(p, w[1]).unwrap() / speed(p, w[0]).unwrap() < 1.1)
                .map(|w| w[0]);
            stops.insert(p.to_string(), json!(stop));
        }
        let pair = |p: u32, r: u32| eff(p, r).map(|e| (e, speed(p, r).unwrap()));
        let e64x16 = pair(64, 16);
        let e256x4 = pair(256, 4);
        let e256x8 = pair(256, 8);
        let best4096 = [(128u32, 32u32), (256, 16), (1024, 4)]
            .iter()
            .filter_map(|&(p, r)| pair(p, r).map(|v| (p, r, v)))
            .collect::<Vec<_>>();
        let _ = writeln!(md, "\nFindings on {}:\n", t.label);
        let _ = writeln!(md, "- Gains stop (doubling R gains < 10%) after R = {} by PE count {} (003: about 8 for every PE count).", stops.values().map(|v| v.as_u64().map_or("none in range".to_string(), |x| x.to_string())).collect::<Vec<_>>().join(", "), pe_counts.iter().map(|p| p.to_string()).collect::<Vec<_>>().join(", "));
        if let (Some(a), Some(b)) = (e64x16, e256x4) {
            let _ = writeln!(md, "- Equal total of 1024 RP blocks: 64 × 16 at {:.1}% (003: > 60%), 256 × 4 at {:.1}% (003: > 50%); fewer PEs with more blocks better: {}.", a.0 * 100.0, b.0 * 100.0, if a.0 > b.0 { "yes" } else { "no" });
        }
        if let Some(c) = e256x8 {
            let _ = writeln!(
                md,
                "- 256 × 8 (2048 RP blocks): {:.1}% (003, ray tracing: ≥ 50%).",
                c.0 * 100.0
            );
        }
        for (p, r, v) in &best4096 {
            let _ = writeln!(
                md,
                "- {p} × {r} = 4096 RP blocks: {:.1}%, speed-up {:.0}× (003: > 60%, about 2500×).",
                v.0 * 100.0,
                v.1
            );
        }
        let _ = writeln!(md);
        let mut sims = Vec::new();
        for (k, (r, wall)) in keys.iter().zip(&results) {
            let mut v = sim_json(r, t1, (k.0 * k.1) as u64, *wall);
            v["pes"] = json!(k.0);
            v["rp_blocks"] = json!(k.1);
            sims.push(v);
        }
        findings.push(json!({"scene": t.label, "gains_stop_after": stops,
            "64x16": e64x16.map(|v| v.0), "256x4": e256x4.map(|v| v.0), "256x8": e256x8.map(|v| v.0),
            "4096_blocks": best4096.iter().map(|(p, r, v)| json!({"pes": p, "rp_blocks": r, "efficiency": v.0, "speedup": v.1})).collect::<Vec<_>>()}));
        rows.push(json!({"pass": pass_json(t), "t1_clocks": t1, "runs": sims}));
        let panels = ["efficiency", "speedup"]
            .iter()
            .map(|what| {
                let s = pe_counts
                    .iter()
                    .enumerate()
                    .map(|(i, &p)| {
                        let pts: Vec<(f64, f64)> = blocks
                            .iter()
                            .map(|&r| {
                                (
                                    r as f64,
                                    if *what == "efficiency" {
                                        eff(p, r).unwrap()
                                    } else {
                                        speed(p, r).unwrap()
                                    },
                                )
                            })
                            .collect();
                        series(&format!("{p} PEs"), i + 1, &pts)
                    })
                    .collect();
                panel(
                    what,
                    "RP blocks per PE",
                    what,
                    s,
                    if *what == "efficiency" {
                        LegendAt::UpperRight
                    } else {
                        LegendAt::UpperLeft
                    },
                )
            })
            .collect();
        write_plot(
            out,
            &Chart {
                stem: format!("{id}-{}", t.label),
                title: format!("{}: 2D skewed, vs RP blocks per PE (003 Fig. 35)", t.label),
                panels,
            },
        )?;
    }
    let doc = json!({"id": id, "published": published, "quick": quick, "size": size, "pe_counts": pe_counts, "rp_blocks": blocks,
        "measured": rows, "findings": findings,
        "environment": {"os": std::env::consts::OS, "arch": std::env::consts::ARCH, "threads": pool.current_num_threads()}});
    super::reproduce::write_report(id, out, &doc, &md, as_json)
}

/// `yamauchi-cfbs`: the cached frame buffer system — 003's queueing model beside the
/// random-arrival simulation, and the caches inside the execution-driven runs.
pub fn cfbs(
    id: &str,
    quick: bool,
    limits: &Limits,
    out: &Path,
    threads: Option<usize>,
    as_json: bool,
) -> Result<()> {
    let published: Value = serde_json::from_str(CFBS).expect("valid JSON");
    let size = size_of(limits, quick)?;
    let max_pes = limits.max_pes.unwrap_or(1024);
    let scenes = scenes_of(limits, if quick { &["tetra"] } else { &["balls"] });
    let pool = workload::pool(threads)?;
    let packets = if quick { 50_000 } else { 400_000 };
    let mut md = String::new();
    let _ = writeln!(md, "# yamauchi-cfbs: the cached frame buffer system\n");
    let _ = writeln!(
        md,
        "Source: {}; {}. {}\n",
        published["source"]["document"].as_str().unwrap_or(""),
        published["source"]["sections"].as_str().unwrap_or(""),
        published["source"]["note"].as_str().unwrap_or("")
    );
    let _ = writeln!(
        md,
        "Measured: `rtbench reproduce {id}{}`.\n",
        if quick { " --quick" } else { "" }
    );

    // 1. The analytic model: saturation by configuration and by miss rate.
    let _ = writeln!(md, "## Queueing model (eqs. 11-21, Table 3)\n\n| m-ary n-stage | P_M | saturation λ_PE (per PE per clock) | digest's derived value |\n|---|---|---|---|");
    let derived = published["claims"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["id"] == "derived-saturation")
        .unwrap()["rows"]
        .clone();
    let mut model_rows = Vec::new();
    for (m, n) in [(2u32, 10u32), (4, 5), (32, 2), (1024, 1)] {
        let s = Model::table3(m, n, 0.5).saturation();
        let d = derived
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["m"] == m)
            .map(|r| r["saturation"].as_f64().unwrap());
        let _ = writeln!(
            md,
            "| {m}-ary {n}-stage | 0.5 | {s:.4e} | {} |",
            d.map_or("–".into(), |d| format!("{d:.4e}"))
        );
        model_rows.push(json!({"m": m, "stages": n, "miss": 0.5, "saturation": s, "derived": d}));
    }
    for pm in [0.1, 0.3, 0.7, 0.9, 1.0] {
        let s = Model::table3(4, 5, pm).saturation();
        let _ = writeln!(md, "| 4-ary 5-stage | {pm} | {s:.4e} | |");
        model_rows.push(json!({"m": 4, "stages": 5, "miss": pm, "saturation": s}));
    }
    let ratio = Model::table3(2, 10, 0.5).saturation() / Model::table3(1024, 1, 0.5).saturation();
    let _ = writeln!(md, "\n2-ary 10-stage tolerates {ratio:.0}× the load of no CFBS (003: several hundred times).\n");

    // 2. Model vs random-arrival simulation, 4-ary 5-stage, P_M = 0.5.
    let model = Model::table3(4, 5, 0.5);
    let sat = model.saturation();
    let lambdas: Vec<f64> = (0..=16)
        .map(|k| 1e-7 * 10f64.powf(k as f64 * 0.25))
        .filter(|&l| l < sat * 20.0)
        .collect();
    let sims: Vec<f64> = pool.install(|| {
        lambdas
            .par_iter()
            .map(|&l| queueing::simulate(&model, l, packets, 1997))
            .collect()
    });
    let _ = writeln!(md, "## 4-ary 5-stage, P_M = 0.5: model vs random-arrival simulation ({packets} packets per point)\n\n| λ_PE | model L_mean as printed | model L_mean normalised | simulated L_mean |\n|---|---|---|---|");
    let mut curve = Vec::new();
    for (&l, &s) in lambdas.iter().zip(&sims) {
        let m = model.latency(l);
        let _ = writeln!(
            md,
            "| {l:.3e} | {} | {} | {s:.1} |",
            m.map_or("saturated".into(), |v| format!("{:.1}", v.0)),
            m.map_or("saturated".into(), |v| format!("{:.1}", v.1))
        );
        curve.push(json!({"lambda": l, "model_printed": m.map(|v| v.0), "model_normalised": m.map(|v| v.1), "simulated": s}));
    }
    // Where each doubles its light-load latency.
    let light_sim = sims[0];
    let light_model = model.latency(lambdas[0]).unwrap().1;
    let knee_sim = lambdas
        .iter()
        .zip(&sims)
        .find(|(_, &s)| s > 2.0 * light_sim)
        .map(|(l, _)| *l);
    let knee_model = lambdas
        .iter()
        .find(|&&l| model.latency(l).is_none_or(|v| v.1 > 2.0 * light_model))
        .copied();
    let _ = writeln!(md, "\nLatency doubles at λ ≈ {} (model, normalised) and {} (simulation), on this grid of λ; model saturation {sat:.3e}. 003: the simulation saturates about an order of magnitude later.\n", knee_model.map_or("–".into(), |v| format!("{v:.2e}")), knee_sim.map_or("beyond the grid".into(), |v| format!("{v:.2e}")));
    let mpts: Vec<(f64, f64)> = curve
        .iter()
        .filter_map(|c| {
            c["model_normalised"]
                .as_f64()
                .map(|v| (c["lambda"].as_f64().unwrap(), v))
        })
        .collect();
    let spts: Vec<(f64, f64)> = curve
        .iter()
        .map(|c| {
            (
                c["lambda"].as_f64().unwrap(),
                c["simulated"].as_f64().unwrap(),
            )
        })
        .collect();
    write_plot(
        out,
        &Chart {
            stem: format!("{id}-model-vs-simulation"),
            title: "4-ary 5-stage CFBS, P_M = 0.5: mean latency vs λ_PE".into(),
            panels: vec![Panel::Xy(XyPanel {
                title: "mean latency".into(),
                x_label: "λ_PE (packets per PE per clock)".into(),
                y_label: "clocks".into(),
                x_log: true,
                y_log: true,
                x_ticks: Vec::new(),
                lines: true,
                legend: LegendAt::UpperLeft,
                series: vec![
                    series("model (normalised)", 1, &mpts),
                    series("random simulation", 2, &spts),
                ],
            })],
        },
    )?;

    // 3. The caches in the execution-driven runs.
    let traced = trace_scenes(&scenes, size, out)?;
    let blocks: Vec<u32> = if quick {
        vec![1, 4, 16]
    } else {
        vec![1, 2, 4, 8, 16, 32]
    };
    let configs: Vec<(u32, u32)> = [(256u32, 16u32), (1024, 32)]
        .into_iter()
        .filter(|&(p, _)| p <= max_pes)
        .collect();
    let mut exec = Vec::new();
    for t in &traced {
        let mut machines = Vec::new();
        let mut keys = Vec::new();
        for &(p, m) in &configs {
            for &r in &blocks {
                for fb in [FrameBuffer::Direct, FrameBuffer::Cached { m }] {
                    machines.push((machine(p, 2, Allocation::Skewed, r), fb));
                    keys.push((p, r, fb));
                }
            }
        }
        eprintln!("{}: simulating {} machines …", t.label, machines.len());
        let results = pool.install(|| run_all(t, &machines));
        let _ = writeln!(md, "## {}: execution-driven, 2D skewed, {size}×{size}\n\n| PEs | CFBS | R | speed-up vs R = 1 | FB share of image time | hit rate | λ_PE | interval var/mean | var/mean² | mean latency |\n|---|---|---|---|---|---|---|---|---|---|", t.label);
        for (k, (r, wall)) in keys.iter().zip(&results) {
            let base = keys
                .iter()
                .position(|b| *b == (k.0, 1, k.2))
                .map(|i| results[i].0.clocks)
                .unwrap_or(r.clocks);
            let f = &r.frame_buffer;
            let lambda = f.packets as f64 / (k.0 as f64 * r.pe_clocks.max(1) as f64);
            let vm = f.interval_var / f.interval_mean.max(1e-9);
            let cv2 = vm / f.interval_mean.max(1e-9);
            let fbname = match k.2 {
                FrameBuffer::Direct => "none (direct GFB)".to_string(),
                FrameBuffer::Cached { m } => format!("{m}-ary 2-stage"),
            };
            let _ = writeln!(
                md,
                "| {} | {fbname} | {} | {:.2} | {:.3} | {} | {lambda:.2e} | {vm:.0} | {cv2:.1} | {:.1} |",
                k.0,
                k.1,
                base as f64 / r.clocks as f64,
                f.finish.saturating_sub(r.pe_clocks) as f64 / r.clocks as f64,
                if matches!(k.2, FrameBuffer::Cached { .. }) {
                    format!("{:.1}%", f.hit_rate() * 100.0)
                } else {
                    "–".into()
                },
                f.latency_mean
            );
            let mut v = sim_json(r, base, 1, *wall);
            v["pes"] = json!(k.0);
            v["rp_blocks"] = json!(k.1);
            v["cfbs"] = json!(matches!(k.2, FrameBuffer::Cached { .. }));
            v["lambda_pe"] = json!(lambda);
            v["interval_var_over_mean"] = json!(vm);
            v["interval_var_over_mean_squared"] = json!(cv2);
            exec.push(v);
        }
        let _ = writeln!(md);
    }
    // 4. Faster processors (003 Fig. 41): the PE units' costs divided by the processor-memory
    // cycle ratio, links and frame buffer as they were.
    let (pp, pm) = *configs.last().unwrap_or(&(256, 16));
    let r_pmcr = if quick { 4 } else { 16 };
    let _ = writeln!(md, "## Processor-memory cycle ratio (003 Fig. 41): {pp} PEs × {r_pmcr} RP blocks, 2D skewed, {}\n\nEvery PE unit cost (Table 4 but the link's hop) divided by the PMCR; links and frame buffer unchanged.\n\n| PMCR | T direct / T with {pm}-ary CFBS | FB share of image time (direct) | FB share (CFBS) | hit rate | λ_PE | mean latency direct | mean latency CFBS |\n|---|---|---|---|---|---|---|---|", scenes.first().map_or("", |s| s.as_str()));
    let mut pmcr_rows = Vec::new();
    for pmcr in if quick {
        vec![1u32, 64]
    } else {
        vec![1u32, 4, 16, 64, 256]
    } {
        let traced = trace_scenes_with(&scenes[..1.min(scenes.len())], size, out, faster(pmcr))?;
        let Some(t) = traced.first() else { break };
        let m = machine(pp, 2, Allocation::Skewed, r_pmcr);
        let res = pool.install(|| {
            run_all(
                t,
                &[(m, FrameBuffer::Direct), (m, FrameBuffer::Cached { m: pm })],
            )
        });
        let (d, c) = (&res[0].0, &res[1].0);
        let share = |r: &SimResult| r.clocks.saturating_sub(r.pe_clocks) as f64 / r.clocks as f64;
        let lambda = d.frame_buffer.packets as f64 / (pp as f64 * d.pe_clocks.max(1) as f64);
        let _ = writeln!(
            md,
            "| {pmcr} | {:.3} | {:.3} | {:.3} | {:.1}% | {lambda:.2e} | {:.1} | {:.1} |",
            d.clocks as f64 / c.clocks as f64,
            share(d),
            share(c),
            c.frame_buffer.hit_rate() * 100.0,
            d.frame_buffer.latency_mean,
            c.frame_buffer.latency_mean
        );
        pmcr_rows.push(json!({"pmcr": pmcr, "pes": pp, "rp_blocks": r_pmcr, "m": pm, "direct": sim_json(d, d.clocks, 1, res[0].1), "cfbs": sim_json(c, d.clocks, 1, res[1].1), "lambda_pe": lambda}));
    }
    let _ = writeln!(md);
    let _ = writeln!(md, "003 (4.3.2): FBC hit rate about 60%; λ about 5.9e-6 (1024 PEs × 1 RP block) and 8.3e-5 (× 32); interval variance 100-1000 times the mean; the caches help only at 1024 PEs with about 16 RP blocks or more. 'FB share' is how much of the image time the frame buffer adds after the last RP block finishes.");
    let doc = json!({"id": id, "published": published, "quick": quick, "size": size,
        "model": model_rows, "model_vs_simulation": curve, "execution_driven": exec, "pmcr": pmcr_rows,
        "environment": {"os": std::env::consts::OS, "arch": std::env::consts::ARCH, "threads": pool.current_num_threads()}});
    super::reproduce::write_report(id, out, &doc, &md, as_json)
}

/// Table 4's costs with every PE unit `pmcr` times faster (at least 1 clock); the link's hop and
/// the frame buffer's costs stay.
fn faster(pmcr: u32) -> Costs {
    let c = Costs::default();
    let f = |v: u32| (v / pmcr).max(1);
    Costs {
        primary: f(c.primary),
        triangle: f(c.triangle),
        sphere: f(c.sphere),
        cone: f(c.cone),
        intensity: f(c.intensity),
        dda_init: f(c.dda_init),
        dda: f(c.dda),
        secondary: f(c.secondary),
        packet: f(c.packet),
        ..c
    }
}
