//! The one 3D-DDA of rtbench (Amanatides and Woo 1987; seed 000 §1.1 and §1.3, seed 002 §1.5,
//! seed 003 §2.4): the walk of a ray through the cells of a uniform grid, near to far, used by
//! the `grid` engine (cells), the breadth-first engine (voxels) and the object-space engine
//! (subspaces).
//!
//! It is resumable: [`Dda`] is the walker's whole state, so a caller can step it, stop, keep it
//! with the ray and continue later (the breadth-first engine keeps it per ray in memory between
//! passes, seed 000 §1.3: "per ray: origin, direction and 3DDDA state"). [`walk`] drives it to
//! the end for the engines that walk a ray in one go.
//!
//! Per axis it keeps the t of the next wall and steps across whichever comes first. A wall's t
//! is computed from its plane index k as `base + k·delta` (base the t of plane 0) rather than
//! accumulated, so rounding does not drift along long rays. Ties step x, then y, then z: a ray
//! through an edge visits one of the side cells (registration is padded so both hold what
//! touches the edge). Stepping spells out the three axes (constant indices), so a walk held in
//! a local stays in registers.

use crate::ray::Ray;
use glam::Vec3;

/// Direction components smaller than this count as zero (as the shared slab test's
/// `MIN_RCP_INPUT`): the ray is taken as parallel to that axis's walls.
pub const MIN_MOVE: f32 = 1e-18;

/// Which face the walk entered the current cell by: `START` for the first cell.
pub const START: u8 = 6;

/// A uniform grid's frame, shared by every grid of rtbench (the `grid` engine's cells, the
/// breadth-first engine's voxels, the object-space engine's subspaces): its box, resolution and
/// cell size. Cell (x, y, z) has index `x + res_x·(y + res_y·z)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Lattice {
    pub lo: Vec3,
    pub hi: Vec3,
    pub res: [u32; 3],
    pub cell: Vec3,
    pub inv_cell: Vec3,
}

impl Lattice {
    /// The box `lo`–`hi` cut into `res` cells per axis.
    pub fn new(lo: Vec3, hi: Vec3, res: [u32; 3]) -> Lattice {
        let resv = Vec3::new(res[0] as f32, res[1] as f32, res[2] as f32);
        Lattice {
            lo,
            hi,
            res,
            cell: (hi - lo) / resv,
            inv_cell: resv / (hi - lo),
        }
    }

    /// The cell coordinates of point `p`, clamped into the grid.
    ///
    /// Written per axis: `[0, 1, 2].map` was compiled as a call of its own that picked each
    /// coordinate by a run-time index (2–3 % of the grid's time on mount6, once a ray).
    #[inline(always)]
    pub fn cell_of(&self, p: Vec3) -> [u32; 3] {
        let q = (p - self.lo) * self.inv_cell;
        let axis = |x: f32, res: u32| (x.max(0.0) as u32).min(res - 1);
        [
            axis(q.x, self.res[0]),
            axis(q.y, self.res[1]),
            axis(q.z, self.res[2]),
        ]
    }

    /// Linear index of cell (x, y, z).
    #[inline]
    pub fn index(&self, c: [u32; 3]) -> usize {
        c[0] as usize
            + self.res[0] as usize * (c[1] as usize + self.res[1] as usize * c[2] as usize)
    }
}

/// The state of one ray's walk: the current cell and, per axis, its step and next wall.
#[derive(Clone, Copy, Debug)]
pub struct Dda {
    /// The current cell (x, y, z).
    pub idx: [i32; 3],
    step: [i32; 3],
    k: [f32; 3],
    base: [f32; 3],
    delta: [f32; 3],
    t_next: [f32; 3],
    /// End of the walk: the ray's tmax or its exit from the grid.
    t_end: f32,
    /// The face the current cell was entered by, as 0–5 (2·axis + 1 when entered moving down
    /// that axis, i.e. by the cell's max face), or [`START`].
    pub entered: u8,
}

impl Dda {
    /// The walk's first cell (where the segment `[tmin, tmax]` enters the grid's box), or `None`
    /// when the segment misses the box.
    #[inline(always)]
    pub fn start(ray: &Ray, g: &Lattice) -> Option<Dda> {
        Dda::start_at(ray, g).map(|(d, _)| d)
    }

    /// [`Dda::start`], and the t where the segment enters the grid's box.
    #[inline(always)]
    pub fn start_at(ray: &Ray, g: &Lattice) -> Option<(Dda, f32)> {
        let d = ray.dir.to_array();
        let (lo, hi, cell) = (g.lo, g.hi, g.cell);
        let (mut t0, mut t1) = (ray.tmin, ray.tmax);
        let mut inv = [0.0f32; 3];
        for i in 0..3 {
            let o = ray.origin[i];
            if d[i].abs() >= MIN_MOVE {
                inv[i] = 1.0 / d[i];
                let ta = (lo[i] - o) * inv[i];
                let tb = (hi[i] - o) * inv[i];
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            } else if o < lo[i] || o > hi[i] {
                return None;
            }
        }
        if t0.is_nan() || t1.is_nan() || t0 > t1 {
            return None;
        }
        let start = g.cell_of(ray.at(t0));
        let mut w = Dda {
            idx: [0; 3],
            step: [0; 3],
            k: [0.0; 3],
            base: [0.0; 3],
            delta: [0.0; 3],
            t_next: [f32::INFINITY; 3],
            t_end: t1,
            entered: START,
        };
        for i in 0..3 {
            w.idx[i] = start[i] as i32;
            if d[i].abs() < MIN_MOVE {
                continue;
            }
            w.base[i] = (lo[i] - ray.origin[i]) * inv[i];
            w.delta[i] = cell[i] * inv[i];
            if inv[i] > 0.0 {
                w.step[i] = 1;
                w.k[i] = (w.idx[i] + 1) as f32;
            } else {
                w.step[i] = -1;
                w.k[i] = w.idx[i] as f32;
            }
            w.t_next[i] = w.base[i] + w.k[i] * w.delta[i];
        }
        Some((w, t0))
    }

