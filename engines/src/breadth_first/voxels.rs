//! The in-memory voxel structure of the basic method (seed 000 §1.3, Algorithm 3.4): per voxel
//! one byte, a "marked" bit (some object's bounding box reaches it) and six face bits, set
//! where the voxel lies on the voxel boundary of some box (the boundary of the box of voxels the
//! bounding box reaches). Rays are registered in voxels, not objects ([`Registrations`]: the rays
//! of each voxel in one pass); see [`super::intersect`].
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

/// Elements reserved up front in the per-ray arrays: they grow to what the memory budget allows
/// as rays come, so a large budget is not mapped before it is used.
pub(crate) const PREALLOCATE: usize = 1 << 16;

/// Pushes onto a per-ray array that never holds more than `capacity` elements (the rays, or the
/// registrations, the budget holds): once its first reservation is full it grows once, straight
/// to `capacity`, instead of doubling. A [`super::slot::Slot`] is 64-byte aligned, and the
/// system allocator grows so aligned a block by allocating the new one, copying and freeing the
/// old (no `mremap`): each doubling held both blocks at once, and the last one reserved up to
/// twice what the budget gave the slots (679,002 rays in 256 MiB: 128 MiB copied into a 256 MiB
/// block, for 166 MiB of slots).
#[inline]
pub(crate) fn push_within<T>(v: &mut Vec<T>, x: T, capacity: usize) {
    // Below the bound, one step to it; past it (a budget that holds fewer than one pass needs),
    // Vec's own doubling, so that pushing stays amortised O(1).
    if v.len() == v.capacity() && v.len() < capacity {
        v.reserve_exact(capacity - v.len());
    }
    v.push(x);
}

pub const MARKED: u8 = 1;

/// Bit of the face on the `max` (true) or `min` side of `axis`.
#[inline]
pub fn face_bit(axis: usize, max: bool) -> u8 {
    1 << (1 + 2 * axis + max as usize)
}

pub struct Voxels {
    /// The grid's box, resolution and voxel size.
    pub lattice: Lattice,
    /// How far boxes are grown against rounding (as the grid engine's).
    pub pad: Vec3,
    pub flags: Vec<u8>,
}

impl Voxels {
    /// An unmarked grid over `bounds` (of the prepared primitives) for `n` primitives.
    pub fn new(bounds: [Vec3; 2], n: u64) -> Voxels {
        Self::with_res(bounds, n, None)
    }

    /// As [`Voxels::new`], with `res` cells per axis when given.
    pub fn with_res(bounds: [Vec3; 2], n: u64, res: Option<u32>) -> Voxels {
        Self::shaped(bounds, n, |extent| match res {
            Some(r) => [r; 3],
            None => cells_per_axis(Resolution::CubeRoot, extent, n as usize, 1.0, [0.0; 3]),
        })
    }

    /// The grid's box and pad for a resolution chosen from the padded box's sides by `res`,
    /// without the flags (the on-disk grid of seed 000 §4.3 keeps them in a file).
    pub fn frame(bounds: [Vec3; 2], n: u64, res: impl FnOnce([f64; 3]) -> [u32; 3]) -> Voxels {
        let mut v = Self::shaped(bounds, n, res);
        v.flags = Vec::new();
        v
    }

    /// As [`Voxels::with_res`], the resolution chosen from the padded box's sides by `res`.
    pub fn shaped(bounds: [Vec3; 2], n: u64, res: impl FnOnce([f64; 3]) -> [u32; 3]) -> Voxels {
        let [mut lo, mut hi] = bounds;
        if !(lo.is_finite() && hi.is_finite()) || n == 0 {
            // No primitive: one empty voxel that no ray is registered in.
            return Voxels {
                lattice: Lattice::new(Vec3::ZERO, Vec3::ONE, [1; 3]),
                pad: Vec3::ZERO,
                flags: vec![0],
            };
        }
        let magnitude = lo.abs().max(hi.abs()).max_element();
        let pad0 = PAD_COORD * magnitude + PAD_CELL * (hi - lo).max_element() + f32::MIN_POSITIVE;
        lo -= Vec3::splat(pad0);
        hi += Vec3::splat(pad0);
        let extent = (hi - lo).as_dvec3().to_array();
        let res = res(extent);
        let lattice = Lattice::new(lo, hi, res);
        let cell = lattice.cell;
        Voxels {
            lattice,
            pad: Vec3::splat(PAD_COORD * magnitude) + cell * PAD_CELL,
            flags: vec![0; res.iter().map(|&r| r as usize).product()],
        }
    }

