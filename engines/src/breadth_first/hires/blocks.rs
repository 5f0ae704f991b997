//! The block-wise traversal of seed 000 Algorithm 4.6 (Fig. 4.3), with Algorithm 4.5's sentinel.
//!
//! The on-disk grid is cut into X-slab blocks that fit in memory. Each ray is put in the block
//! of its current voxel; blocks are read left to right, and each ray moving +X (or not along X)
//! walks its voxels there, recording candidate voxels, and passes to the next block when it
//! leaves; then right to left for the rays moving −X. So each voxel is read at most twice per
//! pass, and always sequentially; a block no ray stands in is not read.
//!
//! One walk per pass does what the basic method did in two (Algorithm 4.5): a new ray finds its
//! first candidate, each ray registers up to `count` candidates, then walks on to the first
//! candidate of the next pass (the sentinel), so that whether it survives the sweep is decided
//! without walking again: its hit is complete once it lies before the sentinel's entry.

use super::super::slot::{face_bit_of, Slot};
use super::super::voxels::MARKED;
use super::disk_grid::DiskGrid;
use crate::engine::Counters;
use crate::geometry::dda::{MIN_MOVE, START};
use std::io;

/// Where a ray's walk stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// A new ray: looking for its first candidate.
    First,
    /// Registering candidates (`k` so far this pass).
    Register,
    /// Registered `count`: walking to the next pass's first candidate.
    Sentinel,
    /// Stands on the next pass's first candidate, entered at `sentinel_entry`.
    Next,
    /// Nothing more to register: done after this pass's sweep (or now, with no registration).
    End,
}

#[derive(Clone, Copy, Debug)]
pub struct Walk {
    pub phase: Phase,
    pub k: u32,
    /// The t where the walk entered the sentinel voxel.
    pub sentinel_entry: f32,
    /// The voxel the walk stands on was counted already (the sentinel).
    counted: bool,
    last_exit: f32,
}

impl Walk {
    pub fn new() -> Walk {
        Walk {
            phase: Phase::First,
            k: 0,
            sentinel_entry: f32::NEG_INFINITY,
            counted: false,
            last_exit: f32::NEG_INFINITY,
        }
    }

    /// The start of a pass for a ray standing on its sentinel.
    pub fn resume(&mut self) {
        if self.phase == Phase::Next {
            self.phase = Phase::Register;
            self.counted = true;
        }
        self.k = 0;
    }
}

impl Default for Walk {
    fn default() -> Self {
        Walk::new()
    }
}

/// What the traversals counted.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tally {
    pub blocks_read: u64,
    pub voxels_read: u64,
    pub traversals: u64,
}

pub struct Blocks {
    /// X-slices per block.
    pub width: u32,
    buf: Vec<u8>,
    forward: Vec<Vec<u32>>,
    backward: Vec<Vec<u32>>,
    pub tally: Tally,
}

/// The walk of one ray inside the block of x-slices `x0..x1`: `Some(x)` when it left the block
/// into slice x, `None` when it is finished for this pass.
#[allow(clippy::too_many_arguments)]
#[inline]
fn walk(
    s: &mut Slot,
    w: &mut Walk,
    si: u32,
    block: &[u8],
    (x0, x1): (u32, u32),
    res: [u32; 3],
    count: u32,
    boundary: bool,
    cands: &mut Vec<(u32, [u32; 3])>,
    c: &mut Counters,
) -> Option<u32> {
    loop {
        let v = s.dda.voxel();
        if !std::mem::take(&mut w.counted) {
            c.cells_visited += 1;
        }
        let f = block[((v[0] - x0) as usize * res[1] as usize + v[1] as usize) * res[2] as usize
            + v[2] as usize];
        let e = s.dda.entered;
        let candidate = f & MARKED != 0 && (!boundary || e == START || f & face_bit_of(e) != 0);
        if w.phase == Phase::First && candidate {
            w.phase = Phase::Register;
        }
        match w.phase {
            Phase::First => {}
            Phase::Register => {
                if candidate {
                    cands.push((si, v));
                    w.k += 1;
                    s.last = v;
                    s.covered = s.dda.t_exit();
                    if s.best_t <= s.covered {
                        w.phase = Phase::End;
                        return None;
                    }
                    if w.k == count {
                        w.phase = Phase::Sentinel;
                    }
                } else if s.best_t <= s.dda.t_exit() {
                    s.covered = s.dda.t_exit();
                    w.phase = Phase::End;
                    return None;
                }
            }
            Phase::Sentinel => {
                if candidate {
                    w.phase = Phase::Next;
                    w.sentinel_entry = w.last_exit;
                    return None;
                }
                if s.best_t <= s.dda.t_exit() {
                    w.phase = Phase::End;
                    return None;
                }
            }
            Phase::Next | Phase::End => return None,
        }
        w.last_exit = s.dda.t_exit();
        if !s.dda.advance(res) {
            if w.phase == Phase::Register {
                s.exhausted = true;
            }
            w.phase = Phase::End;
            return None;
        }
        let x = s.dda.voxel()[0];
        if x < x0 || x >= x1 {
            return Some(x);
        }
    }
}

