//! The high-resolution grid of seed 000 §4.3, which removes the basic method's memory cap on the
//! grid's resolution (`grid=two-level`; `grid=single` is the capped in-memory grid it is
//! measured against, the thesis's "-l" runs). Files, one concept each: [`config`] (switches and
//! the resolution rule of §4.3.3), [`disk_grid`] (the on-disk grid and its subspace-by-subspace
//! preprocessing, §4.3.1), [`blocks`] (the block-wise traversal, Algorithm 4.6, with Algorithm
//! 4.5's sentinel), [`two_level`] (the two-level ray-registration grid with its bounded pool of
//! lower grids, §4.3.3).
//!
//! The sweep is the basic method's (Algorithm 3.5 with S, G and optionally B): only where rays
//! are registered changes, so the rays meet the same objects and the images are those of
//! `grid=cuberoot`, ties between equally near objects aside.
//!
//! Resolution: Klimaszewski's method as the `grid` engine reads it
//! ([`crate::grid::resolution`]; the paper's formula was not available, so this is our reading),
//! density 1 cell per primitive, uncapped, then the rule of §4.3.3 with R_u = 256, R_l = 4.

pub mod blocks;
pub mod config;
pub mod disk_grid;
pub mod two_level;

use super::intersect::Work;
use crate::engine::Counters;
use crate::geometry::TriangleTest;
use crate::ray::{Hit, Ray};
use blocks::{Blocks, Phase, Walk};
use disk_grid::DiskGrid;
use std::io;
use two_level::TwoLevel;

/// The engine's state for `grid=two-level`.
pub struct HiRes {
    pub grid: DiskGrid,
    pub reg: TwoLevel,
    pub blocks: Blocks,
    /// Per ray in memory (parallel to `Work::slots`), its walk.
    pub walks: Vec<Walk>,
    pub cands: Vec<(u32, [u32; 3])>,
    /// The grid file's I/O already reported.
    pub io_reported: crate::store::IoCounters,
}

/// Bytes one registration costs in this mode: the candidate recorded by the traversal and its
/// link in the two-level grid.
pub fn reg_bytes() -> u64 {
    two_level::reg_bytes() + std::mem::size_of::<(u32, [u32; 3])>() as u64
}

pub fn walk_bytes() -> u64 {
    std::mem::size_of::<Walk>() as u64
}

impl Work {
    /// [`Work::trace`] for the high-resolution grid: per pass one block-wise traversal
    /// (registration and sentinel), the two-level registration, the sweep, and the rays whose
    /// hit is complete leave.
    pub(super) fn trace_hires(
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
                        self.slots.push(slot);
                        self.hires.as_mut().expect("hires").walks.push(Walk::new());
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

/// Adds the calls' counts of the high-resolution grid to `c` and resets them.
pub fn report(h: &mut HiRes, c: &mut Counters) {
    let e = &mut c.extra;
    let b = std::mem::take(&mut h.blocks.tally);
    let r = std::mem::take(&mut h.reg.tally);
    let now = h.grid.io;
    let was = std::mem::replace(&mut h.io_reported, now);
    let io = crate::store::IoCounters {
        bytes_read: now.bytes_read - was.bytes_read,
        read_calls: now.read_calls - was.read_calls,
        seeks: now.seeks - was.seeks,
        ..Default::default()
    };
    for (k, v) in [
        ("hr_traversals", b.traversals),
        ("hr_blocks_read", b.blocks_read),
        ("hr_voxels_read", b.voxels_read),
        ("hr_grid_bytes_read", io.bytes_read),
        ("hr_grid_read_calls", io.read_calls),
        ("hr_grid_seeks", io.seeks),
        ("hr_lower_registrations", r.lower),
        ("hr_direct_registrations", r.direct),
        ("hr_lower_grids_used", r.grids_used),
        ("hr_direct_misses", r.direct_misses),
    ] {
        *e.entry(k.into()).or_insert(0) += v;
    }
}
