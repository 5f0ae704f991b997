//! The per-ray set-up of the single-ray traversal, computed in a few SSE instructions.
//! callgrind counted ~290 instructions run once per ray before the first node
//! on gears4's shadow rays (of ~630 per ray in all; Embree's whole shadow ray is ~360): the
//! traceability test branch by branch, the slab ray ([`SlabRay::new`]) and the watertight
//! set-up ([`WatertightRay::new`]) component by component through glam's scalar `Vec3`, and
//! their spills. Here the same values come out of one vector operation per formula.
//!
//! **Bit for bit the same values**: every lane runs the IEEE operation the scalar code runs on
//! that component, in the same order (a division stays a division, no reciprocal estimate and
//! no fused multiply-add), so trees are traversed and triangles tested exactly as before
//! (test `bvh::ray_setup::tests`).

use crate::geometry::kernels::f32::WatertightRay;
use crate::ray::Ray;

/// Whether the ray may be traced: [`Ray::is_traceable`] without branches. `x − x` is 0 for
/// a finite `x` and NaN for ±∞ or NaN, so the sum of the six is 0 exactly when origin and
/// direction are finite; `tmin` and `tmax` must only not be NaN (`tmax` may be +∞).
#[inline(always)]
pub fn traceable(ray: &Ray) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        x86::traceable(ray)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        traceable_scalar(ray)
    }
}

/// [`traceable`] one component at a time (targets without SSE).
#[inline(always)]
#[allow(clippy::eq_op)] // `x - x` is the finiteness test, not a mistake.
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
fn traceable_scalar(ray: &Ray) -> bool {
    let (o, d) = (ray.origin, ray.dir);
    let z = ((o.x - o.x) + (o.y - o.y)) + ((o.z - o.z) + (d.x - d.x)) + ((d.y - d.y) + (d.z - d.z));
    let ordered = (ray.tmin == ray.tmin) & (ray.tmax == ray.tmax);
    (z == 0.0) & ordered
}

/// The ray's octant: bit `a` set when the direction is negative on axis `a`, as the sign
/// bits of `slab_lanes` (`1 / safe(d)` keeps the sign bit of `d`, −0 included) and
/// `SlabRay::negative`.
#[inline(always)]
pub fn octant(ray: &Ray) -> u32 {
    let d = ray.dir;
    (d.x.is_sign_negative() as u32)
        | (d.y.is_sign_negative() as u32) << 1
        | (d.z.is_sign_negative() as u32) << 2
}

