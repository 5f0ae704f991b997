//! Packet traversal (`packet=8|16`): 8 or 16 coherent rays (eye rays of neighbouring pixels,
//! shadow rays of neighbouring points to one light) walk the wide tree together, as Embree's
//! `rtcIntersect8/16` packets do (Wald, Slusallek, Benthin and Wagner 2001, "Interactive
//! rendering with coherent ray tracing"; Embree's `BVHNIntersectorKHybrid`).
//!
//! It is built so that a packet costs less than its rays one by one:
//! - **Set-up once a packet, in lanes**: the rays are transposed into AVX2 lanes (one 8×8
//!   transpose per 8 rays) and the slab test's and the watertight test's per-ray values are
//!   computed for all lanes at once, by the same IEEE operations as `SlabRay::new` and
//!   `WatertightRay::new` (so the same bits).
//! - **Groups**: the rays of a packet that share the slab test's octant and the watertight
//!   set-up's axes (kx, ky, kz) are traced together (almost always the whole packet), so a
//!   node's plane rows and a triangle's rows are the same for every lane.
//! - **Interval cull** (`packet_cull=on`, 8-wide trees): each node's 8 boxes are first tested
//!   in one AVX test against the group's interval ray (least/greatest `rdir`, greatest
//!   `org_near`, least `org_far`), which is conservative for every lane (see
//!   [`x86`]'s `candidates`); only the children it passes are tested lane by lane.
//! - **Triangle × rays in lanes**: a leaf's triangles are tested one at a time against all
//!   lanes (Embree's `TriangleMIntersectorKMoeller`, but with rtbench's watertight test:
//!   [`crate::geometry::triangle_simd::rays_against_triangle`], the same bits as the single-ray
//!   test), each lane within its own segment.
//! - **Lone lanes** (Embree's hybrid switch, at the leaves and nodes only): a leaf reached by at
//!   most 2 live lanes is tested ray by ray with the single-ray kernel (two packets of 4
//!   triangles per AVX test), and an 8-wide node reached by one lane is tested with that ray's
//!   own interval, which is exactly its single-ray box test.
//!
//! Why the answers are the single-ray answers: a lane's box test is the single-ray AVX2 test's
//! arithmetic (the same `fmsub` of the same operands), so a ray visits at least every leaf its
//! own traversal would, and each triangle test gives the single-ray test's bits. Any hit is
//! order-free. Closest hit keeps the nearest `t` over those leaves, the first in leaf order on a
//! tie inside a leaf; only two triangles of different leaves at exactly the same `t` could be
//! reported differently, since the packet visits children in the order of the packet's nearest
//! entry, not the ray's own.
//!
//! Counters count per ray: a node visit and its `len` box tests for every lane active at the
//! node, and the triangles each lane tests.
//!
//! One file of ~1,250 lines: the closest-hit and any-hit loops share the lane set-up, the
//! groups, the interval and lane box tests and the lone-lane tests, which exist only for them.

use super::leaf::{LeafPacket, PACKET};
use super::node::{is_leaf, is_packet_leaf, leaf_range, packet_range};
use super::traverse::{Bvh, STACK_SIZE};
use crate::engine::Counters;
use crate::geometry::TriangleTest;
use crate::ray::{Hit, Ray};

/// Rays per packet: 8 (one AVX register) or 16 (two).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PacketSize {
    Off,
    Eight,
    Sixteen,
}

impl std::str::FromStr for PacketSize {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "off" | "1" => Ok(PacketSize::Off),
            "8" => Ok(PacketSize::Eight),
            "16" => Ok(PacketSize::Sixteen),
            _ => Err("expected off, 8 or 16".into()),
        }
    }
}

impl PacketSize {
    pub fn rays(self) -> usize {
        match self {
            PacketSize::Off => 1,
            PacketSize::Eight => 8,
            PacketSize::Sixteen => 16,
        }
    }
}

/// The triangles of a packet leaf.
#[inline(always)]
fn leaf_packets<const N: usize>(bvh: &Bvh<N>, c: u32) -> (&[LeafPacket], usize) {
    let (first, count) = packet_range(c);
    (&bvh.packets[first..first + count.div_ceil(PACKET)], count)
}

