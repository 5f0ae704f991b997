//! 003's analytic queueing model of the cached frame buffer system (§3.4.3, eqs. 11–21, after
//! Kleinrock) and the random-arrival simulation it was checked against (§4.3.1).
//!
//! The model: N = mⁿ PEs each emit intensity packets as a Poisson process of rate λ_PE; stage i
//! is a communication unit C_i (M/D/1, T_Ci) feeding a frame-buffer cache FBC_i (M/M/1 with
//! mean service T_mp = P_M·T_M + (1 − P_M)·T_H); a packet goes on to stage i + 1 only on a miss
//! (probability P_M); departures are taken as Poisson. As printed, the top stage also serves
//! with T_mp, the link term of L_i is i·T_Ci and L_mean weighs L_i by P_M^(i−1) without
//! normalising; [`Model::latency`] gives that and the properly normalised mean
//! (P_M^(i−1)(1 − P_M) for i < n, P_M^(n−1) for the top stage) with Σ_k T_Ck as the link term.

use serde::Serialize;

/// Table 3's parameters (clocks of one byte) and the tree's shape.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Model {
    pub m: u32,
    pub stages: u32,
    pub miss: f64,
    pub t_c1: f64,
    pub t_ci: f64,
    pub t_hit: f64,
    pub t_miss: f64,
}

impl Model {
    /// Table 3: T_C1 = 8, T_Ci = 64, T_H = 12, T_M = 71.
    pub fn table3(m: u32, stages: u32, miss: f64) -> Model {
        Model {
            m,
            stages,
            miss,
            t_c1: 8.0,
            t_ci: 64.0,
            t_hit: 12.0,
            t_miss: 71.0,
        }
    }

    fn t_c(&self, i: u32) -> f64 {
        if i == 1 {
            self.t_c1
        } else {
            self.t_ci
        }
    }

    /// Eq. (17).
    pub fn t_mp(&self) -> f64 {
        self.miss * self.t_miss + (1.0 - self.miss) * self.t_hit
    }

    /// Arrival rates at C_i and FBC_i (eqs. 11, 14).
    fn rates(&self, i: u32, lambda: f64) -> (f64, f64) {
        let a = (self.m as f64).powi(i as i32 - 1) * self.miss.powi(i as i32 - 1) * lambda;
        (a, a * self.m as f64)
    }

    /// The smallest λ_PE at which some unit's utilisation reaches 1 (eqs. 13, 16).
    pub fn saturation(&self) -> f64 {
        (1..=self.stages)
            .map(|i| {
                let (c, f) = self.rates(i, 1.0);
                (1.0 / (c * self.t_c(i))).min(1.0 / (f * self.t_mp()))
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Mean latency at `lambda` (per PE per clock): (as printed, normalised); `None` at or
    /// past saturation.
    pub fn latency(&self, lambda: f64) -> Option<(f64, f64)> {
        if lambda >= self.saturation() {
            return None;
        }
        let tmp = self.t_mp();
        let (mut wait, mut links) = (0.0, 0.0);
        let (mut printed, mut normal) = (0.0, 0.0);
        for i in 1..=self.stages {
            let (lc, lf) = self.rates(i, lambda);
            let (rc, rf) = (lc * self.t_c(i), lf * tmp);
            wait += rc / (2.0 * (1.0 - rc)) * self.t_c(i) + rf / (1.0 - rf) * tmp;
            links += self.t_c(i);
            let tail = (i - 1) as f64 * self.t_miss + self.t_hit;
            let l_printed = wait + i as f64 * self.t_c(i) + tail;
            let l_sum = wait + links + tail;
            let reach = self.miss.powi(i as i32 - 1);
            printed += reach * l_printed;
            normal += if i < self.stages {
                reach * (1.0 - self.miss)
            } else {
                reach
            } * l_sum;
        }
        Some((printed, normal))
    }
}

/// SplitMix64: a small deterministic generator, so a seed gives the same run everywhere.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in (0, 1].
    fn unit(&mut self) -> f64 {
        ((self.next() >> 11) + 1) as f64 / (1u64 << 53) as f64
    }
}

/// The random-arrival simulation (003 §4.3.1): Poisson emissions per PE (exponential
/// intervals), `packets` in all, each unit a FIFO server with the model's deterministic times
/// (a cache's service is T_H on a hit and T_M on a miss, drawn with probability P_M; a miss is
/// passed up, and the top stage ends every packet). Returns the mean latency in clocks.
pub fn simulate(model: &Model, lambda: f64, packets: usize, seed: u64) -> f64 {
    let pes = (model.m as usize).pow(model.stages);
    let mut rng = SplitMix(seed);
    let per_pe = packets.div_ceil(pes).max(1);
    // (time now, source unit, birth time)
    let mut items: Vec<(f64, u32, f64)> = Vec::with_capacity(per_pe * pes);
    for pe in 0..pes {
        let mut t = 0.0;
        for _ in 0..per_pe {
            t += -rng.unit().ln() / lambda;
            items.push((t, pe as u32, t));
        }
    }
    let mut total = 0.0;
    let count = items.len() as f64;
    for stage in 1..=model.stages {
        // C_i: one link per source, deterministic.
        items.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let sources = items
            .iter()
            .map(|i| i.1)
            .max()
            .map_or(0, |s| s as usize + 1);
        let mut free = vec![0.0f64; sources];
        let tc = model.t_c(stage);
        for it in items.iter_mut() {
            let f = &mut free[it.1 as usize];
            *f = it.0.max(*f) + tc;
            it.0 = *f;
            it.1 /= model.m;
        }
        // FBC_i: one server per group of m sources below.
        items.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut free = vec![0.0f64; sources.div_ceil(model.m as usize)];
        let mut up = Vec::new();
        for it in &items {
            let missed = rng.unit() <= model.miss;
            let f = &mut free[it.1 as usize];
            *f = it.0.max(*f) + if missed { model.t_miss } else { model.t_hit };
            if missed && stage < model.stages {
                up.push((*f, it.1, it.2));
            } else {
                total += *f - it.2;
            }
        }
        items = up;
    }
    total / count
}
