//! The ray–N-box slab test of a wide node ([`super::node::WideNode`]), beside the node layout
//! as madmann91/bvh keeps its ray–node test in `node.h`, in three forms: scalar (any N, the
//! `simd=off` fallback), SSE (N = 4) and AVX2 + FMA (N = 8), with `std::arch` intrinsics.
//!
//! All three compute, for each child box, `t_near = max(tmin, near planes · rdir − org·rdir)`
//! and `t_far = min(tmax, far planes · rdir − org·rdir)` (`org·rdir` widened by a rounding
//! bound, lower for near planes and higher for far ones: `SlabRay`) and report the children with
//! `t_near ≤ t_far` (001 §1.8, thesis Ch. 4.2.3, with the per-ray precomputation of §1.7; near
//! and far planes picked once per ray by the direction's signs, as Embree's `TravRay` does, so
//! no per-box min/max swap). Empty slots hold the empty box, which every form misses.
//!
//! The forms are implemented for the lane types of [`crate::geometry::lanes`] (`Scalar`,
//! `Sse4`, `Avx8`), the vocabulary of the triangle packet test too. Which form a tree is
//! traversed with is chosen at run time in [`super::dispatch`].

use super::node::WideNode;
use crate::geometry::aabb::SlabRay;
use crate::geometry::lanes::Scalar;
use crate::ray::Ray;

/// One slab test of a ray against the N children of a node.
pub trait ChildTest<const N: usize> {
    /// The ray as this test wants it (splatted into SIMD registers for the SIMD forms).
    type Ray: Copy;
    fn prepare(r: &SlabRay) -> Self::Ray;
    /// [`Self::prepare`] of `SlabRay::new(ray, extent)`: the SIMD forms compute it in SSE
    /// registers, bit for bit the same ([`super::ray_setup`]).
    #[inline(always)]
    fn prepare_ray(ray: &Ray, extent: f32) -> Self::Ray {
        Self::prepare(&SlabRay::new(ray, extent))
    }
    /// Bit `i` set when child `i`'s box overlaps `[tmin, tmax]` along the ray; `dist[i]` is
    /// then its entry distance.
    fn test(node: &WideNode<N>, r: &Self::Ray, tmin: f32, tmax: f32, dist: &mut [f32; N]) -> u32;
    /// Whether [`Self::test_octant`] is worth a traversal loop per octant (the SIMD forms,
    /// whose plane rows then become constants).
    const OCTANTS: bool = false;
    /// [`Self::test`] for a ray whose direction is negative on the axes of the bits of `NEG`
    /// (`slab_lanes`' sign bits): the same answer, with the near and far plane rows known at
    /// compile time, so the loop keeps no row offsets (6 loads a node).
    #[inline(always)]
    fn test_octant<const NEG: u32>(
        node: &WideNode<N>,
        r: &Self::Ray,
        tmin: f32,
        tmax: f32,
        dist: &mut [f32; N],
    ) -> u32 {
        Self::test(node, r, tmin, tmax, dist)
    }
    /// Asks for the node-sized block of memory at `p` to be brought into the cache (a hint;
    /// nothing for the scalar form).
    #[inline(always)]
    fn prefetch(_p: *const u8) {}
    /// Writes the children of the slots of the set bits of `mask` to the front of `out`, in
    /// slot order, and returns how many there are (the rest of `out` is left as anything).
    /// `prefetch` is given the address of each child's node or leaf (the scalar and SSE forms
    /// prefetch each, as before; the AVX2 form moves all of them at once in one permutation
    /// and prefetches none).
    #[inline(always)]
    fn compress_children(
        node: &WideNode<N>,
        mask: u32,
        out: &mut [u32; N],
        prefetch: impl Fn(u32),
    ) -> usize {
        let (mut mask, mut n) = (mask, 0);
        while mask != 0 {
            let k = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            prefetch(node.child[k]);
            out[n] = node.child[k];
            n += 1;
        }
        n
    }
}

/// The ray as the scalar slab test wants it (each used slot, `0..len`, one after the other).
#[derive(Clone, Copy)]
pub struct ScalarSlabRay {
    rdir: [f32; 3],
    org_near: [f32; 3],
    org_far: [f32; 3],
    near: [usize; 3],
    far: [usize; 3],
}

impl<const N: usize> ChildTest<N> for Scalar {
    type Ray = ScalarSlabRay;

