//! Single-ray traversal of an N-wide BVH: closest hit and any hit, generic over the slab test
//! ([`ChildTest`]: scalar, SSE or AVX2), with an explicit fixed-size stack (no allocation per
//! ray; 001 §1.9 recursed instead).
//!
//! Order: 001 §1.9 visits children front to back by the sign of the ray direction on the
//! node's split axis (Wald, Boulos and Shirley 2007). Children of a collapsed wide node lie on
//! no single axis, so here, as in Embree's `BVHNNodeTraverser1Hit`, the children a ray hits
//! are ordered by their entry distance: one hit is visited at once, two are compared, more are
//! pushed and sorted so the nearest is popped first. Each stack entry keeps its entry distance,
//! and entries farther than the closest hit found so far are dropped when popped.
//!
//! Any-hit queries (shadow rays) need no order and stop at the first hit (Embree's separate
//! `occluded` kernel does the same).
//!
//! Leaves of triangle packets ([`super::leaf`]) are tested a packet at a time with the shared
//! packet kernel ([`PacketKernel`]: SSE, or lane by lane with `simd=off`). The counters stay
//! exact: `primitive_tests` counts the triangles of a packet leaf (not its padding);
//! `primitive_hits` counts the triangles of a packet that hit within the segment as it was
//! when the packet was tested (testing one by one counts only those that shrink it).

use super::box_test::ChildTest;
use super::leaf::{LeafPacket, PACKET};
use super::node::{is_leaf, is_packet_leaf, leaf_range, packet_range, WideNode};
use super::ray_setup;
use super::tree::MAX_DEPTH;
use crate::engine::Counters;
use crate::geometry::kernels::f32::WatertightRay;
use crate::geometry::triangle_simd::{LaneHits, PairKernel};
use crate::geometry::Prim;
use crate::geometry::TriangleTest;
use crate::ray::{Hit, Ray};

/// The widest tree traversed (bvh8; wider trees are built for statistics only).
pub const MAX_TRAVERSAL_WIDTH: usize = 8;
/// A traversal holds at most N − 1 pending siblings per level of the tree.
pub const STACK_SIZE: usize = (MAX_TRAVERSAL_WIDTH - 1) * MAX_DEPTH + 1;
/// The any-hit stack: [`STACK_SIZE`] and room for a whole node's children written past its
/// top (`ChildTest::compress_children` writes N entries, of which only the pushed count).
const ANY_STACK_SIZE: usize = STACK_SIZE + MAX_TRAVERSAL_WIDTH;

/// A built BVH as traversal reads it: flat node array, root reference, and the primitives in
/// leaf order with their scene objects: triangle packets (packet leaves index `packets`) and
/// scalar primitives (other leaves index `prims` and `objects`).
pub struct Bvh<const N: usize> {
    pub nodes: Vec<WideNode<N>>,
    pub root: u32,
    pub prims: Vec<Prim>,
    pub objects: Vec<u32>,
    pub packets: Vec<LeafPacket>,
    /// The largest absolute coordinate of the root's bounds (0 when empty): the conservative
    /// slab test's bound on plane magnitudes (`SlabRay`).
    pub extent: f32,
}

/// Where child reference `c` points: its node, or its leaf's first packet or primitive. Only
/// ever prefetched, never read through, so it is computed with wrapping arithmetic and no check.
#[inline(always)]
fn child_addr<const N: usize>(bvh: &Bvh<N>, c: u32) -> *const u8 {
    let node = bvh.nodes.as_ptr().wrapping_add(c as usize) as *const u8;
    if !is_leaf(c) {
        node
    } else if is_packet_leaf(c) {
        bvh.packets.as_ptr().wrapping_add(packet_range(c).0) as *const u8
    } else {
        bvh.prims.as_ptr().wrapping_add(leaf_range(c).0) as *const u8
    }
}

