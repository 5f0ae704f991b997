//! The traversal layout of bvh2/bvh4/bvh8: flat arrays of N-wide nodes that store their N
//! children's boxes side by side (structure of arrays), as 001 §1.7 (thesis Ch. 4.2.1) and
//! Embree's `BVHN<N>::AABBNode` do, so one SIMD load gives one plane of all N boxes.
//!
//! A child reference is a `u32`: an inner node's index in the node array, or, with the top bit
//! set, a leaf holding `count` (1–16) consecutive primitives of the engine's reordered
//! primitive array from `first`. In the traversal's tree ([`super::traverse::Bvh`]) a leaf of
//! triangles only has [`PACKET_BIT`] set too: its `count` triangles are then in
//! `ceil(count / 4)` consecutive triangle packets from packet `first` ([`super::leaf`]). Leaves are not nodes of their own: the parent's slot is all a
//! leaf needs (Embree does the same).
//!
//! Empty slots (a node with fewer than N children) get the empty box, +∞ lower and −∞ upper
//! planes, which the slab test misses whatever the ray (Embree's convention). 001 §1.9 instead
//! duplicates a sibling and skips duplicates after the test; an empty box needs no second
//! test at all, so no child is ever tested or visited twice.

use super::tree::{BuildKind, BuildTree, MAX_WIDTH};
use crate::geometry::aabb::Aabb;

/// Top bit: the reference is a leaf.
pub const LEAF_BIT: u32 = 1 << 31;
const COUNT_SHIFT: u32 = 27;
/// Most primitives in one leaf (4 bits of count).
pub const MAX_LEAF_PRIMS: usize = 16;
/// Most primitives a tree can index (27 bits of first primitive).
pub const MAX_PRIMS: usize = 1 << COUNT_SHIFT;
/// In the traversal's tree, set in a leaf reference whose primitives are triangle packets.
/// Leaf indices stay below it.
pub const PACKET_BIT: u32 = 1 << (COUNT_SHIFT - 1);
/// Most primitives a traversal tree can index (leaf indices must leave [`PACKET_BIT`] clear).
pub const MAX_TRAVERSAL_PRIMS: usize = PACKET_BIT as usize;
/// The reference in an empty slot (never followed: the empty box is never hit).
pub const EMPTY_SLOT: u32 = u32::MAX;

/// A leaf reference to primitives `first..first + count`.
#[inline]
pub fn leaf_ref(first: u32, count: u32) -> u32 {
    debug_assert!((1..=MAX_LEAF_PRIMS as u32).contains(&count) && (first as usize) < MAX_PRIMS);
    LEAF_BIT | ((count - 1) << COUNT_SHIFT) | first
}

#[inline]
pub fn is_leaf(r: u32) -> bool {
    r & LEAF_BIT != 0
}

/// A leaf reference to the triangles in packets from `first_packet` (`count` triangles).
#[inline]
pub fn packet_leaf_ref(first_packet: u32, count: u32) -> u32 {
    debug_assert!(first_packet < PACKET_BIT);
    leaf_ref(first_packet, count) | PACKET_BIT
}

/// Whether a leaf reference holds triangle packets (traversal tree only).
#[inline]
pub fn is_packet_leaf(r: u32) -> bool {
    r & PACKET_BIT != 0
}

/// (first packet, triangles) of a packet leaf reference.
#[inline]
pub fn packet_range(r: u32) -> (usize, usize) {
    let (first, count) = leaf_range(r);
    (first & (PACKET_BIT as usize - 1), count)
}

/// (first, count) of a leaf reference.
#[inline]
pub fn leaf_range(r: u32) -> (usize, usize) {
    (
        (r & (MAX_PRIMS as u32 - 1)) as usize,
        (((r >> COUNT_SHIFT) & 15) + 1) as usize,
    )
}

/// Plane rows of [`WideNode::planes`]: lower x, upper x, lower y, upper y, lower z, upper z.
/// A ray picks its near row on axis `a` as `2a + (direction < 0)` (`SlabRay::near_plane`).
pub const PLANES: usize = 6;

