//! 95 % confidence intervals of ratios: every ratio to Embree, every speed-up over one thread and
//! every change `compare` judges carries one, with the samples behind it.
//!
//! Times are compared on the log scale, where a ratio is a difference and the spread of repeated
//! timings is closer to symmetric: a figure is a geometric mean of ratios (paired samples) or a
//! quotient of geometric means (independent samples), and its interval is Student's t interval of
//! the mean log, or Welch's for a difference of means with the Welch–Satterthwaite degrees of
//! freedom, both with quantiles from `statrs`. Fewer than two samples on a side give no interval:
//! a spread cannot be estimated from one sample.
//!
//! Ratios measured in pairs take the median of their logs instead of the mean
//! ([`LogMean::median_of`]), with the standard error of a median from the scaled median absolute
//! deviation: a few pairs that a passing disturbance of the machine hit (the first pairs of a trace
//! that runs beside another process's burst, say) move neither the figure nor its interval, where
//! they moved a mean by a third and widened its interval fivefold.

use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, StudentsT};

/// The confidence level of every interval.
pub const LEVEL: f64 = 0.95;

/// A figure with its 95 % interval and the samples behind it.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Interval {
    pub estimate: f64,
    pub lo: f64,
    pub hi: f64,
    /// Samples behind the figure: pairs for paired ratios, all repeats of both sides otherwise.
    pub n: usize,
    pub level: f64,
}

/// The mean of logs of some samples, its squared standard error and its degrees of freedom: the
/// pieces intervals of log-scale figures are combined from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogMean {
    pub mean: f64,
    /// Squared standard error of `mean`.
    pub var: f64,
    /// Degrees of freedom of `var` (n − 1 for one sample).
    pub df: f64,
    pub n: usize,
}

impl LogMean {
    /// Of positive finite samples; `None` with fewer than two usable samples.
    pub fn of(samples: &[f64]) -> Option<LogMean> {
        LogMean::of_logs(&logs(samples)?)
    }

    /// Of values already on the log scale (one log figure per round, say): their mean, with the
    /// squared standard error s²/n and n − 1 degrees of freedom; `None` with fewer than two
    /// values or any that is not finite.
    pub fn of_logs(logs: &[f64]) -> Option<LogMean> {
        if logs.len() < 2 || logs.iter().any(|l| !l.is_finite()) {
            return None;
        }
        let n = logs.len();
        let mean = logs.iter().sum::<f64>() / n as f64;
        let s2 = logs.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        Some(LogMean {
            mean,
            var: s2 / n as f64,
            df: (n - 1) as f64,
            n,
        })
    }

    /// Of positive finite samples, robustly: the median of the logs, with the squared standard
    /// error of a median of normal samples, (π/2)·σ²/n, and σ estimated as 1.4826 × the median
    /// absolute deviation of the logs; n − 1 degrees of freedom. `None` with fewer than two usable
    /// samples.
    pub fn median_of(samples: &[f64]) -> Option<LogMean> {
        let mut logs = logs(samples)?;
        let n = logs.len();
        let median = median(&mut logs);
        let mut dev: Vec<f64> = logs.iter().map(|l| (l - median).abs()).collect();
        let sigma = 1.4826 * self::median(&mut dev);
        Some(LogMean {
            mean: median,
            var: std::f64::consts::FRAC_PI_2 * sigma * sigma / n as f64,
            df: (n - 1) as f64,
            n,
        })
    }

    /// `self − other` for independent estimates (Welch–Satterthwaite degrees of freedom).
    pub fn minus(&self, other: &LogMean) -> LogMean {
        combine(&[(1.0, *self), (-1.0, *other)])
    }

    /// The interval of `exp(mean)`.
    pub fn interval(&self) -> Interval {
        let half = t_975(self.df) * self.var.sqrt();
        Interval {
            estimate: self.mean.exp(),
            lo: (self.mean - half).exp(),
            hi: (self.mean + half).exp(),
            n: self.n,
            level: LEVEL,
        }
    }
}

/// Σ sign·mean of independent estimates, with Welch–Satterthwaite degrees of freedom.
pub fn combine(terms: &[(f64, LogMean)]) -> LogMean {
    let mean = terms.iter().map(|(s, m)| s * m.mean).sum();
    let var: f64 = terms.iter().map(|(_, m)| m.var).sum();
    let denom: f64 = terms
        .iter()
        .map(|(_, m)| m.var * m.var / m.df.max(1.0))
        .sum();
    let df = if denom > 0.0 {
        var * var / denom
    } else {
        terms.iter().map(|(_, m)| m.df).sum()
    };
    LogMean {
        mean,
        var,
        df: df.max(1.0),
        n: terms.iter().map(|(_, m)| m.n).sum(),
    }
}

/// The two-sided 95 % quantile of Student's t with `df` degrees of freedom.
pub fn t_975(df: f64) -> f64 {
    StudentsT::new(0.0, 1.0, df.max(1.0))
        .map(|t| t.inverse_cdf(0.5 + LEVEL / 2.0))
        .unwrap_or(f64::INFINITY)
}

