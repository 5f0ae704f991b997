//! One ray against a packet of 4 or 8 triangles at once: the shared triangle kernels of
//! `kernels.rs` (watertight, Woop, Benthin and Wald 2013; Möller–Trumbore 1997) written over
//! SIMD lanes, one triangle per lane, as Embree's `TriangleM` leaves are tested (4 triangles
//! per SSE instruction, 8 per AVX instruction).
//!
//! Triangles are stored structure-of-arrays ([`TrianglePacket`]): one load gives a coordinate of
//! one vertex of every triangle of the packet. Unused lanes hold NaN vertices, which no form of
//! either test ever hits (every comparison that accepts a hit is false on NaN).
//!
//! Every form gives exactly the answers of the scalar kernels, lane by lane: the same
//! operations in the same order with no fused multiply-add, the watertight test's fallback to
//! double precision on an edge included. So the watertight packet test keeps its promise (no
//! gaps, no double hits on shared edges), and engines may mix packet and scalar tests freely.
//!
//! Three forms of [`PacketKernel`], one per lane type of [`super::lanes`] (the vocabulary the
//! BVH's box test uses too): [`Scalar`] (any width, lane by lane through the scalar kernels;
//! the fallback), [`Sse4`] (4 lanes, SSE2, part of the x86-64 baseline) and [`Avx8`] (8 lanes,
//! AVX2; callers must check the CPU, see [`Avx8::available`]). [`closest4`] and [`closest8`]
//! choose at run time with `is_x86_feature_detected!`.

use super::kernels::f32::{self as k, WatertightRay};
#[cfg(target_arch = "x86_64")]
use super::lanes::Sse4;
use super::lanes::{Avx8, Scalar};
use crate::geometry::TriangleTest;
use crate::ray::Ray;
use glam::Vec3;

/// K triangles, structure-of-arrays: `v[i][a][lane]` is coordinate `a` (x, y, z) of vertex `i`
/// of the triangle in `lane`. Unused lanes are NaN.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct TrianglePacket<const K: usize> {
    pub v: [[[f32; K]; 3]; 3],
}

impl<const K: usize> TrianglePacket<K> {
    /// A packet of up to K triangles; lanes beyond `tris.len()` are padding that never hits.
    pub fn new(tris: &[[Vec3; 3]]) -> Self {
        assert!(
            tris.len() <= K,
            "{} triangles in a packet of {K}",
            tris.len()
        );
        let mut v = [[[f32::NAN; K]; 3]; 3];
        for (lane, tri) in tris.iter().enumerate() {
            for (i, vertex) in tri.iter().enumerate() {
                for a in 0..3 {
                    v[i][a][lane] = vertex[a];
                }
            }
        }
        TrianglePacket { v }
    }

    /// The triangle in `lane` (NaN vertices for padding).
    pub fn triangle(&self, lane: usize) -> [Vec3; 3] {
        let p = &self.v;
        [0, 1, 2].map(|i| Vec3::new(p[i][0][lane], p[i][1][lane], p[i][2][lane]))
    }
}

/// What a packet test found, lane by lane: `t`, `u`, `v` as the scalar kernels return them,
/// meaningful in the lanes of the returned mask.
#[derive(Clone, Copy, Debug)]
pub struct LaneHits<const K: usize> {
    pub t: [f32; K],
    pub u: [f32; K],
    pub v: [f32; K],
}

impl<const K: usize> Default for LaneHits<K> {
    fn default() -> Self {
        LaneHits {
            t: [0.0; K],
            u: [0.0; K],
            v: [0.0; K],
        }
    }
}

impl<const K: usize> LaneHits<K> {
    /// The lane of `mask` (non-zero) with the smallest `t`, the lowest such lane on a tie: what
    /// testing the lanes one after the other, shrinking `tmax` at each hit, would keep.
    #[inline(always)]
    pub fn nearest(&self, mut mask: u32) -> usize {
        let mut best = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        while mask != 0 {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            if self.t[i] < self.t[best] {
                best = i;
            }
        }
        best
    }
}

/// One form of the packet test.
pub trait PacketKernel<const K: usize> {
    /// The ray as this form wants it (splatted into SIMD registers for the SIMD forms), made
    /// once per ray. `wt` is the ray's watertight set-up (any value for Möller).
    type Ray: Copy;
    fn prepare(origin: Vec3, dir: Vec3, wt: &WatertightRay) -> Self::Ray;
    /// [`Self::prepare`] of the ray with its watertight set-up, and that set-up (for scalar
    /// primitives), from the ray as it lies in memory. `setup` makes the set-up the scalar way
    /// (what the default does); the AVX2 form makes both in SSE lanes instead, bit for bit the
    /// same values (~70 instructions a ray through the stack before).
    #[inline(always)]
    fn prepare_watertight(
        ray: &Ray,
        setup: impl FnOnce(Vec3) -> WatertightRay,
    ) -> (Self::Ray, WatertightRay) {
        let wt = setup(ray.dir);
        (Self::prepare(ray.origin, ray.dir, &wt), wt)
    }
    /// Bit `lane` set when that triangle is hit in `(tmin, tmax)`; `hits` then holds its
    /// `(t, u, v)`. `W`: the watertight test, else Möller–Trumbore.
    fn test<const W: bool>(
        p: &TrianglePacket<K>,
        r: &Self::Ray,
        tmin: f32,
        tmax: f32,
        hits: &mut LaneHits<K>,
    ) -> u32;
}

/// Two packets of 4 tested at once against the same segment: the AVX2
/// form puts packet `a` in the low 4 lanes and `b` in the high 4 of one 8-lane test, so a leaf
/// of 5–8 triangles costs one test's arithmetic instead of two. Lane by lane the same
/// operations as [`PacketKernel::test`], so each lane's hit and `(t, u, v)` are the same bits.
/// The other forms test the two one after the other (the default).
pub trait PairKernel: PacketKernel<4> {
    /// Bit `lane` set when triangle `lane` of `a` is hit in `(tmin, tmax)`, bit `4 + lane`
    /// for `b`; `hits` then holds its `(t, u, v)` in that lane.
    #[inline(always)]
    fn test_pair<const W: bool>(
        a: &TrianglePacket<4>,
        b: &TrianglePacket<4>,
        r: &Self::Ray,
        tmin: f32,
        tmax: f32,
        hits: &mut LaneHits<8>,
    ) -> u32 {
        let mut h = LaneHits::<4>::default();
        let mut mask = 0;
        for (half, p) in [a, b].into_iter().enumerate() {
            let m = Self::test::<W>(p, r, tmin, tmax, &mut h);
            if m != 0 {
                let at = 4 * half;
                hits.t[at..at + 4].copy_from_slice(&h.t);
                hits.u[at..at + 4].copy_from_slice(&h.u);
                hits.v[at..at + 4].copy_from_slice(&h.v);
            }
            mask |= m << (4 * half);
        }
        mask
    }
}

impl PairKernel for Scalar {}