/// The packets of a packet leaf reference, and its triangle count.
#[inline(always)]
fn leaf_packets<const N: usize>(bvh: &Bvh<N>, c: u32) -> (&[LeafPacket], usize) {
    let (first, count) = packet_range(c);
    (&bvh.packets[first..first + count.div_ceil(PACKET)], count)
}

#[derive(Clone, Copy, Default)]
struct Entry {
    node: u32,
    dist: f32,
}

/// The packet tests' output lanes: written by a test before they are read, so made once a
/// batch (setting them for every ray cost 8 stores a ray).
#[derive(Default)]
struct Lanes {
    one: LaneHits<4>,
    pair: LaneHits<8>,
}

/// Counts kept in registers during a batch and added to `Counters` once.
#[derive(Default)]
struct Tally {
    nodes: u64,
    boxes: u64,
    prims: u64,
    prim_hits: u64,
}

/// A node visit in a ray's packed visit count: nodes above bit 32, their boxes below (one
/// scalar add a node; two separate counts were kept in a vector register, two inserts and
/// an add a node).
const NODE_VISIT: u64 = 1 << 32;

impl Tally {
    /// A ray's packed visits ([`NODE_VISIT`]) added to the counts.
    #[inline(always)]
    fn add_visits(&mut self, visits: u64) {
        self.nodes += visits >> 32;
        self.boxes += visits & 0xffff_ffff;
    }

    fn add_to(&self, c: &mut Counters, rays: usize) {
        c.rays += rays as u64;
        c.nodes_visited += self.nodes;
        c.box_tests += self.boxes;
        c.primitive_tests += self.prims;
        c.primitive_hits += self.prim_hits;
    }
}

/// The ray's triangle set-up ([`triangle_setup`]), made at the first leaf that tests a
/// triangle and kept for the rest of the ray. Rays of the scenes of spheres and cones (balls,
/// rings, tree) mostly reach no triangle, and the set-up (the watertight axes and shear, and
/// the packet kernel's splatted lanes) was about 60 of a shadow ray's instructions. The values
/// are the same whenever they are made, so hits and counters are too.
struct LazyTriangleRay<'a, P: PairKernel, const W: bool> {
    ray: &'a Ray,
    made: Option<(P::Ray, WatertightRay)>,
}

impl<'a, P: PairKernel, const W: bool> LazyTriangleRay<'a, P, W> {
    #[inline(always)]
    fn new(ray: &'a Ray) -> Self {
        LazyTriangleRay { ray, made: None }
    }

    /// Written out rather than `Option::get_or_insert_with`: that generic function is compiled
    /// without the kernels' target features, so the set-up's intrinsics did not inline into it
    /// (callgrind: 30 % more instructions on gears4).
    #[inline(always)]
    fn get(&mut self) -> &(P::Ray, WatertightRay) {
        if self.made.is_none() {
            self.made = Some(triangle_setup::<P, W>(self.ray));
        }
        match &self.made {
            Some(made) => made,
            // SAFETY: set just above when it was `None`.
            None => unsafe { std::hint::unreachable_unchecked() },
        }
    }

    /// The watertight set-up a scalar primitive's test takes: the ray's own for a triangle
    /// under the watertight test, and one no test reads otherwise (spheres and cones ignore
    /// it; Möller–Trumbore takes none).
    #[inline(always)]
    fn scalar(&mut self, prim: &Prim) -> WatertightRay {
        if W && matches!(prim, Prim::Triangle(_)) {
            self.get().1
        } else {
            UNUSED_WATERTIGHT
        }
    }
}

/// The watertight set-up passed where no test reads it (as `triangle_setup` makes for
/// Möller–Trumbore).
const UNUSED_WATERTIGHT: WatertightRay = WatertightRay {
    kx: 0,
    ky: 1,
    kz: 2,
    sx: 0.0,
    sy: 0.0,
    sz: 0.0,
};