/// N children: their boxes as six rows of N floats, their references, and how many slots are
/// used (children fill slots `0..len`; the rest are empty). Aligned to a cache line: 64 bytes
/// for N = 2, 128 for N = 4, 256 for N = 8.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
pub struct WideNode<const N: usize> {
    pub planes: [[f32; N]; PLANES],
    pub child: [u32; N],
    pub len: u32,
}

impl<const N: usize> WideNode<N> {
    fn empty() -> Self {
        WideNode {
            planes: [
                [f32::INFINITY; N],
                [f32::NEG_INFINITY; N],
                [f32::INFINITY; N],
                [f32::NEG_INFINITY; N],
                [f32::INFINITY; N],
                [f32::NEG_INFINITY; N],
            ],
            child: [EMPTY_SLOT; N],
            len: 0,
        }
    }

    fn set(&mut self, slot: usize, b: &Aabb, child: u32) {
        for a in 0..3 {
            self.planes[2 * a][slot] = b.lo[a];
            self.planes[2 * a + 1][slot] = b.hi[a];
        }
        self.child[slot] = child;
    }

    /// The box of slot `i`.
    pub fn child_bounds(&self, i: usize) -> Aabb {
        let p = &self.planes;
        Aabb::new(
            glam::Vec3::new(p[0][i], p[2][i], p[4][i]),
            glam::Vec3::new(p[1][i], p[3][i], p[5][i]),
        )
    }
}

/// The flattened tree: nodes in depth-first order (a node's subtree follows it), the root's
/// reference (a leaf when the scene has ≤ leaf-size primitives) and box.
pub struct Flat<const N: usize> {
    pub nodes: Vec<WideNode<N>>,
    pub root: u32,
    pub root_bounds: Aabb,
}

/// Turns a build tree whose nodes have at most N children into N-wide nodes. Leaf ranges keep
/// their positions in `tree.order`.
pub fn flatten<const N: usize>(tree: &BuildTree) -> Flat<N> {
    assert!(N <= MAX_WIDTH);
    let mut nodes = Vec::with_capacity(tree.nodes.len() / (N - 1).max(1) + 1);
    let root = emit(tree, 0, &mut nodes);
    Flat {
        nodes,
        root,
        root_bounds: tree.nodes[0].bounds,
    }
}

fn emit<const N: usize>(tree: &BuildTree, i: u32, out: &mut Vec<WideNode<N>>) -> u32 {
    match tree.nodes[i as usize].kind {
        BuildKind::Leaf { first, count } => leaf_ref(first, count),
        BuildKind::Inner { children, len } => {
            let me = out.len();
            out.push(WideNode::empty());
            let len = len as usize;
            assert!(len <= N, "a build node has {len} children, more than {N}");
            for (slot, &c) in children[..len].iter().enumerate() {
                let r = emit(tree, c, out);
                let b = tree.nodes[c as usize].bounds;
                out[me].set(slot, &b, r);
            }
            out[me].len = len as u32;
            me as u32
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn references_round_trip() {
        for (first, count) in [(0, 1), (5, 16), (MAX_PRIMS as u32 - 1, 3)] {
            let r = leaf_ref(first, count);
            assert!(is_leaf(r));
            assert_eq!(leaf_range(r), (first as usize, count as usize));
        }
        assert!(!is_leaf(12345));
        let r = packet_leaf_ref(PACKET_BIT - 1, 16);
        assert!(is_leaf(r) && is_packet_leaf(r));
        assert_eq!(packet_range(r), (PACKET_BIT as usize - 1, 16));
        assert!(!is_packet_leaf(leaf_ref(PACKET_BIT - 1, 16)));
    }

    #[test]
    fn node_sizes_are_cache_lines() {
        assert_eq!(std::mem::size_of::<WideNode<2>>(), 64);
        assert_eq!(std::mem::size_of::<WideNode<4>>(), 128);
        assert_eq!(std::mem::size_of::<WideNode<8>>(), 256);
    }
}
