//! Axis-aligned boxes and the one scalar ray–box slab test every engine shares.
//!
//! The slab test is Kay and Kajiya's (1986) in the form Embree uses: the ray is prepared once
//! with its inverse direction and `origin × inverse`, so a plane at coordinate `p` is crossed at
//! `t = p·rdir − org_rdir`; for each axis the near plane is chosen by the sign of the direction
//! (Williams et al. 2005), so no min/max swap is needed per box. The SIMD forms of the same test
//! (4 and 8 boxes at once) live with the BVH engines (`bvh/box_test.rs`) and use the same
//! [`SlabRay`].

use crate::ray::Ray;
use glam::Vec3;

/// An axis-aligned box, `lo` ≤ `hi` componentwise unless empty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub lo: Vec3,
    pub hi: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Aabb::EMPTY
    }
}

impl Aabb {
    /// The empty box: the identity of [`Aabb::union`], and never hit by a slab test (its near
    /// plane is at +∞ and its far plane at −∞ whatever the ray's direction).
    pub const EMPTY: Aabb = Aabb {
        lo: Vec3::INFINITY,
        hi: Vec3::NEG_INFINITY,
    };

    pub fn new(lo: Vec3, hi: Vec3) -> Aabb {
        Aabb { lo, hi }
    }

    pub fn is_empty(&self) -> bool {
        self.lo.x > self.hi.x || self.lo.y > self.hi.y || self.lo.z > self.hi.z
    }

    #[inline]
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    #[inline]
    pub fn grow(&mut self, o: &Aabb) {
        self.lo = self.lo.min(o.lo);
        self.hi = self.hi.max(o.hi);
    }

    #[inline]
    pub fn grow_point(&mut self, p: Vec3) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    pub fn centre(&self) -> Vec3 {
        (self.lo + self.hi) * 0.5
    }

    pub fn extent(&self) -> Vec3 {
        (self.hi - self.lo).max(Vec3::ZERO)
    }

    /// The axis (0, 1, 2) along which the box is longest (the first of equals).
    pub fn largest_axis(&self) -> usize {
        let e = self.extent();
        if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        }
    }

    /// Half the surface area (xy + yz + zx): what the surface area heuristic compares (the
    /// factor 2 cancels in every ratio). Zero for an empty box.
    #[inline]
    pub fn half_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.hi - self.lo;
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// Entry distance of `ray` into the box within `[tmin, tmax]`, or `None` when it misses.
    #[inline]
    pub fn slab(&self, r: &SlabRay, tmin: f32, tmax: f32) -> Option<f32> {
        let x = r.near_far(self.lo, self.hi, 0);
        let y = r.near_far(self.lo, self.hi, 1);
        let z = r.near_far(self.lo, self.hi, 2);
        let t_near = x.0.max(y.0).max(z.0).max(tmin);
        let t_far = x.1.min(y.1).min(z.1).min(tmax);
        (t_near <= t_far).then_some(t_near)
    }
}

/// A ray prepared for slab tests (Embree's `TravRay`): the inverse direction, `origin × inverse`
/// and, per axis, whether the direction is negative (then the box's upper plane is the near one).
///
/// Conservative (after Ize 2013, "Robust BVH Ray Traversal"): `plane · rdir − org · rdir` in
/// f32 is off by a few roundings of `(|plane| + |origin|) · |rdir|`, and with the plain products
/// a ray through a box's edge or corner — a ray aimed at a shared edge or vertex of a mesh —
/// could find the box missed and leak through the mesh (the hard-case suite measured 39 leaks of
/// 26 461 such rays in bvh4). So each axis' near distance is lowered and its far distance raised
/// by `4ε (extent + |origin|) |rdir|`, with `extent` the largest coordinate any box can have:
/// folded into two `origin × inverse` terms, one for near planes and one for far planes, it costs
/// the traversal nothing, and widens boxes by about 1e-6 of the scene's size.
#[derive(Clone, Copy, Debug)]
pub struct SlabRay {
    pub rdir: Vec3,
    /// `origin × rdir` plus the rounding bound (subtracted on near planes) …
    pub org_rdir_near: Vec3,
    /// … and minus it (subtracted on far planes).
    pub org_rdir_far: Vec3,
    pub negative: [bool; 3],
}

/// Smallest direction component magnitude inverted as is; smaller ones (and zero) are replaced
/// by ±this value, so the inverse stays finite and no slab computation makes a NaN (Embree's
/// `rcp_safe`).
const MIN_RCP_INPUT: f32 = 1e-18;

/// Roundings covered by the conservative bound (see [`SlabRay`]): the inverse, `origin × inverse`
/// and the plane distance each round once; one more for safety.
const ROUNDINGS: f32 = 4.0 * f32::EPSILON;

impl SlabRay {
    /// [`MIN_RCP_INPUT`], for set-ups that compute the same values in SIMD lanes.
    pub const MIN_RCP_INPUT: f32 = MIN_RCP_INPUT;
    /// [`ROUNDINGS`], likewise.
    pub const ROUNDINGS: f32 = ROUNDINGS;

    /// `extent`: the largest absolute coordinate of any box the ray will be tested against
    /// (the scene's bounds).
    #[inline]
    pub fn new(ray: &Ray, extent: f32) -> SlabRay {
        let safe = |d: f32| {
            if d.abs() < MIN_RCP_INPUT {
                MIN_RCP_INPUT.copysign(d)
            } else {
                d
            }
        };
        let rdir = Vec3::new(
            1.0 / safe(ray.dir.x),
            1.0 / safe(ray.dir.y),
            1.0 / safe(ray.dir.z),
        );
        let org_rdir = ray.origin * rdir;
        let pad = (Vec3::splat(extent.abs()) + ray.origin.abs()) * rdir.abs() * ROUNDINGS;
        SlabRay {
            rdir,
            org_rdir_near: org_rdir + pad,
            org_rdir_far: org_rdir - pad,
            negative: [rdir.x < 0.0, rdir.y < 0.0, rdir.z < 0.0],
        }
    }