/// The per-ray set-up of the triangle test (the packet kernel's lanes, and the watertight
/// set-up for scalar primitives), made only for the watertight test.
#[inline(always)]
fn triangle_setup<P: PairKernel, const W: bool>(ray: &Ray) -> (P::Ray, WatertightRay) {
    if W {
        P::prepare_watertight(ray, ray_setup::watertight)
    } else {
        let wt = UNUSED_WATERTIGHT;
        (P::prepare(ray.origin, ray.dir, &wt), wt)
    }
}

/// The hits of a pair test as testing its two packets one after the other counts them: all of
/// the first packet's, and those of the second nearer than the first's nearest.
#[inline(always)]
fn pair_hits(lanes: &LaneHits<8>, mask: u32) -> u64 {
    let (a, mut b) = (mask & 0xf, mask >> PACKET);
    if a != 0 && b != 0 {
        let near = lanes.t[lanes.nearest(a)];
        let mut kept = 0;
        while b != 0 {
            let i = b.trailing_zeros() as usize;
            b &= b - 1;
            kept += (lanes.t[PACKET + i] < near) as u32;
        }
        b = kept;
        return (a.count_ones() + b) as u64;
    }
    (a.count_ones() + b.count_ones()) as u64
}

/// One exchange of a sorting network over pending entries, `lower` below `upper` on the
/// stack: swapped only when `lower` is strictly nearer, so entries of equal distance keep
/// their order and a network of adjacent exchanges sorts stably, as the insertion sort does.
#[inline(always)]
fn order(lower: &mut Entry, upper: &mut Entry) {
    if lower.dist < upper.dist {
        std::mem::swap(lower, upper);
    }
}

#[inline(always)]
fn triangle_test<const W: bool>() -> TriangleTest {
    if W {
        TriangleTest::Watertight
    } else {
        TriangleTest::Moller
    }
}

/// `OCT` of a traversal whose box test takes the plane rows from the ray at run time.
const ANY_OCTANT: u32 = 8;

/// The ray's node test: with the plane rows of octant `OCT` as constants, or
/// ([`ANY_OCTANT`]) from the ray.
#[inline(always)]
fn node_test<const N: usize, T: ChildTest<N>, const OCT: u32>(
    node: &WideNode<N>,
    tr: &T::Ray,
    tmin: f32,
    tmax: f32,
    dist: &mut [f32; N],
) -> u32 {
    if OCT < ANY_OCTANT {
        T::test_octant::<OCT>(node, tr, tmin, tmax, dist)
    } else {
        T::test(node, tr, tmin, tmax, dist)
    }
}

/// `f::<generics…, OCT>(args…)` with `OCT` the octant `oct` (0–7) as a constant: one loop
/// per octant, as the SIMD box tests want ([`ChildTest::OCTANTS`]).
macro_rules! by_octant {
    ($oct:expr, $f:ident::<$($g:tt),*>($($arg:expr),*)) => {
        match $oct {
            0 => $f::<$($g),*, 0>($($arg),*),
            1 => $f::<$($g),*, 1>($($arg),*),
            2 => $f::<$($g),*, 2>($($arg),*),
            3 => $f::<$($g),*, 3>($($arg),*),
            4 => $f::<$($g),*, 4>($($arg),*),
            5 => $f::<$($g),*, 5>($($arg),*),
            6 => $f::<$($g),*, 6>($($arg),*),
            _ => $f::<$($g),*, 7>($($arg),*),
        }
    };
}

