//! Rounds: `rtbench run --rounds R` and the nightly run every job once per round, each time in a
//! process of its own, and join a job's rounds into one record here. Two processes of one binary
//! on one scene differ in speed by several percent for reasons no process can see from inside
//! (see `rtbench_reports::rounds`); with the round as the unit, that difference is inside every
//! interval and `compare` does not take it for a regression.

use rtbench_reports::{Round, RunRecord, Spread, ThreadScaling};

/// Rounds a job of `run` may take in all when its figure stays wide. On a busy 2-core machine a
/// process now and then runs 10–26 % off its job's usual ratio to Embree: with the runs cut to three
/// rounds a side, one such round widened the interval of a change past the default 5 % threshold
/// and a planted 10 % slowdown went undecided in 2 of 20 compares; with up to nine, 20 of 20 were
/// caught and no run of the same commit was taken for a change (docs/guides/compare-engines.md).
pub const DEFAULT_MAX_ROUNDS: u32 = 9;

/// More rounds than this are refused: each is a process per job.
pub const MAX_ROUNDS_LIMIT: u32 = 100;

/// The half-width (percent) a job's 95 % interval over rounds must reach before its rounds stop.
pub const DEFAULT_TARGET_CI_PCT: f64 = 2.0;

/// How a job's `repeats` and pairs spread over its rounds: never more rounds than repeats, and
/// each count shared out as evenly as it goes (7 repeats over 3 rounds: 3, 2, 2), so the totals
/// are those asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Split {
    pub rounds: u32,
    repeats: u32,
    pairs: u32,
    thread_pairs: u32,
}

/// Round i's share of `total` over `n` rounds.
fn share(total: u32, n: u32, i: u32) -> u32 {
    total / n + u32::from(i < total % n)
}

impl Split {
    pub fn of(rounds: u32, repeats: u32, pairs: u32, thread_pairs: u32) -> Split {
        Split {
            rounds: rounds.clamp(1, repeats.max(1)),
            repeats,
            pairs,
            thread_pairs,
        }
    }

    /// Round `i`'s (repeats, pairs, thread pairs). A round asked for pairs runs at least one,
    /// so that every round has a figure of its own.
    pub fn round(&self, i: u32) -> (u32, u32, u32) {
        let at_least_one = |total: u32| {
            if total == 0 {
                0
            } else {
                share(total, self.rounds, i).max(1)
            }
        };
        (
            share(self.repeats, self.rounds, i).max(1),
            at_least_one(self.pairs),
            at_least_one(self.thread_pairs),
        )
    }
}

/// What one process's record holds, as a round.
fn round_of(r: &RunRecord) -> Round {
    Round {
        repeats: r.time_s.trace.samples.len(),
        pairs: r.paired_ratio.as_ref().map_or(0, |p| p.samples.len()),
        thread_pairs: r
            .thread_scaling
            .as_ref()
            .map_or(0, |s| s.speedup.samples.len()),
    }
}

/// The rounds a record holds (a record of one process is one round).
pub fn rounds_in(r: &RunRecord) -> usize {
    r.rounds.len().max(1)
}

/// How far (percent, the wider side of the 95 % interval over rounds from its estimate) the job's
/// widest figure — its ratio to Embree from pairs, its speed-up over one thread from thread
/// pairs — is from being known to ±`target_pct`: `Some(half-width)` while it is wider, `None`
/// once every figure is within it, or when the record has no figure over rounds to judge (a
/// failed job, Embree's own, a run without pairs, a single round).
pub fn too_wide(r: &RunRecord, target_pct: f64) -> Option<f64> {
    if !r.ok() {
        return None;
    }
    let widths = [
        rtbench_reports::rounds::paired(r),
        rtbench_reports::rounds::speedup(r),
    ];
    let widest = widths
        .into_iter()
        .flatten()
        .map(|m| {
            let i = m.interval();
            (i.hi / i.estimate).max(i.estimate / i.lo) * 100.0 - 100.0
        })
        .fold(None, |acc: Option<f64>, w| {
            Some(acc.map_or(w, |a| a.max(w)))
        })?;
    // A NaN width (a degenerate round) is as wide as can be.
    (widest.is_nan() || widest > target_pct).then_some(if widest.is_nan() {
        f64::INFINITY
    } else {
        widest
    })
}