    pub fn count(&self) -> usize {
        self.flags.len()
    }

    /// The largest resolution along an axis (the r of the registration count policies).
    pub fn max_res(&self) -> u32 {
        self.lattice.res.into_iter().max().unwrap_or(1)
    }

    /// The box of voxels a (padded) bounding box reaches, as the grid engine registers it.
    #[inline]
    pub fn range(&self, lo: Vec3, hi: Vec3) -> ([u32; 3], [u32; 3]) {
        (
            self.lattice.cell_of(lo - self.pad),
            self.lattice.cell_of(hi + self.pad),
        )
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
                let row = self.lattice.index([0, cy, cz]);
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

/// One registration of a ray in a voxel, in the order the rays were registered.
#[derive(Clone, Copy)]
pub struct Reg {
    pub(super) voxel: u32,
    pub(super) slot: u32,
}

/// A registration and its entry in the per-voxel lists ([`Registrations`]).
pub fn reg_bytes() -> u64 {
    (std::mem::size_of::<Reg>() + std::mem::size_of::<u32>()) as u64
}

/// The rays registered in each voxel in one pass: filled by registration, then grouped by voxel
/// into one array (a counting sort) before the sweep, so the sweep walks the rays of a run of
/// voxels as one contiguous slice rather than a linked list of nodes scattered in memory.
///
/// Within a voxel the rays come latest-registered first: the order of the linked lists this
/// replaced, so every count that depends on it (the hierarchy's `bh_level_K_ray_tests`, which
/// stop at the first ray that needs a node) is unchanged.
pub struct Registrations {
    /// In registration order.
    pub(super) regs: Vec<Reg>,
    /// Slot indices grouped by voxel: voxel v's are `slots[first[v]..first[v + 1]]`.
    pub(super) slots: Vec<u32>,
    /// Per voxel, and one past the last: where its rays begin in `slots` (all 0 between passes).
    pub(super) first: Vec<u32>,
    /// The most registrations a pass makes within the budget: what `regs` and `slots` grow to
    /// once their first reservation is full ([`push_within`]).
    capacity: usize,
}

impl Registrations {
    pub fn new(voxels: usize, capacity: usize) -> Registrations {
        // The budget bounds what these may grow to; reserving it all up front would map the
        // whole budget before the first ray (and fail under an address-space limit).
        let reserve = capacity.min(PREALLOCATE);
        Registrations {
            regs: Vec::with_capacity(reserve),
            slots: Vec::with_capacity(reserve),
            first: vec![0; voxels + 1],
            capacity,
        }
    }

    #[inline]
    pub fn push(&mut self, voxel: u32, slot: u32) {
        push_within(&mut self.regs, Reg { voxel, slot }, self.capacity);
        self.first[voxel as usize] += 1;
    }

    /// Registrations made this pass.
    pub fn count(&self) -> usize {
        self.regs.len()
    }

    /// Groups the registrations by voxel (counts were kept by [`Registrations::push`]).
    pub fn group(&mut self) {
        // Running sums: first[v] = the end of voxel v's rays; then each ray is put at its
        // voxel's end, moving it down, so first[v] ends at the voxel's beginning and the earliest
        // registered lands last.
        let mut sum = 0;
        let n = self.first.len() - 1;
        for f in &mut self.first[..n] {
            sum += *f;
            *f = sum;
        }
        self.first[n] = sum;
        self.slots.clear();
        if self.regs.len() > self.slots.capacity() {
            self.slots.reserve_exact(self.capacity.max(self.regs.len()));
        }
        self.slots.resize(self.regs.len(), 0);
        for r in &self.regs {
            let f = &mut self.first[r.voxel as usize];
            *f -= 1;
            self.slots[*f as usize] = r.slot;
        }
    }

    /// The rays of voxels `a..=z` (consecutive indices: one row of a box of voxels).
    #[inline]
    pub fn run(&self, a: usize, z: usize) -> &[u32] {
        &self.slots[self.first[a] as usize..self.first[z + 1] as usize]
    }

    pub fn clear(&mut self) {
        self.first.fill(0);
        self.regs.clear();
        self.slots.clear();
    }
}
