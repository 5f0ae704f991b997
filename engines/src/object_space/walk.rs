//! The 3D-DDA walk from subspace to subspace (003 §2.4: "the next subspace is computed with
//! 3DDDA" [Fujimoto et al., ARTS]; Amanatides and Woo 1987): per axis the t of the next
//! subspace wall, stepping across whichever comes first.
//!
//! A wall's t is computed from its index as `t0 + k·Δt` rather than accumulated, so long rays do
//! not drift; ties step x, then y, then z (a ray through an edge visits one of the side
//! subspaces, which hold what touches the edge because registration is padded).

use crate::grid::build::Cells;
use crate::ray::Ray;

/// Direction components smaller than this count as zero: the ray is parallel to those walls.
const MIN_MOVE: f32 = 1e-18;

/// Per axis: the subspace index, its step, the index past the grid, the next wall's index, the t
/// of wall 0, the t between walls.
#[derive(Clone, Copy)]
struct Axis {
    index: i32,
    step: i32,
    out: i32,
    k: f32,
    base: f32,
    delta: f32,
    next: f32,
}

/// Calls `visit(subspace, t_enter, t_exit)` for the subspaces `ray` crosses within
/// `[tmin, tmax]`, near to far, until it returns true or the ray leaves the grid or ends.
/// `t_exit` is the wall where the ray leaves the subspace (not clipped to `tmax`); the ray ends
/// in the subspace whose `t_exit` reaches `tmax`.
#[inline]
pub fn walk(g: &Cells, ray: &Ray, mut visit: impl FnMut(u32, f32, f32) -> bool) {
    let d = ray.dir.to_array();
    let o = ray.origin.to_array();
    let (mut t0, mut t1) = (ray.tmin, ray.tmax);
    let mut inv = [0.0f32; 3];
    for i in 0..3 {
        if d[i].abs() >= MIN_MOVE {
            inv[i] = 1.0 / d[i];
            let ta = (g.lo[i] - o[i]) * inv[i];
            let tb = (g.hi[i] - o[i]) * inv[i];
            t0 = t0.max(ta.min(tb));
            t1 = t1.min(ta.max(tb));
        } else if o[i] < g.lo[i] || o[i] > g.hi[i] {
            return;
        }
    }
    if t0.is_nan() || t1.is_nan() || t0 > t1 {
        return;
    }
    let start = g.cell_of(ray.at(t0));
    let mut ax = [0, 1, 2].map(|i| {
        let index = start[i] as i32;
        if inv[i] == 0.0 {
            return Axis {
                index,
                step: 0,
                out: -1,
                k: 0.0,
                base: 0.0,
                delta: 0.0,
                next: f32::INFINITY,
            };
        }
        let base = (g.lo[i] - o[i]) * inv[i];
        let delta = g.cell[i] * inv[i];
        let (step, out, k) = if inv[i] > 0.0 {
            (1, g.res[i] as i32, (index + 1) as f32)
        } else {
            (-1, -1, index as f32)
        };
        Axis {
            index,
            step,
            out,
            k,
            base,
            delta,
            next: base + k * delta,
        }
    });
    let (rx, ry) = (g.res[0], g.res[1]);
    let mut t_enter = t0;
    loop {
        let t_exit = ax[0].next.min(ax[1].next).min(ax[2].next);
        let id = ax[0].index as u32 + rx * (ax[1].index as u32 + ry * ax[2].index as u32);
        if visit(id, t_enter, t_exit) || t_exit >= t1 {
            return;
        }
        t_enter = t_exit;
        let i = if ax[0].next <= ax[1].next && ax[0].next <= ax[2].next {
            0
        } else if ax[1].next <= ax[2].next {
            1
        } else {
            2
        };
        let a = &mut ax[i];
        a.index += a.step;
        if a.index == a.out {
            return;
        }
        a.k += a.step as f32;
        a.next = a.base + a.k * a.delta;
    }
}
