//! The in-memory voxel structure of the basic method (seed 000 §1.3, Algorithm 3.4): per voxel
//! one byte, a "marked" bit (some object's bounding box reaches it) and six face bits, set
//! where the voxel lies on the voxel boundary of some box (the boundary of the box of voxels the
//! bounding box reaches). Rays are registered in voxels, not objects; see [`super::intersect`].
//!
//! The grid's box and resolution are the `grid` engine's (⌊n^(1/3) + 0.5⌋ cells per axis with
//! n the primitives, the box padded against `f32` rounding), so both engines walk the same cells;
//! except where that grid would take more than half the memory budget: then n is lowered until
//! it fits (`BreadthFirst::open`), so a budget-bound run keeps room for rays.

use crate::geometry::dda::Lattice;
use crate::grid::build::{PAD_CELL, PAD_COORD};
use crate::grid::config::Resolution;
use crate::grid::resolution::cells_per_axis;
use glam::Vec3;

pub const MARKED: u8 = 1;

/// Bit of the face on the `max` (true) or `min` side of `axis`.
#[inline]
pub fn face_bit(axis: usize, max: bool) -> u8 {
    1 << (1 + 2 * axis + max as usize)
}

pub struct Voxels {
    pub lo: Vec3,
    pub hi: Vec3,
    pub res: [u32; 3],
    pub cell: Vec3,
    pub inv_cell: Vec3,
    /// How far boxes are grown against rounding (as the grid engine's).
    pub pad: Vec3,
    pub flags: Vec<u8>,
}

impl Lattice for Voxels {
    fn lo(&self) -> Vec3 {
        self.lo
    }
    fn hi(&self) -> Vec3 {
        self.hi
    }
    fn res(&self) -> [u32; 3] {
        self.res
    }
    fn cell(&self) -> Vec3 {
        self.cell
    }
    #[inline(always)]
    fn cell_of(&self, p: Vec3) -> [u32; 3] {
        Voxels::cell_of(self, p)
    }
}

impl Voxels {
    /// An unmarked grid over `bounds` (of the prepared primitives) for `n` primitives.
    pub fn new(bounds: [Vec3; 2], n: u64) -> Voxels {
        let [mut lo, mut hi] = bounds;
        if !(lo.is_finite() && hi.is_finite()) || n == 0 {
            // No primitive: one empty voxel that no ray is registered in.
            return Voxels {
                lo: Vec3::ZERO,
                hi: Vec3::ONE,
                res: [1; 3],
                cell: Vec3::ONE,
                inv_cell: Vec3::ONE,
                pad: Vec3::ZERO,
                flags: vec![0],
            };
        }
        let magnitude = lo.abs().max(hi.abs()).max_element();
        let pad0 = PAD_COORD * magnitude + PAD_CELL * (hi - lo).max_element() + f32::MIN_POSITIVE;
        lo -= Vec3::splat(pad0);
        hi += Vec3::splat(pad0);
        let extent = (hi - lo).as_dvec3().to_array();
        let res = cells_per_axis(Resolution::CubeRoot, extent, n as usize, 1.0, [0.0; 3]);
        let resv = Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
        let cell = (hi - lo) / resv;
        Voxels {
            lo,
            hi,
            res,
            cell,
            inv_cell: resv / (hi - lo),
            pad: Vec3::splat(PAD_COORD * magnitude) + cell * PAD_CELL,
            flags: vec![0; res.iter().map(|&r| r as usize).product()],
        }
    }

    pub fn count(&self) -> usize {
        self.flags.len()
    }

    /// The largest resolution along an axis (the r of the registration count policies).
    pub fn max_res(&self) -> u32 {
        self.res.into_iter().max().unwrap_or(1)
    }

    /// The cell coordinates of point `p`, clamped into the grid.
    #[inline]
    pub fn cell_of(&self, p: Vec3) -> [u32; 3] {
        let q = (p - self.lo) * self.inv_cell;
        [0, 1, 2].map(|i| (q[i].max(0.0) as u32).min(self.res[i] - 1))
    }

    #[inline]
    pub fn index(&self, c: [u32; 3]) -> usize {
        c[0] as usize
            + self.res[0] as usize * (c[1] as usize + self.res[1] as usize * c[2] as usize)
    }

    /// The box of voxels a (padded) bounding box reaches, as the grid engine registers it.
    #[inline]
    pub fn range(&self, lo: Vec3, hi: Vec3) -> ([u32; 3], [u32; 3]) {
        (self.cell_of(lo - self.pad), self.cell_of(hi + self.pad))
    }

    /// Algorithm 3.4's loop body for one object: mark the voxels its box reaches, and the faces
    /// of that box of voxels.
    pub fn mark(&mut self, lo: Vec3, hi: Vec3) {
        if !(lo.is_finite() && hi.is_finite()) {
            return;
        }
        let (a, z) = self.range(lo, hi);
        for cz in a[2]..=z[2] {
            for cy in a[1]..=z[1] {
                let row = self.index([0, cy, cz]);
                for cx in a[0]..=z[0] {
                    let mut f = MARKED;
                    for (axis, c) in [(0, cx), (1, cy), (2, cz)] {
                        if c == a[axis] {
                            f |= face_bit(axis, false);
                        }
                        if c == z[axis] {
                            f |= face_bit(axis, true);
                        }
                    }
                    self.flags[row + cx as usize] |= f;
                }
            }
        }
    }

    pub fn marked_count(&self) -> usize {
        self.flags.iter().filter(|&&f| f & MARKED != 0).count()
    }
}