/// Closest hits of a batch of rays.
#[inline(always)]
pub fn closest_batch<const N: usize, T: ChildTest<N>, P: PairKernel>(
    bvh: &Bvh<N>,
    rays: &[Ray],
    hits: &mut [Hit],
    test: TriangleTest,
    counters: &mut Counters,
) {
    let mut stack = [Entry::default(); STACK_SIZE];
    let mut tally = Tally::default();
    let mut lanes = Lanes::default();
    for (ray, hit) in rays.iter().zip(hits.iter_mut()) {
        let (s, l, t) = (&mut stack, &mut lanes, &mut tally);
        *hit = match test {
            TriangleTest::Watertight if T::OCTANTS => by_octant!(
                ray_setup::octant(ray),
                closest::<N, T, P, true>(bvh, ray, s, l, t)
            ),
            TriangleTest::Watertight => closest::<N, T, P, true, ANY_OCTANT>(bvh, ray, s, l, t),
            TriangleTest::Moller => closest::<N, T, P, false, ANY_OCTANT>(bvh, ray, s, l, t),
        };
    }
    tally.add_to(counters, rays.len());
}

/// Any-hit answers of a batch of rays.
#[inline(always)]
pub fn any_batch<const N: usize, T: ChildTest<N>, P: PairKernel>(
    bvh: &Bvh<N>,
    rays: &[Ray],
    out: &mut [bool],
    test: TriangleTest,
    counters: &mut Counters,
) {
    let mut stack = [0u32; ANY_STACK_SIZE];
    let mut tally = Tally::default();
    let mut lanes = Lanes::default();
    for (ray, o) in rays.iter().zip(out.iter_mut()) {
        let (s, l, t) = (&mut stack, &mut lanes, &mut tally);
        *o = match test {
            TriangleTest::Watertight if T::OCTANTS => {
                by_octant!(
                    ray_setup::octant(ray),
                    any::<N, T, P, true>(bvh, ray, s, l, t)
                )
            }
            TriangleTest::Watertight => any::<N, T, P, true, ANY_OCTANT>(bvh, ray, s, l, t),
            TriangleTest::Moller => any::<N, T, P, false, ANY_OCTANT>(bvh, ray, s, l, t),
        };
    }
    tally.add_to(counters, rays.len());
}

