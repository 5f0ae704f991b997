//! What `yamauchi-static-lb` and `yamauchi-dynamic-lb` share (seed 003 §4.2.2): the table's
//! declaration, the simulation of a list of machines on one pass against its 1-PE machine
//! (003 eqs. 24, 25: speed-up and efficiency relative to 1 PE with 1 RP block), and the run over
//! the traced passes on the table's thread pool.

use super::object_space_pass::{self as osp, PassRecord, SimRecord, Traced};
use super::{Checkpoint, Claim, Ctx, Output, Runtime, Table};
use crate::error::Result;
use crate::workload;
use rtbench_engines::object_space::config::FrameBuffer;
use rtbench_engines::object_space::machine::Machine;
use serde::Serialize;

/// A load-balancing table of seed 003: seconds with `--quick`; in full, minutes per machine on
/// the room's radiosity pass (saved as steps, `--resume`).
pub const fn table(
    id: &'static str,
    source: &'static str,
    about: &'static str,
    claims: &'static [Claim],
    run: fn(&Ctx) -> Result<Output>,
) -> Table {
    Table {
        id,
        seed: "003",
        source,
        about,
        runtime: Runtime {
            quick: "seconds",
            full: "minutes",
        },
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
    let pool = workload::pool(ctx.params.threads()?)?;
    let measured = traced
        .iter()
        .map(|t| pool.install(|| measure(t)))
        .collect::<Result<_>>()?;
    Ok((measured, pool.current_num_threads()))
}
