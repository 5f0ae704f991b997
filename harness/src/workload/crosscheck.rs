//! One engine's answers against another's on the same rays. The workload is traced once with the
//! yardstick engine, recording every query; the engine under test answers exactly those queries.
//!
//! A closest-hit query agrees when both miss, both name the same object, or both hit at the same
//! distance within 1e-5 relative (a tie between two objects meeting at the hit point). An
//! any-hit query agrees when both give the same answer. Primitive agreement counts the
//! closest-hit queries only, and only as the same object (or both missing): the tie rule cannot
//! hide an engine that names the wrong object at the right distance.
//!
//! The t error of a hit on the same object is |t − t_ref| / max(t_ref, |origin|∞): relative to
//! the scale at which an `f32` engine can place a point at all. A secondary ray starting on a
//! surface at |origin| ≈ 1 that hits something at t = 0.001 cannot have its t right to better
//! than about 1e-7/0.001 = 1e-4 relative in single precision, however exact the kernel; dividing
//! by t alone would measure where rays start, not the engine. The plain |Δt|/t_ref is reported
//! too (`t_rel_err_raw`).

use super::trace;
use rtbench_engines::{Counters, Engine, Hit};
use rtbench_scenes::Scene;
use serde_json::{json, Value};

const TIE_REL: f32 = 1e-5;

/// Least primitive agreement `check` accepts: ties (two objects meeting at the hit point) are
/// rare, so an engine that passes on the tie rule for more than one closest hit in 100 is naming
/// wrong objects at the right distance.
pub const MIN_PRIMITIVE_AGREEMENT: f64 = 0.99;

/// Quantiles of an error distribution.
#[derive(Clone, Copy, Debug, Default)]
pub struct ErrorQuantiles {
    pub median: f64,
    pub p99: f64,
    pub max: f64,
}

impl ErrorQuantiles {
    pub fn of(mut v: Vec<f64>) -> ErrorQuantiles {
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
    /// Closest-hit queries where both miss or both name the same object (no tie rule).
    pub same_object: u64,
    pub t_rel_err: ErrorQuantiles,
    pub t_rel_err_raw: ErrorQuantiles,
    /// `None` when the images are identical.
    pub image_psnr_db: Option<f64>,
    /// Pixels whose whole ray trees (at all four corners) got the same answers from both
    /// engines — same object for every closest-hit query, same verdict for every shadow query —
    /// how many of those differ in any channel, and their largest difference (0–255).
    pub pixels_same_hits: u64,
    pub pixels_same_hits_differing: u64,
    pub pixels_same_hits_max_diff: u8,
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

    /// The share of closest-hit queries answered with the same object (module docs).
    pub fn primitive_agreement(&self) -> f64 {
        self.same_object as f64 / self.closest_rays.max(1) as f64
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

/// Checks `tested` against `yardstick` on the workload's rays; renders with both, recording, to
/// compare hits query by query and images where the ray trees agree.
pub fn cross_check(
    scene: &Scene,
    tested: &dyn Engine,
    yardstick: &dyn Engine,
    size: u32,
) -> CrossCheck {
    let mut rec = trace::Recording::default();
    let want = trace::render(scene, yardstick, size, Some(&mut rec));
    // The tested engine's own render, recorded too: its ray trees are compared with the
    // yardstick's corner by corner for the image comparison.
    let mut own_rec = trace::Recording::default();
    let own = trace::render(scene, tested, size, Some(&mut own_rec));
    let got = &own;
    let rays: Vec<_> = rec.closest.iter().map(|(r, _)| *r).collect();
    let (mut hits, mut occ) = (Vec::new(), Vec::new());
    let mut counters = Counters::default();
    trace::query_all(
        tested.batch_hint(),
        &rays,
        &mut hits,
        Hit::MISS,
        &mut counters,
        |r, h, c| tested.intersect(r, h, c),
    );
    let srays: Vec<_> = rec.any.iter().map(|(r, _)| *r).collect();
    trace::query_all(
        tested.batch_hint(),
        &srays,
        &mut occ,
        false,
        &mut counters,
        |r, o, c| tested.occluded(r, o, c),
    );

    let mut agree = 0u64;
    let mut same_object = 0u64;
    let (mut t_err, mut t_err_raw) = (Vec::new(), Vec::new());
    let mut mismatches = Vec::new();
    for (i, ((ray, want), got)) in rec.closest.iter().zip(&hits).enumerate() {
        let same = match (want.is_hit(), got.is_hit()) {
            (false, false) => {
                same_object += 1;
                true
            }
            (true, true) => {
                let dt = (want.t - got.t).abs();
                let raw = (dt / want.t.abs().max(f32::MIN_POSITIVE)) as f64;
                if want.object == got.object {
                    same_object += 1;
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
    // Images where the hits agree: a corner agrees when its ray tree in the tested engine's own
    // render got the same answers, query for query, as in the yardstick's (same objects hit,
    // same shadow verdicts, in the same order).
    let w = size as usize + 1;
    // FNV per corner: only compared for equality between the two renders, never stored.
    let tree_hash = |r: &trace::Recording| {
        use std::hash::Hasher;
        let mut h: Vec<fnv::FnvHasher> = (0..w * w).map(|_| fnv::FnvHasher::default()).collect();
        for ((_, hit), c) in r.closest.iter().zip(&r.closest_corner) {
            h[*c as usize].write_u64(hit.object as u64);
        }
        for ((_, b), c) in r.any.iter().zip(&r.any_corner) {
            h[*c as usize].write_u64(1 << 40 | *b as u64);
        }
        h.iter().map(Hasher::finish).collect::<Vec<u64>>()
    };
    let (hw, hg) = (tree_hash(&rec), tree_hash(&own_rec));
    let same_corner: Vec<bool> = hw.iter().zip(&hg).map(|(a, b)| a == b).collect();
    let (pw, pg) = (want.pixels(), got.pixels());
    let (mut n_same, mut n_diff, mut max_diff) = (0u64, 0u64, 0u8);
    for j in 0..size as usize {
        for i in 0..size as usize {
            let corners = [
                j * w + i,
                j * w + i + 1,
                (j + 1) * w + i,
                (j + 1) * w + i + 1,
            ];
            if corners.iter().all(|&c| same_corner[c]) {
                n_same += 1;
                let k = (j * size as usize + i) * 3;
                let d = (0..3)
                    .map(|c| pw[k + c].abs_diff(pg[k + c]))
                    .max()
                    .unwrap_or(0);
                if d > 0 {
                    n_diff += 1;
                    max_diff = max_diff.max(d);
                }
            }
        }
    }
    CrossCheck {
        pixels_same_hits: n_same,
        pixels_same_hits_differing: n_diff,
        pixels_same_hits_max_diff: max_diff,
        closest_rays: rec.closest.len() as u64,
        any_rays: rec.any.len() as u64,
        agree,
        same_object,
        t_rel_err: ErrorQuantiles::of(t_err),
        t_rel_err_raw: ErrorQuantiles::of(t_err_raw),
        image_psnr_db: psnr(pw, pg),
        mismatches,
    }
}
