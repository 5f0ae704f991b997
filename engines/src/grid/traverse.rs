//! Tracing rays through the grid: 3D-DDA (Amanatides and Woo 1987; seed 000 §1.1, seed 002 §1.5;
//! the shared walk of [`crate::geometry::dda`]) over the cells the ray crosses, near to far,
//! testing the primitives registered in each.
//!
//! Closest hit. Seed 002 §1.6: a hit counts only once traversal has reached the cell that holds
//! it, because a primitive spanning several cells may be hit in a later cell, beyond another
//! primitive's nearer hit there. With mailboxes a primitive is tested once, in the first cell
//! that lists it, so its hit cannot wait to be found again later: instead the nearest hit so far
//! is kept across cells (it shortens the ray, so later tests only accept nearer hits), and
//! traversal stops at the end of the first cell whose exit lies beyond it. Both give the nearest
//! hit; this one never tests a primitive twice.
//!
//! Any hit stops at the first primitive that blocks the segment, wherever it lies: an occlusion
//! query needs no order.
//!
//! Rayshade's extras (seed 000 §3.4), each a switch:
//! - per-voxel ray–box culling (Snyder and Barr 1987; Rayshade's `CheckVoxel`): before testing a
//!   primitive in a cell, the bounding box of the ray's piece inside that cell is compared with
//!   the primitive's bounding box. A primitive culled so is not marked in the mailbox, since a
//!   later piece of the ray may still reach it (as in Rayshade).
//! - the shadow cache ([`super::shadow_cache`]), for any-hit queries.
//!
//! Per ray nothing is allocated: the inverse direction and the watertight set-up are computed
//! once, the mailbox and shadow cache belong to the calling batch.

use super::mailbox::Mailbox;
use super::shadow_cache::{Key, ShadowCache};
use super::{Grid, Local};
use crate::engine::Counters;
use crate::geometry::dda;
use crate::geometry::kernels::f32::WatertightRay;
use crate::ray::{Hit, Ray};
use glam::Vec3;

/// Per-ray set-up shared by every primitive test.
pub(super) struct RaySetup {
    wt: WatertightRay,
}

impl RaySetup {
    #[inline]
    pub(super) fn new(ray: &Ray) -> RaySetup {
        RaySetup {
            wt: WatertightRay::new(ray.dir),
        }
    }
}

/// Counts of one ray's walk, kept in locals (registers) while it runs and added to `Counters`
/// once at its end: an increment through `&mut Counters` in the inner loop was a load and a
/// store per reference.
#[derive(Default)]
struct WalkCounts {
    cells: u64,
    empty: u64,
    box_tests: u64,
    culled: u64,
    mailbox_skips: u64,
    tests: u64,
}

impl WalkCounts {
    /// The next primitive of a cell's list, from `list[*at]` on, that the walk tests, counted:
    /// not one this ray tested already (`MB`: its mailbox stamp), nor one whose box is apart
    /// from the ray's piece of the cell (`CULL`); a primitive admitted is stamped. Both walks,
    /// closest and any hit, filter so. `*at` moves past the primitive returned (or to the
    /// list's end).
    ///
    /// The scan keeps its counts in locals and adds them once: the big cells of balls and tree
    /// have hundreds of references that the culling test rejects, and counting each through
    /// the walk's captured counts was a load and a store per reference, one after the other.
    ///
    /// A reference reads its stamp and box unchecked: a compare and a branch less per
    /// reference, the walk's most frequent step, and the scan's registers left to the walk
    /// (−3.5 % instructions on mount6, −6 % on rings7, callgrind, 128²).
    ///
    /// # Safety
    /// Every entry of `list` is below `stamps.len()` (with `MB`) and `bounds.len()` (with
    /// `CULL`).
    #[inline(always)]
    unsafe fn next_admitted<const MB: bool, const CULL: bool>(
        &mut self,
        list: &[u32],
        at: &mut usize,
        stamps: &mut [u32],
        stamp: u32,
        bounds: &[[Vec3; 2]],
        piece: &CullPiece,
    ) -> Option<u32> {
        // Only the rare mailbox skips are counted in the loop: every other reference scanned
        // is box-tested (`CULL`) and then culled, except the one admitted, so the loop carries
        // no count through memory when the compiler runs out of registers.
        let start = *at;
        let mut skips = 0u64;
        let mut k = start;
        let found = loop {
            let Some(&p) = list.get(k) else {
                break None;
            };
            k += 1;
            let i = p as usize;
            debug_assert!((!MB || i < stamps.len()) && (!CULL || i < bounds.len()));
            // SAFETY: `i < stamps.len()` with `MB` (the caller's promise).
            if MB && unsafe { *stamps.get_unchecked(i) } == stamp {
                skips += 1;
                continue;
            }
            // SAFETY: `i < bounds.len()` with `CULL` (the caller's promise).
            if CULL && piece.apart(unsafe { bounds.get_unchecked(i) }) {
                continue;
            }
            if MB {
                // SAFETY: as the stamp's read above.
                unsafe { *stamps.get_unchecked_mut(i) = stamp };
            }
            break Some(p);
        };
        *at = k;
        let admitted = found.is_some() as u64;
        self.mailbox_skips += skips;
        if CULL {
            let boxes = (k - start) as u64 - skips;
            self.box_tests += boxes;
            self.culled += boxes - admitted;
        }
        self.tests += admitted;
        found
    }

