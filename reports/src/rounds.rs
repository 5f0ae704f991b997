//! Rounds as the unit of a run's intervals.
//!
//! Repeats and pairs timed in one process share that process's state and the minute it ran in. On
//! this kind of machine both move an engine's speed against Embree's by several percent for tens
//! of seconds at a time, and one process's pairs cannot see it: 118 processes of grid against
//! Embree on tetra3 (three to nine pairs each, a busy 2-core machine) gave medians of 1.56–1.60 in
//! 101, 1.39–1.46 in 14 and 1.82–1.95 in 3, with every pair of one at 1.39 between 1.38 and 1.40.
//! An interval from one process's pairs is then a few percent wide around a figure that is 10 % off,
//! and two runs of one commit "differ".
//!
//! So `rtbench run` (and the nightly) spread a run over rounds: each round runs every job once, in
//! a process of its own, and the record keeps how many of its samples each round took
//! ([`Round`]). Each round gives one log figure (the median log of its pairs, or its mean log
//! repeat time minus Embree's in the same round), and the run's figure and 95 % interval are
//! Student's t over the round figures ([`LogMean::of_logs`]): what varies between processes and
//! minutes is then inside the interval. Fewer than two rounds give `None`, and callers fall back
//! to the samples of the one process.

use crate::interval::{self, LogMean};
use crate::results::{Round, RunRecord};

/// `samples` cut into the rounds' slices (`size` gives each round's count); `None` unless there
/// are two or more rounds, each with at least one sample, covering the samples exactly.
fn split<'a>(
    samples: &'a [f64],
    rounds: &[Round],
    size: fn(&Round) -> usize,
) -> Option<Vec<&'a [f64]>> {
    if rounds.len() < 2 || rounds.iter().map(size).sum::<usize>() != samples.len() {
        return None;
    }
    let mut out = Vec::with_capacity(rounds.len());
    let mut at = 0;
    for r in rounds {
        let n = size(r);
        if n == 0 {
            return None;
        }
        out.push(&samples[at..at + n]);
        at += n;
    }
    Some(out)
}

/// Ratios measured in pairs (`samples`, one per pair): one figure per round, the median log of
/// its pairs, and their mean over the rounds.
fn of_pairs(samples: &[f64], rounds: &[Round], size: fn(&Round) -> usize) -> Option<LogMean> {
    let figures: Option<Vec<f64>> = split(samples, rounds, size)?
        .into_iter()
        .map(interval::median_log)
        .collect();
    LogMean::of_logs(&figures?)
}

/// The run's trace CPU time over Embree's, from its pairs (`run --paired`), over rounds.
pub fn paired(r: &RunRecord) -> Option<LogMean> {
    of_pairs(&r.paired_ratio.as_ref()?.samples, &r.rounds, |x| x.pairs)
}

/// The run's speed-up over one thread, from its thread pairs (`run --paired-threads`), over rounds.
pub fn speedup(r: &RunRecord) -> Option<LogMean> {
    of_pairs(
        &r.thread_scaling.as_ref()?.speedup.samples,
        &r.rounds,
        |x| x.thread_pairs,
    )
}

/// The run's trace time over its Embree anchor's, round by round: in each round the mean log of
/// the run's repeats minus the mean log of Embree's, which ran minutes apart at most. Over the
/// rounds both ran (`run` gives further rounds to the runs whose paired figure is still wide, and
/// not to Embree's); `None` unless that is two or more.
pub fn quotient(r: &RunRecord, anchor: &RunRecord) -> Option<LogMean> {
    let mean_log = |x: &[f64]| -> Option<f64> {
        (x.iter().all(|v| v.is_finite() && *v > 0.0))
            .then(|| x.iter().map(|v| v.ln()).sum::<f64>() / x.len() as f64)
    };
    let mine = split(&r.time_s.trace_for_compare().samples, &r.rounds, |x| {
        x.repeats
    })?;
    let theirs = split(
        &anchor.time_s.trace_for_compare().samples,
        &anchor.rounds,
        |x| x.repeats,
    )?;
    let figures: Option<Vec<f64>> = mine
        .into_iter()
        .zip(theirs)
        .map(|(a, b)| Some(mean_log(a)? - mean_log(b)?))
        .collect();
    LogMean::of_logs(&figures?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::Spread;

    fn rounds(pairs: &[usize]) -> Vec<Round> {
        pairs
            .iter()
            .map(|&p| Round {
                repeats: 1,
                pairs: p,
                thread_pairs: 0,
            })
            .collect()
    }

    #[test]
    fn a_round_shifted_as_a_whole_widens_the_interval() {
        // Two rounds at 7.7, one whose every pair sits near 7.2: pooled, the median of the pairs
        // has a narrow interval around 7.7; by rounds, the interval covers the shift.
        let samples = [7.70, 7.72, 7.68, 7.69, 7.21, 7.18, 7.24, 7.71];
        let r = RunRecord {
            rounds: rounds(&[3, 3, 2]),
            paired_ratio: Some(Spread::of_ratios(&samples)),
            ..Default::default()
        };
        let pooled = LogMean::median_of(&samples).unwrap().interval();
        let by_rounds = paired(&r).unwrap().interval();
        assert!(pooled.hi / pooled.lo < 1.06, "{pooled:?}");
        assert!(by_rounds.lo < 7.2 && by_rounds.hi > 7.7, "{by_rounds:?}");
        assert_eq!(by_rounds.n, 3);
    }

    #[test]
    fn one_round_or_a_miscount_gives_no_figure() {
        let r = RunRecord {
            rounds: rounds(&[4]),
            paired_ratio: Some(Spread::of_ratios(&[1.0, 1.1, 1.0, 1.2])),
            ..Default::default()
        };
        assert!(paired(&r).is_none());
        let r = RunRecord {
            rounds: rounds(&[2, 3]),
            ..r
        };
        assert!(paired(&r).is_none(), "5 pairs counted, 4 recorded");
    }

    #[test]
    fn the_quotient_pairs_each_round_with_embrees_same_round() {
        // Every round of the engine is twice Embree's, though the machine's speed moved 30 %
        // between rounds: the figure is 2 with an interval of zero width.
        let timings = crate::results::Timings {
            trace_cpu: Spread::of(&[2.0, 2.6, 2.2]),
            ..Default::default()
        };
        let r = RunRecord {
            rounds: rounds(&[0, 0, 0]),
            time_s: timings.clone(),
            ..Default::default()
        };
        let e = RunRecord {
            time_s: crate::results::Timings {
                trace_cpu: Spread::of(&[1.0, 1.3, 1.1]),
                ..timings
            },
            ..r.clone()
        };
        let q = quotient(&r, &e).unwrap().interval();
        assert!((q.estimate - 2.0).abs() < 1e-12 && (q.hi - q.lo).abs() < 1e-9);
        // Embree ran two rounds where the engine ran three: the two rounds both ran.
        let mut two = e.clone();
        two.rounds = rounds(&[0, 0]);
        two.time_s.trace_cpu = Spread::of(&[1.0, 1.3]);
        let q = quotient(&r, &two).unwrap();
        assert_eq!(q.n, 2);
        assert!((q.interval().estimate - 2.0).abs() < 1e-12);
        // One round in common is no interval.
        let mut one = e;
        one.rounds = rounds(&[0]);
        one.time_s.trace_cpu = Spread::of(&[1.0]);
        assert!(quotient(&r, &one).is_none());
    }
}
