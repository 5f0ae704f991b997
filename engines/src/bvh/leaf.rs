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
use super::tree::extend_par;
use crate::geometry::triangle_simd::TrianglePacket;
use crate::geometry::{Geometry, Prim};

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
/// leaves and rewrites the references (and copies the scalar leaves' primitives), noting each
/// packet's range of `order`, then each thread makes a contiguous part of the packets
/// ([`extend_par`]); one thread makes them all in order. The same references, packets and primitives at any thread count. Packet making was
/// 80 M of the 403 M instructions the first thread ran alone in a two-thread build of balls4
/// tessellated (callgrind).
pub fn lay_out_threads<const N: usize>(
    nodes: &mut [WideNode<N>],
    root: &mut u32,
    order: &[u32],
    geometry: &Geometry,
    packets: bool,
    threads: usize,
) -> Leaves {
    let mut out = Leaves::default();
    // Each packet's first position in `order` and its triangle count (1 to PACKET), in packet
    // order.
    let mut ranges: Vec<(u32, u8)> = Vec::new();
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
            let at = ranges.len() as u32;
            for k in (0..count).step_by(PACKET) {
                ranges.push(((first + k) as u32, (count - k).min(PACKET) as u8));
            }
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
    extend_par(&mut out.packets, ranges.len(), threads, |p| {
        let (first, count) = ranges[p];
        packet_of(
            &order[first as usize..first as usize + count as usize],
            geometry,
        )
    });
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