    #[inline(always)]
    fn flush(&self, c: &mut Counters, l: &mut Local) {
        c.cells_visited += self.cells;
        c.empty_cells_visited += self.empty;
        c.box_tests += self.box_tests;
        c.mailbox_skips += self.mailbox_skips;
        c.primitive_tests += self.tests;
        l.culled += self.culled;
    }
}

/// The ray's piece of a cell as the culling test reads it.
#[derive(Clone, Copy)]
struct CullPiece {
    #[cfg(target_arch = "x86_64")]
    lanes: (std::arch::x86_64::__m128, std::arch::x86_64::__m128),
    #[cfg(not(target_arch = "x86_64"))]
    lohi: (Vec3, Vec3),
}

impl CullPiece {
    /// The piece's box `(lo, hi)`. On x86-64 as the lanes `apart` compares with: (hi.x, hi.y,
    /// hi.z, +inf) and (-inf, lo.x, lo.y, lo.z).
    #[inline(always)]
    fn new(piece: (Vec3, Vec3)) -> CullPiece {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            let (lo, hi) = piece;
            // SAFETY: SSE2 is part of the x86-64 baseline; `setr` only places values.
            unsafe {
                CullPiece {
                    lanes: (
                        _mm_setr_ps(hi.x, hi.y, hi.z, f32::INFINITY),
                        _mm_setr_ps(f32::NEG_INFINITY, lo.x, lo.y, lo.z),
                    ),
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            CullPiece { lohi: piece }
        }
    }

    /// Whether the box `b` lies apart from the piece along some axis: `lo > piece.hi` or
    /// `hi < piece.lo` on an axis (`Vec3::cmpgt(..).any()` of either side, the same answer: a
    /// NaN compares false either way). On x86-64 in two SSE comparisons: the box's six floats
    /// as the lanes (lo.x, lo.y, lo.z, hi.x) and (lo.z, hi.x, hi.y, hi.z) against the piece's
    /// lanes, whose padding lanes (+inf, -inf) never compare true.
    #[inline(always)]
    fn apart(&self, b: &[Vec3; 2]) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            // `[Vec3; 2]` is six contiguous floats (`Vec3` is `repr(C)`, 12 bytes).
            let f = b.as_ptr() as *const f32;
            // SAFETY: SSE2 is part of the x86-64 baseline. Each unaligned load reads 4 of the
            // box's 6 floats (from the first and from the third).
            unsafe {
                let lo = _mm_loadu_ps(f);
                let hi = _mm_loadu_ps(f.add(2));
                let (phi, plo) = self.lanes;
                let m = _mm_or_ps(_mm_cmpgt_ps(lo, phi), _mm_cmplt_ps(hi, plo));
                _mm_movemask_ps(m) != 0
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let ([lo, hi], (plo, phi)) = (b, &self.lohi);
            (lo.x > phi.x)
                | (lo.y > phi.y)
                | (lo.z > phi.z)
                | (hi.x < plo.x)
                | (hi.y < plo.y)
                | (hi.z < plo.z)
        }
    }
}

impl Grid {
    /// Walks the cells `ray` crosses within `[ray.tmin, ray.tmax]`, near to far, calling
    /// `visit(cell, t_enter, t_exit)` for each until it returns true or the ray leaves the grid
    /// or ends: the shared 3D-DDA ([`crate::geometry::dda`]), `t_exit` clipped to the ray's end.
    #[inline(always)]
    pub(super) fn walk(&self, ray: &Ray, mut visit: impl FnMut(usize, f32, f32) -> bool) {
        dda::walk(&self.cells.lattice, ray, |d, cell, t_enter, t_wall| {
            visit(cell, t_enter, dda::min_t(t_wall, d.t_end()))
        })
    }