/// [`WatertightRay::new`] without the branches of the axis choice: `kz` is the axis of the
/// largest direction component (the first of equal ones, as there), `kx`, `ky` the next two,
/// swapped when `d[kz] < 0`.
#[inline(always)]
pub fn watertight(d: glam::Vec3) -> WatertightRay {
    let a = d.abs();
    // The same comparisons as `WatertightRay::new`, as selects.
    let kz: usize = if a.x > a.y {
        if a.x > a.z {
            0
        } else {
            2
        }
    } else if a.y > a.z {
        1
    } else {
        2
    };
    let c = d.to_array();
    // (kx, ky) for each kz, unswapped and swapped.
    const AXES: [[(usize, usize); 2]; 3] = [[(1, 2), (2, 1)], [(2, 0), (0, 2)], [(0, 1), (1, 0)]];
    let dz = c[kz];
    let (kx, ky) = AXES[kz][(dz < 0.0) as usize];
    // Tells the compiler the table's axes are in range (no bounds checks below).
    let (kx, ky) = (kx.min(2), ky.min(2));
    WatertightRay {
        kx,
        ky,
        kz,
        sx: c[kx] / dz,
        sy: c[ky] / dz,
        sz: 1.0 / dz,
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::slab_lanes;

#[cfg(target_arch = "x86_64")]
mod x86 {
    use crate::geometry::aabb::SlabRay;
    use crate::ray::Ray;
    use std::arch::x86_64::*;

    /// [`super::traceable`] in two SSE2 registers: the ray is
    /// `repr(C)` (origin, tmin, dir, tmax), so lanes 0–2 of `x − x` summed over the two loads
    /// are 0 exactly when origin and direction are finite; lane 3 (`tmin`, `tmax`) is masked
    /// out of that sum and only tested for NaN (`cmpord`).
    #[inline(always)]
    pub fn traceable(ray: &Ray) -> bool {
        // SAFETY: SSE2 is part of the x86-64 baseline. `Ray` is `repr(C)` (8 floats), so each
        // unaligned load reads 4 floats inside the ray.
        unsafe {
            let p = ray as *const Ray as *const f32;
            let lo = _mm_loadu_ps(p);
            let hi = _mm_loadu_ps(p.add(4));
            let xyz = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
            let diff = _mm_add_ps(_mm_sub_ps(lo, lo), _mm_sub_ps(hi, hi));
            let finite = _mm_cmpeq_ps(_mm_and_ps(diff, xyz), _mm_setzero_ps());
            _mm_movemask_ps(_mm_and_ps(finite, _mm_cmpord_ps(lo, hi))) == 0xf
        }
    }

    /// [`SlabRay::new`] in SSE2 registers: (rdir, org·rdir + pad, org·rdir − pad) in lanes
    /// 0–2 (lane 3 is junk), and the signs of `rdir` as bits 0–2.
    #[inline(always)]
    pub fn slab_lanes(ray: &Ray, extent: f32) -> (__m128, __m128, __m128, u32) {
        // SAFETY: SSE2 is part of the x86-64 baseline. `Ray` is `repr(C)` (origin, tmin,
        // dir, tmax: 8 floats), so each unaligned load reads 4 floats inside the ray.
        unsafe {
            let p = ray as *const Ray as *const f32;
            let o = _mm_loadu_ps(p);
            let d = _mm_loadu_ps(p.add(4));
            let sign = _mm_set1_ps(-0.0);
            let min = _mm_set1_ps(MIN_RCP_INPUT);
            // `safe`: components smaller in magnitude than MIN_RCP_INPUT (zero included)
            // become ±MIN_RCP_INPUT with their sign.
            let abs_d = _mm_andnot_ps(sign, d);
            let tiny = _mm_cmplt_ps(abs_d, min);
            let clamped = _mm_or_ps(_mm_and_ps(d, sign), min);
            let safe = _mm_or_ps(_mm_and_ps(tiny, clamped), _mm_andnot_ps(tiny, d));
            let rdir = _mm_div_ps(_mm_set1_ps(1.0), safe);
            let org_rdir = _mm_mul_ps(o, rdir);
            // (|extent| + |origin|) · |rdir| · ROUNDINGS, in glam's order.
            let e = _mm_set1_ps(extent.abs());
            let pad = _mm_mul_ps(
                _mm_mul_ps(
                    _mm_add_ps(e, _mm_andnot_ps(sign, o)),
                    _mm_andnot_ps(sign, rdir),
                ),
                _mm_set1_ps(ROUNDINGS),
            );
            let near = _mm_add_ps(org_rdir, pad);
            let far = _mm_sub_ps(org_rdir, pad);
            let neg = (_mm_movemask_ps(_mm_cmplt_ps(rdir, _mm_setzero_ps())) & 7) as u32;
            (rdir, near, far, neg)
        }
    }

    const MIN_RCP_INPUT: f32 = SlabRay::MIN_RCP_INPUT;
    const ROUNDINGS: f32 = SlabRay::ROUNDINGS;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::aabb::SlabRay;
    use glam::Vec3;

    /// Rays of every kind the set-up distinguishes: random, axis-aligned (zero and −0
    /// components), tiny components, equal components (the axis choice's ties), non-finite
    /// and NaN bounds.
    fn rays() -> Vec<Ray> {
        let mut s = 12345u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 23) as f32 - 1.0
        };
        let mut out = Vec::new();
        for _ in 0..2000 {
            let o = Vec3::new(next(), next(), next()) * 50.0;
            let d = Vec3::new(next(), next(), next());
            out.push(Ray::new(o, d, 0.0, f32::INFINITY));
        }
        let specials = [
            0.0, -0.0, 1e-20, -1e-20, 1e-18, -1e-18, 0.5, -0.5, 1.0, -1.0,
        ];
        for &x in &specials {
            for &y in &specials {
                for &z in &specials {
                    out.push(Ray::new(
                        Vec3::new(1.0, -2.0, 3.0),
                        Vec3::new(x, y, z),
                        0.1,
                        7.0,
                    ));
                }
            }
        }
        for bad in [f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
            for k in 0..8 {
                let mut v = [0.3f32, 0.2, 0.1, 0.0, 0.5, -0.5, 0.25, 9.0];
                v[k] = bad;
                let r = Ray::new(
                    Vec3::new(v[0], v[1], v[2]),
                    Vec3::new(v[4], v[5], v[6]),
                    v[3],
                    v[7],
                );
                out.push(r);
            }
        }
        out
    }

    #[test]
    fn traceable_as_is_traceable() {
        for r in rays() {
            assert_eq!(traceable(&r), r.is_traceable(), "{r:?}");
            assert_eq!(traceable_scalar(&r), r.is_traceable(), "{r:?}");
        }
    }

    #[test]
    fn watertight_as_the_kernels() {
        for r in rays().iter().filter(|r| r.is_traceable()) {
            let (a, b) = (watertight(r.dir), WatertightRay::new(r.dir));
            assert_eq!((a.kx, a.ky, a.kz), (b.kx, b.ky, b.kz), "{r:?}");
            let bits = |w: &WatertightRay| [w.sx.to_bits(), w.sy.to_bits(), w.sz.to_bits()];
            assert_eq!(bits(&a), bits(&b), "{r:?}");
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn slab_lanes_as_slab_ray() {
        use std::arch::x86_64::*;
        let lanes = |v: __m128| {
            let mut a = [0.0f32; 4];
            // SAFETY: SSE2 baseline; stores 4 floats into `a`.
            unsafe { _mm_storeu_ps(a.as_mut_ptr(), v) };
            [a[0].to_bits(), a[1].to_bits(), a[2].to_bits()]
        };
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        for r in rays().iter().filter(|r| r.is_traceable()) {
            for extent in [0.0, 3.5, 1e4] {
                let want = SlabRay::new(r, extent);
                let (rdir, near, far, neg) = slab_lanes(r, extent);
                assert_eq!(lanes(rdir), bits(want.rdir), "{r:?}");
                assert_eq!(lanes(near), bits(want.org_rdir_near), "{r:?}");
                assert_eq!(lanes(far), bits(want.org_rdir_far), "{r:?}");
                let n = want.negative;
                assert_eq!(neg, n[0] as u32 | (n[1] as u32) << 1 | (n[2] as u32) << 2);
                assert_eq!(octant(r), neg, "{r:?}");
            }
        }
    }
}
