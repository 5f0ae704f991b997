//! A 3D-DDA (Amanatides and Woo 1987) that can stop and resume: each ray in memory keeps its
//! walk between passes (seed 000 §1.3, "per ray: origin, direction and 3DDDA state"). The steps
//! are the `grid` engine's: wall distances computed from the plane index (no drift), ties to x
//! then y, so both engines visit the same cells.

use super::voxels::Voxels;
use crate::ray::Ray;

/// Direction components smaller than this count as zero (as the grid engine's walk).
const MIN_MOVE: f32 = 1e-18;

/// Which face the walk entered the current voxel by: `START` for the first voxel.
pub const START: u8 = 6;

#[derive(Clone, Copy, Debug)]
pub struct Dda {
    pub idx: [i32; 3],
    step: [i32; 3],
    k: [f32; 3],
    base: [f32; 3],
    delta: [f32; 3],
    t_next: [f32; 3],
    /// End of the walk: the ray's tmax or its exit from the grid.
    t_end: f32,
    /// The face bit (see [`super::voxels::face_bit`]) the current voxel was entered by, as
    /// 0–5 (2·axis + max side), or [`START`].
    pub entered: u8,
}

impl Dda {
    /// The walk's first voxel, or `None` when the ray's segment misses the grid.
    pub fn start(ray: &Ray, g: &Voxels) -> Option<Dda> {
        let d = ray.dir.to_array();
        let (mut t0, mut t1) = (ray.tmin, ray.tmax);
        let mut inv = [0.0f32; 3];
        for i in 0..3 {
            let o = ray.origin[i];
            if d[i].abs() >= MIN_MOVE {
                inv[i] = 1.0 / d[i];
                let ta = (g.lo[i] - o) * inv[i];
                let tb = (g.hi[i] - o) * inv[i];
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            } else if o < g.lo[i] || o > g.hi[i] {
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
            w.base[i] = (g.lo[i] - ray.origin[i]) * inv[i];
            w.delta[i] = g.cell[i] * inv[i];
            if inv[i] > 0.0 {
                w.step[i] = 1;
                w.k[i] = (w.idx[i] + 1) as f32;
            } else {
                w.step[i] = -1;
                w.k[i] = w.idx[i] as f32;
            }
            w.t_next[i] = w.base[i] + w.k[i] * w.delta[i];
        }
        Some(w)
    }

    /// Where the ray leaves the current voxel (or ends in it).
    #[inline]
    pub fn t_exit(&self) -> f32 {
        self.t_next[0]
            .min(self.t_next[1])
            .min(self.t_next[2])
            .min(self.t_end)
    }

    #[inline]
    pub fn voxel(&self) -> [u32; 3] {
        self.idx.map(|i| i as u32)
    }

    /// Steps into the next voxel; false when the ray leaves the grid or ends first.
    #[inline]
    pub fn advance(&mut self, g: &Voxels) -> bool {
        let (tx, ty, tz) = (self.t_next[0], self.t_next[1], self.t_next[2]);
        if tx.min(ty).min(tz) >= self.t_end {
            return false;
        }
        let axis = if tx <= ty && tx <= tz {
            0
        } else if ty <= tz {
            1
        } else {
            2
        };
        self.idx[axis] += self.step[axis];
        if self.idx[axis] < 0 || self.idx[axis] >= g.res[axis] as i32 {
            return false;
        }
        self.k[axis] += self.step[axis] as f32;
        self.t_next[axis] = self.base[axis] + self.k[axis] * self.delta[axis];
        // Moving up an axis enters by the voxel's min face.
        self.entered = (2 * axis + (self.step[axis] < 0) as usize) as u8;
        true
    }
}