    /// Where the ray crosses the current cell's exit wall (not clipped to the walk's end).
    #[inline(always)]
    pub fn t_wall(&self) -> f32 {
        min_t(min_t(self.t_next[0], self.t_next[1]), self.t_next[2])
    }

    /// Where the ray leaves the current cell or ends in it.
    #[inline(always)]
    pub fn t_exit(&self) -> f32 {
        min_t(self.t_wall(), self.t_end)
    }

    /// The end of the walk: the ray's tmax or its exit from the grid.
    #[inline(always)]
    pub fn t_end(&self) -> f32 {
        self.t_end
    }

    /// The current cell as (x, y, z).
    #[inline(always)]
    pub fn voxel(&self) -> [u32; 3] {
        let [x, y, z] = self.idx;
        [x as u32, y as u32, z as u32]
    }

    /// The current cell's index `x + res_x·(y + res_y·z)`.
    #[inline(always)]
    pub fn index(&self, res: [u32; 3]) -> usize {
        let [x, y, z] = self.voxel();
        x as usize + res[0] as usize * (y as usize + res[1] as usize * z as usize)
    }

    /// Steps into the next cell; false when the ray ends first or leaves the grid (`res`).
    #[inline(always)]
    pub fn advance(&mut self, res: [u32; 3]) -> bool {
        self.step::<false>(res, &mut 0, &[0; 3])
    }

    /// [`Dda::advance`], moving `cell` by the stepped axis's `stride` as well.
    #[inline(always)]
    fn advance_cell(&mut self, res: [u32; 3], cell: &mut usize, stride: &[usize; 3]) -> bool {
        self.step::<true>(res, cell, stride)
    }

    /// The one step of both: `INDEX` says whether `cell` moves (a constant, so the walk
    /// without an index carries no adds: with zero strides instead, breadth-first's walk ran
    /// 0.3 % more instructions).
    #[inline(always)]
    fn step<const INDEX: bool>(
        &mut self,
        res: [u32; 3],
        cell: &mut usize,
        stride: &[usize; 3],
    ) -> bool {
        let (tx, ty, tz) = (self.t_next[0], self.t_next[1], self.t_next[2]);
        if min_t(min_t(tx, ty), tz) >= self.t_end {
            return false;
        }
        if tx <= ty && tx <= tz {
            if INDEX {
                *cell = cell.wrapping_add(stride[0]);
            }
            self.step_axis::<0>(res)
        } else if ty <= tz {
            if INDEX {
                *cell = cell.wrapping_add(stride[1]);
            }
            self.step_axis::<1>(res)
        } else {
            if INDEX {
                *cell = cell.wrapping_add(stride[2]);
            }
            self.step_axis::<2>(res)
        }
    }

    #[inline(always)]
    fn step_axis<const A: usize>(&mut self, res: [u32; 3]) -> bool {
        self.idx[A] += self.step[A];
        // Below 0 or at `res` and beyond in one unsigned comparison (a negative index is above
        // any resolution as u32; resolutions stay far below 2³¹): one branch a step where there
        // were two (−0.4 % instructions of the grid engine on mount6, callgrind, 128²).
        if self.idx[A] as u32 >= res[A] {
            return false;
        }
        self.k[A] += self.step[A] as f32;
        self.t_next[A] = self.base[A] + self.k[A] * self.delta[A];
        // Moving up an axis enters by the cell's min face.
        self.entered = (2 * A + (self.step[A] < 0) as usize) as u8;
        true
    }
}

/// The smaller of two of a walk's t values. A walk's t values are never NaN (a wall's t is
/// finite or +inf, its end is not NaN: [`Dda::start_at`] returns no walk for a NaN segment), so
/// a plain comparison serves, one `minss` on x86-64, where `f32::min` adds four instructions a
/// use to pass a NaN by. For two equal values it returns `b`.
#[inline(always)]
pub fn min_t(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// Calls `visit(walk, cell, t_enter, t_wall)` for each cell `ray` crosses within `[tmin, tmax]`,
/// near to far, until it returns true or the ray leaves the grid or ends. `cell` is the cell's
/// index ([`Lattice::index`]); `t_wall` is where the ray crosses the cell's exit wall (not
/// clipped to the ray's end: clip with [`Dda::t_end`]); the ray ends in the cell whose `t_wall`
/// reaches it.
///
/// The index is kept beside the walk and moved by the stepped axis's signed stride, one add
/// where [`Dda::index`] was two multiplications and two adds a cell (−1.5 % instructions of the
/// grid engine on mount6, callgrind, 128²).
#[inline(always)]
pub fn walk(g: &Lattice, ray: &Ray, mut visit: impl FnMut(&Dda, usize, f32, f32) -> bool) {
    let Some((mut d, mut t_enter)) = Dda::start_at(ray, g) else {
        return;
    };
    let res = g.res;
    let mut cell = g.index(d.voxel());
    // Per axis, the change of the index for one step (negative ones as wrapping adds).
    let stride = [
        d.step[0] as isize as usize,
        (d.step[1] as isize as usize).wrapping_mul(res[0] as usize),
        (d.step[2] as isize as usize).wrapping_mul(res[0] as usize * res[1] as usize),
    ];
    loop {
        let t_wall = d.t_wall();
        if visit(&d, cell, t_enter, t_wall) || !d.advance_cell(res, &mut cell, &stride) {
            return;
        }
        t_enter = t_wall;
    }
}