    /// The mailbox's stamps and current stamp, and the culling boxes, each as long as the
    /// primitives (`n`) where its switch is on (else empty, and never read).
    #[inline(always)]
    fn per_prim<'a, const MB: bool, const CULL: bool>(
        &'a self,
        mb: &'a mut Mailbox,
        n: usize,
    ) -> (&'a mut [u32], u32, &'a [[Vec3; 2]]) {
        let stamp = mb.ray;
        let stamps: &mut [u32] = if MB { &mut mb.stamps[..n] } else { &mut [] };
        let bounds: &[[Vec3; 2]] = if CULL { &self.prim_bounds[..n] } else { &[] };
        (stamps, stamp, bounds)
    }

    /// The nearest hit of one ray. `MB`: mailboxes on (`mb` then holds one); `CULL`: voxel
    /// culling on. Each switch is a constant of the instance, so the loop over a cell's
    /// references tests neither.
    #[inline]
    pub(super) fn closest<const MB: bool, const CULL: bool>(
        &self,
        ray: &Ray,
        mb: &mut Mailbox,
        c: &mut Counters,
        l: &mut Local,
    ) -> Hit {
        c.rays += 1;
        let s = RaySetup::new(ray);
        let prims = &self.geometry.prims;
        let test = self.config.triangle;
        let mut r = *ray;
        let mut best = u32::MAX;
        let (mut bu, mut bv) = (0.0, 0.0);
        // Primitives kept out of the grid (the floor) first: a near floor hit shortens the walk.
        for &p in &self.floor {
            c.primitive_tests += 1;
            if let Some((t, u, v)) = prims[p as usize].intersect(&r, test, &s.wt) {
                c.primitive_hits += 1;
                (r.tmax, best, bu, bv) = (t, p, u, v);
            }
        }
        if !self.cells.refs.is_empty() {
            if MB {
                mb.next_ray();
            }
            let g = &self.cells;
            let (stamps, stamp, bounds) = self.per_prim::<MB, CULL>(mb, prims.len());
            let mut n = WalkCounts::default();
            let mut hits = 0;
            // The walk covers the segment left after the floor.
            let segment = r;
            self.walk(&segment, |cell, t_enter, t_exit| {
                n.cells += 1;
                // SAFETY: the walk's cells are the lattice's (each axis within its resolution,
                // which `build::build` makes at least 1), and the grid's cells come from
                // `build::build`, whose `offsets` has one entry a cell and one more, ascending to
                // `refs.len()`.
                let span = unsafe { g.span_unchecked(cell) };
                if span.0 == span.1 {
                    n.empty += 1;
                    return r.tmax <= t_exit;
                }
                // SAFETY: `span` is a cell's range in `build::build`'s layout (above).
                let list = unsafe { g.refs_unchecked(span) };
                let piece = CullPiece::new(if CULL {
                    segment_box(&r, t_enter, dda::min_t(t_exit, r.tmax), g.pad)
                } else {
                    (Vec3::ZERO, Vec3::ZERO)
                });
                let mut at = 0;
                // SAFETY: a cell's references index `geometry.prims` (`build::build` registers
                // primitive indices), and `per_prim` cuts `stamps` and `bounds` to its length.
                while let Some(p) = unsafe {
                    n.next_admitted::<MB, CULL>(list, &mut at, stamps, stamp, bounds, &piece)
                } {
                    // Unchecked: −2.6 % instructions on mount6, −1.2 % on rings7 (callgrind,
                    // 128²). The any-hit walk keeps its check: unchecked there, rings7 rose 0.3 %.
                    // SAFETY: `p` is a cell's reference, an index of `geometry.prims` (above).
                    let prim = unsafe { prims.get_unchecked(p as usize) };
                    if let Some((t, u, v)) = prim.intersect(&r, test, &s.wt) {
                        hits += 1;
                        (r.tmax, best, bu, bv) = (t, p, u, v);
                    }
                }
                // Seed 002 §1.6: stop once the nearest hit lies within the cells walked.
                r.tmax <= t_exit
            });
            n.flush(c, l);
            c.primitive_hits += hits;
        }
        if best == u32::MAX {
            Hit::MISS
        } else {
            Hit {
                t: r.tmax,
                object: self.geometry.prim_object[best as usize],
                u: bu,
                v: bv,
            }
        }
    }

    /// Whether anything blocks one ray's segment (`MB`, `CULL`: as [`Grid::closest`]).
    #[inline]
    pub(super) fn any<const MB: bool, const CULL: bool>(
        &self,
        ray: &Ray,
        mb: &mut Mailbox,
        cache: Option<&mut ShadowCache>,
        c: &mut Counters,
        l: &mut Local,
    ) -> bool {
        c.rays += 1;
        let s = RaySetup::new(ray);
        let prims = &self.geometry.prims;
        let test = self.config.triangle;
        if MB {
            mb.next_ray();
        }
        // The shadow cache: try the light's last blocker first.
        let key = cache.as_ref().and_then(|_| Key::of(ray));
        if let (Some(cache), Some(key)) = (cache.as_deref(), key.as_ref()) {
            if let Some(p) = cache.blocker(key) {
                c.primitive_tests += 1;
                if prims[p as usize].intersect(ray, test, &s.wt).is_some() {
                    c.primitive_hits += 1;
                    c.shadow_cache_hits += 1;
                    return true;
                }
                l.cache_misses += 1;
                // Tested and missed: the walk need not test it again.
                if MB {
                    mb.mark(p);
                }
            }
        }
        let mut blocker = u32::MAX;
        for &p in &self.floor {
            c.primitive_tests += 1;
            if prims[p as usize].intersect(ray, test, &s.wt).is_some() {
                c.primitive_hits += 1;
                blocker = p;
                break;
            }
        }
        if blocker == u32::MAX && !self.cells.refs.is_empty() {
            let g = &self.cells;
            let (stamps, stamp, bounds) = self.per_prim::<MB, CULL>(mb, prims.len());
            let mut n = WalkCounts::default();
            self.walk(ray, |cell, t_enter, t_exit| {
                n.cells += 1;
                // SAFETY: the walk's cells are the lattice's (each axis within its resolution,
                // which `build::build` makes at least 1), and the grid's cells come from
                // `build::build`, whose `offsets` has one entry a cell and one more, ascending to
                // `refs.len()`.
                let span = unsafe { g.span_unchecked(cell) };
                if span.0 == span.1 {
                    n.empty += 1;
                    return false;
                }
                // SAFETY: `span` is a cell's range in `build::build`'s layout (above).
                let list = unsafe { g.refs_unchecked(span) };
                let piece = CullPiece::new(if CULL {
                    segment_box(ray, t_enter, t_exit, g.pad)
                } else {
                    (Vec3::ZERO, Vec3::ZERO)
                });
                let mut at = 0;
                // SAFETY: a cell's references index `geometry.prims` (`build::build` registers
                // primitive indices), and `per_prim` cuts `stamps` and `bounds` to its length.
                while let Some(p) = unsafe {
                    n.next_admitted::<MB, CULL>(list, &mut at, stamps, stamp, bounds, &piece)
                } {
                    let prim = &prims[p as usize];
                    if prim.intersect(ray, test, &s.wt).is_some() {
                        blocker = p;
                        return true;
                    }
                }
                false
            });
            n.flush(c, l);
            if blocker != u32::MAX {
                c.primitive_hits += 1;
            }
        }
        if blocker == u32::MAX {
            return false;
        }
        if let (Some(cache), Some(key)) = (cache, key.as_ref()) {
            cache.remember(key, blocker);
        }
        true
    }
}

