//! The pass count: a pass ends here ([`Work::end_pass`]: the counters, and a line on stderr
//! with `progress=on`), and the pass cap (`max_passes=N`) stops the run: the run stops after its first N passes (over all its trace
//! calls), every counter and time of those passes kept, and says so (`bf_pass_cap_reached`).
//!
//! Why: seed 000's basic method cannot finish 10^9 objects in one sitting (Table 4.3: 27 to
//! 110 hours on the thesis's machine), and each of its passes sweeps the whole store, so the
//! time of a few passes and the pass count bound its total (`nakamaru-4.3`'s `basic-passes=N`
//! model). The image of a capped run is not an answer: the rays left are answered MISS without
//! a sweep, and the harness claims no image for it.

use super::intersect::Work;
use crate::{Counters, Hit, Ray};

/// The counter a capped run sets (> 0: the run stopped at the cap; no image).
pub const CAP_REACHED: &str = "bf_pass_cap_reached";

impl Work {
    /// A pass is over: `bf_passes` and the count the cap reads, and with `progress=on` one line
    /// on stderr (a 10^9-object run makes one pass in tens of minutes and nothing else to see).
    pub(super) fn end_pass(&mut self, c: &mut Counters) {
        *c.extra.entry("bf_passes".into()).or_insert(0) += 1;
        self.passes_done += 1;
        if let Some(t0) = self.progress {
            let cap = self
                .max_passes
                .map(|m| format!(" of at most {m}"))
                .unwrap_or_default();
            eprintln!(
                "breadth-first: pass {}{cap} done: {} rays in memory, {:.1} s since the engine opened",
                self.passes_done,
                self.slots.len(),
                t0.elapsed().as_secs_f64()
            );
        }
    }

    /// Whether the cap is reached. Then the rays in memory and the rest of `rays` are answered
    /// MISS (no test, no counter), and [`CAP_REACHED`] is set when any ray was left.
    pub(super) fn capped(
        &mut self,
        rays: &mut dyn Iterator<Item = (u32, Ray)>,
        out: &mut dyn FnMut(u32, Hit),
        c: &mut Counters,
    ) -> bool {
        if self.max_passes.is_none_or(|m| self.passes_done < m) {
            return false;
        }
        let mut left = !self.slots.is_empty();
        for s in self.slots.drain(..) {
            out(s.id, Hit::MISS);
        }
        if let Some(h) = self.hires.as_mut() {
            h.walks.clear();
        }
        for (id, _) in rays {
            out(id, Hit::MISS);
            left = true;
        }
        if left {
            *c.extra.entry(CAP_REACHED.into()).or_insert(0) = 1;
        }
        true
    }
}
