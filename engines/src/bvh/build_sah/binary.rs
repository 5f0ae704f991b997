//! A binary SAH tree from a split search (001 with B = 2).

use super::{leaf_kind, make_leaf, Range, Splitter};
use crate::bvh::config::{T_AABB, T_TRI};
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

/// When a binary tree built for a wide tree with packet leaves stops splitting (Embree's
/// `BVHBuilderBinnedSAH` rule for `BVH8Triangle4`): a range of at most `min` primitives is
/// always a leaf; a larger one of at most `max` becomes a leaf when testing its primitives in
/// blocks of `block` costs no more than its best split (`blocks · T_TRI ≤ T_AABB + Σ
/// (A_i/A)·blocks_i·T_TRI`: one box test per split, since collapsing merges binary levels into
/// wide nodes). Ranges holding a primitive that is not packed (`packable[id]` false: spheres
/// and cones, tested one by one) are leaves only when they hold one primitive.
#[derive(Clone, Copy)]
pub struct BlockLeaves<'a> {
    pub min: usize,
    pub max: usize,
    pub block: usize,
    pub packable: &'a [bool],
}

impl BlockLeaves<'_> {
    fn packable(&self, ids: &[u32]) -> bool {
        ids.iter().all(|&i| self.packable[i as usize])
    }
}

/// A binary SAH tree whose leaves follow [`BlockLeaves`] (the splitter should count in the
/// same blocks: `Binned::with_block`), for collapsing into a wide tree.
pub fn binary_blocks<S: Splitter>(mut s: S, rule: &BlockLeaves) -> BuildTree {
    let root = s.root();
    let mut tree = BuildTree {
        nodes: Vec::with_capacity(2 * root.len() / rule.min.max(1) + 1),
        order: Vec::new(),
    };
    block_node(&mut s, &mut tree, &root, 0, rule);
    tree.order = s.into_order();
    tree
}

fn block_node<S: Splitter>(
    s: &mut S,
    tree: &mut BuildTree,
    r: &Range,
    depth: usize,
    rule: &BlockLeaves,
) -> u32 {
    let n = r.len();
    let packable = n <= rule.max && rule.packable(s.ids(r));
    if n == 1 || (n <= rule.min && packable) {
        return tree.push(r.bounds, leaf_kind(r));
    }
    let split = s.split(r, None, depth >= SAH_MEDIAN_DEPTH);
    let leaf_cost = super::blocks(n, rule.block) as f32 * T_TRI;
    if packable && leaf_cost <= split.cost - T_AABB {
        return tree.push(r.bounds, leaf_kind(r));
    }
    let me = tree.push(r.bounds, leaf_kind(r));
    let mut children = [0; MAX_WIDTH];
    children[0] = block_node(s, tree, &split.left, depth + 1, rule);
    children[1] = block_node(s, tree, &split.right, depth + 1, rule);
    tree.nodes[me as usize].kind = BuildKind::Inner { children, len: 2 };
    me
}
