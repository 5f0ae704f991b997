//! `kanamori-grid`: 002 (Kanamori 2014), the uniform-grid lecture. The handout has no experiments, so
//! each of its qualitative claims is measured: grid against BVH build time over rising size factors;
//! cells visited, empty cells and triangle tests per ray as the cubic resolution sweeps from (1,1,1) to
//! beyond n^(1/3) on tetra and balls (with its floor), with the fastest
//! resolution per size (triangle size) and the handout's (8,8,8); mailbox off (the handout) against
//! on; 3D-DDA against a slab test of every cell; the in-cell hit rule against brute force; and brute
//! force (the `reference` engine) against the object count. Dense against sparse: a survey of every SPD
//! program's empty cells at n^(1/3) per axis picks the densest and the sparsest.
//!
//! The lecture's grid: `insert=exact` (each triangle in every cell it intersects), `mailbox=false`,
//! `preset=rss-r` (no shadow cache, no per-voxel culling), `floor=in`, over the whole scene's box.

use super::published::{self, PublishedClaim, Source};
use super::{environment, Claim, Ctx, Fidelity, Kind, Output, Row, Runtime, Table, Verdict};
use crate::error::Result;
use crate::measure::clock::thread_cpu_seconds;
use crate::select::median;
use crate::source::Source as SceneSource;
use crate::workload::{self, camera::Camera};
use rtbench_engines::geometry::dda::{self, Lattice};
use rtbench_engines::grid::config::GridConfig;
use rtbench_engines::grid::Grid;
use rtbench_engines::{BuildInput, Counters, Engine, Hit, Ray, Settings};
use rtbench_reports::plot::{Chart, LegendAt, Panel, Point as PlotPoint, Series, XyPanel};
use rtbench_reports::{Document, Table as DocTable};
use serde::{Deserialize, Serialize};

pub const TABLE: Table = Table {
    id: "kanamori-grid",
    seed: "002",
    source: "§2-§4 (no tables)",
    about: "002 (Kanamori 2014): uniform grid + 3D-DDA claims: build, density, resolution, mailbox, brute force",
    runtime: Runtime { quick: "1 minute", full: "minutes" },
    params: &[],
    claims: &[
        Claim { key: "brute-force-linear", fidelity: Fidelity::Faithful, why: "" },
        Claim {
            key: "grid-build-fast",
            fidelity: Fidelity::Substituted,
            why: "the handout names no scene: SPD tetra and balls (tessellated) at rising size factors; grid with n^(1/3) cells per axis; rtbench's BVHs and Embree as the BVHs",
        },
        Claim {
            key: "dense-good-sparse-wasteful",
            fidelity: Fidelity::Substituted,
            why: "the handout names no scene: of the seven SPD programs (tessellated), the one with the fewest empty cells at n^(1/3) per axis stands for a dense scene and the one with the most for a sparse one; every program's empty share is shown",
        },
        Claim {
            key: "bvh-better-sparse",
            fidelity: Fidelity::Substituted,
            why: "BVH part only (rtbench has no octree or kd-tree); the survey's densest and sparsest SPD programs as dense and sparse",
        },
        Claim { key: "octree-kdtree", fidelity: Fidelity::NotReproducible, why: "rtbench has no octree and no kd-tree engine" },
        Claim { key: "easy-to-implement", fidelity: Fidelity::NotReproducible, why: "a judgement of effort, not a measurement" },
        Claim { key: "dda-every-cell", fidelity: Fidelity::Faithful, why: "" },
        Claim { key: "in-cell-hit", fidelity: Fidelity::Faithful, why: "" },
        Claim { key: "no-mailbox", fidelity: Fidelity::Faithful, why: "" },
        Claim {
            key: "best-res-depends",
            fidelity: Fidelity::Substituted,
            why: "two size factors of one SPD scene stand for two triangle sizes of one mesh",
        },
        Claim {
            key: "default-8",
            fidelity: Fidelity::Substituted,
            why: "the grid covers the whole scene's box, not one mesh's (tetra is one mesh; balls is spheres and a floor)",
        },
    ],
    run,
};

const PUBLISHED: &str = include_str!("../../../data/published/kanamori-grid.json");

#[derive(Deserialize)]
struct Published {
    source: Source,
    default_resolution: [u32; 3],
    claims: Vec<PublishedClaim>,
}

/// Cubic resolutions the sweep may take (those up to [`BEYOND`]·n^(1/3) are run, and 8 always).
const KS: &[u32] = &[1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128];
/// How far past n^(1/3) cells per axis the sweep goes.
const BEYOND: f64 = 4.0;

