//! An engine's answers on the hard cases against the right ones.
//!
//! Per ray, in this order: a hit with a NaN t, a t outside (tmin, tmax) or an object that is not
//! in the scene is *invalid*; a ray that must hit a closed surface by some t and does not is a
//! *leak*; a hit where the right answer is a miss is a *false hit*; a miss where it is a hit is a
//! *miss* (rays whose right answer is *ambiguous*, see `truth.rs`, are only counted as such);
//! a hit on another object at another distance is a *wrong hit*; a hit on another object
//! at the same distance (within 1e-5) where the right answer is the lower id is a *tie not on the
//! lowest id*. The t error of every other hit is |t − t_f64| / max(t_f64, |origin|∞), as in
//! `rtbench check` (relative to the scale at which an f32 engine can place a point at all).

use super::truth::Truth;
use crate::workload::crosscheck::ErrorQuantiles;
use rtbench_engines::{Hit, Ray};
use serde_json::{json, Value};

const TIE_REL: f64 = 1e-5;

/// Counts over a set of rays.
#[derive(Clone, Debug, Default)]
pub struct Tally {
    pub rays: u64,
    pub must_hit: u64,
    pub invalid: u64,
    pub leaks: u64,
    pub false_hits: u64,
    pub misses: u64,
    pub wrong_hits: u64,
    pub ties_not_lowest: u64,
    pub ambiguous: u64,
    pub t_err: Vec<f64>,
}

impl Tally {
    pub fn add(&mut self, o: &Tally) {
        self.rays += o.rays;
        self.must_hit += o.must_hit;
        self.invalid += o.invalid;
        self.leaks += o.leaks;
        self.false_hits += o.false_hits;
        self.misses += o.misses;
        self.wrong_hits += o.wrong_hits;
        self.ties_not_lowest += o.ties_not_lowest;
        self.ambiguous += o.ambiguous;
        self.t_err.extend_from_slice(&o.t_err);
    }

    /// Rays answered wrongly (invalid, leak, false hit, miss, wrong hit), as a fraction of the
    /// rays with a known answer.
    pub fn wrong_rate(&self) -> f64 {
        (self.invalid + self.leaks + self.false_hits + self.misses + self.wrong_hits) as f64
            / (self.rays - self.ambiguous).max(1) as f64
    }

    pub fn t_err(&self) -> ErrorQuantiles {
        ErrorQuantiles::of(self.t_err.clone())
    }

    pub fn to_json(&self) -> Value {
        json!({
            "rays": self.rays, "must_hit": self.must_hit, "invalid": self.invalid,
            "leaks": self.leaks, "false_hits": self.false_hits, "misses": self.misses,
            "wrong_hits": self.wrong_hits, "ties_not_lowest": self.ties_not_lowest, "ambiguous": self.ambiguous,
            "wrong_rate": self.wrong_rate(), "t_rel_err": self.t_err().to_json(),
        })
    }
}

/// Scores `hits` (an engine's answers to `rays`) against `truth`.
pub fn score(
    rays: &[Ray],
    hits: &[Hit],
    truth: &[Truth],
    must_hit_by: &[Option<f32>],
    objects: usize,
) -> Tally {
    let mut t = Tally::default();
    for (((ray, hit), want), must) in rays.iter().zip(hits).zip(truth).zip(must_hit_by) {
        t.rays += 1;
        if hit.is_hit()
            && (hit.t.is_nan()
                || hit.t <= ray.tmin
                || hit.t >= ray.tmax
                || hit.object as usize >= objects)
        {
            t.invalid += 1;
            continue;
        }
        if let Some(by) = must {
            t.must_hit += 1;
            if !hit.is_hit() || hit.t > *by {
                t.leaks += 1;
                continue;
            }
        }
        if !want.stable {
            t.ambiguous += 1;
            continue;
        }
        match (want.hit, hit.is_hit()) {
            (None, false) => {}
            (None, true) => t.false_hits += 1,
            (Some(_), false) => t.misses += 1,
            (Some((object, tw)), true) => {
                let dt = (hit.t as f64 - tw).abs();
                let tie = dt <= TIE_REL * tw.abs();
                if hit.object != object && !tie {
                    t.wrong_hits += 1;
                    continue;
                }
                if hit.object > object {
                    t.ties_not_lowest += 1;
                }
                let scale = tw
                    .abs()
                    .max(ray.origin.abs().max_element() as f64)
                    .max(f64::MIN_POSITIVE);
                t.t_err.push(dt / scale);
            }
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn each_kind_of_answer_is_counted() {
        let r = Ray::new(Vec3::ZERO, Vec3::Z, 0.0, 10.0);
        let hit = |object, t| Hit {
            t,
            object,
            u: 0.0,
            v: 0.0,
        };
        let truth = |h: Option<(u32, f64)>| Truth {
            hit: h,
            stable: true,
        };
        let rays = [r; 9];
        let hits = [
            hit(0, f32::NAN), // invalid
            Hit::MISS,        // leak
            hit(0, 1.0),      // false hit
            Hit::MISS,        // miss
            hit(1, 5.0),      // wrong hit
            hit(2, 2.0),      // tie not on the lowest id
            hit(0, 2.000002), // t error 1e-6
            hit(0, 11.0),     // invalid: beyond tmax
            hit(0, 1.0),      // ambiguous
        ];
        let want = [
            truth(Some((0, 1.0))),
            truth(Some((0, 1.0))),
            truth(None),
            truth(Some((0, 1.0))),
            truth(Some((0, 1.0))),
            truth(Some((1, 2.0))),
            truth(Some((0, 2.0))),
            truth(None),
            Truth {
                hit: None,
                stable: false,
            },
        ];
        let mut must = [None; 9];
        must[1] = Some(1.5);
        let t = score(&rays, &hits, &want, &must, 3);
        assert_eq!(
            (
                t.invalid,
                t.leaks,
                t.false_hits,
                t.misses,
                t.wrong_hits,
                t.ties_not_lowest,
                t.ambiguous
            ),
            (2, 1, 1, 1, 1, 1, 1)
        );
        assert_eq!(t.t_err.len(), 2);
        assert!((t.t_err().max - 1e-6).abs() < 2e-7);
    }
}
