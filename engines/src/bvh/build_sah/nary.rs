//! 001's N-ary SAH tree, the "stepwise construction" (§1.5, thesis Fig. 3.15).

use super::{leaf_kind, make_leaf, Range, Splitter};
use crate::bvh::tree::{BuildKind, BuildTree, MAX_WIDTH, SAH_MEDIAN_DEPTH};

/// 001's N-ary SAH tree ("stepwise construction", §1.5, thesis Fig. 3.15), N a power of two:
/// split a node's primitives with the binary SAH over all axes, then split each group again
/// with the SAH on that first split's axis only, log2(N) times; the groups become the children
/// in axis order. A group that would become a leaf is not split further (its slot stays
/// empty, 001's empty nodes).
pub fn wide_same_axis<S: Splitter>(mut s: S, leaf: usize, width: usize) -> BuildTree {
    assert!(width.is_power_of_two() && (2..=MAX_WIDTH).contains(&width));
    let root = s.root();
    let mut tree = BuildTree {
        nodes: Vec::with_capacity(2 * root.len() + 1),
        order: Vec::new(),
    };
    wide_node(&mut s, &mut tree, &root, 0, leaf, width);
    tree.order = s.into_order();
    tree
}

fn wide_node<S: Splitter>(
    s: &mut S,
    tree: &mut BuildTree,
    r: &Range,
    depth: usize,
    leaf: usize,
    width: usize,
) -> u32 {
    let n = r.len();
    // `depth` counts binary levels, so the median fallback bounds the depth as in `binary`.
    let median = depth >= SAH_MEDIAN_DEPTH;
    if n == 1 || (median && n <= leaf) {
        return tree.push(r.bounds, leaf_kind(r));
    }
    let first = s.split(r, None, median);
    if make_leaf(n, leaf, first.cost) {
        return tree.push(r.bounds, leaf_kind(r));
    }
    let axis = Some(first.axis);
    // Groups, each with whether it may still be split.
    let mut groups: Vec<(Range, bool)> = vec![(first.left, true), (first.right, true)];
    let levels = width.trailing_zeros() as usize;
    for _ in 1..levels {
        let mut next = Vec::with_capacity(2 * groups.len());
        for &(g, open) in &groups {
            let m = g.len();
            if !open || m == 1 || (median && m <= leaf) {
                next.push((g, false));
                continue;
            }
            let sp = s.split(&g, axis, median);
            if make_leaf(m, leaf, sp.cost) {
                next.push((g, false));
            } else {
                next.push((sp.left, true));
                next.push((sp.right, true));
            }
        }
        groups = next;
    }
    let me = tree.push(r.bounds, leaf_kind(r));
    let mut children = [0; MAX_WIDTH];
    for (slot, (g, _)) in groups.iter().enumerate() {
        children[slot] = wide_node(s, tree, g, depth + levels, leaf, width);
    }
    tree.nodes[me as usize].kind = BuildKind::Inner {
        children,
        len: groups.len() as u8,
    };
    me
}