/// Packet kernels for an N-wide tree, when the CPU has AVX2 and FMA (else `None`: the engine
/// then answers ray by ray). `cull`: test each node's boxes against the packet's interval ray
/// first (`packet_cull`, 8-wide trees).
pub fn kernels<const N: usize>(
    size: PacketSize,
    cull: bool,
) -> Option<super::dispatch::Kernels<N>> {
    #[cfg(target_arch = "x86_64")]
    {
        use crate::geometry::lanes::Avx8;
        if !Avx8::available() {
            return None;
        }
        let (closest, any): (super::dispatch::ClosestFn<N>, super::dispatch::AnyFn<N>) =
            match (size, cull) {
                (PacketSize::Off, _) => return None,
                (PacketSize::Eight, false) => (
                    x86::closest_entry::<N, 1, false>,
                    x86::any_entry::<N, 1, false>,
                ),
                (PacketSize::Eight, true) => (
                    x86::closest_entry::<N, 1, true>,
                    x86::any_entry::<N, 1, true>,
                ),
                (PacketSize::Sixteen, false) => (
                    x86::closest_entry::<N, 2, false>,
                    x86::any_entry::<N, 2, false>,
                ),
                (PacketSize::Sixteen, true) => (
                    x86::closest_entry::<N, 2, true>,
                    x86::any_entry::<N, 2, true>,
                ),
            };
        Some(super::dispatch::Kernels {
            closest,
            any,
            lanes: 8,
            name: match size {
                PacketSize::Eight => "avx2 packets of 8",
                _ => "avx2 packets of 16",
            },
        })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (size, cull);
        None
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::*;
    use crate::bvh::node::WideNode;
    use crate::geometry::aabb::SlabRay;
    use crate::geometry::kernels::f32::WatertightRay;
    use crate::geometry::lanes::Avx8;
    use crate::geometry::triangle_simd::{
        rays_against_triangle, LaneHits, PacketKernel, PairKernel, TriangleRayLanes,
    };
    use std::arch::x86_64::*;

    /// A ray that is never active (the lanes past the end of a short last packet).
    const IDLE: Ray = Ray {
        origin: glam::Vec3::ZERO,
        tmin: f32::INFINITY,
        dir: glam::Vec3::ONE,
        tmax: f32::NEG_INFINITY,
    };

    /// (kx, ky) of the watertight set-up by kz and whether `d[kz] < 0`, as
    /// `WatertightRay::new` picks them.
    const AXES: [[[usize; 2]; 2]; 3] = [[[1, 2], [2, 1]], [[2, 0], [0, 2]], [[0, 1], [1, 0]]];

    /// The rays of a packet in lanes, transposed once for the packet: `o`, `d` per axis,
    /// `tmin`, `tmax`, and the slab test's `rdir`, `org_near`, `org_far` (`SlabRay::new`,
    /// the same IEEE operation per lane, so the same bits as each ray's own set-up).
    struct Fields<const H: usize> {
        o: [[__m256; 3]; H],
        d: [[__m256; 3]; H],
        tmin: [__m256; H],
        tmax: [__m256; H],
        rdir: [[__m256; 3]; H],
        org_near: [[__m256; 3]; H],
        org_far: [[__m256; 3]; H],
        /// Lanes (bit per ray) whose ray may be traced ([`Ray::is_traceable`]).
        traceable: u32,
        /// Per axis: lanes whose `rdir` is negative (the slab test's near plane is the upper).
        negative: [u32; 3],
        /// Per axis: lanes whose direction is `< 0` (the watertight set-up's swap of kx, ky).
        below_zero: [u32; 3],
        /// Per axis: lanes whose watertight `kz` is that axis.
        kz: [u32; 3],
    }

    /// An 8×8 transpose: lane `l` of output `f` is float `f` of row `l`.
    #[inline(always)]
    unsafe fn transpose(r: [__m256; 8]) -> [__m256; 8] {
        let t0 = _mm256_unpacklo_ps(r[0], r[1]);
        let t1 = _mm256_unpackhi_ps(r[0], r[1]);
        let t2 = _mm256_unpacklo_ps(r[2], r[3]);
        let t3 = _mm256_unpackhi_ps(r[2], r[3]);
        let t4 = _mm256_unpacklo_ps(r[4], r[5]);
        let t5 = _mm256_unpackhi_ps(r[4], r[5]);
        let t6 = _mm256_unpacklo_ps(r[6], r[7]);
        let t7 = _mm256_unpackhi_ps(r[6], r[7]);
        let u0 = _mm256_shuffle_ps::<0x44>(t0, t2);
        let u1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
        let u2 = _mm256_shuffle_ps::<0x44>(t1, t3);
        let u3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
        let u4 = _mm256_shuffle_ps::<0x44>(t4, t6);
        let u5 = _mm256_shuffle_ps::<0xEE>(t4, t6);
        let u6 = _mm256_shuffle_ps::<0x44>(t5, t7);
        let u7 = _mm256_shuffle_ps::<0xEE>(t5, t7);
        [
            _mm256_permute2f128_ps::<0x20>(u0, u4),
            _mm256_permute2f128_ps::<0x20>(u1, u5),
            _mm256_permute2f128_ps::<0x20>(u2, u6),
            _mm256_permute2f128_ps::<0x20>(u3, u7),
            _mm256_permute2f128_ps::<0x31>(u0, u4),
            _mm256_permute2f128_ps::<0x31>(u1, u5),
            _mm256_permute2f128_ps::<0x31>(u2, u6),
            _mm256_permute2f128_ps::<0x31>(u3, u7),
        ]
    }

    #[inline(always)]
    unsafe fn bits(v: __m256) -> u32 {
        _mm256_movemask_ps(v) as u32
    }

    /// The packet's lanes (`rays.len() ≤ 8·H`; lanes past the end idle).
    #[inline(always)]
    unsafe fn fields<const H: usize>(rays: &[Ray], extent: f32) -> Fields<H> {
        let mut buf = [IDLE; 16];
        buf[..rays.len()].copy_from_slice(rays);
        let sign = _mm256_set1_ps(-0.0);
        let zero = _mm256_setzero_ps();
        let mut f = Fields::<H> {
            o: [[zero; 3]; H],
            d: [[zero; 3]; H],
            tmin: [zero; H],
            tmax: [zero; H],
            rdir: [[zero; 3]; H],
            org_near: [[zero; 3]; H],
            org_far: [[zero; 3]; H],
            traceable: 0,
            negative: [0; 3],
            below_zero: [0; 3],
            kz: [0; 3],
        };
        for h in 0..H {
            // `Ray` is `repr(C)`, 8 floats (origin, tmin, dir, tmax): one load per ray.
            let mut rows = [_mm256_setzero_ps(); 8];
            for (l, r) in rows.iter_mut().enumerate() {
                *r = _mm256_loadu_ps(&buf[8 * h + l] as *const Ray as *const f32);
            }
            let c = transpose(rows);
            let (o, d) = ([c[0], c[1], c[2]], [c[4], c[5], c[6]]);
            let shift = 8 * h;
            // `Ray::is_traceable`: origin and direction finite (x − x is 0, else NaN),
            // tmin and tmax not NaN.
            let diff = |x: __m256| _mm256_sub_ps(x, x);
            let finite = _mm256_add_ps(
                _mm256_add_ps(
                    _mm256_add_ps(diff(o[0]), diff(o[1])),
                    _mm256_add_ps(diff(o[2]), diff(d[0])),
                ),
                _mm256_add_ps(diff(d[1]), diff(d[2])),
            );
            let ok = _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_EQ_OQ>(finite, zero),
                _mm256_cmp_ps::<_CMP_ORD_Q>(c[3], c[7]),
            );
            f.traceable |= bits(ok) << shift;
            // `SlabRay::new` (as `ray_setup::slab_lanes`, rays in the lanes).
            let min = _mm256_set1_ps(SlabRay::MIN_RCP_INPUT);
            let e = _mm256_set1_ps(extent.abs());
            for a in 0..3 {
                let abs_d = _mm256_andnot_ps(sign, d[a]);
                let tiny = _mm256_cmp_ps::<_CMP_LT_OQ>(abs_d, min);
                let clamped = _mm256_or_ps(_mm256_and_ps(d[a], sign), min);
                let safe = _mm256_blendv_ps(d[a], clamped, tiny);
                let rdir = _mm256_div_ps(_mm256_set1_ps(1.0), safe);
                let org_rdir = _mm256_mul_ps(o[a], rdir);
                let pad = _mm256_mul_ps(
                    _mm256_mul_ps(
                        _mm256_add_ps(e, _mm256_andnot_ps(sign, o[a])),
                        _mm256_andnot_ps(sign, rdir),
                    ),
                    _mm256_set1_ps(SlabRay::ROUNDINGS),
                );
                f.rdir[h][a] = rdir;
                f.org_near[h][a] = _mm256_add_ps(org_rdir, pad);
                f.org_far[h][a] = _mm256_sub_ps(org_rdir, pad);
                f.negative[a] |= bits(_mm256_cmp_ps::<_CMP_LT_OQ>(rdir, zero)) << shift;
                f.below_zero[a] |= bits(_mm256_cmp_ps::<_CMP_LT_OQ>(d[a], zero)) << shift;
            }
            // `WatertightRay::new`'s kz: a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2).
            // (No `map` in this file: its closures were not inlined into the AVX2 kernels.)
            let ab = [
                _mm256_andnot_ps(sign, d[0]),
                _mm256_andnot_ps(sign, d[1]),
                _mm256_andnot_ps(sign, d[2]),
            ];
            let x_y = bits(_mm256_cmp_ps::<_CMP_GT_OQ>(ab[0], ab[1]));
            let x_z = bits(_mm256_cmp_ps::<_CMP_GT_OQ>(ab[0], ab[2]));
            let y_z = bits(_mm256_cmp_ps::<_CMP_GT_OQ>(ab[1], ab[2]));
            let kz0 = x_y & x_z;
            let kz1 = !x_y & y_z;
            f.kz[0] |= kz0 << shift;
            f.kz[1] |= kz1 << shift;
            f.kz[2] |= (!(kz0 | kz1) & 0xff) << shift;
            f.o[h] = o;
            f.d[h] = d;
            f.tmin[h] = c[3];
            f.tmax[h] = c[7];
        }
        let used = if rays.len() >= 32 {
            u32::MAX
        } else {
            (1u32 << rays.len()) - 1
        };
        f.traceable &= used;
        f
    }

    /// The lanes of `lanes` (bits) as an all-ones vector mask, half `h`.
    #[inline(always)]
    unsafe fn lane_mask(lanes: u32, h: usize) -> __m256 {
        let b = _mm256_set1_epi32(((lanes >> (8 * h)) & 0xff) as i32);
        let one = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(b, one), one))
    }

    /// One group of a packet's rays that share the slab test's octant and the watertight
    /// set-up's axes, so that a node's plane rows and a triangle's rows are the same for every
    /// lane: the rays traced together. Lanes outside the group are idle (`tmin` = +∞,
    /// `tmax` = −∞: no box and no triangle is ever hit in them).
    struct Group<const H: usize> {
        rdir: [[__m256; 3]; H],
        org_near: [[__m256; 3]; H],
        org_far: [[__m256; 3]; H],
        tmin: [__m256; H],
        tmax: [__m256; H],
        tri: [TriangleRayLanes<__m256>; H],
        /// Each lane's watertight shear (sx, sy, sz), for the scalar leaves.
        shear: [[__m256; 3]; H],
        k: [usize; 3],
        near_row: [usize; 3],
        far_row: [usize; 3],
        lanes: u32,
        /// The group's interval ray.
        span: Interval,
    }

    /// An interval ray, every lane splatted (the interval/frustum test
    /// of Reshetov, Soupikov and Hurley 2005, "Multi-level ray tracing algorithm", and
    /// Embree's `FrustumK`): per axis the least and greatest `rdir`, the greatest
    /// `org_near`, the least `org_far` over some lanes; the least `tmin` and greatest `tmax`.
    /// Of one lane, it is that lane's ray exactly.
    #[derive(Clone, Copy)]
    struct Interval {
        rdir_lo: [__m256; 3],
        rdir_hi: [__m256; 3],
        near_hi: [__m256; 3],
        far_lo: [__m256; 3],
        tmin_lo: __m256,
        tmax_hi: __m256,
    }

    /// Lane `l`'s ray as an interval ray (every lane of each row its value).
    #[inline(always)]
    unsafe fn lone_interval<const H: usize>(g: &Group<H>, l: usize) -> Interval {
        let (h, q) = (l / 8, l % 8);
        let idx = _mm256_set1_epi32(q as i32);
        let b = |v: __m256| _mm256_permutevar8x32_ps(v, idx);
        let rdir = [b(g.rdir[h][0]), b(g.rdir[h][1]), b(g.rdir[h][2])];
        Interval {
            rdir_lo: rdir,
            rdir_hi: rdir,
            near_hi: [
                b(g.org_near[h][0]),
                b(g.org_near[h][1]),
                b(g.org_near[h][2]),
            ],
            far_lo: [b(g.org_far[h][0]), b(g.org_far[h][1]), b(g.org_far[h][2])],
            tmin_lo: b(g.tmin[h]),
            tmax_hi: b(g.tmax[h]),
        }
    }

    /// The group of `f`'s traceable rays that share the octant and axes of ray `l`.
    #[inline(always)]
    unsafe fn group<const H: usize>(f: &Fields<H>, pending: u32) -> Group<H> {
        let l = pending.trailing_zeros();
        let bit = |m: u32| (m >> l) & 1;
        let same = |m: u32| if bit(m) != 0 { m } else { !m };
        let kz = if bit(f.kz[0]) != 0 {
            0
        } else if bit(f.kz[1]) != 0 {
            1
        } else {
            2
        };
        let swap = bit(f.below_zero[kz]) as usize;
        let lanes = pending
            & same(f.negative[0])
            & same(f.negative[1])
            & same(f.negative[2])
            & f.kz[kz]
            & same(f.below_zero[kz]);
        let [kx, ky] = AXES[kz][swap];
        let k = [kx, ky, kz];
        let neg = [
            bit(f.negative[0]) as usize,
            bit(f.negative[1]) as usize,
            bit(f.negative[2]) as usize,
        ];
        let near_row = [neg[0], 2 + neg[1], 4 + neg[2]];
        let far_row = [1 - neg[0], 3 - neg[1], 5 - neg[2]];
        let one = _mm256_set1_ps(1.0);
        let mut tmin = [_mm256_setzero_ps(); H];
        let mut tmax = [_mm256_setzero_ps(); H];
        let mut shear = [[_mm256_setzero_ps(); 3]; H];
        let inf = _mm256_set1_ps(f32::INFINITY);
        let ninf = _mm256_set1_ps(f32::NEG_INFINITY);
        let mut tri = [TriangleRayLanes::rays(f.o[0], f.d[0], [one; 3], k); H];
        let mut rdir_lo = [inf; 3];
        let mut rdir_hi = [ninf; 3];
        let mut near_hi = [ninf; 3];
        let mut far_lo = [inf; 3];
        let mut tmin_lo = inf;
        let mut tmax_hi = ninf;
        for h in 0..H {
            let m = lane_mask(lanes, h);
            tmin[h] = _mm256_blendv_ps(inf, f.tmin[h], m);
            tmax[h] = _mm256_blendv_ps(ninf, f.tmax[h], m);
            tmin_lo = _mm256_min_ps(tmin_lo, tmin[h]);
            tmax_hi = _mm256_max_ps(tmax_hi, tmax[h]);
            // `WatertightRay::new`: (d[kx] / d[kz], d[ky] / d[kz], 1 / d[kz]).
            let d = f.d[h];
            let s = [
                _mm256_div_ps(d[kx], d[kz]),
                _mm256_div_ps(d[ky], d[kz]),
                _mm256_div_ps(one, d[kz]),
            ];
            shear[h] = s;
            tri[h] = TriangleRayLanes::rays(f.o[h], f.d[h], s, k);
            for a in 0..3 {
                rdir_lo[a] = _mm256_min_ps(rdir_lo[a], _mm256_blendv_ps(inf, f.rdir[h][a], m));
                rdir_hi[a] = _mm256_max_ps(rdir_hi[a], _mm256_blendv_ps(ninf, f.rdir[h][a], m));
                near_hi[a] = _mm256_max_ps(near_hi[a], _mm256_blendv_ps(ninf, f.org_near[h][a], m));
                far_lo[a] = _mm256_min_ps(far_lo[a], _mm256_blendv_ps(inf, f.org_far[h][a], m));
            }
        }
        for a in 0..3 {
            rdir_lo[a] = hmin_all(&[rdir_lo[a]]);
            rdir_hi[a] = hmax_all(&[rdir_hi[a]]);
            near_hi[a] = hmax_all(&[near_hi[a]]);
            far_lo[a] = hmin_all(&[far_lo[a]]);
        }
        let tmin_lo = hmin_all(&[tmin_lo]);
        let tmax_hi = hmax_all(&[tmax_hi]);
        Group {
            span: Interval {
                rdir_lo,
                rdir_hi,
                near_hi,
                far_lo,
                tmin_lo,
                tmax_hi,
            },
            rdir: f.rdir,
            org_near: f.org_near,
            org_far: f.org_far,
            tmin,
            tmax,
            tri,
            shear,
            k,
            near_row,
            far_row,
            lanes,
        }
    }

    /// The least lane of `v`, in every lane.
    #[inline(always)]
    unsafe fn hmin_all<const H: usize>(v: &[__m256; H]) -> __m256 {
        let mut m = v[0];
        for x in &v[1..] {
            m = _mm256_min_ps(m, *x);
        }
        m = _mm256_min_ps(m, _mm256_permute2f128_ps::<1>(m, m));
        m = _mm256_min_ps(m, _mm256_shuffle_ps::<0b01_00_11_10>(m, m));
        _mm256_min_ps(m, _mm256_shuffle_ps::<0b10_11_00_01>(m, m))
    }

    /// The greatest lane of `v`, in every lane.
    #[inline(always)]
    unsafe fn hmax_all<const H: usize>(v: &[__m256; H]) -> __m256 {
        let mut m = v[0];
        for x in &v[1..] {
            m = _mm256_max_ps(m, *x);
        }
        m = _mm256_max_ps(m, _mm256_permute2f128_ps::<1>(m, m));
        m = _mm256_max_ps(m, _mm256_shuffle_ps::<0b01_00_11_10>(m, m));
        _mm256_max_ps(m, _mm256_shuffle_ps::<0b10_11_00_01>(m, m))
    }

    /// The children of an 8-wide node that some ray of the group may hit: the slab test of
    /// the group's interval ray against all 8 boxes in one AVX test, conservative for every
    /// lane. `fmsub(p, r, o)` rounds `p·r − o` once, and rounding is monotone, so a lane's
    /// near distance on an axis is never below `min(fmsub(p, rdir_lo, near_hi),
    /// fmsub(p, rdir_hi, near_hi))` (its `rdir` lies in `[rdir_lo, rdir_hi]`, `p·r` is
    /// linear in `r`, its `org_near` ≤ `near_hi`), and its far distance never above the
    /// like maximum: a child a lane hits always passes. Other widths: every child. Also the
    /// entry distance per child (lane `i`: child `i`); of a one-lane interval
    /// ([`lone_interval`]) both are that ray's single-ray box test exactly.
    #[inline(always)]
    unsafe fn candidates<const N: usize, const H: usize>(
        node: &WideNode<N>,
        g: &Group<H>,
        span: &Interval,
    ) -> (u32, __m256) {
        let all = (1u32 << node.len.min(N as u32)) - 1;
        if N != 8 {
            return (all, _mm256_setzero_ps());
        }
        // `planes` is 6 rows of N = 8 floats; rows < 6 (`near_row`, `far_row`).
        let base = node.planes.as_ptr() as *const f32;
        let row = |r: usize| _mm256_loadu_ps(base.add(8 * r.min(5)));
        let near = |a: usize| {
            let p = row(g.near_row[a]);
            _mm256_min_ps(
                _mm256_fmsub_ps(p, span.rdir_lo[a], span.near_hi[a]),
                _mm256_fmsub_ps(p, span.rdir_hi[a], span.near_hi[a]),
            )
        };
        let far = |a: usize| {
            let p = row(g.far_row[a]);
            _mm256_max_ps(
                _mm256_fmsub_ps(p, span.rdir_lo[a], span.far_lo[a]),
                _mm256_fmsub_ps(p, span.rdir_hi[a], span.far_lo[a]),
            )
        };
        let t_near = _mm256_max_ps(
            _mm256_max_ps(near(0), near(1)),
            _mm256_max_ps(near(2), span.tmin_lo),
        );
        let t_far = _mm256_min_ps(
            _mm256_min_ps(far(0), far(1)),
            _mm256_min_ps(far(2), span.tmax_hi),
        );
        (
            bits(_mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far)) & all,
            t_near,
        )
    }

    /// Child `i`'s box against the group's lanes in `active`: the lanes that hit it (within
    /// each lane's `[tmin, tmax]`) and each lane's entry distance (+∞ where it misses). Per
    /// lane the single-ray AVX2 test's arithmetic (`box_test.rs`): the near plane of each
    /// axis by the octant, `plane · rdir − org · rdir` in one `fmsub`.
    #[inline(always)]
    unsafe fn child_test<const N: usize, const H: usize>(
        node: &WideNode<N>,
        i: usize,
        g: &Group<H>,
        active: u32,
    ) -> (u32, [__m256; H]) {
        let p = &node.planes;
        let plane = |r: usize| _mm256_set1_ps(p[r][i]);
        let near_b = [
            plane(g.near_row[0]),
            plane(g.near_row[1]),
            plane(g.near_row[2]),
        ];
        let far_b = [
            plane(g.far_row[0]),
            plane(g.far_row[1]),
            plane(g.far_row[2]),
        ];
        let inf = _mm256_set1_ps(f32::INFINITY);
        let mut mask = 0u32;
        let mut dist = [inf; H];
        #[allow(clippy::needless_range_loop)] // `h` indexes the group's lanes as well.
        for h in 0..H {
            if (active >> (8 * h)) & 0xff == 0 {
                continue;
            }
            let near = |a: usize| _mm256_fmsub_ps(near_b[a], g.rdir[h][a], g.org_near[h][a]);
            let far = |a: usize| _mm256_fmsub_ps(far_b[a], g.rdir[h][a], g.org_far[h][a]);
            let t_near = _mm256_max_ps(
                _mm256_max_ps(near(0), near(1)),
                _mm256_max_ps(near(2), g.tmin[h]),
            );
            let t_far = _mm256_min_ps(
                _mm256_min_ps(far(0), far(1)),
                _mm256_min_ps(far(2), g.tmax[h]),
            );
            let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far);
            mask |= bits(hit) << (8 * h);
            dist[h] = _mm256_blendv_ps(inf, t_near, hit);
        }
        (mask & active, dist)
    }

    /// The smallest lane of `v` (the order key of a child: the packet's nearest entry).
    #[inline(always)]
    unsafe fn hmin<const H: usize>(v: &[__m256; H]) -> f32 {
        let mut m = v[0];
        for x in &v[1..] {
            m = _mm256_min_ps(m, *x);
        }
        let m4 = _mm_min_ps(_mm256_castps256_ps128(m), _mm256_extractf128_ps::<1>(m));
        let m2 = _mm_min_ps(m4, _mm_movehl_ps(m4, m4));
        let m1 = _mm_min_ss(m2, _mm_shuffle_ps::<1>(m2, m2));
        _mm_cvtss_f32(m1)
    }

    /// Lanes of `active` whose entry distance is within their segment (`dist ≤ tmax`).
    #[inline(always)]
    unsafe fn within<const H: usize>(dist: &[__m256; H], tmax: &[__m256; H], active: u32) -> u32 {
        let mut m = 0;
        for h in 0..H {
            m |= bits(_mm256_cmp_ps::<_CMP_LE_OQ>(dist[h], tmax[h])) << (8 * h);
        }
        m & active
    }

    #[derive(Clone, Copy)]
    struct Entry<const H: usize> {
        node: u32,
        mask: u32,
        dist: [__m256; H],
    }

    /// Scalar copies of a half's lanes.
    #[inline(always)]
    unsafe fn store8(v: __m256) -> [f32; 8] {
        let mut a = [0.0f32; 8];
        _mm256_storeu_ps(a.as_mut_ptr(), v);
        a
    }

    /// The scalar-primitive leaf's ray for lane `l` (spheres, cones: the shared scalar
    /// kernels), with its own watertight set-up.
    #[inline(always)]
    unsafe fn lane_ray<const H: usize>(
        ray: &Ray,
        g: &Group<H>,
        l: usize,
        tmax: f32,
    ) -> (Ray, WatertightRay) {
        let (h, j) = (l / 8, l % 8);
        let s = [
            store8(g.shear[h][0])[j],
            store8(g.shear[h][1])[j],
            store8(g.shear[h][2])[j],
        ];
        let wt = WatertightRay {
            kx: g.k[0],
            ky: g.k[1],
            kz: g.k[2],
            sx: s[0],
            sy: s[1],
            sz: s[2],
        };
        (Ray { tmax, ..*ray }, wt)
    }

    /// Leaves with at most this many live lanes are tested ray by ray with the single-ray
    /// kernel (two leaf packets of 4 triangles per AVX test), not triangle by triangle
    /// against the lanes: a ray-lane test costs as much for one lane as for 8 (Embree's
    /// hybrid switch, `switchThreshold` 2 for coherent rays, applied at the leaves).
    const LONE: u32 = 2;

    /// Lane `l`'s ray splatted for the single-ray packet test (`PairKernel`): the values
    /// `PacketKernel::prepare` makes from the ray and its `WatertightRay` (the same bits).
    #[inline(always)]
    unsafe fn lone_ray<const H: usize>(
        ray: &Ray,
        g: &Group<H>,
        l: usize,
    ) -> TriangleRayLanes<__m256> {
        let (_, wt) = lane_ray(ray, g, l, ray.tmax);
        let splat = |v: glam::Vec3| {
            [
                _mm256_set1_ps(v.x),
                _mm256_set1_ps(v.y),
                _mm256_set1_ps(v.z),
            ]
        };
        let s = [
            _mm256_set1_ps(wt.sx),
            _mm256_set1_ps(wt.sy),
            _mm256_set1_ps(wt.sz),
        ];
        TriangleRayLanes::rays(splat(ray.origin), splat(ray.dir), s, g.k)
    }

    /// A lone ray's nearest hit in a leaf: (packet, lane in it, t, u, v).
    type LoneHit = (usize, usize, f32, f32, f32);

    /// The nearest hit of one ray among a leaf's packets in `(tmin, tmax)`, as the single-ray
    /// traversal tests a leaf (`traverse.rs`: pairs, then the odd packet; the first triangle in
    /// leaf order on a tie of t): (packet, lane in it, t, u, v) and the hits counted there.
    #[inline(always)]
    unsafe fn lone_closest<const W: bool>(
        packets: &[LeafPacket],
        r: &TriangleRayLanes<__m256>,
        tmin: f32,
        mut tmax: f32,
    ) -> (Option<LoneHit>, u64) {
        let mut pair_lanes = LaneHits::<8>::default();
        let mut lanes = LaneHits::<4>::default();
        let mut best = None;
        let mut counted = 0u64;
        let mut pairs = packets.chunks_exact(2);
        for (n, pair) in (&mut pairs).enumerate() {
            let mask = <Avx8 as PairKernel>::test_pair::<W>(
                &pair[0].tri,
                &pair[1].tri,
                r,
                tmin,
                tmax,
                &mut pair_lanes,
            );
            if mask != 0 {
                counted += mask.count_ones() as u64;
                let i = pair_lanes.nearest(mask);
                tmax = pair_lanes.t[i];
                best = Some((
                    2 * n + i / PACKET,
                    i % PACKET,
                    pair_lanes.t[i],
                    pair_lanes.u[i],
                    pair_lanes.v[i],
                ));
            }
        }
        let done = packets.len() - pairs.remainder().len();
        for (n, p) in pairs.remainder().iter().enumerate() {
            let mask = <Avx8 as PacketKernel<PACKET>>::test::<W>(&p.tri, r, tmin, tmax, &mut lanes);
            if mask != 0 {
                counted += mask.count_ones() as u64;
                let i = lanes.nearest(mask);
                tmax = lanes.t[i];
                best = Some((done + n, i, lanes.t[i], lanes.u[i], lanes.v[i]));
            }
        }
        (best, counted)
    }

    /// Whether one ray hits any triangle of a leaf in `(tmin, tmax)` (pairs, then the odd
    /// packet), and the hits counted.
    #[inline(always)]
    unsafe fn lone_any<const W: bool>(
        packets: &[LeafPacket],
        r: &TriangleRayLanes<__m256>,
        tmin: f32,
        tmax: f32,
    ) -> u64 {
        let mut pair_lanes = LaneHits::<8>::default();
        let mut lanes = LaneHits::<4>::default();
        let mut pairs = packets.chunks_exact(2);
        for pair in &mut pairs {
            let mask = <Avx8 as PairKernel>::test_pair::<W>(
                &pair[0].tri,
                &pair[1].tri,
                r,
                tmin,
                tmax,
                &mut pair_lanes,
            );
            if mask != 0 {
                return mask.count_ones() as u64;
            }
        }
        for p in pairs.remainder() {
            let mask = <Avx8 as PacketKernel<PACKET>>::test::<W>(&p.tri, r, tmin, tmax, &mut lanes);
            if mask != 0 {
                return mask.count_ones() as u64;
            }
        }
        0
    }

    /// Closest hits of one group of a packet.
    #[inline(always)]
    unsafe fn closest_group<const N: usize, const H: usize, const W: bool, const CULL: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        hits: &mut [Hit],
        stack: &mut [Entry<H>; STACK_SIZE],
        c: &mut Counters,
        mut g: Group<H>,
    ) {
        let mut lane_hits = LaneHits::<8>::default();
        let mut best = [Hit::MISS; 16];
        let mut sp = 0usize;
        let mut cur = bvh.root;
        let mut cur_mask = g.lanes;
        let (mut nodes, mut boxes, mut prims, mut prim_hits) = (0u64, 0u64, 0u64, 0u64);
        'trace: loop {
            if !is_leaf(cur) {
                let node = &bvh.nodes[cur as usize];
                let n = cur_mask.count_ones() as u64;
                nodes += n;
                boxes += n * node.len as u64;
                let mut found = [(0u32, 0u32, 0.0f32); N];
                let mut dists = [[_mm256_setzero_ps(); H]; N];
                let mut count = 0usize;
                let lone = CULL && N == 8 && cur_mask.count_ones() == 1;
                let mut cand = if lone {
                    // One lane: its own box test of all 8 children (the single-ray test).
                    let (m, t_near) = candidates(
                        node,
                        &g,
                        &lone_interval(&g, cur_mask.trailing_zeros() as usize),
                    );
                    let t = store8(t_near);
                    let mut m = m;
                    while m != 0 {
                        let i = m.trailing_zeros() as usize;
                        m &= m - 1;
                        found[count] = (node.child[i], cur_mask, t[i]);
                        dists[count] = [_mm256_set1_ps(t[i]); H];
                        count += 1;
                    }
                    0
                } else if CULL {
                    candidates(node, &g, &g.span).0
                } else {
                    (1u32 << node.len.min(N as u32)) - 1
                };
                while cand != 0 {
                    let i = cand.trailing_zeros() as usize;
                    cand &= cand - 1;
                    let (m, dist) = child_test::<N, H>(node, i, &g, cur_mask);
                    if m != 0 {
                        found[count] = (node.child[i], m, hmin(&dist));
                        dists[count] = dist;
                        count += 1;
                    }
                }
                if count == 1 {
                    (cur, cur_mask) = (found[0].0, found[0].1);
                    continue;
                }
                if count > 1 {
                    // Farthest first onto the stack, the nearest taken at once (a stable
                    // insertion sort of ≤ N keys: equal keys keep slot order).
                    let mut order = [0u8; N];
                    for a in 0..count {
                        let mut b = a;
                        while b > 0 && found[order[b - 1] as usize].2 < found[a].2 {
                            order[b] = order[b - 1];
                            b -= 1;
                        }
                        order[b] = a as u8;
                    }
                    for &o in &order[..count - 1] {
                        let (node, mask, _) = found[o as usize];
                        stack[sp] = Entry {
                            node,
                            mask,
                            dist: dists[o as usize],
                        };
                        sp += 1;
                    }
                    let (node, mask, _) = found[order[count - 1] as usize];
                    (cur, cur_mask) = (node, mask);
                    continue;
                }
            } else if is_packet_leaf(cur) {
                let (packets, count) = leaf_packets(bvh, cur);
                prims += count as u64 * cur_mask.count_ones() as u64;
                let mut shrunk = false;
                let mut left = if cur_mask.count_ones() <= LONE {
                    0
                } else {
                    count
                };
                if left == 0 {
                    let mut m = cur_mask;
                    while m != 0 {
                        let l = m.trailing_zeros() as usize;
                        m &= m - 1;
                        let (h, q) = (l / 8, l % 8);
                        let r = lone_ray(&rays[l], &g, l);
                        let tmax = store8(g.tmax[h])[q];
                        let (hit, counted) = lone_closest::<W>(packets, &r, rays[l].tmin, tmax);
                        prim_hits += counted;
                        if let Some((pk, i, t, u, v)) = hit {
                            best[l] = Hit {
                                t,
                                object: packets[pk].object[i],
                                u,
                                v,
                            };
                            let mut a = store8(g.tmax[h]);
                            a[q] = t;
                            g.tmax[h] = _mm256_loadu_ps(a.as_ptr());
                            shrunk = true;
                        }
                    }
                }
                for p in &packets[..count.div_ceil(PACKET) * (left > 0) as usize] {
                    let n = left.min(PACKET);
                    left -= n;
                    for j in 0..n {
                        for h in 0..H {
                            let lanes = (cur_mask >> (8 * h)) & 0xff;
                            if lanes == 0 {
                                continue;
                            }
                            let hit = rays_against_triangle::<W>(
                                &p.tri,
                                j,
                                &g.tri[h],
                                g.tmin[h],
                                g.tmax[h],
                                &mut lane_hits,
                            ) & lanes;
                            if hit != 0 {
                                prim_hits += hit.count_ones() as u64;
                                let t = _mm256_loadu_ps(lane_hits.t.as_ptr());
                                g.tmax[h] = _mm256_blendv_ps(g.tmax[h], t, lane_mask(hit, 0));
                                shrunk = true;
                                let mut m = hit;
                                while m != 0 {
                                    let q = m.trailing_zeros() as usize;
                                    m &= m - 1;
                                    best[8 * h + q] = Hit {
                                        t: lane_hits.t[q],
                                        object: p.object[j],
                                        u: lane_hits.u[q],
                                        v: lane_hits.v[q],
                                    };
                                }
                            }
                        }
                    }
                }
                if CULL && shrunk {
                    g.span.tmax_hi = hmax_all(&g.tmax);
                }
            } else {
                let (first, count) = leaf_range(cur);
                let mut m = cur_mask;
                let mut tmax_s = [[0.0f32; 8]; H];
                for (s, t) in tmax_s.iter_mut().zip(&g.tmax) {
                    *s = store8(*t);
                }
                while m != 0 {
                    let l = m.trailing_zeros() as usize;
                    m &= m - 1;
                    let (mut rr, wt) = lane_ray(&rays[l], &g, l, tmax_s[l / 8][l % 8]);
                    let test = triangle_test::<W>();
                    for k in first..first + count {
                        prims += 1;
                        if let Some((t, u, v)) = bvh.prims[k].intersect(&rr, test, &wt) {
                            prim_hits += 1;
                            rr.tmax = t;
                            best[l] = Hit {
                                t,
                                object: bvh.objects[k],
                                u,
                                v,
                            };
                        }
                    }
                    tmax_s[l / 8][l % 8] = rr.tmax;
                }
                for (t, s) in g.tmax.iter_mut().zip(&tmax_s) {
                    *t = _mm256_loadu_ps(s.as_ptr());
                }
                if CULL {
                    g.span.tmax_hi = hmax_all(&g.tmax);
                }
            }
            // Next: the nearest pending entry that some lane still needs.
            loop {
                if sp == 0 {
                    break 'trace;
                }
                sp -= 1;
                let e = &stack[sp];
                let m = within(&e.dist, &g.tmax, e.mask);
                if m != 0 {
                    (cur, cur_mask) = (e.node, m);
                    break;
                }
            }
        }
        let mut m = g.lanes;
        while m != 0 {
            let l = m.trailing_zeros() as usize;
            m &= m - 1;
            hits[l] = best[l];
        }
        c.nodes_visited += nodes;
        c.box_tests += boxes;
        c.primitive_tests += prims;
        c.primitive_hits += prim_hits;
    }

    /// Any-hit answers of one group of a packet: a lane leaves at its first hit (its `tmax`
    /// becomes −∞, so no box is hit in it again); the group stops when no lane is left.
    #[inline(always)]
    unsafe fn any_group<const N: usize, const H: usize, const W: bool, const CULL: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        out: &mut [bool],
        stack: &mut [(u32, u32); STACK_SIZE],
        c: &mut Counters,
        mut g: Group<H>,
    ) {
        let mut lane_hits = LaneHits::<8>::default();
        let mut alive = g.lanes;
        let mut sp = 0usize;
        let mut cur = bvh.root;
        let mut cur_mask = alive;
        let (mut nodes, mut boxes, mut prims, mut prim_hits) = (0u64, 0u64, 0u64, 0u64);
        let ninf = _mm256_set1_ps(f32::NEG_INFINITY);
        loop {
            let mask = cur_mask & alive;
            if mask != 0 {
                if !is_leaf(cur) {
                    let node = &bvh.nodes[cur as usize];
                    let n = mask.count_ones() as u64;
                    nodes += n;
                    boxes += n * node.len as u64;
                    let mut cand = if CULL && N == 8 && mask.count_ones() == 1 {
                        // One lane: its own box test of all 8 children (the single-ray test).
                        let l = mask.trailing_zeros() as usize;
                        let mut m = candidates(node, &g, &lone_interval(&g, l)).0;
                        while m != 0 {
                            let i = m.trailing_zeros() as usize;
                            m &= m - 1;
                            stack[sp] = (node.child[i], mask);
                            sp += 1;
                        }
                        0
                    } else if CULL {
                        candidates(node, &g, &g.span).0
                    } else {
                        (1u32 << node.len.min(N as u32)) - 1
                    };
                    while cand != 0 {
                        let i = cand.trailing_zeros() as usize;
                        cand &= cand - 1;
                        let (m, _) = child_test::<N, H>(node, i, &g, mask);
                        if m != 0 {
                            stack[sp] = (node.child[i], m);
                            sp += 1;
                        }
                    }
                } else if is_packet_leaf(cur) {
                    let (packets, count) = leaf_packets(bvh, cur);
                    let mut left = count;
                    let mut live = mask;
                    if live.count_ones() <= LONE {
                        let mut m = live;
                        while m != 0 {
                            let l = m.trailing_zeros() as usize;
                            m &= m - 1;
                            let r = lone_ray(&rays[l], &g, l);
                            prims += count as u64;
                            let hit = lone_any::<W>(packets, &r, rays[l].tmin, rays[l].tmax);
                            if hit != 0 {
                                prim_hits += hit;
                                out[l] = true;
                                alive &= !(1 << l);
                                live &= !(1 << l);
                                let h = l / 8;
                                g.tmax[h] =
                                    _mm256_blendv_ps(g.tmax[h], ninf, lane_mask(1 << (l % 8), 0));
                            }
                        }
                        left = 0;
                    }
                    'leaf: for p in &packets[..count.div_ceil(PACKET) * (left > 0) as usize] {
                        let n = left.min(PACKET);
                        left -= n;
                        for j in 0..n {
                            prims += live.count_ones() as u64;
                            for h in 0..H {
                                let lanes = (live >> (8 * h)) & 0xff;
                                if lanes == 0 {
                                    continue;
                                }
                                let hit = rays_against_triangle::<W>(
                                    &p.tri,
                                    j,
                                    &g.tri[h],
                                    g.tmin[h],
                                    g.tmax[h],
                                    &mut lane_hits,
                                ) & lanes;
                                if hit != 0 {
                                    prim_hits += hit.count_ones() as u64;
                                    g.tmax[h] =
                                        _mm256_blendv_ps(g.tmax[h], ninf, lane_mask(hit, 0));
                                    live &= !(hit << (8 * h));
                                    alive &= !(hit << (8 * h));
                                    let mut m = hit;
                                    while m != 0 {
                                        let q = m.trailing_zeros() as usize;
                                        m &= m - 1;
                                        out[8 * h + q] = true;
                                    }
                                }
                            }
                            if live == 0 {
                                break 'leaf;
                            }
                        }
                    }
                    if alive == 0 {
                        break;
                    }
                    if CULL && live != mask {
                        g.span.tmax_hi = hmax_all(&g.tmax);
                    }
                } else {
                    let (first, count) = leaf_range(cur);
                    let mut m = mask;
                    while m != 0 {
                        let l = m.trailing_zeros() as usize;
                        m &= m - 1;
                        let (rr, wt) = lane_ray(&rays[l], &g, l, rays[l].tmax);
                        let test = triangle_test::<W>();
                        for k in first..first + count {
                            prims += 1;
                            if bvh.prims[k].intersect(&rr, test, &wt).is_some() {
                                prim_hits += 1;
                                out[l] = true;
                                alive &= !(1 << l);
                                let h = l / 8;
                                g.tmax[h] =
                                    _mm256_blendv_ps(g.tmax[h], ninf, lane_mask(1 << (l % 8), 0));
                                break;
                            }
                        }
                    }
                    if alive == 0 {
                        break;
                    }
                    if CULL {
                        g.span.tmax_hi = hmax_all(&g.tmax);
                    }
                }
            }
            if sp == 0 {
                break;
            }
            sp -= 1;
            (cur, cur_mask) = stack[sp];
        }
        c.nodes_visited += nodes;
        c.box_tests += boxes;
        c.primitive_tests += prims;
        c.primitive_hits += prim_hits;
    }

    fn triangle_test<const W: bool>() -> TriangleTest {
        if W {
            TriangleTest::Watertight
        } else {
            TriangleTest::Moller
        }
    }

    pub fn closest_entry<const N: usize, const H: usize, const CULL: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        hits: &mut [Hit],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        assert!(Avx8::available(), "this kernel needs AVX2 and FMA");
        // SAFETY: the CPU has AVX2 and FMA (asserted above), all the callee requires.
        unsafe { closest_impl::<N, H, CULL>(bvh, rays, hits, t, c) }
    }

    pub fn any_entry<const N: usize, const H: usize, const CULL: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        out: &mut [bool],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        assert!(Avx8::available(), "this kernel needs AVX2 and FMA");
        // SAFETY: the CPU has AVX2 and FMA (asserted above), all the callee requires.
        unsafe { any_impl::<N, H, CULL>(bvh, rays, out, t, c) }
    }

    #[target_feature(enable = "avx2,fma")]
    unsafe fn closest_impl<const N: usize, const H: usize, const CULL: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        hits: &mut [Hit],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        let zero = _mm256_setzero_ps();
        let mut stack = [Entry {
            node: 0,
            mask: 0,
            dist: [zero; H],
        }; STACK_SIZE];
        let k = 8 * H;
        for (rs, hs) in rays.chunks(k).zip(hits.chunks_mut(k)) {
            for h in hs.iter_mut() {
                *h = Hit::MISS;
            }
            let f = fields::<H>(rs, bvh.extent);
            let mut pending = f.traceable;
            while pending != 0 {
                let g = group(&f, pending);
                pending &= !g.lanes;
                match t {
                    TriangleTest::Watertight => {
                        closest_group::<N, H, true, CULL>(bvh, rs, hs, &mut stack, c, g)
                    }
                    TriangleTest::Moller => {
                        closest_group::<N, H, false, CULL>(bvh, rs, hs, &mut stack, c, g)
                    }
                }
            }
        }
        c.rays += rays.len() as u64;
    }

    #[target_feature(enable = "avx2,fma")]
    unsafe fn any_impl<const N: usize, const H: usize, const CULL: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        out: &mut [bool],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        let mut stack = [(0u32, 0u32); STACK_SIZE];
        let k = 8 * H;
        for (rs, os) in rays.chunks(k).zip(out.chunks_mut(k)) {
            for o in os.iter_mut() {
                *o = false;
            }
            let f = fields::<H>(rs, bvh.extent);
            let mut pending = f.traceable;
            while pending != 0 {
                let g = group(&f, pending);
                pending &= !g.lanes;
                match t {
                    TriangleTest::Watertight => {
                        any_group::<N, H, true, CULL>(bvh, rs, os, &mut stack, c, g)
                    }
                    TriangleTest::Moller => {
                        any_group::<N, H, false, CULL>(bvh, rs, os, &mut stack, c, g)
                    }
                }
            }
        }
        c.rays += rays.len() as u64;
    }
}