/// The two scenes and the two sizes each is swept at.
struct Setting {
    /// The density survey: every SPD program at one size factor (dense and sparse chosen from it).
    survey: [(&'static str, u32); 7],
    sweep: [(&'static str, [u32; 2]); 2],
    build_sfs: [(&'static str, std::ops::RangeInclusive<u32>); 2],
    brute_sfs: std::ops::RangeInclusive<u32>,
    image: u32,
    check_image: u32,
    repeats: usize,
}

fn setting(quick: bool) -> Setting {
    if quick {
        Setting {
            survey: [("balls", 2), ("gears", 2), ("mount", 5), ("rings", 2), ("teapot", 4), ("tetra", 5), ("tree", 6)],
            sweep: [("tetra", [4, 5]), ("balls", [1, 2])],
            build_sfs: [("tetra", 3..=6), ("balls", 1..=3)],
            brute_sfs: 1..=5,
            image: 96,
            check_image: 48,
            repeats: 3,
        }
    } else {
        Setting {
            survey: [("balls", 3), ("gears", 3), ("mount", 6), ("rings", 3), ("teapot", 6), ("tetra", 6), ("tree", 8)],
            sweep: [("tetra", [5, 6]), ("balls", [2, 3])],
            build_sfs: [("tetra", 3..=8), ("balls", 1..=4)],
            brute_sfs: 1..=6,
            image: 192,
            check_image: 96,
            repeats: 5,
        }
    }
}

/// The lecture's grid at `res` cells per axis (`cuberoot` or `X,Y,Z`).
fn lecture_grid(input: &BuildInput, res: &str, mailbox: bool) -> Result<Grid> {
    let kv = [("res", res), ("insert", "exact"), ("mailbox", if mailbox { "true" } else { "false" }), ("preset", "rss-r"), ("floor", "in")];
    let config = GridConfig::from_settings(Settings::new("grid", kv.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect()))?;
    Ok(Grid::build(input, config)?)
}

fn prepare(scene: &str, sf: u32) -> Result<workload::Prepared> {
    workload::prepare(&SceneSource::resolve(scene, Some(sf), Some(3), None)?)
}

/// Closest-hit counters of one pass and the median CPU time of up to `repeats` passes (fewer when one
/// pass takes over 2 s).
fn time(e: &dyn Engine, rays: &[Ray], repeats: usize) -> (Counters, f64, Vec<Hit>) {
    let mut hits = vec![Hit::MISS; rays.len()];
    let mut first = Counters::default();
    let mut cpu = Vec::new();
    for i in 0..repeats {
        let mut c = Counters::default();
        let c0 = thread_cpu_seconds();
        e.intersect(rays, &mut hits, &mut c);
        let s = thread_cpu_seconds() - c0;
        cpu.push(s);
        if i == 0 {
            first = c;
        }
        if s > 2.0 {
            break;
        }
    }
    (first, median(&mut cpu), hits)
}

/// One grid measured on one ray set.
#[derive(Clone, Debug, Serialize)]
struct GridPoint {
    scene: &'static str,
    sf: u32,
    triangles: usize,
    res: [u32; 3],
    mailbox: bool,
    cells: f64,
    empty_cells: f64,
    references: f64,
    structure_bytes: u64,
    build_s: f64,
    rays: usize,
    cells_per_ray: f64,
    empty_cells_per_ray: f64,
    tests_per_ray: f64,
    cpu_s: f64,
}

fn measure_grid(scene: &'static str, sf: u32, input: &BuildInput, res: &str, mailbox: bool, rays: &[Ray], repeats: usize) -> Result<GridPoint> {
    let g = lecture_grid(input, res, mailbox)?;
    let s = g.build_stats();
    let (c, cpu_s, _) = time(&g, rays, repeats);
    let n = rays.len().max(1) as f64;
    let stat = |k: &str| s.get(k).copied().unwrap_or(0.0);
    Ok(GridPoint {
        scene,
        sf,
        triangles: input.geometry.prims.len(),
        res: [stat("res_x") as u32, stat("res_y") as u32, stat("res_z") as u32],
        mailbox,
        cells: stat("cells"),
        empty_cells: stat("empty_cells"),
        references: stat("references"),
        structure_bytes: g.structure_bytes(),
        build_s: stat("build_s"),
        rays: rays.len(),
        cells_per_ray: c.cells_visited as f64 / n,
        empty_cells_per_ray: c.empty_cells_visited as f64 / n,
        tests_per_ray: c.primitive_tests as f64 / n,
        cpu_s,
    })
}

/// Build times of one engine at one size.
#[derive(Clone, Debug, Serialize)]
struct BuildPoint {
    scene: &'static str,
    sf: u32,
    triangles: usize,
    engine: &'static str,
    build_s: f64,
}

const BUILD_ENGINES: &[super::engine_timing::Timee] = &[
    ("grid (lecture, n^(1/3) per axis)", "grid", &[("res", "cuberoot"), ("insert", "exact"), ("mailbox", "false"), ("preset", "rss-r")]),
    ("grid (bbox insertion)", "grid", &[("res", "cuberoot"), ("insert", "bbox"), ("mailbox", "false"), ("preset", "rss-r")]),
    ("bvh2 (binned SAH)", "bvh2", &[]),
    ("bvh4 (binned SAH, collapsed)", "bvh4", &[]),
    ("embree", "embree", &[]),
];

/// Builds of each engine at one size. The engines take turns, five builds each, and each build
/// is timed by what it ran on: the grid and the BVHs build on this thread, so their time is this
/// thread's CPU time, which other processes on the machine do not lengthen (a build takes
/// 0.1–50 ms, and wall times of so short a span moved the grid ÷ BVH ratio past the claim's 0.5
/// with the load); Embree builds on its own threads, so its time is wall time.
fn measure_builds(scene: &'static str, sf: u32, input: &BuildInput, out: &mut Vec<BuildPoint>) -> Result<()> {
    const BUILDS: usize = 5;
    let engines: Vec<_> = BUILD_ENGINES
        .iter()
        .filter(|&&(_, engine, _)| super::engine_timing::available(engine))
        .collect();
    let mut times = vec![Vec::with_capacity(BUILDS); engines.len()];
    for _ in 0..BUILDS {
        for (&&(_, engine, kv), t) in engines.iter().zip(&mut times) {
            let cpu = thread_cpu_seconds();
            let (e, wall) = workload::build(engine, input, super::engine_timing::settings(kv))?;
            let cpu = thread_cpu_seconds() - cpu;
            drop(e);
            t.push(if engine == "embree" { wall } else { cpu });
        }
    }
    for (&&(label, _, _), mut t) in engines.iter().zip(times) {
        out.push(BuildPoint { scene, sf, triangles: input.geometry.prims.len(), engine: label, build_s: median(&mut t) });
    }
    Ok(())
}

/// 3D-DDA against a slab test of every cell, for one lattice and ray set.
#[derive(Clone, Debug, Serialize)]
struct DdaCheck {
    scene: &'static str,
    sf: u32,
    res: [u32; 3],
    rays: usize,
    /// Cells the ray crosses with positive length (slab test), summed over the rays.
    crossed: u64,
    /// Of those, cells the DDA did not visit.
    missed: u64,
    /// Cells the DDA visited that the ray only touches (length 0 within tolerance) or not at all.
    extra: u64,
}

fn dda_check(scene: &'static str, sf: u32, lattice: &Lattice, rays: &[Ray]) -> DdaCheck {
    let res = lattice.res;
    let total = res.iter().map(|&r| r as usize).product::<usize>();
    let mut seen = vec![u32::MAX; total];
    let (mut crossed, mut missed, mut extra) = (0u64, 0u64, 0u64);
    let tol = 1e-4 * lattice.cell.min_element();
    for (i, ray) in rays.iter().enumerate() {
        let stamp = i as u32;
        let mut visited = 0u64;
        dda::walk(lattice, ray, |_, cell, _, _| {
            seen[cell] = stamp;
            visited += 1;
            false
        });
        let (mut on_ray, mut missed_here) = (0u64, 0u64);
        let inv = ray.dir.recip();
        for z in 0..res[2] {
            for y in 0..res[1] {
                for x in 0..res[0] {
                    let lo = lattice.lo + lattice.cell * glam::Vec3::new(x as f32, y as f32, z as f32);
                    let hi = lo + lattice.cell;
                    let (a, b) = ((lo - ray.origin) * inv, (hi - ray.origin) * inv);
                    let t0 = a.min(b).max_element().max(ray.tmin);
                    let t1 = a.max(b).min_element().min(ray.tmax);
                    // Positive length inside the cell (measured along the unit direction).
                    if (t1 - t0) * ray.dir.length() > tol {
                        crossed += 1;
                        on_ray += 1;
                        if seen[lattice.index([x, y, z])] != stamp {
                            missed_here += 1;
                        }
                    }
                }
            }
        }
        missed += missed_here;
        extra += visited.saturating_sub(on_ray - missed_here);
    }
    DdaCheck { scene, sf, res, rays: rays.len(), crossed, missed, extra }
}

/// The in-cell hit rule (mailbox off) against brute force on the same rays.
#[derive(Clone, Debug, Serialize)]
struct HitCheck {
    scene: &'static str,
    sf: u32,
    res: String,
    rays: usize,
    hits: usize,
    /// Rays whose hit distance differs from brute force's (or hit against miss).
    differ: usize,
    /// Rays with the same distance but another object (ties on shared edges).
    other_object: usize,
}

fn hit_check(scene: &'static str, sf: u32, input: &BuildInput, res: &str, reference: &[Hit], rays: &[Ray]) -> Result<HitCheck> {
    let g = lecture_grid(input, res, false)?;
    let mut hits = vec![Hit::MISS; rays.len()];
    g.intersect(rays, &mut hits, &mut Counters::default());
    let (mut differ, mut other) = (0, 0);
    for (a, b) in hits.iter().zip(reference) {
        match (a.t.is_finite(), b.t.is_finite()) {
            (false, false) => {}
            (true, true) if (a.t - b.t).abs() <= 1e-4 * b.t.abs().max(1.0) => {
                if a.object != b.object {
                    other += 1;
                }
            }
            _ => differ += 1,
        }
    }
    Ok(HitCheck { scene, sf, res: res.into(), rays: rays.len(), hits: reference.iter().filter(|h| h.t.is_finite()).count(), differ, other_object: other })
}

/// Brute force at one object count.
#[derive(Clone, Debug, Serialize)]
struct BrutePoint {
    sf: u32,
    objects: usize,
    rays: usize,
    tests_per_ray: f64,
    us_per_ray: f64,
}

/// BVH time on the sweep's rays, for the sparse/dense comparison.
#[derive(Clone, Debug, Serialize)]
struct BvhTime {
    scene: &'static str,
    sf: u32,
    cpu_s: f64,
}

#[derive(Serialize)]
struct Result_ {
    id: &'static str,
    published: serde_json::Value,
    quick: bool,
    image: u32,
    sweep: Vec<GridPoint>,
    /// The lecture's grid at n^(1/3) per axis, mailbox off and on, and at (8,8,8) with the mailbox on.
    settings: Vec<GridPoint>,
    bvh: Vec<BvhTime>,
    /// Every SPD program's grid at n^(1/3) per axis (mailbox off) and its bvh4 time: the
    /// densest (fewest empty cells) and sparsest stand for 002's dense and sparse scenes.
    survey: Vec<(GridPoint, f64)>,
    builds: Vec<BuildPoint>,
    dda: Vec<DdaCheck>,
    hits: Vec<HitCheck>,
    brute: Vec<BrutePoint>,
    environment: serde_json::Value,
}

fn run(ctx: &Ctx) -> Result<Output> {
    let (p, raw): (Published, _) = published::load(ctx.id, PUBLISHED);
    let s = setting(ctx.quick);
    let d8 = p.default_resolution;
    let d8s = format!("{},{},{}", d8[0], d8[1], d8[2]);
    let (mut sweep, mut settings, mut bvh, mut dda_checks, mut hit_checks) = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for &(scene, sfs) in &s.sweep {
        for (i, &sf) in sfs.iter().enumerate() {
            eprintln!("{}: {scene}{sf} resolution sweep …", ctx.id);
            let prepared = prepare(scene, sf)?;
            let input = &prepared.input;
            let cam = Camera::new(&input.scene.view);
            let rays = cam.pixel_centre_rays(s.image, s.image);
            let n = input.geometry.prims.len() as f64;
            let top = BEYOND * n.cbrt();
            for &k in KS.iter().filter(|&&k| (k as f64) <= top || k == d8[0]) {
                sweep.push(measure_grid(scene, sf, input, &format!("{k},{k},{k}"), false, &rays, s.repeats)?);
            }
            if i == 1 {
                // The settings comparison, on the larger size.
                for (res, mb) in [("cuberoot", false), ("cuberoot", true), (d8s.as_str(), true)] {
                    settings.push(measure_grid(scene, sf, input, res, mb, &rays, s.repeats)?);
                }
                let (e, _) = workload::build("bvh4", input, Vec::new())?;
                let (_, cpu_s, _) = time(e.as_ref(), &rays, s.repeats);
                bvh.push(BvhTime { scene, sf, cpu_s });
            } else {
                // Correctness on the smaller size: DDA against slab tests, hits against brute force.
                let check = cam.pixel_centre_rays(s.check_image, s.check_image);
                for res in [d8s.as_str(), "cuberoot"] {
                    let g = lecture_grid(input, res, false)?;
                    dda_checks.push(dda_check(scene, sf, &g.cells().lattice, &check));
                }
                let (r, _) = workload::build("reference", input, Vec::new())?;
                let mut reference = vec![Hit::MISS; check.len()];
                r.intersect(&check, &mut reference, &mut Counters::default());
                for res in [d8s.as_str(), "cuberoot"] {
                    hit_checks.push(hit_check(scene, sf, input, res, &reference, &check)?);
                }
            }
        }
    }
    let mut survey = Vec::new();
    for &(scene, sf) in &s.survey {
        eprintln!("{}: {scene}{sf} density survey …", ctx.id);
        let prepared = prepare(scene, sf)?;
        let input = &prepared.input;
        let rays = Camera::new(&input.scene.view).pixel_centre_rays(s.image, s.image);
        let g = measure_grid(scene, sf, input, "cuberoot", false, &rays, s.repeats)?;
        let (e, _) = workload::build("bvh4", input, Vec::new())?;
        let (_, bvh_s, _) = time(e.as_ref(), &rays, s.repeats);
        survey.push((g, bvh_s));
    }
    let mut builds = Vec::new();
    for (scene, sfs) in &s.build_sfs {
        for sf in sfs.clone() {
            eprintln!("{}: {scene}{sf} builds …", ctx.id);
            let prepared = prepare(scene, sf)?;
            measure_builds(scene, sf, &prepared.input, &mut builds)?;
        }
    }
    let mut brute = Vec::new();
    for sf in s.brute_sfs.clone() {
        eprintln!("{}: tetra{sf} brute force …", ctx.id);
        let prepared = prepare("tetra", sf)?;
        let rays = Camera::new(&prepared.input.scene.view).pixel_centre_rays(32, 32);
        let (r, _) = workload::build("reference", &prepared.input, Vec::new())?;
        let (c, cpu_s, _) = time(r.as_ref(), &rays, s.repeats);
        brute.push(BrutePoint { sf, objects: prepared.input.scene.objects.len(), rays: rays.len(), tests_per_ray: c.primitive_tests as f64 / rays.len() as f64, us_per_ray: cpu_s * 1e6 / rays.len() as f64 });
    }
    let result = Result_ { id: ctx.id, published: raw, quick: ctx.quick, image: s.image, sweep, settings, bvh, survey, builds, dda: dda_checks, hits: hit_checks, brute, environment: environment(1) };
    let rows = rows(&p, &result);
    let doc = document(&p, &result, &rows);
    let charts = s.sweep.iter().map(|(scene, _)| chart(ctx.id, scene, &result.sweep)).collect();
    let mut out = Output::new(&result, rows, doc);
    out.charts = charts;
    Ok(out)
}

/// The share of a grid's cells that hold no triangle.
fn empty_share(g: &GridPoint) -> f64 {
    g.empty_cells / g.cells.max(1.0)
}

/// A surveyed scene's grid and its bvh4 time.
type Timed<'a> = (&'a GridPoint, f64);

/// The survey's densest scene (fewest empty cells at n^(1/3) per axis) and its sparsest, each with
/// its bvh4 time; none with fewer than two scenes.
fn dense_and_sparse(survey: &[(GridPoint, f64)]) -> Option<(Timed<'_>, Timed<'_>)> {
    let by = |a: &&(GridPoint, f64), b: &&(GridPoint, f64)| empty_share(&a.0).total_cmp(&empty_share(&b.0));
    let d = survey.iter().min_by(by)?;
    let s = survey.iter().max_by(by)?;
    if std::ptr::eq(d, s) {
        return None;
    }
    Some(((&d.0, d.1), (&s.0, s.1)))
}

/// The fastest cubic resolution of one scene size, and the (8,8,8) point.
fn best<'a>(sweep: &'a [GridPoint], scene: &str, sf: u32) -> Option<&'a GridPoint> {
    sweep.iter().filter(|g| g.scene == scene && g.sf == sf).min_by(|a, b| a.cpu_s.total_cmp(&b.cpu_s))
}

/// Least-squares slope of log y against log x.
fn log_slope(pts: &[(f64, f64)]) -> f64 {
    let n = pts.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = pts.iter().map(|&(x, y)| (x.ln(), y.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = lx.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

fn res_str(r: [u32; 3]) -> String {
    format!("({},{},{})", r[0], r[1], r[2])
}

fn rows(p: &Published, r: &Result_) -> Vec<Row> {
    let claim = |id: &str| published::claim(&p.claims, id).claim.clone();
    let mut rows = Vec::new();
    // Brute force: tests per ray = objects; time per ray linear in the count (fit over ≥ 64 objects).
    let exact = r.brute.iter().all(|b| (b.tests_per_ray - b.objects as f64).abs() < 1e-9);
    let fit: Vec<(f64, f64)> = r.brute.iter().filter(|b| b.objects >= 64).map(|b| (b.objects as f64, b.us_per_ray)).collect();
    let slope = if fit.len() >= 2 { log_slope(&fit) } else { f64::NAN };
    rows.push(Row::new("brute-force-linear", "tetra, reference engine", claim("brute-force-linear"), format!("tests/ray = objects: {}; log-log slope of time/ray vs objects {:.2}", if exact { "yes" } else { "no" }, slope), Kind::Shape, Verdict::of(exact && (0.8..=1.2).contains(&slope))));
    // Build time: each grid insertion against the fastest single-threaded BVH, from 1,000 triangles.
    for (scene, _) in setting(r.quick).build_sfs.iter() {
        let sfs: std::collections::BTreeSet<u32> = r.builds.iter().filter(|b| b.scene == *scene).map(|b| b.sf).collect();
        for (grid, label) in [("grid (lecture", "exact insertion"), ("grid (bbox", "bbox insertion")] {
            let mut ratios = Vec::new();
            let mut holds = true;
            for sf in &sfs {
                let at = |l: &str| r.builds.iter().find(|b| b.scene == *scene && b.sf == *sf && b.engine.starts_with(l));
                let Some(g) = at(grid) else { continue };
                let Some(b) = ["bvh2", "bvh4"].iter().filter_map(|l| at(l).map(|b| b.build_s)).min_by(|a, b| a.total_cmp(b)) else { continue };
                ratios.push(format!("{} tris {:.2}", g.triangles, g.build_s / b));
                if g.triangles >= 1000 {
                    holds &= g.build_s < 0.5 * b;
                }
            }
            rows.push(
                Row::new("grid-build-fast", format!("{scene}, grid ({label}) build ÷ fastest of bvh2/bvh4 build"), claim("grid-build-fast"), ratios.join(", "), Kind::Ratio, Verdict::of(holds && !ratios.is_empty()))
                    .with_note("holds when under 0.5 (twice as fast) at every size from 1,000 triangles; the handout does not say which insertion test it uses; Embree (multi-threaded build) is in the build table"),
            );
        }
    }
    // Dense vs sparse at n^(1/3) per axis, mailbox off: the survey's densest and sparsest scenes.
    if let Some((dense, sparse)) = dense_and_sparse(&r.survey) {
        let ((t, bt), (b, bb)) = (dense, sparse);
        let frac = |g: &GridPoint| (empty_share(g), g.empty_cells_per_ray / g.cells_per_ray.max(1e-9), g.structure_bytes as f64 / g.triangles as f64);
        let (ft, fb) = (frac(t), frac(b));
        let (tn, bn) = (format!("{}{}", t.scene, t.sf), format!("{}{}", b.scene, b.sf));
        rows.push(
            Row::new("dense-good-sparse-wasteful", format!("memory: {tn} (densest) vs {bn} (sparsest), n^(1/3) per axis"), claim("dense-good-sparse-wasteful"), format!("empty cells {:.0}% vs {:.0}%; bytes/triangle {:.1} vs {:.1}", ft.0 * 100.0, fb.0 * 100.0, ft.2, fb.2), Kind::Ordering, Verdict::Shown)
                .with_note("the order of empty shares is how the two were chosen: shown, the bytes per triangle are the finding"),
        );
        rows.push(
            Row::new("dense-good-sparse-wasteful", format!("traversal: {tn} vs {bn}, n^(1/3) per axis"), claim("dense-good-sparse-wasteful"), format!("empty among visited cells {:.0}% vs {:.0}%; tests/ray {:.1} vs {:.1}", ft.1 * 100.0, fb.1 * 100.0, t.tests_per_ray, b.tests_per_ray), Kind::Ordering, Verdict::of(fb.1 > ft.1))
                .with_note("holds when the sparse scene's rays spend the larger share of their steps in empty cells"),
        );
        let (rt, rb) = (t.cpu_s / bt, b.cpu_s / bb);
        rows.push(Row::new("bvh-better-sparse", format!("grid (n^(1/3), no mailbox) time ÷ bvh4 time, {tn} vs {bn}"), claim("bvh-better-sparse"), format!("{rt:.2} vs {rb:.2}"), Kind::Ordering, Verdict::of(rb > rt && rb > 1.0)));
    }
    rows.push(Row::new("octree-kdtree", "-", claim("octree-kdtree"), "no octree or kd-tree engine", Kind::Ordering, Verdict::NotMeasured));
    rows.push(Row::new("easy-to-implement", "-", claim("easy-to-implement"), "not measurable", Kind::Ordering, Verdict::NotMeasured));
    for d in &r.dda {
        rows.push(Row::new("dda-every-cell", format!("{}{} {}, {} rays", d.scene, d.sf, res_str(d.res), d.rays), claim("dda-every-cell"), format!("{} cells crossed, {} missed by the DDA, {} touched-only visited", d.crossed, d.missed, d.extra), Kind::Count, Verdict::of(d.missed == 0 && d.crossed > 0)));
    }
    for h in &r.hits {
        rows.push(Row::new("in-cell-hit", format!("{}{} res {}, {} rays ({} hits)", h.scene, h.sf, h.res, h.rays, h.hits), claim("in-cell-hit"), format!("{} differ from brute force ({} same t, other object)", h.differ, h.other_object), Kind::Count, Verdict::of(h.differ == 0)));
    }
    // Mailbox off vs on at n^(1/3) per axis.
    for scene in ["tetra", "balls"] {
        let off = r.settings.iter().find(|g| g.scene == scene && !g.mailbox);
        let on = r.settings.iter().find(|g| g.scene == scene && g.mailbox && g.res == off.map_or([0; 3], |o| o.res));
        if let (Some(off), Some(on)) = (off, on) {
            rows.push(Row::new(
                "no-mailbox",
                format!("{scene}{} {}", off.sf, res_str(off.res)),
                claim("no-mailbox"),
                format!("tests/ray off {:.2} vs on {:.2} (+{:.0}%); time off ÷ on {:.2}", off.tests_per_ray, on.tests_per_ray, (off.tests_per_ray / on.tests_per_ray.max(1e-9) - 1.0) * 100.0, off.cpu_s / on.cpu_s),
                Kind::Ordering,
                Verdict::of(off.tests_per_ray >= on.tests_per_ray),
            ));
        }
    }
    // Best resolution per size, and the handout's (8,8,8).
    let s = setting(r.quick);
    for (scene, sfs) in s.sweep {
        let b: Vec<Option<&GridPoint>> = sfs.iter().map(|&sf| best(&r.sweep, scene, sf)).collect();
        if let (Some(small), Some(large)) = (b[0], b[1]) {
            rows.push(Row::new(
                "best-res-depends",
                format!("{scene}{} ({} tris) vs {scene}{} ({} tris)", small.sf, small.triangles, large.sf, large.triangles),
                claim("best-res-depends"),
                format!("fastest {} vs {}", res_str(small.res), res_str(large.res)),
                Kind::Ordering,
                Verdict::of(large.res[0] > small.res[0]),
            ));
        }
        for &sf in &sfs {
            let (Some(bp), Some(d)) = (best(&r.sweep, scene, sf), r.sweep.iter().find(|g| g.scene == scene && g.sf == sf && g.res == p.default_resolution)) else { continue };
            rows.push(Row::new(
                "default-8",
                format!("{scene}{sf} ({} tris)", d.triangles),
                "(8,8,8)",
                format!("(8,8,8): {:.1} tests/ray, {:.2}x the fastest {}'s time ({:.1} tests/ray)", d.tests_per_ray, d.cpu_s / bp.cpu_s, res_str(bp.res), bp.tests_per_ray),
                Kind::Ratio,
                Verdict::Shown,
            ));
        }
    }
    rows
}

fn chart(id: &str, scene: &str, sweep: &[GridPoint]) -> Chart {
    let mut sfs: Vec<u32> = sweep.iter().filter(|g| g.scene == scene).map(|g| g.sf).collect();
    sfs.dedup();
    let series = |f: fn(&GridPoint) -> f64, name: &str| -> Vec<Series> {
        sfs.iter()
            .enumerate()
            .map(|(i, &sf)| Series {
                name: format!("{scene}{sf} {name}"),
                color: 1 + i,
                // Zero (no empty cell visited) has no place on a log axis: those points are left out.
                points: sweep.iter().filter(|g| g.scene == scene && g.sf == sf && f(g) > 0.0).map(|g| PlotPoint { x: g.res[0] as f64, y: f(g), y_range: None }).collect(),
            })
            .collect()
    };
    let panel = |title: &str, y: &str, series: Vec<Series>| {
        Panel::Xy(XyPanel { title: title.into(), x_label: "cells per axis k (k,k,k)".into(), y_label: y.into(), x_log: true, y_log: true, x_ticks: Vec::new(), lines: true, legend: LegendAt::UpperRight, series })
    };
    let mut cells = series(|g| g.cells_per_ray, "cells");
    let mut empty = series(|g| g.empty_cells_per_ray, "empty cells");
    for s in &mut empty {
        s.color += 2;
    }
    cells.append(&mut empty);
    Chart {
        stem: format!("{id}-{scene}"),
        title: format!("002 uniform grid on {scene}: no mailbox, exact insertion"),
        panels: vec![panel("triangle tests per ray", "tests / ray", series(|g| g.tests_per_ray, "tests")), panel("cells visited per ray", "cells / ray", cells)],
    }
}

fn document(p: &Published, r: &Result_, rows: &[Row]) -> Document {
    let _ = rows;
    let mut doc = Document::new("kanamori-grid: 002's uniform grid and 3D-DDA, claim by claim");
    doc.paragraph(format!("Source: {}. {}", p.source.cite(), p.source.note.as_deref().unwrap_or("")));
    doc.paragraph(format!(
        "Measured: `rtbench reproduce kanamori-grid{q}`: the lecture's grid (`insert=exact mailbox=false preset=rss-r floor=in`, over the scene's box), {i}x{i} eye rays through pixel centres, closest hit, one thread; times are the median CPU time of up to {n} passes. Scenes tessellated at SPD resolution 3.",
        q = if r.quick { " --quick" } else { "" },
        i = r.image,
        n = setting(r.quick).repeats
    ));
    doc.heading("Resolution sweep (plots: plots/kanamori-grid-tetra.svg, plots/kanamori-grid-balls.svg)");
    let mut t = DocTable::new("", &["scene", "triangles", "res", "cells", "empty %", "refs/tri", "cells/ray", "empty cells/ray", "tests/ray", "CPU ms"]);
    for g in &r.sweep {
        t.push(vec![format!("{}{}", g.scene, g.sf), g.triangles.to_string(), res_str(g.res), format!("{:.0}", g.cells), format!("{:.0}", 100.0 * g.empty_cells / g.cells.max(1.0)), format!("{:.2}", g.references / g.triangles as f64), format!("{:.1}", g.cells_per_ray), format!("{:.1}", g.empty_cells_per_ray), format!("{:.1}", g.tests_per_ray), format!("{:.1}", g.cpu_s * 1e3)]);
    }
    doc.table(t);
    doc.heading("Settings: n^(1/3) per axis with mailbox off (the handout) and on; (8,8,8) with the mailbox");
    let mut t = DocTable::new("", &["scene", "res", "mailbox", "cells/ray", "empty cells/ray", "tests/ray", "CPU ms", "bytes/tri"]);
    for g in &r.settings {
        t.push(vec![format!("{}{}", g.scene, g.sf), res_str(g.res), if g.mailbox { "on" } else { "off" }.into(), format!("{:.1}", g.cells_per_ray), format!("{:.1}", g.empty_cells_per_ray), format!("{:.1}", g.tests_per_ray), format!("{:.1}", g.cpu_s * 1e3), format!("{:.1}", g.structure_bytes as f64 / g.triangles as f64)]);
    }
    for b in &r.bvh {
        t.push(vec![format!("{}{}", b.scene, b.sf), "bvh4 (default)".into(), "-".into(), "-".into(), "-".into(), "-".into(), format!("{:.1}", b.cpu_s * 1e3), "-".into()]);
    }
    doc.table(t);
    doc.heading("Density survey: every SPD program's grid at n^(1/3) per axis, mailbox off (the densest and the sparsest stand for 002's dense and sparse scenes)");
    let mut t = DocTable::new("", &["scene", "triangles", "res", "empty cells %", "empty among visited %", "tests/ray", "grid CPU ms", "bvh4 CPU ms", "grid ÷ bvh4"]);
    for (g, b) in &r.survey {
        t.push(vec![format!("{}{}", g.scene, g.sf), g.triangles.to_string(), res_str(g.res), format!("{:.1}", 100.0 * empty_share(g)), format!("{:.1}", 100.0 * g.empty_cells_per_ray / g.cells_per_ray.max(1e-9)), format!("{:.1}", g.tests_per_ray), format!("{:.1}", g.cpu_s * 1e3), format!("{:.1}", b * 1e3), format!("{:.2}", g.cpu_s / b.max(1e-12))]);
    }
    doc.table(t);
    doc.heading("Build time against size (median of 5 builds taken in turn: CPU time of the building thread, wall time for Embree, which builds on its own threads)");
    let mut t = DocTable::new("", &["scene", "triangles", "engine", "build ms"]);
    for b in &r.builds {
        t.push(vec![format!("{}{}", b.scene, b.sf), b.triangles.to_string(), b.engine.into(), format!("{:.2}", b.build_s * 1e3)]);
    }
    doc.table(t);
    doc.heading("Brute force (reference engine, f64) against the object count, tetra, 32x32 rays");
    let mut t = DocTable::new("", &["scene", "objects", "tests/ray", "µs/ray"]);
    for b in &r.brute {
        t.push(vec![format!("tetra{}", b.sf), b.objects.to_string(), format!("{:.1}", b.tests_per_ray), format!("{:.2}", b.us_per_ray)]);
    }
    doc.table(t);
    doc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_published_claims_parse_and_each_has_a_declared_key() {
        let (p, _): (Published, _) = published::load("kanamori-grid", PUBLISHED);
        assert_eq!(p.default_resolution, [8, 8, 8]);
        for c in &p.claims {
            assert!(TABLE.claims.iter().any(|d| d.key == c.id), "{} is not declared", c.id);
        }
        assert_eq!(p.claims.len(), TABLE.claims.len());
    }

    #[test]
    fn log_slope_recovers_a_power() {
        let pts: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0].iter().map(|&x: &f64| (x, 3.0 * x.powf(1.5))).collect();
        assert!((log_slope(&pts) - 1.5).abs() < 1e-9);
    }

    #[test]
    fn the_dda_visits_every_cell_a_ray_crosses() {
        let l = Lattice::new(glam::Vec3::ZERO, glam::Vec3::splat(4.0), [4, 4, 4]);
        let rays: Vec<Ray> = (0..50)
            .map(|i| {
                let a = i as f32 * 0.37;
                Ray::new(glam::Vec3::new(-1.0, 0.3 + 0.05 * i as f32, 0.2), glam::Vec3::new(1.0, a.sin() * 0.4, a.cos() * 0.3).normalize(), 0.0, f32::INFINITY)
            })
            .collect();
        let d = dda_check("t", 0, &l, &rays);
        assert!(d.crossed > 50);
        assert_eq!(d.missed, 0);
    }
}
