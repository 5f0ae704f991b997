//! A binary SAH tree from a split search (001 with B = 2).

use super::{leaf_kind, make_leaf, Range, Splitter};
use crate::bvh::tree::{BuildKind, BuildTree, MAX_WIDTH, SAH_MEDIAN_DEPTH};

/// Binary SAH tree (001 with B = 2; Wald, Boulos and Shirley 2007).
pub fn binary<S: Splitter>(mut s: S, leaf: usize) -> BuildTree {
    let root = s.root();
    let mut tree = BuildTree {
        nodes: Vec::with_capacity(2 * root.len() + 1),
        order: Vec::new(),
    };
    binary_node(&mut s, &mut tree, &root, 0, leaf);
    tree.order = s.into_order();
    tree
}

fn binary_node<S: Splitter>(
    s: &mut S,
    tree: &mut BuildTree,
    r: &Range,
    depth: usize,
    leaf: usize,
) -> u32 {
    let n = r.len();
    let median = depth >= SAH_MEDIAN_DEPTH;
    if n == 1 || (median && n <= leaf) {
        return tree.push(r.bounds, leaf_kind(r));
    }
    let split = s.split(r, None, median);
    if make_leaf(n, leaf, split.cost) {
        return tree.push(r.bounds, leaf_kind(r));
    }
    let me = tree.push(r.bounds, leaf_kind(r));
    let mut children = [0; MAX_WIDTH];
    children[0] = binary_node(s, tree, &split.left, depth + 1, leaf);
    children[1] = binary_node(s, tree, &split.right, depth + 1, leaf);
    tree.nodes[me as usize].kind = BuildKind::Inner { children, len: 2 };
    me
}
