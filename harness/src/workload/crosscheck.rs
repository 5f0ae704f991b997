//! One engine's answers against another's on the same rays. The workload is traced once with the
//! yardstick engine, recording every query; the engine under test answers exactly those queries.
//!
//! A closest-hit query agrees when both miss, both name the same object, or both hit at the same
//! distance within 1e-5 relative (a tie between two objects meeting at the hit point). An
//! any-hit query agrees when both give the same answer.
//!
//! The t error of a hit on the same object is |t − t_ref| / max(t_ref, |origin|∞): relative to
//! the scale at which an `f32` engine can place a point at all. A secondary ray starting on a
//! surface at |origin| ≈ 1 that hits something at t = 0.001 cannot have its t right to better
//! than about 1e-7/0.001 = 1e-4 relative in single precision, however exact the kernel; dividing
//! by t alone would measure where rays start, not the engine. The plain |Δt|/t_ref is reported
//! too (`t_rel_err_raw`).

use super::trace::{self, Render};
use rayon::prelude::*;
use rtbench_engines::{Counters, Engine, Hit};
use rtbench_scenes::Scene;
use serde_json::{json, Value};

const TIE_REL: f32 = 1e-5;

/// Quantiles of an error distribution.
#[derive(Clone, Copy, Debug, Default)]
pub struct ErrorQuantiles {
    pub median: f64,
    pub p99: f64,
    pub max: f64,
}

impl ErrorQuantiles {
    fn of(mut v: Vec<f64>) -> ErrorQuantiles {
        v.sort_by(|a, b| a.total_cmp(b));
        let q = |p: f64| {
            if v.is_empty() {
                0.0
            } else {
                v[((v.len() - 1) as f64 * p).round() as usize]
            }
        };
        ErrorQuantiles {
            median: q(0.5),
            p99: q(0.99),
            max: v.last().copied().unwrap_or(0.0),
        }
    }

    pub fn to_json(self) -> Value {
        json!({"median": self.median, "p99": self.p99, "max": self.max})
    }
}

pub struct CrossCheck {
    pub closest_rays: u64,
    pub any_rays: u64,
    pub agree: u64,
    pub t_rel_err: ErrorQuantiles,
    pub t_rel_err_raw: ErrorQuantiles,
    /// `None` when the images are identical.
    pub image_psnr_db: Option<f64>,
    /// The first few disagreeing queries.
    pub mismatches: Vec<Value>,
}

impl CrossCheck {
    pub fn rays(&self) -> u64 {
        self.closest_rays + self.any_rays
    }

    pub fn agreement(&self) -> f64 {
        self.agree as f64 / self.rays().max(1) as f64
    }
}

fn psnr(a: &[u8], b: &[u8]) -> Option<f64> {
    let mse: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x as f64 - *y as f64).powi(2))
        .sum::<f64>()
        / a.len().max(1) as f64;
    (mse > 0.0).then(|| 10.0 * (255.0f64 * 255.0 / mse).log10())
}

/// Checks `tested` against `yardstick` on the workload's rays. `tested_render`, if the caller
/// has already rendered with the tested engine, saves a render.
pub fn cross_check(
    scene: &Scene,
    tested: &dyn Engine,
    yardstick: &dyn Engine,
    size: u32,
    tested_render: Option<&Render>,
) -> CrossCheck {
    let mut rec = trace::Recording::default();
    let want = trace::render(scene, yardstick, size, Some(&mut rec));
    let own;
    let got = match tested_render {
        Some(r) => r,
        None => {
            own = trace::render(scene, tested, size, None);
            &own
        }
    };
    let rays: Vec<_> = rec.closest.iter().map(|(r, _)| *r).collect();
    let mut hits = vec![Hit::MISS; rays.len()];
    rays.par_chunks(4096)
        .zip(hits.par_chunks_mut(4096))
        .for_each(|(r, h)| tested.intersect(r, h, &mut Counters::default()));
    let srays: Vec<_> = rec.any.iter().map(|(r, _)| *r).collect();
    let mut occ = vec![false; srays.len()];
    srays
        .par_chunks(4096)
        .zip(occ.par_chunks_mut(4096))
        .for_each(|(r, o)| tested.occluded(r, o, &mut Counters::default()));

    let mut agree = 0u64;
    let (mut t_err, mut t_err_raw) = (Vec::new(), Vec::new());
    let mut mismatches = Vec::new();
    for (i, ((ray, want), got)) in rec.closest.iter().zip(&hits).enumerate() {
        let same = match (want.is_hit(), got.is_hit()) {
            (false, false) => true,
            (true, true) => {
                let dt = (want.t - got.t).abs();
                let raw = (dt / want.t.abs().max(f32::MIN_POSITIVE)) as f64;
                if want.object == got.object {
                    let scale = want
                        .t
                        .abs()
                        .max(ray.origin.abs().max_element())
                        .max(f32::MIN_POSITIVE);
                    t_err.push((dt / scale) as f64);
                    t_err_raw.push(raw);
                    true
                } else {
                    raw <= TIE_REL as f64
                }
            }
            _ => false,
        };
        if same {
            agree += 1;
        } else if mismatches.len() < 8 {
            mismatches.push(json!({"query": "closest", "index": i,
                "origin": ray.origin.to_array(), "dir": ray.dir.to_array(),
                "want": {"object": want.is_hit().then_some(want.object), "t": want.is_hit().then_some(want.t)},
                "got": {"object": got.is_hit().then_some(got.object), "t": got.is_hit().then_some(got.t)}}));
        }
    }
    for (i, ((ray, want), got)) in rec.any.iter().zip(&occ).enumerate() {
        if want == got {
            agree += 1;
        } else if mismatches.len() < 8 {
            mismatches.push(
                json!({"query": "any", "index": i, "origin": ray.origin.to_array(),
                "dir": ray.dir.to_array(), "tmax": ray.tmax, "want": want, "got": got}),
            );
        }
    }
    CrossCheck {
        closest_rays: rec.closest.len() as u64,
        any_rays: rec.any.len() as u64,
        agree,
        t_rel_err: ErrorQuantiles::of(t_err),
        t_rel_err_raw: ErrorQuantiles::of(t_err_raw),
        image_psnr_db: psnr(&want.pixels(), &got.pixels()),
        mismatches,
    }
}