impl Blocks {
    pub fn new(res: [u32; 3], block_bytes: u64) -> Blocks {
        let slice = (res[1] as u64 * res[2] as u64).max(1);
        let width = (block_bytes / slice).clamp(1, res[0] as u64) as u32;
        let n = res[0].div_ceil(width) as usize;
        Blocks {
            width,
            buf: Vec::new(),
            forward: vec![Vec::new(); n],
            backward: vec![Vec::new(); n],
            tally: Tally::default(),
        }
    }

    /// Bytes of the block buffer.
    pub fn bytes(res: [u32; 3], block_bytes: u64) -> u64 {
        let slice = res[1] as u64 * res[2] as u64;
        (block_bytes / slice.max(1)).clamp(1, res[0] as u64) * slice
    }

    /// One pass's traversal of every ray in memory (Algorithm 4.6), recording each ray's
    /// candidate voxels in `cands`.
    #[allow(clippy::too_many_arguments)]
    pub fn traverse(
        &mut self,
        grid: &mut DiskGrid,
        slots: &mut [Slot],
        walks: &mut [Walk],
        count: u32,
        boundary: bool,
        cands: &mut Vec<(u32, [u32; 3])>,
        c: &mut Counters,
    ) -> io::Result<()> {
        let res = grid.res;
        let wd = self.width;
        // Lists an earlier failed call may have left.
        self.forward.iter_mut().for_each(Vec::clear);
        self.backward.iter_mut().for_each(Vec::clear);
        for (si, s) in slots.iter().enumerate() {
            walks[si].resume();
            let b = (s.dda.voxel()[0] / wd) as usize;
            if s.ray.dir.x <= -MIN_MOVE {
                self.backward[b].push(si as u32);
            } else {
                self.forward[b].push(si as u32);
            }
        }
        self.tally.traversals += 1;
        let n = self.forward.len();
        for backward in [false, true] {
            for i in 0..n {
                let b = if backward { n - 1 - i } else { i };
                let list = std::mem::take(if backward {
                    &mut self.backward[b]
                } else {
                    &mut self.forward[b]
                });
                if list.is_empty() {
                    continue;
                }
                let x0 = b as u32 * wd;
                let x1 = (x0 + wd).min(res[0]);
                grid.read_slab(x0, x1, &mut self.buf)?;
                self.tally.blocks_read += 1;
                self.tally.voxels_read += self.buf.len() as u64;
                for &si in &list {
                    let (s, w) = (&mut slots[si as usize], &mut walks[si as usize]);
                    if let Some(x) = walk(
                        s,
                        w,
                        si,
                        &self.buf,
                        (x0, x1),
                        res,
                        count,
                        boundary,
                        cands,
                        c,
                    ) {
                        let to = (x / wd) as usize;
                        // A +X ray leaves rightwards, a −X ray leftwards: to a block still ahead.
                        if backward {
                            self.backward[to].push(si);
                        } else {
                            self.forward[to].push(si);
                        }
                    }
                }
            }
        }
        Ok(())
    }
}
