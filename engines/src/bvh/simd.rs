//! The ray–N-box slab test of a wide node, in three forms: scalar (any N, the `simd=off`
//! fallback), SSE (N = 4) and AVX2 + FMA (N = 8), with `std::arch` intrinsics.
//!
//! All three compute, for each child box, `t_near = max(tmin, near planes · rdir − org·rdir)`
//! and `t_far = min(tmax, far planes · rdir − org·rdir)` and report the children with
//! `t_near ≤ t_far` (001 §1.8, thesis Ch. 4.2.3, with the per-ray precomputation of §1.7; near
//! and far planes picked once per ray by the direction's signs, as Embree's `TravRay` does, so
//! no per-box min/max swap). Empty slots hold the empty box, which every form misses.
//!
//! The SIMD forms are chosen at run time with `is_x86_feature_detected!`; the whole traversal
//! loop is compiled inside a `#[target_feature]` function for AVX2 so the intrinsics inline.

use super::node::WideNode;
use super::traverse::{self, Bvh};
use crate::engine::{Counters, TriangleTest};
use crate::geometry::aabb::SlabRay;
use crate::ray::{Hit, Ray};

/// One slab test of a ray against the N children of a node.
pub trait ChildTest<const N: usize> {
    /// The ray as this test wants it (splatted into SIMD registers for the SIMD forms).
    type Ray: Copy;
    fn prepare(r: &SlabRay) -> Self::Ray;
    /// Bit `i` set when child `i`'s box overlaps `[tmin, tmax]` along the ray; `dist[i]` is
    /// then its entry distance.
    fn test(node: &WideNode<N>, r: &Self::Ray, tmin: f32, tmax: f32, dist: &mut [f32; N]) -> u32;
    /// Asks for the `bytes` from `x` to be brought into the cache (a hint; nothing for the
    /// scalar form). Embree's traversal does the same for every child the ray hits.
    #[inline(always)]
    fn prefetch<X>(_x: &X, _bytes: usize) {}
}

/// The batch entry points of one traversal kernel.
pub type ClosestFn<const N: usize> = fn(&Bvh<N>, &[Ray], &mut [Hit], TriangleTest, &mut Counters);
pub type AnyFn<const N: usize> = fn(&Bvh<N>, &[Ray], &mut [bool], TriangleTest, &mut Counters);

#[derive(Clone, Copy)]
pub struct Kernels<const N: usize> {
    pub closest: ClosestFn<N>,
    pub any: AnyFn<N>,
    /// SIMD lanes of the box test (0: scalar).
    pub lanes: usize,
    pub name: &'static str,
}

/// The scalar kernels (any width).
pub fn scalar<const N: usize>() -> Kernels<N> {
    Kernels {
        closest: traverse::closest_batch::<N, Scalar>,
        any: traverse::any_batch::<N, Scalar>,
        lanes: 0,
        name: "scalar",
    }
}