#[inline(always)]
fn closest<const N: usize, T: ChildTest<N>, P: PairKernel, const W: bool, const OCT: u32>(
    bvh: &Bvh<N>,
    ray: &Ray,
    stack: &mut [Entry; STACK_SIZE],
    lanes: &mut Lanes,
    tally: &mut Tally,
) -> Hit {
    if !ray_setup::traceable(ray) {
        return Hit::MISS;
    }
    let tr = T::prepare_ray(ray, bvh.extent);
    let mut setup = LazyTriangleRay::<P, W>::new(ray);
    let Lanes {
        one: lanes,
        pair: pair_lanes,
    } = lanes;
    let (tmin, mut tmax) = (ray.tmin, ray.tmax);
    let mut best = Hit::MISS;
    let mut dist = [0.0f32; N];
    let mut sp = 0usize;
    let mut cur = bvh.root;
    let mut visits = 0u64;
    loop {
        if !is_leaf(cur) {
            let node = &bvh.nodes[cur as usize];
            visits += NODE_VISIT | node.len as u64;
            let mut mask = node_test::<N, T, OCT>(node, &tr, tmin, tmax, &mut dist);
            if mask != 0 {
                let i = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if mask == 0 {
                    cur = node.child[i];
                    continue;
                }
                let j = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if mask == 0 {
                    let (near, far) = if dist[j] < dist[i] { (j, i) } else { (i, j) };
                    // A child put on the stack is fetched while its sibling is traversed
                    // (Embree prefetches every child it is going to visit).
                    T::prefetch(child_addr(bvh, node.child[far]));
                    stack[sp] = Entry {
                        node: node.child[far],
                        dist: dist[far],
                    };
                    sp += 1;
                    cur = node.child[near];
                    continue;
                }
                // Three or more: sorted farthest first (bottom) to nearest (top), equal
                // distances in child order (a stable sort of the children in slot order).
                let entry = |k: usize| {
                    T::prefetch(child_addr(bvh, node.child[k]));
                    Entry {
                        node: node.child[k],
                        dist: dist[k],
                    }
                };
                let k = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let (mut a, mut b, mut c) = (entry(i), entry(j), entry(k));
                if mask == 0 {
                    // Three: sorted in registers by adjacent exchanges (Embree's `sort` of
                    // three stack items).
                    order(&mut a, &mut b);
                    order(&mut b, &mut c);
                    order(&mut a, &mut b);
                    stack[sp] = a;
                    stack[sp + 1] = b;
                    sp += 2;
                    cur = c.node;
                    continue;
                }
                let l = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let mut d = entry(l);
                if mask == 0 {
                    // Four: odd-even transposition (four rounds of adjacent exchanges).
                    order(&mut a, &mut b);
                    order(&mut c, &mut d);
                    order(&mut b, &mut c);
                    order(&mut a, &mut b);
                    order(&mut c, &mut d);
                    order(&mut b, &mut c);
                    stack[sp] = a;
                    stack[sp + 1] = b;
                    stack[sp + 2] = c;
                    sp += 3;
                    cur = d.node;
                    continue;
                }
                // Five or more: push all, then insertion-sort the new entries.
                let base = sp;
                for e in [a, b, c, d] {
                    stack[sp] = e;
                    sp += 1;
                }
                while mask != 0 {
                    let k = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    stack[sp] = entry(k);
                    sp += 1;
                }
                for a in base + 1..sp {
                    let e = stack[a];
                    let mut b = a;
                    while b > base && stack[b - 1].dist < e.dist {
                        stack[b] = stack[b - 1];
                        b -= 1;
                    }
                    stack[b] = e;
                }
                sp -= 1;
                cur = stack[sp].node;
                continue;
            }
        } else if is_packet_leaf(cur) {
            let (packets, count) = leaf_packets(bvh, cur);
            tally.prims += count as u64;
            let pr = &setup.get().0;
            // Two packets per test (`PairKernel`), both against the segment as it was before
            // them. Testing them one after the other would test the second against the first's
            // nearest hit: the nearest of the eight lanes (the first packet's on a tie of t) is
            // the hit that would have kept, and `prim_hits` counts the second packet's hits
            // only where they are nearer than the first's.
            let n = packets.len();
            let mut k = 0;
            while k + 1 < n {
                let (a, b) = (&packets[k], &packets[k + 1]);
                let mask = P::test_pair::<W>(&a.tri, &b.tri, pr, tmin, tmax, pair_lanes);
                if mask != 0 {
                    let i = pair_lanes.nearest(mask);
                    tally.prim_hits += pair_hits(pair_lanes, mask);
                    tmax = pair_lanes.t[i];
                    let p = if i < PACKET { a } else { b };
                    best = Hit {
                        t: pair_lanes.t[i],
                        object: p.object[i % PACKET],
                        u: pair_lanes.u[i],
                        v: pair_lanes.v[i],
                    };
                }
                k += 2;
            }
            if k < n {
                let p = &packets[k];
                let mask = P::test::<W>(&p.tri, pr, tmin, tmax, lanes);
                if mask != 0 {
                    tally.prim_hits += mask.count_ones() as u64;
                    let i = lanes.nearest(mask);
                    tmax = lanes.t[i];
                    best = Hit {
                        t: lanes.t[i],
                        object: p.object[i],
                        u: lanes.u[i],
                        v: lanes.v[i],
                    };
                }
            }
        } else {
            let (first, count) = leaf_range(cur);
            for k in first..first + count {
                tally.prims += 1;
                let r = Ray { tmax, ..*ray };
                let wt = setup.scalar(&bvh.prims[k]);
                if let Some((t, u, v)) = bvh.prims[k].intersect(&r, triangle_test::<W>(), &wt) {
                    tally.prim_hits += 1;
                    tmax = t;
                    best = Hit {
                        t,
                        object: bvh.objects[k],
                        u,
                        v,
                    };
                }
            }
        }
        // Next: the nearest pending entry not beyond the closest hit so far.
        loop {
            if sp == 0 {
                tally.add_visits(visits);
                return best;
            }
            sp -= 1;
            let e = stack[sp];
            if e.dist <= tmax {
                cur = e.node;
                break;
            }
        }
    }
}

