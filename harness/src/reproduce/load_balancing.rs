//! What `yamauchi-static-lb` and `yamauchi-dynamic-lb` share (seed 003 §4.2.2): the table's
//! declaration, the simulation of a list of machines on one pass against its 1-PE machine
//! (003 eqs. 24, 25: speed-up and efficiency relative to 1 PE with 1 RP block), and the run over
//! the traced passes on the table's thread pool.

use super::object_space_pass::{self as osp, PassRecord, SimRecord, Traced};
use super::{Checkpoint, Claim, Ctx, Output, Runtime, Table};
use crate::error::Result;
use rtbench_engines::object_space::config::FrameBuffer;
use rtbench_engines::object_space::machine::Machine;
use serde::Serialize;

/// A load-balancing table of seed 003: `quick` with `--quick` and `full` in full (a minute or two
/// of CPU per machine on the room's radiosity pass, each saved as a step for `--resume`), as
/// measured on this 2-core machine.
pub const fn table(
    id: &'static str,
    source: &'static str,
    about: &'static str,
    quick: &'static str,
    full: &'static str,
    claims: &'static [Claim],
    run: fn(&Ctx) -> Result<Output>,
) -> Table {
    Table {
        id,
        seed: "003",
        source,
        about,
        runtime: Runtime { quick, full },
        params: osp::PARAMS,
        claims,
        run,
    }
}

/// What a table measured on one pass: each machine's run (the table's own record `R`) against
/// the first machine's clocks, T(1).
#[derive(Serialize)]
pub struct Measured<R> {
    pub pass: PassRecord,
    pub t1_clocks: u64,
    pub runs: Vec<R>,
}

/// Simulates `machines` on `t` with the direct frame buffer (the first machine: 1 PE, 1 RP
/// block), each saved as a step in `checkpoint`, and records run i with `record(i, its record
/// over PEs × RP blocks processing units)`.
pub fn measure<R>(
    t: &Traced,
    machines: &[Machine],
    checkpoint: &Checkpoint,
    record: impl Fn(usize, SimRecord) -> R,
) -> Result<Measured<R>> {
    let direct: Vec<_> = machines.iter().map(|&m| (m, FrameBuffer::Direct)).collect();
    eprintln!("{}: simulating {} machines …", t.label, machines.len());
    let results = osp::run_all(t, &direct, checkpoint)?;
    let t1 = results[0].0.clocks;
    let runs = machines
        .iter()
        .zip(&results)
        .enumerate()
        .map(|(i, (m, (r, wall)))| {
            let units = m.pe_count() as u64 * m.rp_blocks as u64;
            record(i, SimRecord::new(r, t1, units, *wall))
        })
        .collect();
    Ok(Measured {
        pass: t.record(),
        t1_clocks: t1,
        runs,
    })
}

/// Measures every traced pass in turn on the table's pool (`--threads`, the machines of a pass
/// side by side): the measurements and the pool's thread count.
pub fn measure_passes<M: Send>(
    ctx: &Ctx,
    traced: &[Traced],
    measure: impl Fn(&Traced) -> Result<M> + Send + Sync,
) -> Result<(Vec<M>, usize)> {
    let pool = crate::measure::threads::pool(ctx.params.threads()?)?;
    let measured = traced
        .iter()
        .map(|t| pool.install(|| measure(t)))
        .collect::<Result<_>>()?;
    Ok((measured, pool.current_num_threads()))
}

/// Why a machine's efficiency is what it is, split exactly (003 eqs. 24, 25 with the busy time
/// taken apart): efficiency = T(1) / (T × units) = (T(1) / busy) × (busy / (T × units)), and
/// busy / (T × units) = (busiest PE's busy share of T) / imbalance. So efficiency × imbalance =
/// work ratio × the busiest PE's busy share: below 1 either because the machine does more work
/// than the 1-PE machine (the radiosity pass: PEs shoot side by side, more shots) or because
/// its busiest PE waits (for rays to reach it).
#[derive(Serialize, Clone, Copy, Debug, PartialEq)]
pub struct Explained {
    /// Machines above 1 PE the ranges cover.
    pub machines: usize,
    /// Range of efficiency × imbalance (1: the load balance explains it all).
    pub of_balance: (f64, f64),
    /// Range of T(1) / busy clocks summed over the machine (1: no extra work).
    pub work: (f64, f64),
    /// Range of the busiest PE's busy share of the run (1: never waits).
    pub busiest_busy: (f64, f64),
}

/// The split over `sims` (pass the machines other than the 1-PE one; pure); `None` if empty.
pub fn explain<'a>(sims: impl Iterator<Item = &'a SimRecord>) -> Option<Explained> {
    let range = |r: (f64, f64), v: f64| (r.0.min(v), r.1.max(v));
    let empty = (f64::INFINITY, f64::NEG_INFINITY);
    let mut e = Explained {
        machines: 0,
        of_balance: empty,
        work: empty,
        busiest_busy: empty,
    };
    for s in sims.filter(|s| s.utilisation > 0.0) {
        e.machines += 1;
        e.of_balance = range(e.of_balance, s.efficiency * s.imbalance);
        e.work = range(e.work, s.efficiency / s.utilisation);
        e.busiest_busy = range(e.busiest_busy, s.utilisation * s.imbalance);
    }
    (e.machines > 0).then_some(e)
}

impl Explained {
    pub fn text(&self) -> String {
        let r = |(a, b): (f64, f64)| format!("{:.0}–{:.0}%", a * 100.0, b * 100.0);
        format!(
            "Efficiency against load balance, {} machines above 1 PE: efficiency × imbalance = {} \
             (1/imbalance explains it all at 100%); it splits exactly into the work ratio T(1) / busy clocks \
             = {} (below 100%: more work than the 1-PE machine, e.g. more shots when PEs shoot side by side) \
             and the busiest PE's busy share of the run = {} (below 100%: the busiest PE waits for work).",
            self.machines,
            r(self.of_balance),
            r(self.work),
            r(self.busiest_busy)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reproduce::object_space_pass::tests::sim;

    fn machine(efficiency: f64, utilisation: f64, imbalance: f64) -> SimRecord {
        let mut s = sim(1, 1, 1);
        (s.efficiency, s.utilisation, s.imbalance) = (efficiency, utilisation, imbalance);
        s
    }

    #[test]
    fn efficiency_splits_into_balance_work_and_the_busiest_pes_waiting() {
        assert_eq!(explain([].iter()), None);
        // Balance explains it all: 50% efficient at imbalance 2, busiest PE always busy.
        let even = machine(0.5, 0.5, 2.0);
        // Same balance, 40% more work (the radiosity pass's extra shots): 0.5 / 1.4.
        let more_work = machine(0.5 / 1.4, 0.5, 2.0);
        // Same work, the busiest PE busy 80% of the run.
        let waits = machine(0.4, 0.4, 2.0);
        let e = explain([even, more_work, waits].iter()).unwrap();
        assert_eq!(e.machines, 3);
        let close = |(a, b): (f64, f64), (c, d): (f64, f64)| {
            assert!(
                (a - c).abs() < 1e-12 && (b - d).abs() < 1e-12,
                "{a} {b} vs {c} {d}"
            )
        };
        close(e.of_balance, (1.0 / 1.4, 1.0));
        close(e.work, (1.0 / 1.4, 1.0));
        close(e.busiest_busy, (0.8, 1.0));
        assert!(e.text().contains("71–100%"), "{}", e.text());
    }
}