    #[inline(always)]
    fn prepare(r: &SlabRay) -> ScalarSlabRay {
        ScalarSlabRay {
            rdir: r.rdir.to_array(),
            org_near: r.org_rdir_near.to_array(),
            org_far: r.org_rdir_far.to_array(),
            near: [r.near_plane(0), r.near_plane(1), r.near_plane(2)],
            far: [r.far_plane(0), r.far_plane(1), r.far_plane(2)],
        }
    }

    #[inline(always)]
    fn test(
        node: &WideNode<N>,
        r: &ScalarSlabRay,
        tmin: f32,
        tmax: f32,
        dist: &mut [f32; N],
    ) -> u32 {
        let p = &node.planes;
        let (nx, ny, nz) = (&p[r.near[0]], &p[r.near[1]], &p[r.near[2]]);
        let (fx, fy, fz) = (&p[r.far[0]], &p[r.far[1]], &p[r.far[2]]);
        let mut mask = 0;
        for i in 0..(node.len as usize).min(N) {
            let t_near = (nx[i] * r.rdir[0] - r.org_near[0])
                .max(ny[i] * r.rdir[1] - r.org_near[1])
                .max(nz[i] * r.rdir[2] - r.org_near[2])
                .max(tmin);
            let t_far = (fx[i] * r.rdir[0] - r.org_far[0])
                .min(fy[i] * r.rdir[1] - r.org_far[1])
                .min(fz[i] * r.rdir[2] - r.org_far[2])
                .min(tmax);
            if t_near <= t_far {
                mask |= 1 << i;
                dist[i] = t_near;
            }
        }
        mask
    }
}

/// The scalar slab test without 001's per-ray precomputation (§1.7, thesis Ch. 4.2.2): the ray
/// is kept as origin and direction, and every box test divides by the direction and orders each
/// slab's two distances with a min and a max, as PBRT's `BBox::IntersectP` [PH04] does. For
/// `precompute=off` only: 001's ablation of what the precomputation is worth.
pub struct ScalarPerBox;

/// The ray as origin and direction (recovered from the slab ray to within its rounding pad).
#[derive(Clone, Copy)]
pub struct PlainRay {
    org: [f32; 3],
    dir: [f32; 3],
}

impl<const N: usize> ChildTest<N> for ScalarPerBox {
    type Ray = PlainRay;

    #[inline(always)]
    fn prepare(r: &SlabRay) -> PlainRay {
        let dir = r.rdir.recip();
        let org = (r.org_rdir_near + r.org_rdir_far) * 0.5 * dir;
        PlainRay {
            org: org.to_array(),
            dir: dir.to_array(),
        }
    }