    /// Index (0–5) of the near plane on `axis` in a node's plane array ordered lo_x, hi_x, lo_y,
    /// hi_y, lo_z, hi_z; the far plane is the other one of the pair.
    #[inline]
    pub fn near_plane(&self, axis: usize) -> usize {
        2 * axis + self.negative[axis] as usize
    }

    #[inline]
    pub fn far_plane(&self, axis: usize) -> usize {
        2 * axis + 1 - self.negative[axis] as usize
    }

    /// (near, far) crossing distances of the slab of `axis`.
    #[inline]
    fn near_far(&self, lo: Vec3, hi: Vec3, axis: usize) -> (f32, f32) {
        let (a, b) = if self.negative[axis] {
            (hi[axis], lo[axis])
        } else {
            (lo[axis], hi[axis])
        };
        (
            a * self.rdir[axis] - self.org_rdir_near[axis],
            b * self.rdir[axis] - self.org_rdir_far[axis],
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slab_hits_misses_and_empty() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let r = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 0.0, f32::INFINITY);
        let s = SlabRay::new(&r, 5.0);
        // The entry is lowered by the rounding bound, 4ε·(5 + 5) ≈ 5e-6.
        assert!((b.slab(&s, 0.0, f32::INFINITY).unwrap() - 4.0).abs() < 1e-5);
        // Segment ends before the box.
        assert!(b.slab(&s, 0.0, 3.9).is_none());
        // Axis-parallel ray beside the box (zero direction components).
        let r = Ray::new(Vec3::new(2.0, 0.0, -5.0), Vec3::Z, 0.0, f32::INFINITY);
        assert!(b.slab(&SlabRay::new(&r, 5.0), 0.0, f32::INFINITY).is_none());
        // Backwards direction: near plane is the upper one.
        let r = Ray::new(Vec3::new(0.5, 0.5, 5.0), -Vec3::Z, 0.0, f32::INFINITY);
        assert!((b.slab(&SlabRay::new(&r, 5.0), 0.0, 100.0).unwrap() - 4.0).abs() < 1e-5);
        // Inside: entry clamps to tmin.
        let r = Ray::new(Vec3::ZERO, Vec3::X, 0.0, f32::INFINITY);
        assert_eq!(b.slab(&SlabRay::new(&r, 5.0), 0.0, 10.0), Some(0.0));
        // The empty box is never hit, from any side.
        for d in [Vec3::X, -Vec3::Y, Vec3::new(1.0, -1.0, 0.0)] {
            let r = Ray::new(Vec3::ZERO, d, 0.0, f32::INFINITY);
            assert!(Aabb::EMPTY
                .slab(&SlabRay::new(&r, 5.0), 0.0, 1e30)
                .is_none());
        }
        // A flat box (a square in z = 0) is hit head on.
        let f = Aabb::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0));
        let r = Ray::new(Vec3::new(0.3, 0.2, 2.0), -Vec3::Z, 0.0, f32::INFINITY);
        assert!((f.slab(&SlabRay::new(&r, 5.0), 0.0, 10.0).unwrap() - 2.0).abs() < 1e-5);
    }

    /// Rays aimed exactly at corners and edge points of boxes, from far and near, in random
    /// directions that enter the box: every one must find the box (the conservative bound).
    #[test]
    fn rays_through_corners_and_edges_find_the_box() {
        let mut rng = fastrand::Rng::with_seed(0x2545_f491_4f6c_dd1d);
        let mut f = || rng.f32();
        let mut missed = 0;
        for _ in 0..20_000 {
            let lo = Vec3::new(f() * 4.0 - 2.0, f() * 4.0 - 2.0, f() * 4.0 - 2.0);
            let b = Aabb::new(lo, lo + Vec3::new(f() + 0.1, f() + 0.1, f() + 0.1));
            // A corner, or a point on an edge along x.
            let mut p = Vec3::new(
                if f() < 0.5 { b.lo.x } else { b.hi.x },
                if f() < 0.5 { b.lo.y } else { b.hi.y },
                if f() < 0.5 { b.lo.z } else { b.hi.z },
            );
            if f() < 0.5 {
                p.x = b.lo.x + (b.hi.x - b.lo.x) * f();
            }
            // A direction from outside into the box through p: towards its centre.
            let d = (b.centre() - p).normalize() + Vec3::new(f(), f(), f()) * 0.2;
            let r = Ray::new(p - d * (1.0 + 30.0 * f()), d, 0.0, f32::INFINITY);
            if b.slab(&SlabRay::new(&r, 4.0), 0.0, f32::INFINITY).is_none() {
                missed += 1;
            }
        }
        assert_eq!(missed, 0);
    }

    #[test]
    fn union_and_area() {
        let mut b = Aabb::EMPTY;
        assert_eq!(b.half_area(), 0.0);
        b.grow(&Aabb::new(Vec3::ZERO, Vec3::ONE));
        b.grow_point(Vec3::new(2.0, 1.0, 1.0));
        assert_eq!(b.hi, Vec3::new(2.0, 1.0, 1.0));
        assert_eq!(b.half_area(), 2.0 + 1.0 + 2.0);
        assert_eq!(b.centre(), Vec3::new(1.0, 0.5, 0.5));
    }
}