#[inline(always)]
fn any<const N: usize, T: ChildTest<N>, P: PairKernel, const W: bool, const OCT: u32>(
    bvh: &Bvh<N>,
    ray: &Ray,
    stack: &mut [u32; ANY_STACK_SIZE],
    lanes: &mut Lanes,
    tally: &mut Tally,
) -> bool {
    if !ray_setup::traceable(ray) {
        return false;
    }
    let tr = T::prepare_ray(ray, bvh.extent);
    let mut setup = LazyTriangleRay::<P, W>::new(ray);
    let Lanes {
        one: lanes,
        pair: pair_lanes,
    } = lanes;
    let (tmin, tmax) = (ray.tmin, ray.tmax);
    let mut dist = [0.0f32; N];
    let mut sp = 0usize;
    let mut cur = bvh.root;
    let mut visits = 0u64;
    loop {
        if !is_leaf(cur) {
            let node = &bvh.nodes[cur as usize];
            visits += NODE_VISIT | node.len as u64;
            let mut mask = node_test::<N, T, OCT>(node, &tr, tmin, tmax, &mut dist);
            if mask != 0 {
                let i = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                // The others are pushed in slot order, all at once (`compress_children`), and
                // without asking first whether there are any: that branch went either way
                // (cachegrind's simulation: 36 % of it mispredicted on gears4), and with none
                // the call stores entries past the top that are never read.
                let out: &mut [u32; N] = (&mut stack[sp..sp + N]).try_into().unwrap();
                sp += T::compress_children(node, mask, out, |c| T::prefetch(child_addr(bvh, c)));
                cur = node.child[i];
                continue;
            }
        } else if is_packet_leaf(cur) {
            let (packets, count) = leaf_packets(bvh, cur);
            let pr = &setup.get().0;
            // Two packets per test (`PairKernel`); the counters as if tested one by one. An
            // index loop: leaves hold 2.0 packets on average, and the chunk iterator's set-up
            // (pairs, remainder, enumeration) cost more than the one pair it mostly yields.
            let n = packets.len();
            let mut k = 0;
            while k + 1 < n {
                let (a, b) = (&packets[k].tri, &packets[k + 1].tri);
                let mask = P::test_pair::<W>(a, b, pr, tmin, tmax, pair_lanes);
                if mask != 0 {
                    // The leaf stops at the first packet with a hit: its triangles and those
                    // before it.
                    let (first, m) = if mask & 0xf != 0 {
                        (k, mask & 0xf)
                    } else {
                        (k + 1, mask >> PACKET)
                    };
                    tally.prims += count.min((first + 1) * PACKET) as u64;
                    tally.prim_hits += m.count_ones() as u64;
                    tally.add_visits(visits);
                    return true;
                }
                k += 2;
            }
            if k < n {
                let mask = P::test::<W>(&packets[k].tri, pr, tmin, tmax, lanes);
                if mask != 0 {
                    // The leaf stops at this packet: its triangles and those before it.
                    tally.prims += count.min((k + 1) * PACKET) as u64;
                    tally.prim_hits += mask.count_ones() as u64;
                    tally.add_visits(visits);
                    return true;
                }
            }
            tally.prims += count as u64;
        } else {
            let (first, count) = leaf_range(cur);
            for k in first..first + count {
                tally.prims += 1;
                let wt = setup.scalar(&bvh.prims[k]);
                if bvh.prims[k]
                    .intersect(ray, triangle_test::<W>(), &wt)
                    .is_some()
                {
                    tally.prim_hits += 1;
                    tally.add_visits(visits);
                    return true;
                }
            }
        }
        if sp == 0 {
            tally.add_visits(visits);
            return false;
        }
        sp -= 1;
        cur = stack[sp];
    }
}
