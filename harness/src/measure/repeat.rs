//! The one repeat and warm-up policy of `run`, `reproduce` and `nightly`: [`WARMUP`] untimed
//! passes first (a fresh process's first pass runs measurably slower: cold caches, page faults on
//! first touch, which would widen every spread), then the timed repeats, each measured by one span ([`span`]).
//! Pairs (an engine and Embree, or one thread and many, traced back to back) follow [`pairs`].

use super::span::{span, Sample, Span, Workers};

/// The wall time the pairs of one paired measurement span at least. On this kind of shared machine
/// the speed of one kind of code against another shifts for a fraction of a second at a time (a
/// burst on the other core slows a memory-bound trace more than a compute-bound one): traces of a
/// few tens of milliseconds once put five pairs in a row inside one such episode, and the run's
/// ratio moved by 30 %. Spread over two seconds, an episode touches a few of the pairs, and the
/// median of the pairs ([`rtbench_reports::interval::LogMean::median_of`]) passes over them.
pub const PAIR_SPAN_S: f64 = 2.0;

/// Pairs stop at this many times the number asked for, however short each pair is.
pub const PAIR_CAP_FACTOR: u32 = 8;

/// Runs `pair(i)` for i = 0, 1, … at least `min` times, and on until the pairs have spanned
/// `span_s` of wall time ([`PAIR_SPAN_S`], or its share of it in one round of several), but at
/// most `min` × [`PAIR_CAP_FACTOR`] and `max` times; returns the pairs' values. With `min` 0 it
/// runs none.
pub fn pairs<T, E>(
    min: u32,
    max: u32,
    span_s: f64,
    mut pair: impl FnMut(u32) -> Result<T, E>,
) -> Result<Vec<T>, E> {
    let cap = min.saturating_mul(PAIR_CAP_FACTOR).min(max.max(min));
    let clock = Span::start(Workers::Caller);
    let mut out = Vec::with_capacity(min as usize);
    let mut i = 0;
    while i < min || (i < cap && clock.elapsed_s() < span_s) {
        out.push(pair(i)?);
        i += 1;
    }
    Ok(out)
}

/// Untimed passes before the timed ones.
pub const WARMUP: u32 = 1;

/// How many timed repeats, after the warm-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Repeats {
    pub warmup: u32,
    pub timed: u32,
}

impl Repeats {
    /// `timed` repeats (at least one) after the warm-up.
    pub fn new(timed: u32) -> Repeats {
        Repeats {
            warmup: WARMUP,
            timed: timed.max(1),
        }
    }

    /// Runs `pass` `warmup` times untimed, then `timed` times, each measured by one span of
    /// `workers`; returns each timed pass's value with its sample. `pass` is told whether it is
    /// timed (a timed pass may prepare outside its span through [`Timed::span`]).
    pub fn run<T, E>(
        &self,
        workers: Workers,
        mut pass: impl FnMut(&mut Timed) -> Result<T, E>,
    ) -> Result<Vec<(T, Sample)>, E> {
        for _ in 0..self.warmup {
            pass(&mut Timed {
                workers,
                sample: None,
            })?;
        }
        (0..self.timed)
            .map(|_| {
                let mut t = Timed {
                    workers,
                    sample: None,
                };
                let out = pass(&mut t)?;
                let sample = t.sample.unwrap_or_default();
                Ok((out, sample))
            })
            .collect()
    }
}

/// One pass of [`Repeats::run`]: the part of it to time goes through [`Timed::span`].
pub struct Timed {
    workers: Workers,
    sample: Option<Sample>,
}

impl Timed {
    /// Runs `f`, measured (the last call of a pass is the one recorded).
    pub fn span<T>(&mut self, f: impl FnOnce() -> T) -> T {
        let (out, sample) = span(self.workers, f);
        self.sample = Some(sample);
        out
    }

    /// Records a sample measured inside the pass (a render measures its own trace, apart from
    /// its setup).
    pub fn record(&mut self, sample: Sample) {
        self.sample = Some(sample);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warmup_passes_are_run_and_not_kept() {
        let mut calls = 0;
        let out = Repeats::new(3)
            .run(Workers::Caller, |t| {
                calls += 1;
                Ok::<_, ()>(t.span(|| calls))
            })
            .unwrap();
        assert_eq!(calls, 4);
        assert_eq!(out.iter().map(|(c, _)| *c).collect::<Vec<_>>(), [2, 3, 4]);
        assert_eq!(Repeats::new(0).timed, 1);
    }

    #[test]
    fn fast_pairs_go_on_until_they_span_the_window_and_stop_at_the_cap() {
        // Instant pairs: the window never fills, so the cap ends them.
        let n = pairs(5, 1000, PAIR_SPAN_S, |_| Ok::<_, ()>(()))
            .unwrap()
            .len();
        assert_eq!(n, (5 * PAIR_CAP_FACTOR) as usize);
        assert_eq!(
            pairs(5, 7, PAIR_SPAN_S, |_| Ok::<_, ()>(())).unwrap().len(),
            7
        );
        assert_eq!(
            pairs(0, 1000, PAIR_SPAN_S, |_| Ok::<_, ()>(()))
                .unwrap()
                .len(),
            0
        );
        // Pairs longer than the window: exactly the minimum.
        let slow = pairs(2, 1000, PAIR_SPAN_S, |_| {
            std::thread::sleep(std::time::Duration::from_secs_f64(PAIR_SPAN_S / 2.0 + 0.01));
            Ok::<_, ()>(())
        });
        assert_eq!(slow.unwrap().len(), 2);
        assert_eq!(
            pairs(3, 1000, PAIR_SPAN_S, |i| if i == 1 {
                Err(i)
            } else {
                Ok(i)
            }),
            Err(1)
        );
    }
}
