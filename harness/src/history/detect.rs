//! Detection for a shared, noisy machine.
//!
//! - Exact counters: any change against the last night of the same fingerprint is a finding.
//! - Instruction counts: a change past the suite's small tolerance.
//! - Times (trace CPU time over Embree's in the same night, per repeat; criterion estimates):
//!   tonight's median is compared with the nights of the baseline by a one-sided prediction
//!   interval on the log scale, `(ln v − mean) / (s·√(1 + 1/K)) > t(1 − α; K − 1)`, where `mean`
//!   and `s` are the mean and standard deviation of the K baseline nights' log medians: the
//!   history's own night-to-night spread, whatever the machine's load did to it. α is the suite's
//!   false-alarm budget per night split over the gated time metrics (Bonferroni), so at most
//!   `budget` nights in expectation carry a false alarm. Two confirmations must also hold: the
//!   change exceeds `min_change_pct`, and a Mann–Whitney rank test of tonight's repeats against
//!   the baseline's repeats says "greater" at p < 0.05 (one outlying repeat does not make a median
//!   move alone), and every round (each a separate process) shows the change on its own: its
//!   median is past the baseline's centre by `min_change_pct` in the same direction. A real
//!   change of the code moves every process; an unlucky process (heap and code layout, a burst
//!   of load during its pairs) moves one. All three can only remove alarms, so the budget still
//!   bounds the false-alarm rate.
//! - The baseline is the last `baseline_nights` nights of the same fingerprint, cut at the latest
//!   change point found in them by E-divisive (energy statistic, permutation test, as Hunter
//!   does): after a real, accepted change the baseline is the nights since.

use statrs::distribution::{ContinuousCDF, Normal, StudentsT};

/// Student's t quantile with `nu` degrees of freedom (statrs).
pub fn t_quantile(p: f64, nu: f64) -> f64 {
    StudentsT::new(0.0, 1.0, nu.max(1e-9))
        .map(|t| t.inverse_cdf(p))
        .unwrap_or(f64::NAN)
}

/// One-sided Mann–Whitney p-value that `x` tends to be greater than `y` (normal approximation
/// with tie and continuity corrections). 1 when either side is empty.
pub fn mann_whitney_greater(x: &[f64], y: &[f64]) -> f64 {
    let (n1, n2) = (x.len() as f64, y.len() as f64);
    if x.is_empty() || y.is_empty() {
        return 1.0;
    }
    let mut all: Vec<(f64, bool)> = x
        .iter()
        .map(|&v| (v, true))
        .chain(y.iter().map(|&v| (v, false)))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    let n = all.len();
    let mut rank_x = 0.0;
    let mut ties = 0.0;
    let mut i = 0;
    while i < n {
        let mut j = i;
        while j + 1 < n && all[j + 1].0 == all[i].0 {
            j += 1;
        }
        let r = (i + j) as f64 / 2.0 + 1.0;
        let t = (j - i + 1) as f64;
        ties += t * t * t - t;
        for a in &all[i..=j] {
            if a.1 {
                rank_x += r;
            }
        }
        i = j + 1;
    }
    let u = rank_x - n1 * (n1 + 1.0) / 2.0;
    let mean = n1 * n2 / 2.0;
    let nn = n1 + n2;
    let var = n1 * n2 / 12.0 * ((nn + 1.0) - ties / (nn * (nn - 1.0)));
    if var <= 0.0 {
        return if u > mean { 0.0 } else { 1.0 };
    }
    let z = (u - mean - 0.5) / var.sqrt();
    1.0 - normal_cdf(z)
}

/// The standard normal distribution function (statrs).
pub fn normal_cdf(z: f64) -> f64 {
    Normal::standard().cdf(z)
}

pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.total_cmp(b));
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        (s[n / 2 - 1] + s[n / 2]) / 2.0
    }
}

fn mean_sd(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, var.sqrt())
}

