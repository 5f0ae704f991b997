//! Embree as the yardstick: every engine's trace time is read as a ratio to Embree's trace time on the
//! same scene (program, SF, tessellation, hash: all in the scene's name) with the same threads, measured
//! in the same results set. Noise common to the whole run (a busy machine, a slow night) cancels.

use crate::results::RunRecord;
use std::collections::BTreeMap;

/// The engine name of the yardstick.
pub const EMBREE: &str = "embree";

/// Embree's ok runs of one results set, by (scene name, threads).
pub struct Anchors<'a> {
    by_scene: BTreeMap<(&'a str, usize), &'a RunRecord>,
}

impl<'a> Anchors<'a> {
    /// Picks, for each (scene, threads), Embree's ok run; when Embree ran there with several settings,
    /// the run with default settings wins, else the first by key.
    pub fn of(records: &'a [RunRecord]) -> Anchors<'a> {
        let mut by_scene: BTreeMap<(&str, usize), &RunRecord> = BTreeMap::new();
        for r in records
            .iter()
            .filter(|r| r.engine == EMBREE && r.ok() && r.time_s.trace.median > 0.0)
        {
            let slot = by_scene
                .entry((r.scene.name.as_str(), r.threads))
                .or_insert(r);
            let better = (r.settings.is_empty() && !slot.settings.is_empty())
                || (r.settings.is_empty() == slot.settings.is_empty() && r.key < slot.key);
            if better {
                *slot = r;
            }
        }
        Anchors { by_scene }
    }

    /// Embree's run for the scene and threads of `run`.
    pub fn anchor(&self, run: &RunRecord) -> Option<&'a RunRecord> {
        self.by_scene
            .get(&(run.scene.name.as_str(), run.threads))
            .copied()
    }

    /// `run`'s median trace time over Embree's; `None` without an Embree run, or when `run` failed.
    pub fn ratio(&self, run: &RunRecord) -> Option<f64> {
        if !run.ok() {
            return None;
        }
        let a = self.anchor(run)?;
        Some(run.time_s.trace.median / a.time_s.trace.median)
    }
}

/// Sets every ok run's [`RunRecord::ratio_to_embree`] from its Embree run in `records` (trace CPU
/// time when recorded, else wall time; the quotient of geometric means with its Welch interval,
/// or over the rounds both ran where they ran two or more, [`crate::rounds::quotient`]);
/// clears it where there is no Embree run or too few repeats.
pub fn attach_ratios(records: &mut [RunRecord]) {
    let ratios: Vec<Option<crate::interval::Interval>> = {
        let anchors = Anchors::of(records);
        records
            .iter()
            .map(|r| {
                let a = anchors.anchor(r).filter(|_| r.ok() && r.engine != EMBREE)?;
                if let Some(q) = crate::rounds::quotient(r, a) {
                    return Some(q.interval());
                }
                crate::interval::of_quotient(
                    &r.time_s.trace_for_compare().samples,
                    &a.time_s.trace_for_compare().samples,
                )
            })
            .collect()
    };
    for (r, q) in records.iter_mut().zip(ratios) {
        r.ratio_to_embree = q;
    }
}