/// The ray as the scalar form wants it (lane by lane through the scalar kernels; any width; the
/// fallback and the reference).
#[derive(Clone, Copy)]
pub struct ScalarTriangleRay {
    origin: Vec3,
    dir: Vec3,
    wt: WatertightRay,
}

impl<const K: usize> PacketKernel<K> for Scalar {
    type Ray = ScalarTriangleRay;

    #[inline(always)]
    fn prepare(origin: Vec3, dir: Vec3, wt: &WatertightRay) -> ScalarTriangleRay {
        ScalarTriangleRay {
            origin,
            dir,
            wt: *wt,
        }
    }

    #[inline(always)]
    fn test<const W: bool>(
        p: &TrianglePacket<K>,
        r: &ScalarTriangleRay,
        tmin: f32,
        tmax: f32,
        hits: &mut LaneHits<K>,
    ) -> u32 {
        let mut mask = 0;
        for lane in 0..K {
            // Padding lanes (NaN vertices) never hit, nor would a triangle with a NaN vertex:
            // skipped, since testing them lane by lane costs as much as a triangle.
            if p.v[0][0][lane].is_nan() {
                continue;
            }
            let [a, b, c] = p.triangle(lane);
            let hit = if W {
                k::triangle_watertight(r.origin, &r.wt, tmin, tmax, a, b, c)
            } else {
                k::triangle_moller(r.origin, r.dir, tmin, tmax, a, b, c)
            };
            if let Some((t, u, v)) = hit {
                mask |= 1 << lane;
                hits.t[lane] = t;
                hits.u[lane] = u;
                hits.v[lane] = v;
            }
        }
        mask
    }
}

/// Nearest hit of a ray among the triangles of a packet of 4: (lane, t, u, v). SSE on x86-64,
/// the scalar kernels elsewhere.
pub fn closest4(
    p: &TrianglePacket<4>,
    origin: Vec3,
    dir: Vec3,
    test: TriangleTest,
    tmin: f32,
    tmax: f32,
) -> Option<(usize, f32, f32, f32)> {
    #[cfg(target_arch = "x86_64")]
    {
        closest_with::<4, Sse4>(p, origin, dir, test, tmin, tmax)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        closest_with::<4, Scalar>(p, origin, dir, test, tmin, tmax)
    }
}

/// Nearest hit of a ray among the triangles of a packet of 8: (lane, t, u, v). AVX2 when the
/// CPU has it (checked at run time), the scalar kernels otherwise.
pub fn closest8(
    p: &TrianglePacket<8>,
    origin: Vec3,
    dir: Vec3,
    test: TriangleTest,
    tmin: f32,
    tmax: f32,
) -> Option<(usize, f32, f32, f32)> {
    #[cfg(target_arch = "x86_64")]
    if Avx8::available() {
        // SAFETY: the CPU has AVX2 and FMA (checked just above), all the callee requires.
        return unsafe { x86::closest8_avx2(p, origin, dir, test, tmin, tmax) };
    }
    closest_with::<8, Scalar>(p, origin, dir, test, tmin, tmax)
}

/// Nearest hit among a packet's triangles with the form `P`.
#[inline(always)]
pub fn closest_with<const K: usize, P: PacketKernel<K>>(
    p: &TrianglePacket<K>,
    origin: Vec3,
    dir: Vec3,
    test: TriangleTest,
    tmin: f32,
    tmax: f32,
) -> Option<(usize, f32, f32, f32)> {
    let wt = WatertightRay::new(dir);
    let r = P::prepare(origin, dir, &wt);
    let mut hits = LaneHits::default();
    let mask = match test {
        TriangleTest::Watertight => P::test::<true>(p, &r, tmin, tmax, &mut hits),
        TriangleTest::Moller => P::test::<false>(p, &r, tmin, tmax, &mut hits),
    };
    (mask != 0).then(|| {
        let i = hits.nearest(mask);
        (i, hits.t[i], hits.u[i], hits.v[i])
    })
}

