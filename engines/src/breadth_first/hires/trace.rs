//! The trace of one call with the high-resolution grid: per pass the block-wise traversal, the
//! two-level registration and the sweep (seed 000 §4.3).

use super::blocks::{Phase, Walk};
use crate::breadth_first::intersect::Work;
use crate::breadth_first::voxels::push_within;
use crate::engine::Counters;
use crate::geometry::TriangleTest;
use crate::ray::{Hit, Ray};
use std::io;

impl Work {
    /// [`Work::trace`] for the high-resolution grid: per pass one block-wise traversal
    /// (registration and sentinel), the two-level registration, the sweep, and the rays whose
    /// hit is complete leave.
    pub(in crate::breadth_first) fn trace_hires(
        &mut self,
        rays: &mut dyn Iterator<Item = (u32, Ray)>,
        any: bool,
        test: TriangleTest,
        out: &mut dyn FnMut(u32, Hit),
        c: &mut Counters,
    ) -> io::Result<()> {
        {
            let h = self.hires.as_mut().expect("grid=two-level");
            h.walks.clear();
            h.reg.clear();
        }
        let mut input_left = true;
        let mut pass = 0usize;
        loop {
            if self.capped(rays, out, c) {
                return Ok(());
            }
            let may_read = self.refill || self.slots.is_empty();
            while may_read && input_left && self.slots.len() < self.capacity {
                let Some((id, ray)) = rays.next() else {
                    input_left = false;
                    break;
                };
                match self.admit(id, ray, any, test, c) {
                    Ok(slot) => {
                        push_within(&mut self.slots, slot, self.capacity);
                        let walks = &mut self.hires.as_mut().expect("hires").walks;
                        push_within(walks, Walk::new(), self.capacity);
                    }
                    Err(best) => out(id, best),
                }
            }
            if self.slots.is_empty() {
                return Ok(());
            }
            pass += 1;
            *c.extra
                .entry(format!("bf_pass_{pass:03}_rays"))
                .or_insert(0) += self.slots.len() as u64;
            let count = self.registration_count(self.slots.len()) as u32;
            let h = self.hires.as_mut().expect("hires");
            h.cands.clear();
            h.blocks.traverse(
                &mut h.grid,
                &mut self.slots,
                &mut h.walks,
                count,
                self.boundary,
                &mut h.cands,
                c,
            )?;
            if self.cold {
                h.grid.drop_cache();
            }
            h.reg.register(&h.cands);
            *c.extra.entry("bf_registrations".into()).or_insert(0) += h.cands.len() as u64;
            self.sweep(any, test, c)?;
            self.end_pass(c);
            // Algorithm 4.5: done when the hit lies before the sentinel (every voxel up to it
            // was swept or holds no box not met before), or the walk has no sentinel.
            let h = self.hires.as_mut().expect("hires");
            let mut i = 0;
            while i < self.slots.len() {
                let s = &mut self.slots[i];
                let w = h.walks[i];
                s.prev = s.last;
                let done = (any && s.best.is_hit())
                    || w.phase != Phase::Next
                    || s.best_t <= s.covered
                    || s.best_t <= w.sentinel_entry;
                if done {
                    out(s.id, s.best);
                    self.slots.swap_remove(i);
                    h.walks.swap_remove(i);
                } else {
                    i += 1;
                }
            }
        }
    }
}
