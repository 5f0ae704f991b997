//! Speed-up over one thread, measured in pairs in one process (`rtbench run --paired-threads N`).
//!
//! On a shared machine two separate runs (one at one thread, one at two) minutes apart gave
//! speed-ups from 1.47× to 2.48× for the same engine and scene: a burst of
//! other load falls on one side of the ratio only. Timing the same trace at one thread and at the
//! run's thread count back to back, N times, alternating which goes first, puts a burst on both
//! sides of most pairs; the median of the N ratios is the figure, their range its spread.

use crate::results::Spread;
use serde::{Deserialize, Serialize};

/// One run's traces at one thread against the same traces at its own thread count.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct ThreadScaling {
    /// The run's thread count (the other side of every pair).
    pub threads: usize,
    /// Wall seconds of the one-thread traces, one per pair.
    pub one_thread_s: Spread,
    /// Wall seconds of the traces at `threads`, one per pair.
    pub threads_s: Spread,
    /// Per pair: the one-thread wall time over the wall time at `threads`.
    pub speedup: Spread,
    /// CPU seconds the pool's threads used in the same traces, one per pair: at `threads` over
    /// one thread, it says how much more work (or waiting on shared hardware, or spinning) the
    /// same trace cost when split.
    pub one_thread_cpu_s: Spread,
    pub threads_cpu_s: Spread,
}

impl ThreadScaling {
    /// The scaling of `pairs`: (one-thread wall s, wall s at `threads`, one-thread CPU s, CPU s
    /// at `threads`) per pair. The speed-up of a pair is its own two wall times' ratio, never
    /// a ratio of medians, so that a pair slowed as a whole by outside load still gives its
    /// ratio.
    pub fn of(threads: usize, pairs: &[(f64, f64, f64, f64)]) -> ThreadScaling {
        let col = |f: fn(&(f64, f64, f64, f64)) -> f64| pairs.iter().map(f).collect::<Vec<_>>();
        ThreadScaling {
            threads,
            one_thread_s: Spread::of(&col(|p| p.0)),
            threads_s: Spread::of(&col(|p| p.1)),
            speedup: Spread::of_ratios(&col(|p| p.0 / p.1.max(1e-12))),
            one_thread_cpu_s: Spread::of(&col(|p| p.2)),
            threads_cpu_s: Spread::of(&col(|p| p.3)),
        }
    }

    /// Pool CPU seconds at `threads` over those at one thread (medians): 1.0 when splitting the
    /// trace cost no extra CPU time.
    pub fn cpu_growth(&self) -> f64 {
        self.threads_cpu_s.median / self.one_thread_cpu_s.median.max(1e-12)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speedup_is_each_pairs_own_ratio() {
        // Pair 2 was slowed as a whole (both sides ×3): its ratio is still 2. A ratio of
        // medians would give 0.4 / 0.25 = 1.6, a mean of times 0.6 / 0.3 = 2.0 by luck only.
        let pairs = [
            (0.40, 0.20, 0.40, 0.42),
            (1.20, 0.60, 1.20, 1.25),
            (0.44, 0.25, 0.44, 0.46),
        ];
        let s = ThreadScaling::of(2, &pairs);
        assert_eq!(s.threads, 2);
        assert_eq!(s.speedup.samples, vec![2.0, 2.0, 0.44 / 0.25]);
        assert_eq!(
            (s.speedup.min, s.speedup.median, s.speedup.max),
            (0.44 / 0.25, 2.0, 2.0)
        );
        assert_eq!(s.one_thread_s.median, 0.44);
        assert_eq!(s.threads_s.median, 0.25);
        assert!((s.cpu_growth() - 0.46 / 0.44).abs() < 1e-12);
    }

    #[test]
    fn swapped_sides_invert_the_speedup() {
        let s = ThreadScaling::of(2, &[(0.2, 0.5, 0.2, 0.5), (0.3, 0.6, 0.3, 0.6)]);
        assert_eq!(s.speedup.samples, vec![0.4, 0.5]);
        assert!((s.speedup.median - 0.45).abs() < 1e-12);
    }
}