/// The energy statistic of splitting `x` at `tau` (Matteson & James' E-divisive, α = 1).
fn energy(x: &[f64], tau: usize) -> f64 {
    let (a, b) = x.split_at(tau);
    let (n, m) = (a.len() as f64, b.len() as f64);
    let mut between = 0.0;
    for p in a {
        for q in b {
            between += (p - q).abs();
        }
    }
    let within = |s: &[f64]| {
        let mut w = 0.0;
        for i in 0..s.len() {
            for j in i + 1..s.len() {
                w += (s[i] - s[j]).abs();
            }
        }
        let k = s.len() as f64;
        if k < 2.0 {
            0.0
        } else {
            w / (k * (k - 1.0) / 2.0)
        }
    };
    let e = 2.0 * between / (n * m) - within(a) - within(b);
    e * n * m / (n + m)
}

fn best_split(x: &[f64], min_seg: usize) -> Option<(usize, f64)> {
    (min_seg..=x.len().saturating_sub(min_seg))
        .map(|t| (t, energy(x, t)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
}

/// Change points of a series (indices where a new segment starts), by E-divisive: binary
/// segmentation on the energy statistic, each split kept when a permutation test (199
/// permutations) gives p ≤ `alpha`. Segments have at least `min_seg` points.
pub fn change_points(x: &[f64], alpha: f64, min_seg: usize) -> Vec<usize> {
    let mut out = Vec::new();
    // Seeded, so a night's change points are the same each time they are computed.
    let mut rng = fastrand::Rng::with_seed(0x9E37_79B9_7F4A_7C15);
    let mut todo = vec![(0usize, x.len())];
    while let Some((lo, hi)) = todo.pop() {
        let seg = &x[lo..hi];
        if seg.len() < 2 * min_seg {
            continue;
        }
        let Some((tau, stat)) = best_split(seg, min_seg) else {
            continue;
        };
        let perms = 199;
        let mut above = 0;
        let mut y = seg.to_vec();
        for _ in 0..perms {
            rng.shuffle(&mut y);
            if best_split(&y, min_seg).is_some_and(|(_, s)| s >= stat) {
                above += 1;
            }
        }
        let p = (above + 1) as f64 / (perms + 1) as f64;
        if p <= alpha {
            out.push(lo + tau);
            todo.push((lo, lo + tau));
            todo.push((lo + tau, hi));
        }
    }
    out.sort_unstable();
    out
}

/// The verdict on one time-like metric (lower is better).
#[derive(Clone, Debug, PartialEq)]
pub struct TimeVerdict {
    /// +1 regression, −1 improvement, 0 neither.
    pub direction: i32,
    /// Tonight against the baseline's centre, percent.
    pub change_pct: f64,
    /// The baseline's centre (geometric mean of its nights).
    pub baseline: f64,
    /// How many prediction-interval widths tonight lies out, and the threshold.
    pub score: f64,
    pub threshold: f64,
    /// One night's prediction width on the log scale, without the `√(1 + 1/K)` factor.
    pub spread: f64,
    pub mw_p: f64,
    /// The smallest (for a slowdown; the largest for a speed-up) round's change, percent.
    pub weakest_round_pct: f64,
}

/// The first-night threshold of a two-night rule: a suspect at `√α`, so that a change must
/// stand out on each night at `√α` and on the two nights' mean at `α` (below). Independent
/// nights under no change pass both at a rate of at most `α`: the mean test alone bounds it.
pub fn suspect_alpha(alpha: f64) -> f64 {
    alpha.sqrt()
}

/// Tonight's value, samples and round medians against the baseline nights' values and samples
/// (`None` when the baseline has fewer than 3 nights; `alpha` is this metric's share of the
/// false-alarm budget); over two nights when `previous` (the suspect night's value, left out of
/// `nights`) is given: the centre of tonight's and the previous night's log values is tested
/// against the baseline with the prediction width of a mean of two, `s·√(1/2 + 1/K)`, and the
/// change must also stand out tonight alone at [`suspect_alpha`]. The change reported is the
/// two nights' centre against the baseline's.
pub fn time_verdict_over(
    tonight: f64,
    previous: Option<f64>,
    tonight_samples: &[f64],
    rounds: &[f64],
    nights: &[(f64, Vec<f64>)],
    alpha: f64,
    min_change_pct: f64,
) -> Option<TimeVerdict> {
    if let Some(prev) = previous.filter(|p| *p > 0.0) {
        let single = time_verdict_over(
            tonight,
            None,
            tonight_samples,
            rounds,
            nights,
            suspect_alpha(alpha),
            min_change_pct,
        )?;
        let k = nights.iter().filter(|(v, _)| *v > 0.0).count() as f64;
        let d = (tonight.ln() + prev.ln()) / 2.0 - single.baseline.ln();
        let score = d / (single.spread * (0.5 + 1.0 / k).sqrt());
        let threshold = t_quantile(1.0 - alpha, k - 1.0);
        let change_pct = (d.exp() - 1.0) * 100.0;
        let direction =
            if single.direction == 1 && score > threshold && change_pct >= min_change_pct {
                1
            } else if single.direction == -1 && score < -threshold && change_pct <= -min_change_pct
            {
                -1
            } else {
                0
            };
        return Some(TimeVerdict {
            direction,
            change_pct,
            score,
            threshold,
            ..single
        });
    }
    let logs: Vec<f64> = nights
        .iter()
        .map(|(v, _)| *v)
        .filter(|v| *v > 0.0)
        .map(f64::ln)
        .collect();
    if logs.len() < 3 || tonight <= 0.0 {
        return None;
    }
    let k = logs.len() as f64;
    let (m, sd) = mean_sd(&logs);
    // A floor on the spread: the repeats' own noise (a night's median of n repeats moves by
    // about σ/√n even on a quiet machine), so a baseline of lucky identical nights does not make
    // every tiny wobble significant.
    let within = {
        let rel: Vec<f64> = nights
            .iter()
            .map(|(v, s)| {
                if s.len() < 2 || *v <= 0.0 {
                    0.0
                } else {
                    let mad = median(&s.iter().map(|x| (x - v).abs()).collect::<Vec<_>>());
                    1.4826 * mad / v / (s.len() as f64).sqrt()
                }
            })
            .collect();
        median(&rel)
    };
    let spread = sd.max(within).max(1e-6);
    let s = spread * (1.0 + 1.0 / k).sqrt();
    let d = tonight.ln() - m;
    let threshold = t_quantile(1.0 - alpha, k - 1.0);
    let score = d / s;
    let change_pct = (d.exp() - 1.0) * 100.0;
    let pooled: Vec<f64> = nights.iter().flat_map(|(_, s)| s.iter().copied()).collect();
    let (mw_up, mw_down) = (
        mann_whitney_greater(tonight_samples, &pooled),
        mann_whitney_greater(&pooled, tonight_samples),
    );
    let big = change_pct.abs() >= min_change_pct;
    let centre = m.exp();
    let round_pct = |r: &f64| (r / centre - 1.0) * 100.0;
    let rounds_pct: Vec<f64> = if rounds.is_empty() {
        vec![change_pct]
    } else {
        rounds.iter().map(round_pct).collect()
    };
    let weakest_up = rounds_pct.iter().copied().fold(f64::INFINITY, f64::min);
    let weakest_down = rounds_pct.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let direction = if score > threshold && big && mw_up < 0.05 && weakest_up >= min_change_pct {
        1
    } else if score < -threshold && big && mw_down < 0.05 && weakest_down <= -min_change_pct {
        -1
    } else {
        0
    };
    Some(TimeVerdict {
        direction,
        change_pct,
        baseline: m.exp(),
        score,
        threshold,
        spread,
        mw_p: if d >= 0.0 { mw_up } else { mw_down },
        weakest_round_pct: if d >= 0.0 { weakest_up } else { weakest_down },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_match_the_tables() {
        assert!((normal_cdf(1.959964) - 0.975).abs() < 1e-6);
        // t(0.995; 9) = 3.2498, t(0.999; 4) = 7.1732 (tables)
        assert!((t_quantile(0.995, 9.0) - 3.2498).abs() < 1e-3);
        assert!((t_quantile(0.99, 4.0) - 3.7469).abs() < 1e-3);
        assert!((normal_cdf(1.959964) - 0.975).abs() < 1e-6);
    }

    #[test]
    fn mann_whitney_sees_a_shift_and_not_its_absence() {
        let y: Vec<f64> = (0..20).map(|i| 1.0 + 0.01 * i as f64).collect();
        let x: Vec<f64> = y.iter().map(|v| v + 0.5).collect();
        assert!(mann_whitney_greater(&x, &y) < 1e-4);
        assert!(mann_whitney_greater(&y, &x) > 0.99);
        assert!(mann_whitney_greater(&y, &y) > 0.3);
    }

    #[test]
    fn e_divisive_finds_a_step_and_nothing_in_flat_noise() {
        let mut r = fastrand::Rng::with_seed(42);
        let mut noise = || r.u64(..1000) as f64 / 1000.0 * 0.02;
        let flat: Vec<f64> = (0..30).map(|_| 1.0 + noise()).collect();
        assert!(change_points(&flat, 0.01, 4).is_empty());
        let step: Vec<f64> = (0..30)
            .map(|i| if i < 18 { 1.0 } else { 1.1 } + noise())
            .collect();
        assert_eq!(change_points(&step, 0.01, 4), vec![18]);
    }

    #[test]
    fn a_slowdown_past_the_spread_is_a_regression_and_noise_is_not() {
        let nights: Vec<(f64, Vec<f64>)> = [1.00, 1.01, 0.99, 1.005, 0.995, 1.0]
            .iter()
            .map(|&v| (v, vec![v * 0.99, v, v * 1.01]))
            .collect();
        let slow = [1.07, 1.08, 1.09];
        let v = time_verdict_over(1.08, None, &slow, &slow, &nights, 0.001, 1.0).unwrap();
        assert_eq!(v.direction, 1, "{v:?}");
        let same = [0.995, 1.005, 1.01];
        let v = time_verdict_over(1.005, None, &same, &same, &nights, 0.001, 1.0).unwrap();
        assert_eq!(v.direction, 0, "{v:?}");
        let fast = [0.89, 0.9, 0.91];
        let v = time_verdict_over(0.9, None, &fast, &fast, &nights, 0.001, 1.0).unwrap();
        assert_eq!(v.direction, -1, "{v:?}");
        assert!(time_verdict_over(1.0, None, &[1.0], &[1.0], &nights[..2], 0.001, 1.0).is_none());
    }

    #[test]
    fn one_unlucky_round_is_not_a_regression() {
        let nights: Vec<(f64, Vec<f64>)> = [1.00, 1.01, 0.99, 1.005, 0.995, 1.0]
            .iter()
            .map(|&v| (v, vec![v * 0.99, v, v * 1.01]))
            .collect();
        // Two rounds of three samples 8% up, one round as before: the median moves, but one
        // process did not see the change, so it was the others' luck, not the code.
        let samples = [1.08, 1.08, 1.09, 1.0, 1.0, 1.01, 1.07, 1.08, 1.08];
        let rounds = [1.08, 1.0, 1.08];
        let v = time_verdict_over(1.08, None, &samples, &rounds, &nights, 0.001, 1.0).unwrap();
        assert_eq!(v.direction, 0, "{v:?}");
        assert!(v.weakest_round_pct.abs() < 1.0, "{v:?}");
        let rounds = [1.08, 1.07, 1.08];
        let v = time_verdict_over(1.08, None, &samples, &rounds, &nights, 0.001, 1.0).unwrap();
        assert_eq!(v.direction, 1, "{v:?}");
    }
}