/// Rays in lanes against one triangle (the packet traversal's leaves, `bvh/packet.rs`).
#[cfg(target_arch = "x86_64")]
pub use x86::{rays_against_triangle, TriangleRayLanes};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{LaneHits, PacketKernel, PairKernel, TrianglePacket};
    use crate::geometry::kernels::f32::WatertightRay;
    use crate::geometry::lanes::{Avx8, Sse4};
    use crate::geometry::TriangleTest;
    use crate::ray::Ray;
    use glam::Vec3;
    use std::arch::x86_64::*;

    /// The lane operations the kernels use, for 4 lanes (`__m128`) and 8 (`__m256`), so each
    /// kernel is written once. Plain IEEE operations only (no FMA, no approximate reciprocal):
    /// each lane rounds exactly as the scalar kernel does.
    ///
    /// Safety: the methods use SSE2 (x86-64 baseline) or AVX; the `__m256` ones may only run
    /// on a CPU with AVX, which the `Avx8` form's callers guarantee.
    trait Lanes: Copy {
        const K: usize;
        unsafe fn splat(x: f32) -> Self;
        /// Loads `K` floats from `p`.
        unsafe fn load(p: *const f32) -> Self;
        /// Stores `K` floats to `p`.
        unsafe fn store(self, p: *mut f32);
        unsafe fn add(self, o: Self) -> Self;
        unsafe fn sub(self, o: Self) -> Self;
        unsafe fn mul(self, o: Self) -> Self;
        unsafe fn div(self, o: Self) -> Self;
        unsafe fn and(self, o: Self) -> Self;
        unsafe fn or(self, o: Self) -> Self;
        /// `!self & o`.
        unsafe fn andnot(self, o: Self) -> Self;
        // Comparisons: ordered (false on NaN) except `ne`, `nlt`, `ngt` (true on NaN), as
        // the scalar `!=`, `!(a < b)`, `!(a > b)`.
        unsafe fn eq(self, o: Self) -> Self;
        unsafe fn ne(self, o: Self) -> Self;
        unsafe fn lt(self, o: Self) -> Self;
        unsafe fn gt(self, o: Self) -> Self;
        unsafe fn le(self, o: Self) -> Self;
        unsafe fn ge(self, o: Self) -> Self;
        unsafe fn nlt(self, o: Self) -> Self;
        unsafe fn ngt(self, o: Self) -> Self;
        unsafe fn mask(self) -> u32;
    }

    impl Lanes for __m128 {
        const K: usize = 4;
        #[inline(always)]
        unsafe fn splat(x: f32) -> Self {
            _mm_set1_ps(x)
        }
        #[inline(always)]
        unsafe fn load(p: *const f32) -> Self {
            _mm_loadu_ps(p)
        }
        #[inline(always)]
        unsafe fn store(self, p: *mut f32) {
            _mm_storeu_ps(p, self)
        }
        #[inline(always)]
        unsafe fn add(self, o: Self) -> Self {
            _mm_add_ps(self, o)
        }
        #[inline(always)]
        unsafe fn sub(self, o: Self) -> Self {
            _mm_sub_ps(self, o)
        }
        #[inline(always)]
        unsafe fn mul(self, o: Self) -> Self {
            _mm_mul_ps(self, o)
        }
        #[inline(always)]
        unsafe fn div(self, o: Self) -> Self {
            _mm_div_ps(self, o)
        }
        #[inline(always)]
        unsafe fn and(self, o: Self) -> Self {
            _mm_and_ps(self, o)
        }
        #[inline(always)]
        unsafe fn or(self, o: Self) -> Self {
            _mm_or_ps(self, o)
        }
        #[inline(always)]
        unsafe fn andnot(self, o: Self) -> Self {
            _mm_andnot_ps(self, o)
        }
        #[inline(always)]
        unsafe fn eq(self, o: Self) -> Self {
            _mm_cmpeq_ps(self, o)
        }
        #[inline(always)]
        unsafe fn ne(self, o: Self) -> Self {
            _mm_cmpneq_ps(self, o)
        }
        #[inline(always)]
        unsafe fn lt(self, o: Self) -> Self {
            _mm_cmplt_ps(self, o)
        }
        #[inline(always)]
        unsafe fn gt(self, o: Self) -> Self {
            _mm_cmpgt_ps(self, o)
        }
        #[inline(always)]
        unsafe fn le(self, o: Self) -> Self {
            _mm_cmple_ps(self, o)
        }
        #[inline(always)]
        unsafe fn ge(self, o: Self) -> Self {
            _mm_cmpge_ps(self, o)
        }
        #[inline(always)]
        unsafe fn nlt(self, o: Self) -> Self {
            _mm_cmpnlt_ps(self, o)
        }
        #[inline(always)]
        unsafe fn ngt(self, o: Self) -> Self {
            _mm_cmpngt_ps(self, o)
        }
        #[inline(always)]
        unsafe fn mask(self) -> u32 {
            _mm_movemask_ps(self) as u32
        }
    }

    impl Lanes for __m256 {
        const K: usize = 8;
        #[inline(always)]
        unsafe fn splat(x: f32) -> Self {
            _mm256_set1_ps(x)
        }
        #[inline(always)]
        unsafe fn load(p: *const f32) -> Self {
            _mm256_loadu_ps(p)
        }
        #[inline(always)]
        unsafe fn store(self, p: *mut f32) {
            _mm256_storeu_ps(p, self)
        }
        #[inline(always)]
        unsafe fn add(self, o: Self) -> Self {
            _mm256_add_ps(self, o)
        }
        #[inline(always)]
        unsafe fn sub(self, o: Self) -> Self {
            _mm256_sub_ps(self, o)
        }
        #[inline(always)]
        unsafe fn mul(self, o: Self) -> Self {
            _mm256_mul_ps(self, o)
        }
        #[inline(always)]
        unsafe fn div(self, o: Self) -> Self {
            _mm256_div_ps(self, o)
        }
        #[inline(always)]
        unsafe fn and(self, o: Self) -> Self {
            _mm256_and_ps(self, o)
        }
        #[inline(always)]
        unsafe fn or(self, o: Self) -> Self {
            _mm256_or_ps(self, o)
        }
        #[inline(always)]
        unsafe fn andnot(self, o: Self) -> Self {
            _mm256_andnot_ps(self, o)
        }
        #[inline(always)]
        unsafe fn eq(self, o: Self) -> Self {
            _mm256_cmp_ps::<_CMP_EQ_OQ>(self, o)
        }
        #[inline(always)]
        unsafe fn ne(self, o: Self) -> Self {
            _mm256_cmp_ps::<_CMP_NEQ_UQ>(self, o)
        }
        #[inline(always)]
        unsafe fn lt(self, o: Self) -> Self {
            _mm256_cmp_ps::<_CMP_LT_OQ>(self, o)
        }
        #[inline(always)]
        unsafe fn gt(self, o: Self) -> Self {
            _mm256_cmp_ps::<_CMP_GT_OQ>(self, o)
        }
        #[inline(always)]
        unsafe fn le(self, o: Self) -> Self {
            _mm256_cmp_ps::<_CMP_LE_OQ>(self, o)
        }
        #[inline(always)]
        unsafe fn ge(self, o: Self) -> Self {
            _mm256_cmp_ps::<_CMP_GE_OQ>(self, o)
        }
        #[inline(always)]
        unsafe fn nlt(self, o: Self) -> Self {
            _mm256_cmp_ps::<_CMP_NLT_UQ>(self, o)
        }
        #[inline(always)]
        unsafe fn ngt(self, o: Self) -> Self {
            _mm256_cmp_ps::<_CMP_NGT_UQ>(self, o)
        }
        #[inline(always)]
        unsafe fn mask(self) -> u32 {
            _mm256_movemask_ps(self) as u32
        }
    }

    /// The segment `(tmin, tmax)` of each lane, made only when a lane passes the edge tests:
    /// one ray's bounds splatted (`Splat`; splatting them before the call cost the
    /// single-ray kernels 1.4 % more instructions on gears4), or each lane's own (a pair of
    /// lane vectors: rays in the lanes).
    trait Segment<L> {
        /// # Safety
        /// The lanes' instruction set present.
        unsafe fn bounds(self) -> (L, L);
    }

    /// One ray's `(tmin, tmax)`, splatted into every lane.
    struct Splat(f32, f32);

    impl<L: Lanes> Segment<L> for Splat {
        #[inline(always)]
        unsafe fn bounds(self) -> (L, L) {
            (L::splat(self.0), L::splat(self.1))
        }
    }

    impl<L: Lanes> Segment<L> for (L, L) {
        #[inline(always)]
        unsafe fn bounds(self) -> (L, L) {
            self
        }
    }

    /// A ray splatted into lanes: origin, direction, and the watertight shear with its axes.
    #[derive(Clone, Copy)]
    pub struct TriangleRayLanes<L> {
        o: [L; 3],
        d: [L; 3],
        /// sx, sy, sz of the watertight set-up.
        s: [L; 3],
        /// The origin on the set-up's axes: o[kx], o[ky], o[kz] (so the per-packet code
        /// indexes no array by a run-time axis, which kept the ray in memory).
        ok: [L; 3],
        /// kx, ky, kz of the watertight set-up, each < 3.
        k: [usize; 3],
    }

    #[inline(always)]
    unsafe fn prepare<L: Lanes>(o: Vec3, d: Vec3, wt: &WatertightRay) -> TriangleRayLanes<L> {
        // Clamped so that a hand-made `WatertightRay` cannot make a row load leave the packet.
        let k = [wt.kx.min(2), wt.ky.min(2), wt.kz.min(2)];
        let oa = o.to_array();
        // Written out (no `map`: its closure was not inlined into the AVX2 kernels).
        TriangleRayLanes {
            o: [L::splat(o.x), L::splat(o.y), L::splat(o.z)],
            d: [L::splat(d.x), L::splat(d.y), L::splat(d.z)],
            s: [L::splat(wt.sx), L::splat(wt.sy), L::splat(wt.sz)],
            ok: [L::splat(oa[k[0]]), L::splat(oa[k[1]]), L::splat(oa[k[2]])],
            k,
        }
    }

    /// The row of [`AXES`] and [`PERM`], `2 kz + (d[kz] < 0)`, by a key of six bits: bits
    /// 0–2 (a.x > a.y, a.y > a.z, a.z ≥ a.x) of the direction's magnitudes `a`, bits 3–5 the
    /// signs `d < 0`. `kz` is `WatertightRay::new`'s choice: `a.x > a.y ? (a.x > a.z ? 0 : 2)
    /// : (a.y > a.z ? 1 : 2)`, with `a.x > a.z` the negation of bit 2.
    const ROW: [u8; 64] = {
        let mut t = [0u8; 64];
        let mut key = 0;
        while key < 64 {
            let (x_y, y_z, x_z) = (key & 1 != 0, key & 2 != 0, key & 4 == 0);
            let kz = if x_y {
                if x_z {
                    0
                } else {
                    2
                }
            } else if y_z {
                1
            } else {
                2
            };
            t[key] = (2 * kz + ((key >> (3 + kz)) & 1)) as u8;
            key += 1;
        }
        t
    };
    /// (kx, ky) by `2 kz + (d[kz] < 0)` (swapped when negative), as `WatertightRay::new`;
    /// rows 6 and 7 only pad the table to a power of two. Every entry is < 3.
    const AXES: [[usize; 2]; 8] = [
        [1, 2],
        [2, 1],
        [2, 0],
        [0, 2],
        [0, 1],
        [1, 0],
        [0, 1],
        [0, 1],
    ];
    /// The lanes (kx, ky, kz, kz) of the same rows, for `vpermilps`.
    const PERM: [[i32; 4]; 8] = [
        [1, 2, 0, 0],
        [2, 1, 0, 0],
        [2, 0, 1, 1],
        [0, 2, 1, 1],
        [0, 1, 2, 2],
        [1, 0, 2, 2],
        [0, 1, 2, 2],
        [0, 1, 2, 2],
    ];

    /// `WatertightRay::new(dir)` and the ray's lanes (`prepare`) in SSE registers: the axis choice from two comparisons of the magnitudes, the direction and
    /// origin put on the set-up's axes by one `vpermilps` each, and `(d[kx], d[ky], 1) / d[kz]`
    /// as one division. Each lane runs the scalar code's IEEE operation (a division stays a
    /// division), so the values are the same bits (test `watertight_lanes_as_the_kernels`).
    ///
    /// Safety: AVX (and so SSE4.1) present.
    #[inline(always)]
    unsafe fn watertight_lanes(ray: &Ray) -> (TriangleRayLanes<__m256>, WatertightRay) {
        // `Ray` is `repr(C)` (origin, tmin, dir, tmax): each load reads 4 floats of the ray.
        let p = ray as *const Ray as *const f32;
        let o = _mm_loadu_ps(p);
        let d = _mm_loadu_ps(p.add(4));
        let a = _mm_andnot_ps(_mm_set1_ps(-0.0), d);
        // a against (a.y, a.z, a.x): lanes 0, 1 by `>`, lane 2 by `≥` (the key of `ROW`).
        let next = _mm_shuffle_ps::<0b00_00_10_01>(a, a);
        let axes = _mm_blend_ps::<0b0100>(_mm_cmpgt_ps(a, next), _mm_cmpge_ps(a, next));
        let neg = _mm_movemask_ps(_mm_cmplt_ps(d, _mm_setzero_ps())) & 7;
        let key = (_mm_movemask_ps(axes) & 7) | (neg << 3);
        let row = ROW[key as usize] as usize & 7;
        let kz = row >> 1;
        let [kx, ky] = AXES[row];
        let perm = _mm_loadu_si128(PERM[row].as_ptr() as *const __m128i);
        let dk = _mm_permutevar_ps(d, perm);
        let ok = _mm_permutevar_ps(o, perm);
        // (d[kx], d[ky], 1, d[kz]) / d[kz]: sx, sy, sz.
        let s = _mm_div_ps(
            _mm_blend_ps::<0b0100>(dk, _mm_set1_ps(1.0)),
            _mm_permute_ps::<0b10_10_10_10>(dk),
        );
        let wt = WatertightRay {
            kx,
            ky,
            kz,
            sx: _mm_cvtss_f32(s),
            sy: _mm_cvtss_f32(_mm_movehdup_ps(s)),
            sz: _mm_cvtss_f32(_mm_movehl_ps(s, s)),
        };
        let splat = |v: __m128| {
            [
                _mm256_broadcastss_ps(v),
                _mm256_broadcastss_ps(_mm_movehdup_ps(v)),
                _mm256_broadcastss_ps(_mm_movehl_ps(v, v)),
            ]
        };
        let lanes = TriangleRayLanes {
            o: splat(o),
            d: splat(d),
            s: splat(s),
            ok: splat(ok),
            k: [kx, ky, kz],
        };
        (lanes, wt)
    }

    /// Row `a` (an axis, < 3) of vertex `i` (< 3) of a packet of `L::K` lanes.
    ///
    /// Safety: `i < 3`, `a < 3`, `K == L::K`, and the lanes' instruction set present.
    #[inline(always)]
    unsafe fn row<L: Lanes, const K: usize>(p: &TrianglePacket<K>, i: usize, a: usize) -> L {
        debug_assert!(K == L::K && i < 3 && a < 3);
        // Unchecked: `a` is an axis of the ray's set-up, not a constant, and the bounds checks
        // cost 6 instructions a packet.
        L::load((p.v.as_ptr() as *const f32).add((3 * i + a) * K))
    }

    /// The watertight test (`kernels.rs`, `triangle_watertight`) on every lane; `row(i, a)`
    /// loads coordinate `a` of vertex `i` of every lane (one packet, or two side by side, or
    /// one triangle splatted for rays in the lanes), `tmin`, `tmax` each lane's segment.
    #[inline(always)]
    unsafe fn watertight<L: Lanes, const K: usize>(
        row: impl Fn(usize, usize) -> L,
        r: &TriangleRayLanes<L>,
        segment: impl Segment<L>,
        hits: &mut LaneHits<K>,
    ) -> u32 {
        // The vertices relative to the origin, on the three axes of the ray's set-up.
        let rel = |i: usize, j: usize| row(i, r.k[j]).sub(r.ok[j]);
        let (a_x, a_y, a_z) = (rel(0, 0), rel(0, 1), rel(0, 2));
        let (b_x, b_y, b_z) = (rel(1, 0), rel(1, 1), rel(1, 2));
        let (c_x, c_y, c_z) = (rel(2, 0), rel(2, 1), rel(2, 2));
        let (sx, sy, sz) = (r.s[0], r.s[1], r.s[2]);
        let ax = a_x.sub(sx.mul(a_z));
        let ay = a_y.sub(sy.mul(a_z));
        let bx = b_x.sub(sx.mul(b_z));
        let by = b_y.sub(sy.mul(b_z));
        let cx = c_x.sub(sx.mul(c_z));
        let cy = c_y.sub(sy.mul(c_z));
        let mut u = cx.mul(by).sub(cy.mul(bx));
        let mut v = ax.mul(cy).sub(ay.mul(cx));
        let mut w = bx.mul(ay).sub(by.mul(ax));
        let zero = L::splat(0.0);
        let on_edge = u.eq(zero).or(v.eq(zero)).or(w.eq(zero)).mask();
        if on_edge != 0 {
            (u, v, w) = edge_in_f64::<L, K>(on_edge, [ax, ay, bx, by, cx, cy], [u, v, w]);
        }
        let neg = u.lt(zero).or(v.lt(zero)).or(w.lt(zero));
        let pos = u.gt(zero).or(v.gt(zero)).or(w.gt(zero));
        let det = u.add(v).add(w);
        let ok = neg.and(pos).andnot(det.ne(zero));
        // Most rays miss every triangle of a packet: stop before the division (Embree's
        // kernels do the same).
        if ok.mask() == 0 {
            return 0;
        }
        let (tmin, tmax) = segment.bounds();
        let az = sz.mul(a_z);
        let bz = sz.mul(b_z);
        let cz = sz.mul(c_z);
        let inv = L::splat(1.0).div(det);
        let t = u.mul(az).add(v.mul(bz)).add(w.mul(cz)).mul(inv);
        let hit = ok.and(t.gt(tmin)).and(t.lt(tmax)).mask();
        if hit != 0 {
            t.store(hits.t.as_mut_ptr());
            v.mul(inv).store(hits.u.as_mut_ptr());
            w.mul(inv).store(hits.v.as_mut_ptr());
        }
        hit
    }

    /// The scalar kernel's fallback for rays through an edge or vertex: u, v, w recomputed in
    /// double precision, in the lanes where one of them is zero.
    #[cold]
    #[inline(never)]
    unsafe fn edge_in_f64<L: Lanes, const K: usize>(
        lanes: u32,
        e: [L; 6],
        uvw: [L; 3],
    ) -> (L, L, L) {
        let mut f = [[0.0f32; K]; 6];
        for (row, x) in f.iter_mut().zip(e) {
            x.store(row.as_mut_ptr());
        }
        let mut out = [[0.0f32; K]; 3];
        for (row, x) in out.iter_mut().zip(uvw) {
            x.store(row.as_mut_ptr());
        }
        for lane in (0..K).filter(|&l| lanes & (1 << l) != 0) {
            let [ax, ay, bx, by, cx, cy] = f.map(|row| row[lane] as f64);
            out[0][lane] = (cx * by - cy * bx) as f32;
            out[1][lane] = (ax * cy - ay * cx) as f32;
            out[2][lane] = (bx * ay - by * ax) as f32;
        }
        (
            L::load(out[0].as_ptr()),
            L::load(out[1].as_ptr()),
            L::load(out[2].as_ptr()),
        )
    }

    /// Möller–Trumbore (`kernels.rs`, `triangle_moller`) on every lane, with glam's operation
    /// order for cross and dot products.
    #[inline(always)]
    unsafe fn moller<L: Lanes, const K: usize>(
        row: impl Fn(usize, usize) -> L,
        r: &TriangleRayLanes<L>,
        segment: impl Segment<L>,
        hits: &mut LaneHits<K>,
    ) -> u32 {
        let v0 = [0, 1, 2].map(|a| row(0, a));
        let e1 = [0, 1, 2].map(|a| row(1, a).sub(v0[a]));
        let e2 = [0, 1, 2].map(|a| row(2, a).sub(v0[a]));
        let cross = |a: [L; 3], b: [L; 3]| {
            [
                a[1].mul(b[2]).sub(b[1].mul(a[2])),
                a[2].mul(b[0]).sub(b[2].mul(a[0])),
                a[0].mul(b[1]).sub(b[0].mul(a[1])),
            ]
        };
        let dot = |a: [L; 3], b: [L; 3]| a[0].mul(b[0]).add(a[1].mul(b[1])).add(a[2].mul(b[2]));
        let d = r.d;
        let pv = cross(d, e2);
        let det = dot(e1, pv);
        let inv = L::splat(1.0).div(det);
        let s = [0, 1, 2].map(|a| r.o[a].sub(v0[a]));
        let u = dot(s, pv).mul(inv);
        let q = cross(s, e1);
        let v = dot(d, q).mul(inv);
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let inside = det
            .ne(zero)
            .and(u.ge(zero))
            .and(u.le(one))
            .and(v.nlt(zero))
            .and(u.add(v).ngt(one));
        // Most rays miss every triangle of a packet: stop before t.
        if inside.mask() == 0 {
            return 0;
        }
        let (tmin, tmax) = segment.bounds();
        let t = dot(e2, q).mul(inv);
        let hit = inside.and(t.gt(tmin)).and(t.lt(tmax)).mask();
        if hit != 0 {
            t.store(hits.t.as_mut_ptr());
            u.store(hits.u.as_mut_ptr());
            v.store(hits.v.as_mut_ptr());
        }
        hit
    }

    /// 4 triangles per instruction, SSE2 (x86-64 baseline: safe to use anywhere on x86-64).
    impl PacketKernel<4> for Sse4 {
        type Ray = TriangleRayLanes<__m128>;

        #[inline(always)]
        fn prepare(origin: Vec3, dir: Vec3, wt: &WatertightRay) -> Self::Ray {
            // SAFETY: SSE2 is part of the x86-64 baseline; `set1` only broadcasts.
            unsafe { prepare(origin, dir, wt) }
        }

        #[inline(always)]
        fn test<const W: bool>(
            p: &TrianglePacket<4>,
            r: &Self::Ray,
            tmin: f32,
            tmax: f32,
            hits: &mut LaneHits<4>,
        ) -> u32 {
            // SAFETY: SSE2 is part of the x86-64 baseline. Every load reads one row of 4
            // floats of `p.v` (`row`: vertex and axis < 3), every store writes one row of 4
            // floats of `hits` or of a local array of 4.
            unsafe {
                let row = |i, a| row::<_, 4>(p, i, a);
                if W {
                    watertight(row, r, Splat(tmin, tmax), hits)
                } else {
                    moller(row, r, Splat(tmin, tmax), hits)
                }
            }
        }
    }

    impl PairKernel for Sse4 {}

    /// Packets of 4 in AVX2 code: one packet in the low 4 lanes (the SSE form's arithmetic),
    /// two side by side in all 8 ([`PairKernel`]). Only for code that has checked
    /// [`Avx8::available`] (the BVH's AVX2 + FMA entry points).
    impl PacketKernel<4> for Avx8 {
        type Ray = TriangleRayLanes<__m256>;

        #[inline(always)]
        fn prepare(origin: Vec3, dir: Vec3, wt: &WatertightRay) -> Self::Ray {
            // SAFETY: only reached from code run after `Avx8::available()` (this form's
            // contract); `set1` only broadcasts.
            unsafe { prepare(origin, dir, wt) }
        }

        #[inline(always)]
        fn prepare_watertight(
            ray: &Ray,
            _: impl FnOnce(Vec3) -> WatertightRay,
        ) -> (Self::Ray, WatertightRay) {
            // SAFETY: only reached from code run after `Avx8::available()` (this form's
            // contract), all `watertight_lanes` needs.
            unsafe { watertight_lanes(ray) }
        }

        #[inline(always)]
        fn test<const W: bool>(
            p: &TrianglePacket<4>,
            r: &Self::Ray,
            tmin: f32,
            tmax: f32,
            hits: &mut LaneHits<4>,
        ) -> u32 {
            // SAFETY: AVX is present (this form's contract); the casts take the low 4 lanes
            // of each splat (no instruction). Every load reads one row of 4 floats of `p.v`,
            // every store writes one row of 4 floats of `hits` or of a local array of 4.
            unsafe {
                let low = |x: [__m256; 3]| {
                    [
                        _mm256_castps256_ps128(x[0]),
                        _mm256_castps256_ps128(x[1]),
                        _mm256_castps256_ps128(x[2]),
                    ]
                };
                let r4 = TriangleRayLanes::<__m128> {
                    o: low(r.o),
                    d: low(r.d),
                    s: low(r.s),
                    ok: low(r.ok),
                    k: r.k,
                };
                let row = |i, a| row::<__m128, 4>(p, i, a);
                if W {
                    watertight(row, &r4, Splat(tmin, tmax), hits)
                } else {
                    moller(row, &r4, Splat(tmin, tmax), hits)
                }
            }
        }
    }

    impl PairKernel for Avx8 {
        #[inline(always)]
        fn test_pair<const W: bool>(
            a: &TrianglePacket<4>,
            b: &TrianglePacket<4>,
            r: &Self::Ray,
            tmin: f32,
            tmax: f32,
            hits: &mut LaneHits<8>,
        ) -> u32 {
            // SAFETY: AVX is present (this form's contract). Each load reads one row of 4
            // floats of `a.v` (low lanes) and the same row of `b.v` (high lanes); every store
            // writes one row of 8 floats of `hits` or of a local array of 8.
            unsafe {
                let row = |i: usize, c: usize| {
                    debug_assert!(i < 3 && c < 3);
                    // Unchecked as in `row`: `c` is an axis of the set-up (< 3).
                    let at = (3 * i + c) * 4;
                    _mm256_loadu2_m128(
                        (b.v.as_ptr() as *const f32).add(at),
                        (a.v.as_ptr() as *const f32).add(at),
                    )
                };
                if W {
                    watertight(row, r, Splat(tmin, tmax), hits)
                } else {
                    moller(row, r, Splat(tmin, tmax), hits)
                }
            }
        }
    }

    /// 8 triangles per instruction, AVX. Only for code that has checked [`Avx8::available`]
    /// (the BVH's AVX2 + FMA entry points; [`super::closest8`]).
    impl PacketKernel<8> for Avx8 {
        type Ray = TriangleRayLanes<__m256>;

        #[inline(always)]
        fn prepare(origin: Vec3, dir: Vec3, wt: &WatertightRay) -> Self::Ray {
            // SAFETY: only reached from code run after `Avx8::available()` (this form's
            // contract); `set1` only broadcasts.
            unsafe { prepare(origin, dir, wt) }
        }

        #[inline(always)]
        fn prepare_watertight(
            ray: &Ray,
            _: impl FnOnce(Vec3) -> WatertightRay,
        ) -> (Self::Ray, WatertightRay) {
            // SAFETY: only reached from code run after `Avx8::available()` (this form's
            // contract), all `watertight_lanes` needs.
            unsafe { watertight_lanes(ray) }
        }

        #[inline(always)]
        fn test<const W: bool>(
            p: &TrianglePacket<8>,
            r: &Self::Ray,
            tmin: f32,
            tmax: f32,
            hits: &mut LaneHits<8>,
        ) -> u32 {
            // SAFETY: only reached from code run after `Avx8::available()` (this form's
            // contract). Every load reads one row of 8 floats of `p.v`, every store writes one
            // row of 8 floats of `hits` or of a local array of 8.
            unsafe {
                let row = |i, a| row::<_, 8>(p, i, a);
                if W {
                    watertight(row, r, Splat(tmin, tmax), hits)
                } else {
                    moller(row, r, Splat(tmin, tmax), hits)
                }
            }
        }
    }

    /// [`super::closest8`] compiled with AVX2 and FMA, so the AVX intrinsics inline.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma")]
    pub unsafe fn closest8_avx2(
        p: &TrianglePacket<8>,
        origin: Vec3,
        dir: Vec3,
        test: TriangleTest,
        tmin: f32,
        tmax: f32,
    ) -> Option<(usize, f32, f32, f32)> {
        super::closest_with::<8, Avx8>(p, origin, dir, test, tmin, tmax)
    }

    impl TriangleRayLanes<__m256> {
        /// Eight rays in the lanes (the packet traversal's leaves):
        /// origins `o`, directions `d` and each ray's watertight shear `s` (its own
        /// `WatertightRay`'s sx, sy, sz), all rays sharing the set-up's axes `k` (kx, ky, kz).
        pub fn rays(o: [__m256; 3], d: [__m256; 3], s: [__m256; 3], k: [usize; 3]) -> Self {
            // Clamped as in `prepare`: a row load never leaves the packet.
            let k = [k[0].min(2), k[1].min(2), k[2].min(2)];
            TriangleRayLanes {
                o,
                d,
                s,
                ok: [o[k[0]], o[k[1]], o[k[2]]],
                k,
            }
        }
    }

    /// Triangle `j` of a packet against the rays in the lanes of `r` ([`TriangleRayLanes::rays`]),
    /// each within its own `(tmin, tmax)`: one triangle and 8 rays per instruction, as
    /// Embree's `TriangleMIntersectorKMoeller` tests a leaf against a ray packet. The lanes run the same operations as [`PacketKernel::test`] (the triangle's
    /// coordinates splatted instead of the ray's), so each lane's mask bit and `(t, u, v)` are
    /// the bits the single-ray test gives that ray.
    ///
    /// # Safety
    /// The CPU must have AVX (the packet traversal's AVX2 + FMA entry points check it), and
    /// `j < 4`.
    #[inline(always)]
    pub unsafe fn rays_against_triangle<const W: bool>(
        p: &TrianglePacket<4>,
        j: usize,
        r: &TriangleRayLanes<__m256>,
        tmin: __m256,
        tmax: __m256,
        hits: &mut LaneHits<8>,
    ) -> u32 {
        debug_assert!(j < 4);
        // Row `(3 i + a)` of the packet holds coordinate `a` of vertex `i` of its 4 triangles;
        // `i`, `a` < 3 (`rays` clamps the axes), so every load is inside `p.v`.
        let base = (p.v.as_ptr() as *const f32).add(j.min(3));
        let row = |i: usize, a: usize| _mm256_broadcast_ss(&*base.add((3 * i + a) * 4));
        if W {
            watertight(row, r, (tmin, tmax), hits)
        } else {
            moller(row, r, (tmin, tmax), hits)
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        /// The AVX2 form's set-up in lanes gives the bits of `WatertightRay::new` and of
        /// `prepare` from it, on random directions and every combination of ±0, ±1e-20, ±0.5,
        /// ±1 components (ties of the axis choice, zero and negative-zero signs).
        #[test]
        fn watertight_lanes_as_the_kernels() {
            if !Avx8::available() {
                return;
            }
            let specials = [0.0, -0.0, 1e-20, -1e-20, 0.5, -0.5, 1.0, -1.0];
            let mut dirs = Vec::new();
            for &x in &specials {
                for &y in &specials {
                    for &z in &specials {
                        dirs.push(Vec3::new(x, y, z));
                    }
                }
            }
            let mut s = 99u64;
            for _ in 0..2000 {
                let mut c = [0.0f32; 3];
                for x in &mut c {
                    s = s
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    *x = (s >> 40) as f32 / (1u64 << 23) as f32 - 1.0;
                }
                dirs.push(Vec3::from_array(c));
            }
            let bits = |v: &[__m256; 3]| {
                v.map(|x| {
                    let mut a = [0.0f32; 8];
                    // SAFETY: AVX present (checked above); stores 8 floats into `a`.
                    unsafe { _mm256_storeu_ps(a.as_mut_ptr(), x) };
                    a.map(f32::to_bits)
                })
            };
            for (i, d) in dirs.into_iter().enumerate() {
                let o = Vec3::new(1.5, -2.25, 3.0 + i as f32);
                let ray = Ray::new(o, d, 0.0, f32::INFINITY);
                let want = WatertightRay::new(d);
                // SAFETY: AVX2 present (checked above).
                let (lanes, wt) = unsafe { watertight_lanes(&ray) };
                let want_lanes: TriangleRayLanes<__m256> =
                    <Avx8 as PacketKernel<8>>::prepare(o, d, &want);
                let w = |w: &WatertightRay| {
                    (
                        [w.kx, w.ky, w.kz],
                        [w.sx.to_bits(), w.sy.to_bits(), w.sz.to_bits()],
                    )
                };
                assert_eq!(w(&wt), w(&want), "{d:?}");
                assert_eq!(lanes.k, want_lanes.k, "{d:?}");
                for (a, b) in [
                    (&lanes.s, &want_lanes.s),
                    (&lanes.ok, &want_lanes.ok),
                    (&lanes.o, &want_lanes.o),
                    (&lanes.d, &want_lanes.d),
                ] {
                    assert_eq!(bits(a), bits(b), "{d:?}");
                }
            }
        }

        /// Rays in the lanes against one triangle (`rays_against_triangle`) give, lane by lane,
        /// the single-ray packet test's mask bit and (t, u, v) bits for that triangle, with
        /// each lane's own segment; rays grouped by their watertight axes, 8 to a test.
        #[test]
        fn rays_in_lanes_as_the_single_test() {
            if !Avx8::available() {
                return;
            }
            let (tris, rays) = super::super::tests::cases();
            let packets: Vec<TrianglePacket<4>> = tris.chunks(4).map(TrianglePacket::new).collect();
            let mut by_axes: std::collections::BTreeMap<[usize; 3], Vec<(Vec3, Vec3)>> =
                Default::default();
            for &(o, d) in &rays {
                let w = WatertightRay::new(d);
                by_axes.entry([w.kx, w.ky, w.kz]).or_default().push((o, d));
            }
            let mut hits = 0;
            for (k, group) in by_axes {
                for (n, eight) in group.chunks(8).enumerate() {
                    let lane = |f: &dyn Fn(usize) -> f32| {
                        let a: [f32; 8] = std::array::from_fn(|l| f(l.min(eight.len() - 1)));
                        // SAFETY: AVX present (checked above); loads the 8 floats of `a`.
                        unsafe { _mm256_loadu_ps(a.as_ptr()) }
                    };
                    let wts: Vec<WatertightRay> =
                        eight.iter().map(|&(_, d)| WatertightRay::new(d)).collect();
                    let o = [0, 1, 2].map(|a| lane(&|l| eight[l].0[a]));
                    let d = [0, 1, 2].map(|a| lane(&|l| eight[l].1[a]));
                    let s = [
                        lane(&|l| wts[l].sx),
                        lane(&|l| wts[l].sy),
                        lane(&|l| wts[l].sz),
                    ];
                    let r = TriangleRayLanes::rays(o, d, s, k);
                    // Every other lane's segment ends at 2 (alternating by chunk).
                    let tmax_of = |l: usize| {
                        if (l + n).is_multiple_of(2) {
                            f32::INFINITY
                        } else {
                            2.0
                        }
                    };
                    let tmin = lane(&|_| 0.0);
                    let tmax = lane(&|l| tmax_of(l));
                    for p in &packets {
                        for j in 0..4 {
                            let mut got = LaneHits::<8>::default();
                            // SAFETY: AVX present (checked above), j < 4.
                            let (mw, mm) = unsafe {
                                (
                                    rays_against_triangle::<true>(p, j, &r, tmin, tmax, &mut got),
                                    rays_against_triangle::<false>(
                                        p,
                                        j,
                                        &r,
                                        tmin,
                                        tmax,
                                        &mut LaneHits::default(),
                                    ),
                                )
                            };
                            for (l, &(o, d)) in eight.iter().enumerate() {
                                let one = <Sse4 as PacketKernel<4>>::prepare(o, d, &wts[l]);
                                let mut want = LaneHits::<4>::default();
                                let w = <Sse4 as PacketKernel<4>>::test::<true>(
                                    p,
                                    &one,
                                    0.0,
                                    tmax_of(l),
                                    &mut want,
                                );
                                let m = <Sse4 as PacketKernel<4>>::test::<false>(
                                    p,
                                    &one,
                                    0.0,
                                    tmax_of(l),
                                    &mut LaneHits::default(),
                                );
                                assert_eq!((mw >> l) & 1, (w >> j) & 1, "{o} {d} lane {l}");
                                assert_eq!((mm >> l) & 1, (m >> j) & 1, "Möller {o} {d}");
                                if (w >> j) & 1 != 0 {
                                    hits += 1;
                                    let b = |x: f32| x.to_bits();
                                    assert_eq!(
                                        (b(got.t[l]), b(got.u[l]), b(got.v[l])),
                                        (b(want.t[j]), b(want.u[j]), b(want.v[j])),
                                        "{o} {d} lane {l}"
                                    );
                                }
                            }
                        }
                    }
                }
            }
            // 160 watertight hits of these rays (each ray's lane against each triangle).
            assert!(hits > 100, "only {hits} hits");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::TriangleTest;

    /// A small deterministic generator (64-bit LCG, top bits), in [-1, 1).
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 40) as f32 / (1u64 << 23) as f32 - 1.0
        }
        fn vec(&mut self) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next())
        }
    }

    /// The nearest hit by the scalar kernels, triangle after triangle.
    fn scalar_closest(
        tris: &[[Vec3; 3]],
        o: Vec3,
        d: Vec3,
        test: TriangleTest,
        tmin: f32,
        mut tmax: f32,
    ) -> Option<(usize, f32, f32, f32)> {
        let wt = WatertightRay::new(d);
        let mut best = None;
        for (i, &[a, b, c]) in tris.iter().enumerate() {
            let h = match test {
                TriangleTest::Watertight => k::triangle_watertight(o, &wt, tmin, tmax, a, b, c),
                TriangleTest::Moller => k::triangle_moller(o, d, tmin, tmax, a, b, c),
            };
            if let Some((t, u, v)) = h {
                tmax = t;
                best = Some((i, t, u, v));
            }
        }
        best
    }

    /// Triangles of a grid of quads in the plane z = 0 (two per quad, sharing a diagonal, and
    /// sharing edges with their neighbours), some random triangles, and rays of three kinds:
    /// through the grid's vertices and edges exactly (the watertight test's hard case),
    /// random, and parallel to the plane.
    pub(super) fn cases() -> (Vec<[Vec3; 3]>, Vec<(Vec3, Vec3)>) {
        let mut rng = Lcg(7);
        let mut tris = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                let p = |x: i32, y: i32| Vec3::new((i + x) as f32, (j + y) as f32, 0.0);
                tris.push([p(0, 0), p(1, 0), p(1, 1)]);
                tris.push([p(0, 0), p(1, 1), p(0, 1)]);
            }
        }
        for _ in 0..14 {
            let c = rng.vec() * 3.0 + Vec3::new(1.5, 1.5, 0.0);
            tris.push([c + rng.vec(), c + rng.vec(), c + rng.vec()]);
        }
        let mut rays = Vec::new();
        for j in 0..=6 {
            for i in 0..=6 {
                let target = Vec3::new(i as f32 * 0.5, j as f32 * 0.5, 0.0);
                for dir in [Vec3::Z, Vec3::new(0.1, 0.2, 1.0), -Vec3::Z] {
                    rays.push((target - dir * 2.0, dir));
                }
            }
        }
        for _ in 0..400 {
            let o = rng.vec() * 6.0 + Vec3::new(1.5, 1.5, 0.0);
            rays.push((o, rng.vec().normalize_or(Vec3::X)));
        }
        rays.push((Vec3::new(-1.0, 0.5, 0.0), Vec3::X));
        (tris, rays)
    }

    fn check<const K: usize>(
        form: &str,
        closest: impl Fn(
            &TrianglePacket<K>,
            Vec3,
            Vec3,
            TriangleTest,
            f32,
            f32,
        ) -> Option<(usize, f32, f32, f32)>,
    ) {
        let (tris, rays) = cases();
        let mut hits = 0;
        for test in [TriangleTest::Watertight, TriangleTest::Moller] {
            for chunk in tris.chunks(K) {
                let p = TrianglePacket::<K>::new(chunk);
                for &(o, d) in &rays {
                    for tmax in [f32::INFINITY, 2.0] {
                        let want = scalar_closest(chunk, o, d, test, 0.0, tmax);
                        let got = closest(&p, o, d, test, 0.0, tmax);
                        assert_eq!(got, want, "{form} {test:?}: ray {o} {d}, {chunk:?}");
                        let lanes = closest_with::<K, Scalar>(&p, o, d, test, 0.0, tmax);
                        assert_eq!(lanes, want, "scalar packets {test:?}: ray {o} {d}");
                        hits += want.is_some() as usize;
                    }
                }
            }
        }
        assert!(hits > 300, "{form}: only {hits} hits");
    }

    #[test]
    fn packets_give_the_scalar_kernels_answers() {
        check::<4>("closest4", closest4);
        check::<8>("closest8", closest8);
    }

    /// A pair test gives, lane by lane, the two packets' single tests (same mask bits, same
    /// t, u, v bits), on the AVX2 form (when the CPU has it) and the default form.
    #[test]
    fn pairs_give_the_single_tests_answers() {
        fn pairs<P: PairKernel>(prepare: impl Fn(Vec3, Vec3) -> P::Ray) -> usize {
            let (tris, rays) = cases();
            let packets: Vec<TrianglePacket<4>> = tris.chunks(4).map(TrianglePacket::new).collect();
            let mut hits = 0;
            for w in packets.windows(2) {
                for &(o, d) in &rays {
                    let r = prepare(o, d);
                    for tmax in [f32::INFINITY, 2.0] {
                        let mut pair = LaneHits::<8>::default();
                        let m = P::test_pair::<true>(&w[0], &w[1], &r, 0.0, tmax, &mut pair);
                        for (half, p) in w.iter().enumerate() {
                            let mut h = LaneHits::<4>::default();
                            let want = P::test::<true>(p, &r, 0.0, tmax, &mut h);
                            assert_eq!((m >> (4 * half)) & 0xf, want, "ray {o} {d}");
                            for lane in (0..4).filter(|l| want & (1 << l) != 0) {
                                let at = 4 * half + lane;
                                let bits = |t: f32, u: f32, v: f32| {
                                    [t.to_bits(), u.to_bits(), v.to_bits()]
                                };
                                assert_eq!(
                                    bits(pair.t[at], pair.u[at], pair.v[at]),
                                    bits(h.t[lane], h.u[lane], h.v[lane])
                                );
                                hits += 1;
                            }
                        }
                    }
                }
            }
            hits
        }
        let scalar = pairs::<Scalar>(|o, d| {
            <Scalar as PacketKernel<4>>::prepare(o, d, &WatertightRay::new(d))
        });
        assert!(scalar > 100, "only {scalar} hits");
        #[cfg(target_arch = "x86_64")]
        if Avx8::available() {
            #[target_feature(enable = "avx2,fma")]
            unsafe fn avx() -> usize {
                pairs::<Avx8>(|o, d| {
                    <Avx8 as PacketKernel<4>>::prepare(o, d, &WatertightRay::new(d))
                })
            }
            // SAFETY: the CPU has AVX2 and FMA (checked just above).
            assert_eq!(unsafe { avx() }, scalar);
        }
    }

    #[test]
    fn padding_never_hits() {
        let p = TrianglePacket::<4>::new(&[]);
        for d in [Vec3::Z, Vec3::X, Vec3::new(1.0, 2.0, 3.0)] {
            for test in [TriangleTest::Watertight, TriangleTest::Moller] {
                assert_eq!(closest4(&p, -d, d, test, 0.0, f32::INFINITY), None);
            }
        }
    }

    /// Rays through the shared edges and vertices of the quad grid hit the watertight packet
    /// test exactly once or (at an edge between two triangles of one packet) the nearer-first
    /// of the two, never nothing: every ray aimed at the grid's inside finds a triangle.
    #[test]
    fn watertight_packets_leave_no_gaps() {
        let (tris, _) = cases();
        let grid = &tris[..18];
        for j in 1..6 {
            for i in 1..6 {
                let target = Vec3::new(i as f32 * 0.5, j as f32 * 0.5, 0.0);
                let d = Vec3::new(0.1, 0.2, 1.0);
                let found = grid.chunks(4).any(|c| {
                    closest4(
                        &TrianglePacket::new(c),
                        target - d * 2.0,
                        d,
                        TriangleTest::Watertight,
                        0.0,
                        f32::INFINITY,
                    )
                    .is_some()
                });
                assert!(found, "gap at {target}");
            }
        }
    }
}
