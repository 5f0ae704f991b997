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
    let mut out = Leaves::default();
    let mut place = |r: u32| -> u32 {
        if !is_leaf(r) || r == EMPTY_SLOT {
            return r;
        }
        let (first, count) = leaf_range(r);
        let ids = &order[first..first + count];
        let tris: Option<Vec<[glam::Vec3; 3]>> = ids
            .iter()
            .map(|&i| match geometry.prims[i as usize] {
                Prim::Triangle(t) => Some(t),
                _ => None,
            })
            .collect();
        match tris {
            Some(tris) if packets => {
                let at = out.packets.len() as u32;
                for (t, o) in tris.chunks(PACKET).zip(ids.chunks(PACKET)) {
                    let mut object = [u32::MAX; PACKET];
                    for (slot, &i) in object.iter_mut().zip(o) {
                        *slot = geometry.prim_object[i as usize];
                    }
                    out.packets.push(LeafPacket {
                        tri: TrianglePacket::new(t),
                        object,
                    });
                }
                packet_leaf_ref(at, count as u32)
            }
            _ => {
                let at = out.prims.len() as u32;
                for &i in ids {
                    out.prims.push(geometry.prims[i as usize]);
                    out.objects.push(geometry.prim_object[i as usize]);
                }
                super::node::leaf_ref(at, count as u32)
            }
        }
    };
    *root = place(*root);
    for node in nodes.iter_mut() {
        for slot in 0..node.len as usize {
            node.child[slot] = place(node.child[slot]);
        }
    }
    out
}