/// The bounding box of the ray's piece from `t0` to `t1`, grown by `pad` against rounding.
/// A cell's `t0` and `t1` are finite, so the ends have no NaN and plain comparisons order
/// them (`Vec3::min` and `max` spent five more instructions each passing NaN by).
#[inline(always)]
fn segment_box(ray: &Ray, t0: f32, t1: f32, pad: Vec3) -> (Vec3, Vec3) {
    let a = ray.at(t0);
    let b = ray.at(t1);
    let lo = Vec3::select(a.cmplt(b), a, b);
    let hi = Vec3::select(a.cmplt(b), b, a);
    (lo - pad, hi + pad)
}

/// The cells a ray visits, in order, as (x, y, z): for tests and debugging (seed 002 §1.7's
/// "cells visited by this pixel's ray").
#[cfg(test)]
pub fn cells_along(grid: &Grid, ray: &Ray) -> Vec<[u32; 3]> {
    let r = grid.cells.lattice.res;
    let mut out = Vec::new();
    grid.walk(ray, |c, _, _| {
        let c = c as u32;
        out.push([c % r[0], (c / r[0]) % r[1], c / (r[0] * r[1])]);
        false
    });
    out
}

/// How many cells the DDA walk of `ray` steps through in `grid` (the walk alone: no primitive
/// test). For the criterion benchmark of one DDA step (engines/benches/kernels.rs).
#[doc(hidden)]
pub fn dda_cells(grid: &Grid, ray: &Ray) -> usize {
    let mut n = 0;
    grid.walk(ray, |_, _, _| {
        n += 1;
        false
    });
    n
}