    #[inline(always)]
    fn test(node: &WideNode<N>, r: &PlainRay, tmin: f32, tmax: f32, dist: &mut [f32; N]) -> u32 {
        // Plane 2a is the minimum along axis a and 2a + 1 the maximum (`SlabRay::near_plane`).
        let p = &node.planes;
        let mut mask = 0;
        for i in 0..(node.len as usize).min(N) {
            // The empty box (minimum above maximum) is missed, as by the other forms.
            if p[0][i] > p[1][i] {
                continue;
            }
            let (mut t0, mut t1) = (tmin, tmax);
            for a in 0..3 {
                let ta = (p[2 * a][i] - r.org[a]) / r.dir[a];
                let tb = (p[2 * a + 1][i] - r.org[a]) / r.dir[a];
                t0 = t0.max(ta.min(tb));
                t1 = t1.min(ta.max(tb));
            }
            // The recovered origin rounds; widen by a few ulps so no box the precomputed test
            // reports is lost.
            if t0 <= t1 + 4.0 * f32::EPSILON * t1.abs().max(t0.abs()) {
                mask |= 1 << i;
                dist[i] = t0;
            }
        }
        mask
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::super::node::{WideNode, PLANES};
    use super::super::ray_setup::slab_lanes;
    use super::ChildTest;
    use crate::geometry::aabb::SlabRay;
    use crate::geometry::lanes::{Avx8, Sse4};
    use crate::ray::Ray;
    use std::arch::x86_64::*;

    /// Offsets of the near and far plane rows from the sign bits of `slab_lanes`.
    #[inline(always)]
    fn offsets_from_signs(neg: u32, n: usize) -> ([usize; 3], [usize; 3]) {
        let bit = |a: usize| ((neg >> a) & 1) as usize;
        (
            [bit(0) * n, (2 + bit(1)) * n, (4 + bit(2)) * n],
            [(1 - bit(0)) * n, (3 - bit(1)) * n, (5 - bit(2)) * n],
        )
    }

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

    // ------------------------------------------------------------------ SSE, 4 boxes at once

    /// The ray splatted into lanes (`__m128` or `__m256`), with the offsets of the near and far
    /// plane rows.
    #[derive(Clone, Copy)]
    pub struct SlabRayLanes<R> {
        rdir: [R; 3],
        org_near: [R; 3],
        org_far: [R; 3],
        near: [usize; 3],
        far: [usize; 3],
    }

    /// Prefetches the `lines` cache lines from `p` (a node: 2 lines for N = 4, 4 for N = 8;
    /// or as much of a leaf's primitives).
    #[inline(always)]
    fn prefetch_lines(p: *const u8, lines: usize) {
        for l in 0..lines {
            // SAFETY: SSE is part of the x86-64 baseline. A prefetch is only a hint: it never
            // faults and reads nothing into the program, whatever the address.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * l) as *const i8) };
        }
    }

    /// 4 boxes at once in 128-bit registers; `FMA` fuses the plane distance's multiply and
    /// subtract (only instantiated inside the AVX2 + FMA entry points).
    impl<const FMA: bool> ChildTest<4> for Sse4<FMA> {
        type Ray = SlabRayLanes<__m128>;

        #[inline(always)]
        fn prefetch(p: *const u8) {
            prefetch_lines(p, 2)
        }

        #[inline(always)]
        fn prepare_ray(ray: &Ray, extent: f32) -> SlabRayLanes<__m128> {
            let (rdir, on, of, neg) = slab_lanes(ray, extent);
            let (near, far) = offsets_from_signs(neg, 4);
            // SAFETY: SSE is part of the x86-64 baseline; the shuffles only move lanes.
            unsafe {
                let splat = |v: __m128| {
                    [
                        _mm_shuffle_ps::<0x00>(v, v),
                        _mm_shuffle_ps::<0x55>(v, v),
                        _mm_shuffle_ps::<0xaa>(v, v),
                    ]
                };
                SlabRayLanes {
                    rdir: splat(rdir),
                    org_near: splat(on),
                    org_far: splat(of),
                    near,
                    far,
                }
            }
        }

        #[inline(always)]
        fn prepare(r: &SlabRay) -> SlabRayLanes<__m128> {
            let (near, far) = plane_offsets(r, 4);
            let splat = |v: f32| {
                let lanes = [v; 4];
                // SAFETY: SSE is part of the x86-64 baseline; the load reads the 4 floats of
                // the local `lanes`.
                unsafe { _mm_loadu_ps(lanes.as_ptr()) }
            };
            let (d, on, of) = (r.rdir, r.org_rdir_near, r.org_rdir_far);
            SlabRayLanes {
                rdir: [splat(d.x), splat(d.y), splat(d.z)],
                org_near: [splat(on.x), splat(on.y), splat(on.z)],
                org_far: [splat(of.x), splat(of.y), splat(of.z)],
                near,
                far,
            }
        }

        const OCTANTS: bool = true;

        #[inline(always)]
        fn test(
            node: &WideNode<4>,
            r: &SlabRayLanes<__m128>,
            tmin: f32,
            tmax: f32,
            dist: &mut [f32; 4],
        ) -> u32 {
            slab4::<FMA>(node, r, r.near, r.far, tmin, tmax, dist)
        }

        #[inline(always)]
        fn test_octant<const NEG: u32>(
            node: &WideNode<4>,
            r: &SlabRayLanes<__m128>,
            tmin: f32,
            tmax: f32,
            dist: &mut [f32; 4],
        ) -> u32 {
            let (near, far) = offsets_from_signs(NEG & 7, 4);
            slab4::<FMA>(node, r, near, far, tmin, tmax, dist)
        }
    }

    /// The SSE slab test with the near and far plane rows at `near`, `far` (offsets in floats,
    /// each `row · 4` with `row < 6`: `offsets_from_signs`).
    #[inline(always)]
    fn slab4<const FMA: bool>(
        node: &WideNode<4>,
        r: &SlabRayLanes<__m128>,
        near: [usize; 3],
        far: [usize; 3],
        tmin: f32,
        tmax: f32,
        dist: &mut [f32; 4],
    ) -> u32 {
        let base = node.planes.as_ptr() as *const f32;
        // SAFETY: SSE is part of the x86-64 baseline, and `FMA` is only set in the kernels
        // reached through the feature-checked AVX2 + FMA entry points (`super::dispatch`).
        // `planes` is 6 rows of 4 contiguous floats (repr(C) arrays) and every offset is
        // `row · 4` with `row < 6` (`offsets_from_signs`, `plane_offsets`), so each unaligned
        // load reads 4 floats inside the node; the store writes exactly the 4 floats of `dist`.
        unsafe {
            let plane = |off: usize, a: usize, org: &[__m128; 3]| {
                let p = _mm_loadu_ps(base.add(off));
                if FMA {
                    _mm_fmsub_ps(p, r.rdir[a], org[a])
                } else {
                    _mm_sub_ps(_mm_mul_ps(p, r.rdir[a]), org[a])
                }
            };
            let (on, of) = (&r.org_near, &r.org_far);
            let t_near = _mm_max_ps(
                _mm_max_ps(plane(near[0], 0, on), plane(near[1], 1, on)),
                _mm_max_ps(plane(near[2], 2, on), _mm_set1_ps(tmin)),
            );
            let t_far = _mm_min_ps(
                _mm_min_ps(plane(far[0], 0, of), plane(far[1], 1, of)),
                _mm_min_ps(plane(far[2], 2, of), _mm_set1_ps(tmax)),
            );
            _mm_storeu_ps(dist.as_mut_ptr(), t_near);
            _mm_movemask_ps(_mm_cmple_ps(t_near, t_far)) as u32
        }
    }

    // ------------------------------------------------------------ AVX2 + FMA, 8 boxes at once

    /// 8 boxes at once in 256-bit registers, with FMA.
    impl ChildTest<8> for Avx8 {
        type Ray = SlabRayLanes<__m256>;

        #[inline(always)]
        fn prefetch(p: *const u8) {
            prefetch_lines(p, 4)
        }

        #[inline(always)]
        fn prepare_ray(ray: &Ray, extent: f32) -> SlabRayLanes<__m256> {
            let (rdir, on, of, neg) = slab_lanes(ray, extent);
            let (near, far) = offsets_from_signs(neg, 8);
            // SAFETY: only reached from the AVX2 + FMA entry points (`avx2_entry!`), which run
            // only on CPUs with both; the shuffles and broadcasts only move lanes.
            unsafe {
                let splat = |v: __m128| {
                    [
                        _mm256_broadcastss_ps(v),
                        _mm256_broadcastss_ps(_mm_shuffle_ps::<0x55>(v, v)),
                        _mm256_broadcastss_ps(_mm_shuffle_ps::<0xaa>(v, v)),
                    ]
                };
                SlabRayLanes {
                    rdir: splat(rdir),
                    org_near: splat(on),
                    org_far: splat(of),
                    near,
                    far,
                }
            }
        }

        #[inline(always)]
        fn prepare(r: &SlabRay) -> SlabRayLanes<__m256> {
            let (near, far) = plane_offsets(r, 8);
            let (d, on, of) = (r.rdir, r.org_rdir_near, r.org_rdir_far);
            // SAFETY: only reached from the AVX2 + FMA entry points (`avx2_entry!`), which run
            // only on CPUs with both; `set1` only broadcasts a value.
            unsafe {
                SlabRayLanes {
                    rdir: [
                        _mm256_set1_ps(d.x),
                        _mm256_set1_ps(d.y),
                        _mm256_set1_ps(d.z),
                    ],
                    org_near: [
                        _mm256_set1_ps(on.x),
                        _mm256_set1_ps(on.y),
                        _mm256_set1_ps(on.z),
                    ],
                    org_far: [
                        _mm256_set1_ps(of.x),
                        _mm256_set1_ps(of.y),
                        _mm256_set1_ps(of.z),
                    ],
                    near,
                    far,
                }
            }
        }

        const OCTANTS: bool = true;

        #[inline(always)]
        fn test(
            node: &WideNode<8>,
            r: &SlabRayLanes<__m256>,
            tmin: f32,
            tmax: f32,
            dist: &mut [f32; 8],
        ) -> u32 {
            slab8(node, r, r.near, r.far, tmin, tmax, dist)
        }

        /// One permutation of the eight child references by a table of the 256 masks, and
        /// one store: the loop of the default form took a data-dependent branch per child
        /// (about 17 instructions a child with its prefetch, 2.5 children a shadow ray on
        /// gears4). Any-hit traversal showed no change in speed without the prefetch.
        #[inline(always)]
        fn compress_children(
            node: &WideNode<8>,
            mask: u32,
            out: &mut [u32; 8],
            _prefetch: impl Fn(u32),
        ) -> usize {
            let m = (mask & 0xff) as usize;
            // SAFETY: AVX2 is present (only reached through the feature-checked entry points
            // of `avx2_entry!`). The loads read the 8 references of `child` and the 8 bytes of
            // one table row; the store writes exactly the 8 entries of `out`.
            unsafe {
                let children = _mm256_loadu_si256(node.child.as_ptr() as *const __m256i);
                let row = _mm_loadl_epi64(COMPRESS[m].as_ptr() as *const __m128i);
                let moved = _mm256_permutevar8x32_epi32(children, _mm256_cvtepu8_epi32(row));
                _mm256_storeu_si256(out.as_mut_ptr() as *mut __m256i, moved);
            }
            // A table, not `count_ones`: the entry points do not enable POPCNT.
            COUNT[m] as usize
        }

        #[inline(always)]
        fn test_octant<const NEG: u32>(
            node: &WideNode<8>,
            r: &SlabRayLanes<__m256>,
            tmin: f32,
            tmax: f32,
            dist: &mut [f32; 8],
        ) -> u32 {
            let (near, far) = offsets_from_signs(NEG & 7, 8);
            slab8(node, r, near, far, tmin, tmax, dist)
        }
    }

    /// For each 8-bit mask, the slots of its set bits in ascending order (then zeros): the
    /// lane indices that move those children to the front.
    static COMPRESS: [[u8; 8]; 256] = {
        let mut t = [[0u8; 8]; 256];
        let mut m = 0;
        while m < 256 {
            let (mut k, mut n) = (0, 0);
            while k < 8 {
                if m & (1 << k) != 0 {
                    t[m][n] = k as u8;
                    n += 1;
                }
                k += 1;
            }
            m += 1;
        }
        t
    };

    /// The set bits of each 8-bit mask.
    static COUNT: [u8; 256] = {
        let mut t = [0u8; 256];
        let mut m = 0;
        while m < 256 {
            t[m] = (m as u32).count_ones() as u8;
            m += 1;
        }
        t
    };

    /// The AVX2 slab test with the near and far plane rows at `near`, `far` (offsets in
    /// floats, each `row · 8` with `row < 6`: `offsets_from_signs`).
    #[inline(always)]
    fn slab8(
        node: &WideNode<8>,
        r: &SlabRayLanes<__m256>,
        near: [usize; 3],
        far: [usize; 3],
        tmin: f32,
        tmax: f32,
        dist: &mut [f32; 8],
    ) -> u32 {
        let base = node.planes.as_ptr() as *const f32;
        // SAFETY: AVX2 and FMA are present (only reached through the feature-checked entry
        // points of `avx2_entry!`). `planes` is 6 rows of 8 contiguous floats and every offset
        // is `row · 8` with `row < 6` (`offsets_from_signs`, `plane_offsets`), so each
        // unaligned load reads 8 floats inside the node; the store writes exactly the 8 floats
        // of `dist`.
        unsafe {
            // t = plane · rdir − org · rdir in one rounding (Embree's `madd` form).
            let plane = |off: usize, a: usize, org: &[__m256; 3]| {
                _mm256_fmsub_ps(_mm256_loadu_ps(base.add(off)), r.rdir[a], org[a])
            };
            let (on, of) = (&r.org_near, &r.org_far);
            let t_near = _mm256_max_ps(
                _mm256_max_ps(plane(near[0], 0, on), plane(near[1], 1, on)),
                _mm256_max_ps(plane(near[2], 2, on), _mm256_set1_ps(tmin)),
            );
            let t_far = _mm256_min_ps(
                _mm256_min_ps(plane(far[0], 0, of), plane(far[1], 1, of)),
                _mm256_min_ps(plane(far[2], 2, of), _mm256_set1_ps(tmax)),
            );
            _mm256_storeu_ps(dist.as_mut_ptr(), t_near);
            _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) as u32
        }
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::super::node::{WideNode, PLANES};
    use super::ChildTest;
    use crate::geometry::lanes::{Avx8, Scalar};

    /// For every mask, the AVX2 form's table moves the same children, in the same order, as
    /// the default form's loop pushes.
    #[test]
    fn avx2_compression_matches_the_loop() {
        if !Avx8::available() {
            return;
        }
        let node = WideNode::<8> {
            planes: [[0.0; 8]; PLANES],
            child: [10, 11, 12, 13, 14, 15, 16, 17],
            len: 8,
        };
        for mask in 0..256u32 {
            let mut want = [u32::MAX; 8];
            let n = <Scalar as ChildTest<8>>::compress_children(&node, mask, &mut want, |_| {});
            assert_eq!(n, mask.count_ones() as usize);
            let mut got = [u32::MAX; 8];
            let m = <Avx8 as ChildTest<8>>::compress_children(&node, mask, &mut got, |_| {});
            assert_eq!((m, &got[..m]), (n, &want[..n]), "mask {mask:#04x}");
        }
    }
}
