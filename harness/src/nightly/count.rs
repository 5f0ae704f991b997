//! The region the nightly's instruction counts cover (`rtbench count-one`, run under valgrind by
//! [`super::tools::instructions`]).
//!
//! One binary's whole-process count moved by up to 0.6 % on the same input: a rayon pool starts
//! even at one thread, and how long its idle workers spin (`find_work`, `Injector::steal`,
//! `sched_yield`) before sleeping depends on scheduling, so valgrind counted a different number of
//! spin iterations each run. So here the scene is generated, the engine built and the workload
//! traced once (the warm-up: first-touch buffers, lazily initialised tables) before the counted
//! region, all on the calling thread, which is the only thread of a one-thread pool
//! (`use_current_thread`: no worker is spawned, so none spins); the counted region is
//! [`counted_trace`] alone, which valgrind's callgrind counts with `--collect-atstart=no
//! --toggle-collect=` on its symbol (cachegrind's own start/stop client requests need valgrind
//! 3.22; Debian 12 ships 3.19). The parent also runs the child with a fixed environment.

use crate::error::{input, Result};
use crate::source::Source;
use crate::workload::{self, trace};

/// The symbol callgrind's `--toggle-collect` names (a pattern over demangled names).
pub const COUNTED_SYMBOL: &str = "*nightly::count::counted_trace*";

/// The traced region whose instructions are counted. Never inlined: callgrind toggles counting
/// on this function's entry and exit.
#[inline(never)]
pub fn counted_trace(
    scene: &rtbench_scenes::Scene,
    engine: &dyn rtbench_engines::Engine,
    size: u32,
) -> trace::Render {
    trace::render(scene, engine, size, None)
}

/// Generates `source`, builds `engine`, traces once untimed and once counted, all on the calling
/// thread; returns the rays the counted trace shot.
pub fn count_one(
    engine: &str,
    settings: Vec<(String, String)>,
    source: &Source,
    size: u32,
) -> Result<u64> {
    workload::check_size(size)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .use_current_thread()
        .build()
        .map_err(|e| input(format!("cannot start the counting thread: {e}")))?;
    let out = pool.install(|| -> Result<u64> {
        let prepared = workload::prepare(source)?;
        let scene = &prepared.input.scene;
        let (built, _) = workload::build(engine, &prepared.input, settings)?;
        let program = match source {
            Source::Program(p, _) => Some(p.name()),
            Source::File(_) | Source::Room(_) => None,
        };
        let built: Box<dyn rtbench_engines::Engine> =
            match crate::runs::plant::from_env(engine, program) {
                Some(p) => Box::new(crate::runs::plant::Planted::new(built, p)),
                None => built,
            };
        trace::render(scene, built.as_ref(), size, None);
        let r = counted_trace(scene, built.as_ref(), size);
        if let Some(f) = built.failure() {
            return Err(input(f));
        }
        Ok(r.stats.total)
    });
    drop(pool);
    out
}