/// The logs of the samples when there are at least two and every one is positive and finite.
fn logs(samples: &[f64]) -> Option<Vec<f64>> {
    let logs: Vec<f64> = samples
        .iter()
        .filter(|x| x.is_finite() && **x > 0.0)
        .map(|x| x.ln())
        .collect();
    (logs.len() >= 2 && logs.len() == samples.len()).then_some(logs)
}

/// The median log of one or more positive finite samples (`None` otherwise): one round's figure
/// of its pairs ([`crate::rounds`]).
pub fn median_log(samples: &[f64]) -> Option<f64> {
    if samples.is_empty() || samples.iter().any(|x| !x.is_finite() || *x <= 0.0) {
        return None;
    }
    let mut logs: Vec<f64> = samples.iter().map(|x| x.ln()).collect();
    Some(median(&mut logs))
}

/// The median of some values (NaN for none); sorts them.
fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

/// Paired ratios (one per pair, e.g. engine over Embree traced back to back): the exponential of
/// the median log and its interval ([`LogMean::median_of`]); `None` with fewer than two pairs.
pub fn of_ratios(samples: &[f64]) -> Option<Interval> {
    LogMean::median_of(samples).map(|m| m.interval())
}

/// Independent samples `a` and `b` (an engine's repeats and Embree's, in two processes): the
/// quotient of their geometric means and its Welch interval; `None` with fewer than two samples
/// on either side.
pub fn of_quotient(a: &[f64], b: &[f64]) -> Option<Interval> {
    Some(LogMean::of(a)?.minus(&LogMean::of(b)?).interval())
}

impl Interval {
    /// `0.93× [0.91, 0.95] (n 6)` style text: the figure, its interval, its samples.
    pub fn text(&self) -> String {
        format!(
            "{} [{}, {}]",
            crate::number::ratio(self.estimate),
            crate::number::ratio(self.lo),
            crate::number::ratio(self.hi)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles_match_the_tables() {
        // Two-sided 95 %: 12.706 (1), 4.303 (2), 2.571 (5), 2.228 (10), 1.960 (∞).
        for (df, q) in [(1.0, 12.706), (2.0, 4.303), (5.0, 2.571), (10.0, 2.228)] {
            assert!((t_975(df) - q).abs() < 1e-3, "{df}: {}", t_975(df));
        }
        assert!((t_975(1e6) - 1.960).abs() < 1e-3);
    }

    #[test]
    fn paired_ratios_give_the_median_and_an_interval_from_the_deviations() {
        let i = of_ratios(&[1.0, 1.1, 1.2]).unwrap();
        let logs = [0.0f64, 1.1f64.ln(), 1.2f64.ln()];
        let m = logs[1];
        let mad = (logs[2] - m).abs().min((logs[0] - m).abs());
        let half = 4.303 * (std::f64::consts::FRAC_PI_2 / 3.0).sqrt() * 1.4826 * mad;
        assert!((i.estimate - 1.1).abs() < 1e-12);
        assert!((i.lo - (m - half).exp()).abs() < 1e-3);
        assert!((i.hi - (m + half).exp()).abs() < 1e-3);
        assert_eq!((i.n, i.level), (3, 0.95));
        assert!(of_ratios(&[1.0]).is_none(), "one sample has no spread");
        assert!(
            of_ratios(&[1.0, -1.0]).is_none(),
            "a non-positive ratio is no ratio"
        );
    }

    #[test]
    fn a_few_disturbed_pairs_move_neither_the_median_nor_its_interval() {
        // 20 pairs near 1.65, four of them in a row hit by a disturbance (+30 … +55 %).
        let mut pairs: Vec<f64> = (0..20)
            .map(|k| 1.65 * (1.0 + 0.004 * ((k % 5) as f64 - 2.0)))
            .collect();
        let quiet = of_ratios(&pairs).unwrap();
        for (k, f) in [1.3, 1.4, 1.45, 1.55].into_iter().enumerate() {
            pairs[3 + k] *= f;
        }
        let hit = of_ratios(&pairs).unwrap();
        assert!((hit.estimate / quiet.estimate - 1.0).abs() < 0.01);
        assert!(hit.hi / hit.lo < 1.03, "{hit:?}");
        let mean = LogMean::of(&pairs).unwrap().interval();
        assert!(
            mean.estimate / quiet.estimate > 1.05 && mean.hi / mean.lo > 1.1,
            "{mean:?}"
        );
    }

    #[test]
    fn a_quotient_of_equal_spreads_has_welch_degrees_of_freedom() {
        // Equal variances and sizes: Welch's df is 2(n − 1).
        let a = [2.0, 2.2, 2.4];
        let b = [1.0, 1.1, 1.2];
        let q = LogMean::of(&a).unwrap().minus(&LogMean::of(&b).unwrap());
        assert!((q.df - 4.0).abs() < 1e-9);
        let i = of_quotient(&a, &b).unwrap();
        assert!((i.estimate - 2.0).abs() < 1e-9);
        assert!(i.lo < 2.0 && i.hi > 2.0);
        assert_eq!(i.n, 6);
    }
}