/// Joins round `next` into the job's record `acc`: samples follow acc's, `rounds` says which are
/// whose, intervals are taken over the rounds. A failed round fails the job. A round that traced
/// another answer (another image, other counters or ray counts) fails it too: each round traces
/// the same rays through the same engine, so they must agree bit for bit.
pub fn absorb(mut acc: RunRecord, next: RunRecord) -> RunRecord {
    if !acc.ok() {
        return acc;
    }
    let n = rounds_in(&acc) + 1;
    if !next.ok() {
        return RunRecord {
            reason: Some(format!(
                "round {n}: {}",
                next.reason.as_deref().unwrap_or("failed")
            )),
            ..next
        };
    }
    let differs = if acc.image_sha256 != next.image_sha256 {
        Some("another image")
    } else if acc.counters != next.counters {
        Some("other counters")
    } else if acc.rays_total != next.rays_total {
        Some("another number of rays")
    } else {
        None
    };
    if let Some(what) = differs {
        acc.status = "failed".into();
        acc.reason = Some(format!(
            "round {n} traced {what} than round 1: the engine's answer is not deterministic"
        ));
        return acc;
    }
    if acc.rounds.is_empty() {
        acc.rounds.push(round_of(&acc));
    }
    acc.rounds.push(round_of(&next));
    let cat = |x: &Spread, y: &Spread| {
        let mut v = x.samples.clone();
        v.extend(&y.samples);
        Spread::of(&v)
    };
    let t = &mut acc.time_s;
    let u = &next.time_s;
    t.build = cat(&t.build, &u.build);
    t.trace = cat(&t.trace, &u.trace);
    t.intersect = cat(&t.intersect, &u.intersect);
    t.shade = cat(&t.shade, &u.shade);
    t.trace_cpu = cat(&t.trace_cpu, &u.trace_cpu);
    acc.samples.extend(next.samples);
    acc.paired_ratio = match (acc.paired_ratio.take(), next.paired_ratio) {
        (Some(x), Some(y)) => {
            let mut v = x.samples;
            v.extend(y.samples);
            Some(Spread::of_ratios(&v))
        }
        (x, y) => x.or(y),
    };
    acc.thread_scaling = match (acc.thread_scaling.take(), next.thread_scaling) {
        (Some(x), Some(y)) => Some(ThreadScaling {
            threads: x.threads,
            one_thread_s: cat(&x.one_thread_s, &y.one_thread_s),
            threads_s: cat(&x.threads_s, &y.threads_s),
            speedup: {
                let mut v = x.speedup.samples;
                v.extend(y.speedup.samples);
                Spread::of_ratios(&v)
            },
            one_thread_cpu_s: cat(&x.one_thread_cpu_s, &y.one_thread_cpu_s),
            threads_cpu_s: cat(&x.threads_cpu_s, &y.threads_cpu_s),
        }),
        (x, y) => x.or(y),
    };
    // The intervals of paired figures over rounds, where every round has pairs.
    let paired = rtbench_reports::rounds::paired(&acc);
    if let (Some(p), Some(m)) = (acc.paired_ratio.as_mut(), paired) {
        p.interval = Some(m.interval());
    }
    let speedup = rtbench_reports::rounds::speedup(&acc);
    if let (Some(s), Some(m)) = (acc.thread_scaling.as_mut(), speedup) {
        s.speedup.interval = Some(m.interval());
    }
    acc.repeats += next.repeats;
    acc.mrays_per_s = acc.rays_total as f64 / acc.time_s.trace.median.max(1e-12) / 1e6;
    acc.wall_s += next.wall_s;
    acc.peak_rss_bytes = acc.peak_rss_bytes.max(next.peak_rss_bytes);
    acc.finished_at = next.finished_at;
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(trace: &[f64], pairs: &[f64], image: &str) -> RunRecord {
        RunRecord {
            key: "grid/balls3@1".into(),
            status: "ok".into(),
            repeats: trace.len() as u32,
            image_sha256: Some(image.into()),
            time_s: rtbench_reports::Timings {
                trace: Spread::of(trace),
                trace_cpu: Spread::of(trace),
                ..Default::default()
            },
            paired_ratio: Some(Spread::of_ratios(pairs)),
            rays_total: 1000,
            ..Default::default()
        }
    }

    #[test]
    fn rounds_keep_whose_samples_are_whose() {
        let a = record(&[1.0], &[7.7, 7.8], "x");
        let b = record(&[1.1], &[7.2, 7.25], "x");
        let c = record(&[1.0], &[7.7, 7.75], "x");
        let r = absorb(absorb(a, b), c);
        assert!(r.ok());
        assert_eq!(r.rounds.len(), 3);
        assert_eq!(
            r.rounds.iter().map(|x| x.pairs).collect::<Vec<_>>(),
            [2, 2, 2]
        );
        assert_eq!(r.repeats, 3);
        assert_eq!(r.time_s.trace.samples, [1.0, 1.1, 1.0]);
        // The interval is over the three rounds' medians (7.75, 7.225, 7.725): it covers the
        // second round's shift, where the six pairs pooled would not.
        let i = r.paired_ratio.unwrap().interval.unwrap();
        assert_eq!(i.n, 3);
        assert!(i.lo < 7.225 && i.hi > 7.75, "{i:?}");
    }

    #[test]
    fn a_round_with_another_answer_or_a_failure_fails_the_job() {
        let r = absorb(record(&[1.0], &[2.0], "x"), record(&[1.0], &[2.0], "y"));
        assert!(!r.ok());
        assert!(r.reason.unwrap().contains("round 2 traced another image"));
        let mut failed = record(&[1.0], &[2.0], "x");
        failed.status = "failed".into();
        failed.reason = Some("time limit: still running after 5 s".into());
        let r = absorb(record(&[1.0], &[2.0], "x"), failed);
        assert_eq!(
            r.reason.as_deref(),
            Some("round 2: time limit: still running after 5 s")
        );
    }

    #[test]
    fn rounds_go_on_while_the_figure_is_wide() {
        // Three rounds at 1.00, 1.01 and 0.99: ±2.5 % (t with 2 degrees of freedom), wider than
        // ±2 %, narrower than ±3 %.
        let mut r = record(&[1.0], &[1.0], "a");
        for x in [1.01, 0.99] {
            r = absorb(r, record(&[1.0], &[x], "a"));
        }
        let w = too_wide(&r, 2.0).expect("wider than 2 %");
        assert!(w > 2.0 && w < 3.0, "{w}");
        assert_eq!(too_wide(&r, 3.0), None);
        // A fourth round at 1.00 brings it within ±2 %.
        let r = absorb(r, record(&[1.0], &[1.0], "a"));
        assert_eq!(too_wide(&r, 2.0), None);
        // Nothing to judge: one round, or no pairs.
        assert_eq!(too_wide(&record(&[1.0], &[1.0, 1.5], "a"), 0.1), None);
        let mut bare = record(&[1.0], &[], "a");
        bare.paired_ratio = None;
        let bare = absorb(bare.clone(), bare);
        assert_eq!(too_wide(&bare, 0.1), None);
    }

    #[test]
    fn repeats_and_pairs_spread_over_rounds() {
        let s = Split::of(3, 3, 5, 0);
        assert_eq!(s.rounds, 3);
        assert_eq!(
            [s.round(0), s.round(1), s.round(2)],
            [(1, 2, 0), (1, 2, 0), (1, 1, 0)]
        );
        let s = Split::of(3, 7, 2, 9);
        assert_eq!(
            [s.round(0), s.round(1), s.round(2)],
            [(3, 1, 3), (2, 1, 3), (2, 1, 3)]
        );
        // No more rounds than repeats.
        let s = Split::of(3, 1, 9, 0);
        assert_eq!((s.rounds, s.round(0)), (1, (1, 9, 0)));
    }
}