/// SSE kernels for bvh4 (SSE2 is part of x86-64, so always there on that target).
pub fn sse4() -> Option<Kernels<4>> {
    #[cfg(target_arch = "x86_64")]
    {
        Some(Kernels {
            closest: traverse::closest_batch::<4, x86::Sse4>,
            any: traverse::any_batch::<4, x86::Sse4>,
            lanes: 4,
            name: "sse",
        })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

/// AVX2 + FMA kernels for bvh8, when the CPU has both.
pub fn avx8() -> Option<Kernels<8>> {
    #[cfg(target_arch = "x86_64")]
    {
        x86::has_avx2_fma().then_some(Kernels {
            closest: x86::avx8_closest,
            any: x86::avx8_any,
            lanes: 8,
            name: "avx2",
        })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

/// Scalar slab test of each used slot (`0..len`).
pub struct Scalar;

#[derive(Clone, Copy)]
pub struct ScalarRay {
    rdir: [f32; 3],
    org_rdir: [f32; 3],
    near: [usize; 3],
    far: [usize; 3],
}

impl<const N: usize> ChildTest<N> for Scalar {
    type Ray = ScalarRay;

    #[inline(always)]
    fn prepare(r: &SlabRay) -> ScalarRay {
        ScalarRay {
            rdir: r.rdir.to_array(),
            org_rdir: r.org_rdir.to_array(),
            near: [r.near_plane(0), r.near_plane(1), r.near_plane(2)],
            far: [r.far_plane(0), r.far_plane(1), r.far_plane(2)],
        }
    }

    #[inline(always)]
    fn test(node: &WideNode<N>, r: &ScalarRay, tmin: f32, tmax: f32, dist: &mut [f32; N]) -> u32 {
        let p = &node.planes;
        let (nx, ny, nz) = (&p[r.near[0]], &p[r.near[1]], &p[r.near[2]]);
        let (fx, fy, fz) = (&p[r.far[0]], &p[r.far[1]], &p[r.far[2]]);
        let mut mask = 0;
        for i in 0..(node.len as usize).min(N) {
            let t_near = (nx[i] * r.rdir[0] - r.org_rdir[0])
                .max(ny[i] * r.rdir[1] - r.org_rdir[1])
                .max(nz[i] * r.rdir[2] - r.org_rdir[2])
                .max(tmin);
            let t_far = (fx[i] * r.rdir[0] - r.org_rdir[0])
                .min(fy[i] * r.rdir[1] - r.org_rdir[1])
                .min(fz[i] * r.rdir[2] - r.org_rdir[2])
                .min(tmax);
            if t_near <= t_far {
                mask |= 1 << i;
                dist[i] = t_near;
            }
        }
        mask
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::super::node::{WideNode, PLANES};
    use super::super::traverse::{self, Bvh};
    use super::ChildTest;
    use crate::engine::{Counters, TriangleTest};
    use crate::geometry::aabb::SlabRay;
    use crate::ray::{Hit, Ray};
    use std::arch::x86_64::*;

    /// Offsets (in floats) of the near and far plane rows of a node of width `n`; each is
    /// `row · n` with `row < PLANES`, so a load of `n` floats from there stays in the node.
    fn plane_offsets(r: &SlabRay, n: usize) -> ([usize; 3], [usize; 3]) {
        let near = [
            r.near_plane(0) * n,
            r.near_plane(1) * n,
            r.near_plane(2) * n,
        ];
        let far = [r.far_plane(0) * n, r.far_plane(1) * n, r.far_plane(2) * n];
        debug_assert!(near.iter().chain(&far).all(|&o| o + n <= PLANES * n));
        (near, far)
    }

    pub fn has_avx2_fma() -> bool {
        is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
    }

    // ------------------------------------------------------------------ SSE, 4 boxes at once

    pub struct Sse4;

    #[derive(Clone, Copy)]
    pub struct Sse4Ray {
        rdir: [__m128; 3],
        org_rdir: [__m128; 3],
        near: [usize; 3],
        far: [usize; 3],
    }

    /// Prefetches the cache lines of `bytes` bytes from `x`.
    #[inline(always)]
    fn prefetch_lines<X>(x: &X, bytes: usize) {
        let p = x as *const X as *const i8;
        let mut off = 0;
        while off < bytes {
            // SAFETY: SSE is part of the x86-64 baseline; a prefetch is only a hint and never
            // faults, whatever the address (the offset stays within `bytes` of a live object
            // or just past it, which `wrapping_add` computes without assuming anything).
            unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(off)) };
            off += 64;
        }
    }

    impl ChildTest<4> for Sse4 {
        type Ray = Sse4Ray;

        #[inline(always)]
        fn prefetch<X>(x: &X, bytes: usize) {
            prefetch_lines(x, bytes)
        }

        #[inline(always)]
        fn prepare(r: &SlabRay) -> Sse4Ray {
            let (near, far) = plane_offsets(r, 4);
            let splat = |v: f32| {
                let lanes = [v; 4];
                // SAFETY: SSE is part of the x86-64 baseline; the load reads the 4 floats of
                // the local `lanes`.
                unsafe { _mm_loadu_ps(lanes.as_ptr()) }
            };
            let (d, o) = (r.rdir, r.org_rdir);
            Sse4Ray {
                rdir: [splat(d.x), splat(d.y), splat(d.z)],
                org_rdir: [splat(o.x), splat(o.y), splat(o.z)],
                near,
                far,
            }
        }

        #[inline(always)]
        fn test(node: &WideNode<4>, r: &Sse4Ray, tmin: f32, tmax: f32, dist: &mut [f32; 4]) -> u32 {
            let base = node.planes.as_ptr() as *const f32;
            // SAFETY: SSE is part of the x86-64 baseline. `planes` is 6 rows of 4 contiguous
            // floats (repr(C) arrays) and every offset is `row · 4` with `row < 6`
            // (`plane_offsets`), so each unaligned load reads 4 floats inside the node; the
            // store writes exactly the 4 floats of `dist`.
            unsafe {
                let plane = |off: usize, a: usize| {
                    _mm_sub_ps(
                        _mm_mul_ps(_mm_loadu_ps(base.add(off)), r.rdir[a]),
                        r.org_rdir[a],
                    )
                };
                let t_near = _mm_max_ps(
                    _mm_max_ps(plane(r.near[0], 0), plane(r.near[1], 1)),
                    _mm_max_ps(plane(r.near[2], 2), _mm_set1_ps(tmin)),
                );
                let t_far = _mm_min_ps(
                    _mm_min_ps(plane(r.far[0], 0), plane(r.far[1], 1)),
                    _mm_min_ps(plane(r.far[2], 2), _mm_set1_ps(tmax)),
                );
                _mm_storeu_ps(dist.as_mut_ptr(), t_near);
                _mm_movemask_ps(_mm_cmple_ps(t_near, t_far)) as u32
            }
        }
    }

    // ------------------------------------------------------------ AVX2 + FMA, 8 boxes at once

    pub struct Avx8;

    #[derive(Clone, Copy)]
    pub struct Avx8Ray {
        rdir: [__m256; 3],
        org_rdir: [__m256; 3],
        near: [usize; 3],
        far: [usize; 3],
    }

    impl ChildTest<8> for Avx8 {
        type Ray = Avx8Ray;

        #[inline(always)]
        fn prefetch<X>(x: &X, bytes: usize) {
            prefetch_lines(x, bytes)
        }

        #[inline(always)]
        fn prepare(r: &SlabRay) -> Avx8Ray {
            let (near, far) = plane_offsets(r, 8);
            let (d, o) = (r.rdir, r.org_rdir);
            // SAFETY: only reached from `avx8_closest_impl` / `avx8_any_impl`, which are
            // compiled for and called only on CPUs with AVX2 and FMA (checked in
            // `avx8_closest` / `avx8_any`); `set1` only broadcasts a value.
            unsafe {
                Avx8Ray {
                    rdir: [
                        _mm256_set1_ps(d.x),
                        _mm256_set1_ps(d.y),
                        _mm256_set1_ps(d.z),
                    ],
                    org_rdir: [
                        _mm256_set1_ps(o.x),
                        _mm256_set1_ps(o.y),
                        _mm256_set1_ps(o.z),
                    ],
                    near,
                    far,
                }
            }
        }

        #[inline(always)]
        fn test(node: &WideNode<8>, r: &Avx8Ray, tmin: f32, tmax: f32, dist: &mut [f32; 8]) -> u32 {
            let base = node.planes.as_ptr() as *const f32;
            // SAFETY: AVX2 and FMA are present (only reached through the feature-checked entry
            // points below). `planes` is 6 rows of 8 contiguous floats and every offset is
            // `row · 8` with `row < 6` (`plane_offsets`), so each unaligned load reads 8 floats
            // inside the node; the store writes exactly the 8 floats of `dist`.
            unsafe {
                // t = plane · rdir − org · rdir in one rounding (Embree's `madd` form).
                let plane = |off: usize, a: usize| {
                    _mm256_fmsub_ps(_mm256_loadu_ps(base.add(off)), r.rdir[a], r.org_rdir[a])
                };
                let t_near = _mm256_max_ps(
                    _mm256_max_ps(plane(r.near[0], 0), plane(r.near[1], 1)),
                    _mm256_max_ps(plane(r.near[2], 2), _mm256_set1_ps(tmin)),
                );
                let t_far = _mm256_min_ps(
                    _mm256_min_ps(plane(r.far[0], 0), plane(r.far[1], 1)),
                    _mm256_min_ps(plane(r.far[2], 2), _mm256_set1_ps(tmax)),
                );
                _mm256_storeu_ps(dist.as_mut_ptr(), t_near);
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) as u32
            }
        }
    }

    pub fn avx8_closest(
        bvh: &Bvh<8>,
        rays: &[Ray],
        hits: &mut [Hit],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        assert!(has_avx2_fma(), "the AVX2 kernel needs AVX2 and FMA");
        // SAFETY: the CPU has AVX2 and FMA (asserted above), all `avx8_closest_impl` requires.
        unsafe { avx8_closest_impl(bvh, rays, hits, t, c) }
    }

    pub fn avx8_any(
        bvh: &Bvh<8>,
        rays: &[Ray],
        out: &mut [bool],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        assert!(has_avx2_fma(), "the AVX2 kernel needs AVX2 and FMA");
        // SAFETY: the CPU has AVX2 and FMA (asserted above), all `avx8_any_impl` requires.
        unsafe { avx8_any_impl(bvh, rays, out, t, c) }
    }

    /// The whole batch loop compiled with AVX2 and FMA, so `Avx8`'s intrinsics inline into it.
    #[target_feature(enable = "avx2,fma")]
    unsafe fn avx8_closest_impl(
        bvh: &Bvh<8>,
        rays: &[Ray],
        hits: &mut [Hit],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        traverse::closest_batch::<8, Avx8>(bvh, rays, hits, t, c)
    }

    #[target_feature(enable = "avx2,fma")]
    unsafe fn avx8_any_impl(
        bvh: &Bvh<8>,
        rays: &[Ray],
        out: &mut [bool],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        traverse::any_batch::<8, Avx8>(bvh, rays, out, t, c)
    }
}
