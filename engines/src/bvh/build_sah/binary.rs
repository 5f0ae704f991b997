//! A binary SAH tree from a split search (001 with B = 2).

use super::{leaf_kind, make_leaf, Binned, Range, Splitter};
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

/// Ranges smaller than this are never handed to another thread (a thread costs more than
/// building a few thousand primitives).
pub(super) const FORK_MIN: usize = 4096;

/// [`binary_blocks`] over the binned search on `threads` threads: the ranges on both sides of
/// the top `⌈log2 threads⌉ + 2` levels of splits (not counting splits with a side below
/// [`FORK_MIN`]) are built on threads of their own (`std::thread::scope`), each splitting its
/// own side of the splitter in place ([`Binned::fork`]), and the subtrees are appended in the
/// order the one-thread build makes them. Every split is the one the one-thread build chooses,
/// so the tree is the same node for node (test `bvh::tests::threads_build_the_same_tree`);
/// what runs in parallel is the binning of the subtrees, 86% of the build (callgrind).
pub fn binary_blocks_threads(mut s: Binned<'_>, rule: &BlockLeaves, threads: usize) -> BuildTree {
    if threads <= 1 {
        return binary_blocks(s, rule);
    }
    let root = s.root();
    let mut tree = BuildTree {
        nodes: Vec::with_capacity(2 * root.len() / rule.min.max(1) + 1),
        order: Vec::new(),
    };
    // Four subtrees per thread, so that uneven splits still keep every core busy. Fresh
    // processes' two-thread builds of balls4 tessellated: with forks
    // that copied the splitter, two per thread took 0.243–0.254 s (3 builds) and four
    // 0.225–0.234 s (4); with forks in place, four 0.220–0.227 s (4) and eight 0.222–0.227 s (4).
    let forks = threads.next_power_of_two().trailing_zeros() as usize + 2;
    fork_node(&mut s, &mut tree, &root, 0, rule, forks, threads);
    tree.order = s.into_order();
    tree
}

fn fork_node(
    s: &mut Binned<'_>,
    tree: &mut BuildTree,
    r: &Range,
    depth: usize,
    rule: &BlockLeaves,
    forks: usize,
    threads: usize,
) -> u32 {
    let n = r.len();
    if forks == 0 || n < 2 * FORK_MIN {
        return block_node(s, tree, r, depth, rule);
    }
    let packable = n <= rule.max && rule.packable(s.ids(r));
    // (A range this large is never a leaf: n > max.) Only the top split has every thread
    // free: below it each range has a thread of its own already. Its binning ran alone on
    // one thread, 71 M instructions of the 403 M the first thread ran alone on balls4
    // tessellated at two threads (callgrind).
    let split = s.split_threads(r, None, depth >= SAH_MEDIAN_DEPTH, threads);
    let leaf_cost = super::blocks(n, rule.block) as f32 * T_TRI;
    if packable && leaf_cost <= split.cost - T_AABB {
        return tree.push(r.bounds, leaf_kind(r));
    }
    let me = tree.push(r.bounds, leaf_kind(r));
    let mut children = [0; MAX_WIDTH];
    if split.left.len().min(split.right.len()) < FORK_MIN {
        // One side is too small for a thread of its own (balls4 tessellated: its top split
        // cuts 18 triangles of the floor from 797,132): it is built here, the other side
        // splits on with every thread, and no splitter part is copied. The nodes come in the
        // one-thread build's order, as `block_node` pushes them.
        let left_small = split.left.len() < FORK_MIN;
        children[0] = if left_small {
            block_node(s, tree, &split.left, depth + 1, rule)
        } else {
            fork_node(s, tree, &split.left, depth + 1, rule, forks, threads)
        };
        children[1] = if left_small {
            fork_node(s, tree, &split.right, depth + 1, rule, forks, threads)
        } else {
            block_node(s, tree, &split.right, depth + 1, rule)
        };
        tree.nodes[me as usize].kind = BuildKind::Inner { children, len: 2 };
        return me;
    }
    // The two sides split the splitter in place (`Binned::fork`). The left side is built on
    // this thread straight into `tree`, where the one-thread build puts it (right after `me`);
    // the right side into a tree of its own, reserved up front (growing it by doubling cost
    // copies and page faults), and appended after the left.
    let (mut left_s, mut right_s) = s.fork(split.right.start);
    let right = std::thread::scope(|scope| {
        let right = scope.spawn(|| {
            let mut t = BuildTree {
                nodes: Vec::with_capacity(2 * split.right.len() / rule.min.max(1) + 1),
                order: Vec::new(),
            };
            fork_node(
                &mut right_s,
                &mut t,
                &split.right,
                depth + 1,
                rule,
                forks - 1,
                1,
            );
            t
        });
        children[0] = fork_node(
            &mut left_s,
            tree,
            &split.left,
            depth + 1,
            rule,
            forks - 1,
            1,
        );
        right.join().expect("a build thread panicked")
    });
    children[1] = tree.append_shifted(&right.nodes, 0, threads);
    tree.nodes[me as usize].kind = BuildKind::Inner { children, len: 2 };
    me
}
