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
pub mod trace;
pub mod two_level;

use crate::engine::Counters;
use blocks::{Blocks, Walk};
use disk_grid::DiskGrid;
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
