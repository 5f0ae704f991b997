//! The one repeat and warm-up policy of `run`, `reproduce` and `nightly`: [`WARMUP`] untimed
//! passes first (a fresh process's first pass runs measurably slower: cold caches, page faults on
//! first touch, which would widen every spread), then the timed repeats, each measured by one span ([`span`]).

use super::span::{span, Sample, Workers};

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
}
