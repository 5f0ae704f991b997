//! Packet traversal (`packet=8|16`): 8 or 16 coherent rays (eye rays of neighbouring pixels,
//! shadow rays of neighbouring points to one light) walk the wide tree together, as Embree's
//! `rtcIntersect8/16` packets do (Wald, Slusallek, Benthin and Wagner 2001, "Interactive
//! rendering with coherent ray tracing"; Embree's `BVHNIntersectorKHybrid` in packet mode).
//!
//! The rays are held in AVX2 lanes (one or two `__m256` per quantity) and each child box of a
//! node is tested against all of them at once: one node fetch and one set of stack operations
//! serve the whole packet. A child is visited when at least one ray of the packet that is still
//! active there hits its box; the rays that hit it ride along as a mask. In a leaf every ray of
//! the mask is tested against the leaf's triangle packets with the single-ray kernel
//! (4 triangles per SSE test, the one [`super::traverse`] uses), so each ray's hits are exactly
//! the single-ray traversal's.
//!
//! Why the answers are the single-ray answers: the lane slab test is the single-ray AVX2 test
//! per lane (the same `fmsub` of the same operands, the near plane picked by the direction's
//! sign), so a ray visits at least every leaf its own traversal would (it may visit more: a
//! child is entered for the packet, and a ray's lane there is only tested when its own box test
//! said so, so no more leaves in fact). Any hit is order-free. Closest hit takes the nearest
//! `t` over every leaf the ray's box test admits; only two triangles at exactly the same `t`
//! could be reported differently (the first found wins), since the packet visits children in
//! the order of the packet's nearest entry, not the ray's own.
//!
//! Counters count per ray, as single rays do: a node visit and its `len` box tests for every
//! ray active at the node, and the primitive tests of each ray in each leaf.
//!
//! One file of ~680 lines: the closest-hit and any-hit loops share the lane set-up and the
//! lane box test, which exist only for them.

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
/// then answers ray by ray).
pub fn kernels<const N: usize>(size: PacketSize) -> Option<super::dispatch::Kernels<N>> {
    #[cfg(target_arch = "x86_64")]
    {
        use crate::geometry::lanes::Avx8;
        if !Avx8::available() {
            return None;
        }
        let k = super::dispatch::Kernels {
            closest: match size {
                PacketSize::Off => return None,
                PacketSize::Eight => x86::closest_entry::<N, 1>,
                PacketSize::Sixteen => x86::closest_entry::<N, 2>,
            },
            any: match size {
                PacketSize::Off => return None,
                PacketSize::Eight => x86::any_entry::<N, 1>,
                PacketSize::Sixteen => x86::any_entry::<N, 2>,
            },
            lanes: 8,
            name: match size {
                PacketSize::Eight => "avx2 packets of 8",
                _ => "avx2 packets of 16",
            },
        };
        Some(k)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = size;
        None
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::*;
    use crate::geometry::aabb::SlabRay;
    use crate::geometry::kernels::f32::WatertightRay;
    use crate::geometry::lanes::{Avx8, Sse4};
    use crate::geometry::triangle_simd::{LaneHits, PacketKernel};
    use std::arch::x86_64::*;

    type TriRay = <Sse4 as PacketKernel<PACKET>>::Ray;

    /// The watertight test's per-ray set-up (`W`), or the unused placeholder Möller–Trumbore
    /// takes.
    fn watertight<const W: bool>(dir: glam::Vec3) -> WatertightRay {
        if W {
            WatertightRay::new(dir)
        } else {
            WatertightRay {
                kx: 0,
                ky: 1,
                kz: 2,
                sx: 0.0,
                sy: 0.0,
                sz: 0.0,
            }
        }
    }

    fn triangle_test<const W: bool>() -> TriangleTest {
        if W {
            TriangleTest::Watertight
        } else {
            TriangleTest::Moller
        }
    }

    /// The rays of a packet in lanes: `H` registers of 8 lanes per quantity (8·H rays).
    struct Lanes<const H: usize> {
        rdir: [[__m256; 3]; H],
        org_near: [[__m256; 3]; H],
        org_far: [[__m256; 3]; H],
        /// All ones in a lane whose direction is negative on that axis (near plane = upper).
        negative: [[__m256; 3]; H],
        tmin: [__m256; H],
        /// Kept equal to `tmax_s` (reloaded after every leaf that shrinks it).
        tmax: [__m256; H],
        tmax_s: [f32; 16],
        tmin_s: [f32; 16],
        tri: [TriRay; 16],
        origin: [glam::Vec3; 16],
        /// Near and far plane rows per axis when every ray of the packet has the same direction
        /// signs (eye rays, shadow rays to one light: nearly always); `mixed` otherwise.
        near_row: [usize; 3],
        far_row: [usize; 3],
        mixed: bool,
    }

    #[derive(Clone, Copy, Default)]
    struct Entry {
        node: u32,
        mask: u32,
        dist: f32,
    }

    /// Loads 8 floats of a lane array.
    #[inline(always)]
    unsafe fn load8(a: &[f32; 16], h: usize) -> __m256 {
        _mm256_loadu_ps(a.as_ptr().add(8 * h))
    }

    /// Sets up the lanes of `rays` (at most 8·H; lanes past the end and rays that cannot be
    /// traced are left out of the returned active mask).
    #[inline(always)]
    unsafe fn prepare<const N: usize, const H: usize, const W: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
    ) -> (Lanes<H>, u32) {
        let mut rdir = [[0.0f32; 16]; 3];
        let mut org_near = [[0.0f32; 16]; 3];
        let mut org_far = [[0.0f32; 16]; 3];
        let mut neg = [[0.0f32; 16]; 3];
        let mut tmin_s = [0.0f32; 16];
        let mut tmax_s = [f32::NEG_INFINITY; 16];
        let mut active = 0u32;
        let blank = <Sse4 as PacketKernel<PACKET>>::prepare(
            glam::Vec3::ZERO,
            glam::Vec3::X,
            &WatertightRay::new(glam::Vec3::X),
        );
        let mut tri = [blank; 16];
        let mut origin = [glam::Vec3::ZERO; 16];
        let mut signs: Option<[bool; 3]> = None;
        let mut mixed = false;
        for (l, ray) in rays.iter().enumerate() {
            if !ray.is_traceable() {
                continue;
            }
            active |= 1 << l;
            let s = SlabRay::new(ray, bvh.extent);
            for a in 0..3 {
                rdir[a][l] = s.rdir[a];
                org_near[a][l] = s.org_rdir_near[a];
                org_far[a][l] = s.org_rdir_far[a];
                neg[a][l] = if s.negative[a] {
                    f32::from_bits(u32::MAX)
                } else {
                    0.0
                };
            }
            tmin_s[l] = ray.tmin;
            tmax_s[l] = ray.tmax;
            let wt = watertight::<W>(ray.dir);
            tri[l] = <Sse4 as PacketKernel<PACKET>>::prepare(ray.origin, ray.dir, &wt);
            origin[l] = ray.origin;
            match signs {
                None => signs = Some(s.negative),
                Some(g) => mixed |= g != s.negative,
            }
        }
        let g = signs.unwrap_or([false; 3]);
        let near_row = [0, 1, 2].map(|a| 2 * a + g[a] as usize);
        let far_row = [0, 1, 2].map(|a| 2 * a + 1 - g[a] as usize);
        let lanes = Lanes {
            rdir: std::array::from_fn(|h| std::array::from_fn(|a| load8(&rdir[a], h))),
            org_near: std::array::from_fn(|h| std::array::from_fn(|a| load8(&org_near[a], h))),
            org_far: std::array::from_fn(|h| std::array::from_fn(|a| load8(&org_far[a], h))),
            negative: std::array::from_fn(|h| std::array::from_fn(|a| load8(&neg[a], h))),
            tmin: std::array::from_fn(|h| load8(&tmin_s, h)),
            tmax: std::array::from_fn(|h| load8(&tmax_s, h)),
            tmax_s,
            tmin_s,
            tri,
            origin,
            near_row,
            far_row,
            mixed,
        };
        (lanes, active)
    }

    /// Child `i`'s box against every lane: the lanes that hit it (within each lane's
    /// `[tmin, tmax]`) and, with `ORDER`, the nearest entry distance among them. Per lane this
    /// is the single-ray AVX2 test's arithmetic (`box_test.rs`): the near plane of each axis by
    /// the lane's direction sign, `plane · rdir − org · rdir` in one `fmsub`. `MIXED`: the
    /// packet's rays differ in sign, and each lane picks its planes with a blend; otherwise the
    /// rows are picked once for the packet, as the single-ray test does.
    #[inline(always)]
    unsafe fn child_test<const N: usize, const H: usize, const MIXED: bool, const ORDER: bool>(
        node: &super::super::node::WideNode<N>,
        i: usize,
        r: &Lanes<H>,
        active: u32,
    ) -> (u32, f32) {
        let p = &node.planes;
        let (near_b, far_b) = if MIXED {
            (
                [
                    _mm256_set1_ps(p[0][i]),
                    _mm256_set1_ps(p[2][i]),
                    _mm256_set1_ps(p[4][i]),
                ],
                [
                    _mm256_set1_ps(p[1][i]),
                    _mm256_set1_ps(p[3][i]),
                    _mm256_set1_ps(p[5][i]),
                ],
            )
        } else {
            (
                [0, 1, 2].map(|a| _mm256_set1_ps(p[r.near_row[a]][i])),
                [0, 1, 2].map(|a| _mm256_set1_ps(p[r.far_row[a]][i])),
            )
        };
        let mut mask = 0u32;
        let mut nearest = _mm256_set1_ps(f32::INFINITY);
        for h in 0..H {
            if (active >> (8 * h)) & 0xff == 0 {
                continue;
            }
            // MIXED: near_b holds the lower planes and far_b the upper ones.
            let near = |a: usize| {
                let plane = if MIXED {
                    _mm256_blendv_ps(near_b[a], far_b[a], r.negative[h][a])
                } else {
                    near_b[a]
                };
                _mm256_fmsub_ps(plane, r.rdir[h][a], r.org_near[h][a])
            };
            let far = |a: usize| {
                let plane = if MIXED {
                    _mm256_blendv_ps(far_b[a], near_b[a], r.negative[h][a])
                } else {
                    far_b[a]
                };
                _mm256_fmsub_ps(plane, r.rdir[h][a], r.org_far[h][a])
            };
            let t_near = _mm256_max_ps(
                _mm256_max_ps(near(0), near(1)),
                _mm256_max_ps(near(2), r.tmin[h]),
            );
            let t_far = _mm256_min_ps(
                _mm256_min_ps(far(0), far(1)),
                _mm256_min_ps(far(2), r.tmax[h]),
            );
            let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(t_near, t_far);
            let m = (_mm256_movemask_ps(hit) as u32) << (8 * h);
            mask |= m;
            if ORDER {
                nearest = _mm256_min_ps(
                    nearest,
                    _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), t_near, hit),
                );
            }
        }
        mask &= active;
        if mask == 0 || !ORDER {
            return (mask, 0.0);
        }
        // Horizontal minimum (lanes outside `active` only widen it: still a valid order key).
        let m4 = _mm_min_ps(
            _mm256_castps256_ps128(nearest),
            _mm256_extractf128_ps::<1>(nearest),
        );
        let m2 = _mm_min_ps(m4, _mm_movehl_ps(m4, m4));
        let m1 = _mm_min_ss(m2, _mm_shuffle_ps::<1>(m2, m2));
        (mask, _mm_cvtss_f32(m1))
    }

    #[inline(always)]
    unsafe fn reload_tmax<const H: usize>(r: &mut Lanes<H>) {
        for h in 0..H {
            r.tmax[h] = load8(&r.tmax_s, h);
        }
    }

    /// Closest hits of a packet (`rays.len() ≤ 8·H`).
    #[inline(always)]
    unsafe fn closest_packet<const N: usize, const H: usize, const W: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        hits: &mut [Hit],
        stack: &mut [Entry; STACK_SIZE],
        c: &mut Counters,
    ) {
        for h in hits.iter_mut() {
            *h = Hit::MISS;
        }
        let (r, active) = prepare::<N, H, W>(bvh, rays);
        if active == 0 {
            return;
        }
        if r.mixed {
            closest_lanes::<N, H, W, true>(bvh, rays, hits, stack, c, r, active)
        } else {
            closest_lanes::<N, H, W, false>(bvh, rays, hits, stack, c, r, active)
        }
    }

    #[inline(always)]
    unsafe fn closest_lanes<const N: usize, const H: usize, const W: bool, const MIXED: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        hits: &mut [Hit],
        stack: &mut [Entry; STACK_SIZE],
        c: &mut Counters,
        mut r: Lanes<H>,
        active: u32,
    ) {
        let mut lanes = LaneHits::default();
        let mut sp = 0usize;
        let mut cur = Entry {
            node: bvh.root,
            mask: active,
            dist: f32::NEG_INFINITY,
        };
        loop {
            if !is_leaf(cur.node) {
                let node = &bvh.nodes[cur.node as usize];
                let n_active = cur.mask.count_ones() as u64;
                c.nodes_visited += n_active;
                c.box_tests += n_active * node.len as u64;
                let base = sp;
                for i in 0..(node.len as usize).min(N) {
                    let (mask, dist) = child_test::<N, H, MIXED, true>(node, i, &r, cur.mask);
                    if mask != 0 {
                        stack[sp] = Entry {
                            node: node.child[i],
                            mask,
                            dist,
                        };
                        sp += 1;
                    }
                }
                // Farthest first, so the nearest is popped next (insertion sort, ≤ N entries).
                for a in base + 1..sp {
                    let e = stack[a];
                    let mut b = a;
                    while b > base && stack[b - 1].dist < e.dist {
                        stack[b] = stack[b - 1];
                        b -= 1;
                    }
                    stack[b] = e;
                }
            } else if is_packet_leaf(cur.node) {
                let (packets, count) = leaf_packets(bvh, cur.node);
                let mut m = cur.mask;
                let mut shrunk = false;
                while m != 0 {
                    let l = m.trailing_zeros() as usize;
                    m &= m - 1;
                    c.primitive_tests += count as u64;
                    let (tmin, mut tmax) = (r.tmin_s[l], r.tmax_s[l]);
                    for p in packets {
                        let hit = <Sse4 as PacketKernel<PACKET>>::test::<W>(
                            &p.tri, &r.tri[l], tmin, tmax, &mut lanes,
                        );
                        if hit != 0 {
                            c.primitive_hits += hit.count_ones() as u64;
                            let i = lanes.nearest(hit);
                            tmax = lanes.t[i];
                            hits[l] = Hit {
                                t: lanes.t[i],
                                object: p.object[i],
                                u: lanes.u[i],
                                v: lanes.v[i],
                            };
                        }
                    }
                    if tmax != r.tmax_s[l] {
                        r.tmax_s[l] = tmax;
                        shrunk = true;
                    }
                }
                if shrunk {
                    reload_tmax(&mut r);
                }
            } else {
                let (first, count) = leaf_range(cur.node);
                let mut m = cur.mask;
                let mut shrunk = false;
                while m != 0 {
                    let l = m.trailing_zeros() as usize;
                    m &= m - 1;
                    let ray = &rays[l];
                    let mut rr = Ray::new(r.origin[l], ray.dir, r.tmin_s[l], r.tmax_s[l]);
                    let wt = watertight::<W>(ray.dir);
                    let test = triangle_test::<W>();
                    for k in first..first + count {
                        c.primitive_tests += 1;
                        if let Some((t, u, v)) = bvh.prims[k].intersect(&rr, test, &wt) {
                            c.primitive_hits += 1;
                            rr.tmax = t;
                            hits[l] = Hit {
                                t,
                                object: bvh.objects[k],
                                u,
                                v,
                            };
                        }
                    }
                    if rr.tmax != r.tmax_s[l] {
                        r.tmax_s[l] = rr.tmax;
                        shrunk = true;
                    }
                }
                if shrunk {
                    reload_tmax(&mut r);
                }
            }
            // Next: the nearest pending entry that some ray of its mask may still need.
            loop {
                if sp == 0 {
                    return;
                }
                sp -= 1;
                let e = stack[sp];
                let mut m = e.mask;
                let mut keep = 0u32;
                while m != 0 {
                    let l = m.trailing_zeros() as usize;
                    m &= m - 1;
                    if e.dist <= r.tmax_s[l] {
                        keep |= 1 << l;
                    }
                }
                if keep != 0 {
                    cur = Entry { mask: keep, ..e };
                    break;
                }
            }
        }
    }

    /// Any-hit answers of a packet (`rays.len() ≤ 8·H`): a ray leaves the packet at its first
    /// hit; the packet stops when no ray is left.
    #[inline(always)]
    unsafe fn any_packet<const N: usize, const H: usize, const W: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        out: &mut [bool],
        stack: &mut [Entry; STACK_SIZE],
        c: &mut Counters,
    ) {
        for o in out.iter_mut() {
            *o = false;
        }
        let (r, active) = prepare::<N, H, W>(bvh, rays);
        if r.mixed {
            any_lanes::<N, H, W, true>(bvh, rays, out, stack, c, &r, active)
        } else {
            any_lanes::<N, H, W, false>(bvh, rays, out, stack, c, &r, active)
        }
    }

    #[inline(always)]
    unsafe fn any_lanes<const N: usize, const H: usize, const W: bool, const MIXED: bool>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        out: &mut [bool],
        stack: &mut [Entry; STACK_SIZE],
        c: &mut Counters,
        r: &Lanes<H>,
        mut active: u32,
    ) {
        let mut lanes = LaneHits::default();
        let mut sp = 0usize;
        let mut cur = bvh.root;
        let mut cur_mask = active;
        while active != 0 {
            let mask = cur_mask & active;
            if mask != 0 {
                if !is_leaf(cur) {
                    let node = &bvh.nodes[cur as usize];
                    let n_active = mask.count_ones() as u64;
                    c.nodes_visited += n_active;
                    c.box_tests += n_active * node.len as u64;
                    for i in 0..(node.len as usize).min(N) {
                        let (m, _) = child_test::<N, H, MIXED, false>(node, i, r, mask);
                        if m != 0 {
                            stack[sp] = Entry {
                                node: node.child[i],
                                mask: m,
                                dist: 0.0,
                            };
                            sp += 1;
                        }
                    }
                } else if is_packet_leaf(cur) {
                    let (packets, count) = leaf_packets(bvh, cur);
                    let mut m = mask;
                    while m != 0 {
                        let l = m.trailing_zeros() as usize;
                        m &= m - 1;
                        let (tmin, tmax) = (r.tmin_s[l], r.tmax_s[l]);
                        let mut tested = count as u64;
                        for (n, p) in packets.iter().enumerate() {
                            let hit = <Sse4 as PacketKernel<PACKET>>::test::<W>(
                                &p.tri, &r.tri[l], tmin, tmax, &mut lanes,
                            );
                            if hit != 0 {
                                tested = count.min((n + 1) * PACKET) as u64;
                                c.primitive_hits += hit.count_ones() as u64;
                                out[l] = true;
                                active &= !(1 << l);
                                break;
                            }
                        }
                        c.primitive_tests += tested;
                    }
                } else {
                    let (first, count) = leaf_range(cur);
                    let mut m = mask;
                    while m != 0 {
                        let l = m.trailing_zeros() as usize;
                        m &= m - 1;
                        let ray = &rays[l];
                        let wt = watertight::<W>(ray.dir);
                        let test = triangle_test::<W>();
                        for k in first..first + count {
                            c.primitive_tests += 1;
                            if bvh.prims[k].intersect(ray, test, &wt).is_some() {
                                c.primitive_hits += 1;
                                out[l] = true;
                                active &= !(1 << l);
                                break;
                            }
                        }
                    }
                }
            }
            if sp == 0 {
                return;
            }
            sp -= 1;
            cur = stack[sp].node;
            cur_mask = stack[sp].mask;
        }
    }

    pub fn closest_entry<const N: usize, const H: usize>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        hits: &mut [Hit],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        assert!(Avx8::available(), "this kernel needs AVX2 and FMA");
        // SAFETY: the CPU has AVX2 and FMA (asserted above), all the callee requires.
        unsafe { closest_impl::<N, H>(bvh, rays, hits, t, c) }
    }

    pub fn any_entry<const N: usize, const H: usize>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        out: &mut [bool],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        assert!(Avx8::available(), "this kernel needs AVX2 and FMA");
        // SAFETY: the CPU has AVX2 and FMA (asserted above), all the callee requires.
        unsafe { any_impl::<N, H>(bvh, rays, out, t, c) }
    }

    #[target_feature(enable = "avx2,fma")]
    unsafe fn closest_impl<const N: usize, const H: usize>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        hits: &mut [Hit],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        let mut stack = [Entry::default(); STACK_SIZE];
        let k = 8 * H;
        for (rs, hs) in rays.chunks(k).zip(hits.chunks_mut(k)) {
            match t {
                TriangleTest::Watertight => {
                    closest_packet::<N, H, true>(bvh, rs, hs, &mut stack, c)
                }
                TriangleTest::Moller => closest_packet::<N, H, false>(bvh, rs, hs, &mut stack, c),
            }
        }
        c.rays += rays.len() as u64;
    }

    #[target_feature(enable = "avx2,fma")]
    unsafe fn any_impl<const N: usize, const H: usize>(
        bvh: &Bvh<N>,
        rays: &[Ray],
        out: &mut [bool],
        t: TriangleTest,
        c: &mut Counters,
    ) {
        let mut stack = [Entry::default(); STACK_SIZE];
        let k = 8 * H;
        for (rs, os) in rays.chunks(k).zip(out.chunks_mut(k)) {
            match t {
                TriangleTest::Watertight => any_packet::<N, H, true>(bvh, rs, os, &mut stack, c),
                TriangleTest::Moller => any_packet::<N, H, false>(bvh, rs, os, &mut stack, c),
            }
        }
        c.rays += rays.len() as u64;
    }
}
