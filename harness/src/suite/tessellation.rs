//! `rtbench check --suite tessellation`: what tessellating the curved primitives costs in image
//! error and buys or costs in time. balls, rings and tree (spheres, cylinders, cones) are traced
//! curved and at `--tessellate RES` for RES 1…8 with every engine; the image error is the RMSE
//! of the pixel-corner colours (clamped to 0…1) against the same engine's curved render, the time
//! is the render's query time (the best of three renders when one takes under a second).
//!
//! An engine whose render takes longer than `BUDGET_S` stops its curve there (the brute-force
//! reference would take minutes at RES 8); the report says where.

use crate::error::Result;
use crate::workload::trace;
use rtbench_engines::geometry::Geometry;
use rtbench_engines::{build_engine, BuildInput};
use rtbench_scenes::generate_scene;
use rtbench_scenes::spd::{Options, Program};
use std::sync::Arc;
use std::time::Instant;

/// The scenes and size factors (small enough that RES 8, about 100 000 triangles, builds fast).
const SCENES: [(Program, u32); 3] = [(Program::Balls, 2), (Program::Rings, 2), (Program::Tree, 6)];
const MAX_RES: u32 = 8;
/// A render slower than this ends the engine's curve on that scene.
const BUDGET_S: f64 = 10.0;
/// Renders under a second are repeated this many times, the fastest kept (the machine is noisy).
const REPEATS: usize = 3;

pub struct TessPoint {
    pub res: u32,
    pub rmse: f64,
    pub time_s: f64,
    pub triangles: usize,
}

pub struct Curve {
    pub scene: String,
    pub engine: String,
    pub curved_s: f64,
    pub points: Vec<TessPoint>,
    pub stopped: Option<String>,
}

pub struct TessResults {
    pub size: u32,
    pub curves: Vec<Curve>,
    pub seconds: f64,
}

fn input(p: Program, sf: u32, tessellate: Option<u32>) -> BuildInput {
    let scene = generate_scene(
        p,
        &Options {
            size_factor: sf,
            tessellate,
            ..Options::standard(p)
        },
    )
    .expect("the tessellation scenes are valid");
    BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene: Arc::new(scene),
    }
}

/// Renders `input` with `engine`; the corners and the best query time (and the slowest wall
/// time, for the budget).
fn timed(input: &BuildInput, name: &str, size: u32) -> Result<(Vec<glam::Vec3>, f64, f64)> {
    let e = build_engine(name, input, vec![])?;
    let r = trace::render_chunked(
        &input.scene,
        e.as_ref(),
        size,
        trace::DEFAULT_CHUNK,
        true,
        None,
    );
    let (mut best, wall) = (r.intersect_s, r.trace_s);
    if wall < 1.0 {
        for _ in 1..REPEATS {
            best = best.min(trace::render(&input.scene, e.as_ref(), size, None).intersect_s);
        }
    }
    Ok((r.corners, best, wall))
}

/// The RES at which a power law fitted (least squares in log–log) to the measured RMSEs
/// reaches `target`, when the error falls with RES.
pub fn extrapolate(points: &[TessPoint], target: f64) -> Option<f64> {
    let xy: Vec<(f64, f64)> = points
        .iter()
        .filter(|p| p.rmse > 0.0)
        .map(|p| ((p.res as f64).ln(), p.rmse.ln()))
        .collect();
    if xy.len() < 3 {
        return None;
    }
    let n = xy.len() as f64;
    let (sx, sy) = xy.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let (mx, my) = (sx / n, sy / n);
    let sxx: f64 = xy.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = xy.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let slope = sxy / sxx;
    (slope < 0.0).then(|| ((target.ln() - (my - slope * mx)) / slope).exp())
}

fn rmse(a: &[glam::Vec3], b: &[glam::Vec3]) -> f64 {
    let c = |v: glam::Vec3| v.clamp(glam::Vec3::ZERO, glam::Vec3::ONE).as_dvec3();
    let sum: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (c(*x) - c(*y)).length_squared())
        .sum();
    (sum / (3 * a.len().max(1)) as f64).sqrt()
}

pub fn run(engines: &[String], size: u32) -> Result<TessResults> {
    let t0 = Instant::now();
    let mut curves = Vec::new();
    for (p, sf) in SCENES {
        let curved = input(p, sf, None);
        let tess: Vec<BuildInput> = (1..=MAX_RES).map(|r| input(p, sf, Some(r))).collect();
        for name in engines {
            let (reference, curved_s, _) = timed(&curved, name, size)?;
            let mut c = Curve {
                scene: format!("{}{sf}", p.name()),
                engine: name.clone(),
                curved_s,
                points: Vec::new(),
                stopped: None,
            };
            for (i, input) in tess.iter().enumerate() {
                let res = i as u32 + 1;
                let (corners, time_s, wall) = timed(input, name, size)?;
                c.points.push(TessPoint {
                    res,
                    rmse: rmse(&corners, &reference),
                    time_s,
                    triangles: input.geometry.prims.len(),
                });
                if wall > BUDGET_S && res < MAX_RES {
                    c.stopped = Some(format!(
                        "RES {res} took {wall:.1} s, over the {BUDGET_S} s budget"
                    ));
                    break;
                }
            }
            eprintln!(
                "tessellation {} {}: {}",
                c.scene,
                c.engine,
                c.points
                    .iter()
                    .map(|p| format!("{}:{:.1e}", p.res, p.rmse))
                    .collect::<Vec<_>>()
                    .join(" ")
            );
            curves.push(c);
        }
    }
    let t = TessResults {
        size,
        curves,
        seconds: t0.elapsed().as_secs_f64(),
    };
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_law_extrapolation() {
        // RMSE = 0.1 / RES: 1e-3 at RES 100.
        let pts: Vec<TessPoint> = (1..=8)
            .map(|r| TessPoint {
                res: r,
                rmse: 0.1 / r as f64,
                time_s: 0.0,
                triangles: 0,
            })
            .collect();
        assert!((extrapolate(&pts, 1e-3).unwrap() - 100.0).abs() < 1e-6);
        assert_eq!(extrapolate(&pts[..2], 1e-3), None);
    }
}
