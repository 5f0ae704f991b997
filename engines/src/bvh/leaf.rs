//! The traversal tree's leaves: triangles in packets of 4, tested with one SIMD triangle test
//! ([`crate::geometry::triangle_simd`]), as Embree's `Triangle4` leaves are; every other
//! leaf keeps its primitives as [`Prim`]s, tested one by one with the scalar kernels.
//!
//! A leaf whose primitives are all triangles becomes `ceil(count / 4)` consecutive
//! [`LeafPacket`]s (the last one padded with triangles that never hit); `leaf=4` thus gives one
//! packet per leaf. A leaf holding a sphere or a cone stays scalar as a whole, its triangles
//! included (such leaves only occur in the scenes that mix the two). With `packets=off` every
//! leaf stays scalar.

use super::node::{is_leaf, leaf_range, packet_leaf_ref, WideNode, EMPTY_SLOT};
use crate::geometry::triangle_simd::TrianglePacket;
use crate::geometry::{Geometry, Prim};
use std::mem::MaybeUninit;

/// Triangles per leaf packet (Embree's `Triangle4`: one SSE test, or one half of AVX).
pub const PACKET: usize = 4;

/// Up to [`PACKET`] triangles of a leaf and their scene objects (160 bytes).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct LeafPacket {
    pub tri: TrianglePacket<PACKET>,
    pub object: [u32; PACKET],
}

/// Where the traversal tree's leaves keep their primitives.
#[derive(Default)]
pub struct Leaves {
    /// Primitives of the scalar leaves, in leaf order, and their scene objects.
    pub prims: Vec<Prim>,
    pub objects: Vec<u32>,
    /// Triangle packets of the packet leaves, in leaf order.
    pub packets: Vec<LeafPacket>,
}

/// The packet of up to [`PACKET`] triangles `ids` (indices into `geometry`), gathered on the
/// stack (no allocation per leaf).
#[inline(always)]
fn packet_of(ids: &[u32], geometry: &Geometry) -> LeafPacket {
    let mut tris = [[glam::Vec3::ZERO; 3]; PACKET];
    let mut object = [u32::MAX; PACKET];
    for (lane, &i) in ids.iter().enumerate() {
        if let Prim::Triangle(t) = geometry.prims[i as usize] {
            tris[lane] = t;
        }
        object[lane] = geometry.prim_object[i as usize];
    }
    LeafPacket {
        tri: TrianglePacket::new(&tris[..ids.len()]),
        object,
    }
}

/// [`lay_out`] with the triangle packets made on `threads` threads: one pass numbers the
/// leaves and rewrites the references (and copies the scalar leaves' primitives), then each
/// thread fills a contiguous part of the packets; one thread fills them all in that pass's
/// order. The same references, packets and primitives at any thread count. Packet making was
/// 80 M of the 403 M instructions the first thread ran alone in a two-thread build of balls4
/// tessellated (callgrind, issue 20, session 12).
pub fn lay_out_threads<const N: usize>(
    nodes: &mut [WideNode<N>],
    root: &mut u32,
    order: &[u32],
    geometry: &Geometry,
    packets: bool,
    threads: usize,
) -> Leaves {
    let mut out = Leaves::default();
    // (first of the leaf's range of `order`, its count, its first packet), in packet order.
    let mut jobs: Vec<(u32, u32, u32)> = Vec::new();
    let mut next = 0u32;
    let mut place = |r: u32| -> u32 {
        if !is_leaf(r) || r == EMPTY_SLOT {
            return r;
        }
        let (first, count) = leaf_range(r);
        let ids = &order[first..first + count];
        if packets
            && ids
                .iter()
                .all(|&i| matches!(geometry.prims[i as usize], Prim::Triangle(_)))
        {
            let at = next;
            next += count.div_ceil(PACKET) as u32;
            jobs.push((first as u32, count as u32, at));
            packet_leaf_ref(at, count as u32)
        } else {
            let at = out.prims.len() as u32;
            for &i in ids {
                out.prims.push(geometry.prims[i as usize]);
                out.objects.push(geometry.prim_object[i as usize]);
            }
            super::node::leaf_ref(at, count as u32)
        }
    };
    *root = place(*root);
    for node in nodes.iter_mut() {
        for slot in 0..node.len as usize {
            node.child[slot] = place(node.child[slot]);
        }
    }
    // Every packet 0..next belongs to exactly one job (numbered in order above), so the fill
    // below writes each once, straight into the spare capacity: no pass on one thread blanks
    // 32 MB first (balls4 tessellated; issue 20, session 15).
    let mut packets: Vec<LeafPacket> = Vec::with_capacity(next as usize);
    let fill = |slice: &mut [MaybeUninit<LeafPacket>], mine: &[(u32, u32, u32)], from: usize| {
        for &(first, count, at) in mine {
            let ids = &order[first as usize..(first + count) as usize];
            let at = at as usize - from;
            for (p, o) in slice[at..].iter_mut().zip(ids.chunks(PACKET)) {
                p.write(packet_of(o, geometry));
            }
        }
    };
    let all = &mut packets.spare_capacity_mut()[..next as usize];
    if threads <= 1 {
        fill(all, &jobs, 0);
    } else {
        // Cut the jobs where the packets reach each thread's share; each part fills its own
        // contiguous packets.
        let share = (next as usize).div_ceil(threads).max(1);
        std::thread::scope(|scope| {
            let mut rest: &mut [MaybeUninit<LeafPacket>] = all;
            let mut jobs_left: &[(u32, u32, u32)] = &jobs;
            let mut base = 0usize;
            while !jobs_left.is_empty() {
                let end = base + share;
                let k = jobs_left
                    .iter()
                    .position(|j| j.2 as usize >= end)
                    .unwrap_or(jobs_left.len());
                let (mine, more_jobs) = jobs_left.split_at(k);
                let upto = more_jobs.first().map_or(next as usize, |j| j.2 as usize);
                let (slice, more) = std::mem::take(&mut rest).split_at_mut(upto - base);
                let from = base;
                let fill = &fill;
                scope.spawn(move || fill(slice, mine, from));
                rest = more;
                jobs_left = more_jobs;
                base = upto;
            }
        });
    }
    // SAFETY: the jobs' packets cover 0..next, each written once above (every job's
    // `count.div_ceil(PACKET)` packets from its `at`); all threads joined at the scope's end.
    unsafe { packets.set_len(next as usize) };
    out.packets = packets;
    out
}

/// Turns the leaf references of `nodes` and `root`, ranges of the build order `order` (indices
/// into `geometry`), into the traversal tree's: packet leaves (with `packets`) or ranges of the
/// returned scalar primitives. Leaves are laid out in node order, so siblings stay close.
pub fn lay_out<const N: usize>(
    nodes: &mut [WideNode<N>],
    root: &mut u32,
    order: &[u32],
    geometry: &Geometry,
    packets: bool,
) -> Leaves {
    lay_out_threads(nodes, root, order, geometry, packets, 1)
}
