//! Object-median builders (001 §1.4, thesis Ch. 3.4; Kay and Kajiya 1986): the axis cycles
//! X → Y → Z with depth (round robin, not chosen per node), primitives are ordered by the centre
//! of their box on that axis and cut into equal counts with integer truncation.
//!
//! Ordering is done with selection (`select_nth_unstable_by`), not a full sort: the groups are
//! the same sets as after sorting (ties are broken by primitive index), in O(n) per level.

use super::tree::{BuildKind, BuildPrims, BuildTree, MAX_WIDTH};

/// Binary tree: primitives `0 … n/2 − 1` of the sorted order go left, the rest right; a node
/// of at most `leaf` primitives is a leaf.
pub fn binary(prims: &BuildPrims, leaf: usize) -> BuildTree {
    nway(prims, leaf, 2)
}

/// N-ary tree straight from the median (001 §1.4's B-way split): group `i` of a node with `n`
/// primitives holds sorted positions `⌊i·n/B⌋ … ⌊(i+1)·n/B⌋ − 1`, so groups are empty when
/// n < B (001's "empty nodes"); empty groups make no child.
pub fn nway(prims: &BuildPrims, leaf: usize, width: usize) -> BuildTree {
    assert!((2..=MAX_WIDTH).contains(&width) && leaf >= 1);
    let mut tree = BuildTree {
        nodes: Vec::with_capacity(2 * prims.len() / leaf.max(1) + 1),
        order: (0..prims.len() as u32).collect(),
    };
    let n = prims.len();
    build(prims, &mut tree, 0, n, 0, leaf, width);
    tree
}

fn build(
    prims: &BuildPrims,
    tree: &mut BuildTree,
    start: usize,
    end: usize,
    depth: usize,
    leaf: usize,
    width: usize,
) -> u32 {
    let bounds = prims.bounds_of(&tree.order[start..end]);
    let n = end - start;
    if n <= leaf {
        return tree.push(
            bounds,
            BuildKind::Leaf {
                first: start as u32,
                count: n as u32,
            },
        );
    }
    let axis = depth % 3;
    let cuts: Vec<usize> = (0..=width).map(|i| i * n / width).collect();
    select_groups(prims, &mut tree.order[start..end], &cuts, axis);
    let me = tree.push(
        bounds,
        BuildKind::Inner {
            children: [0; MAX_WIDTH],
            len: 0,
        },
    );
    let mut children = [0u32; MAX_WIDTH];
    let mut len = 0;
    for g in cuts.windows(2) {
        if g[1] > g[0] {
            children[len] = build(
                prims,
                tree,
                start + g[0],
                start + g[1],
                depth + 1,
                leaf,
                width,
            );
            len += 1;
        }
    }
    tree.nodes[me as usize].kind = BuildKind::Inner {
        children,
        len: len as u8,
    };
    me
}

/// Reorders `ids` so that each range `cuts[i]..cuts[i+1]` holds the primitives of sorted
/// positions `cuts[i]..cuts[i+1]` on `axis` (multi-selection: one `select_nth` at the middle
/// cut, then each side recursively).
fn select_groups(prims: &BuildPrims, ids: &mut [u32], cuts: &[usize], axis: usize) {
    // Only the interior cuts (not 0 or ids.len()) need a selection, each once: with fewer
    // primitives than groups, cuts repeat (empty groups), and a repeated cut would ask the
    // left part for a position one past its end.
    let mut inner: Vec<usize> = cuts
        .iter()
        .copied()
        .filter(|&c| c > 0 && c < ids.len())
        .collect();
    inner.dedup();
    select_rec(prims, ids, 0, &inner, axis);
}

fn select_rec(prims: &BuildPrims, ids: &mut [u32], offset: usize, cuts: &[usize], axis: usize) {
    if cuts.is_empty() || ids.len() < 2 {
        return;
    }
    let m = cuts.len() / 2;
    let k = cuts[m] - offset;
    ids.select_nth_unstable_by(k, |&a, &b| prims.cmp(a, b, axis));
    let (lo, hi) = ids.split_at_mut(k);
    select_rec(prims, lo, offset, &cuts[..m], axis);
    select_rec(prims, hi, offset + k, &cuts[m + 1..], axis);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::aabb::Aabb;
    use glam::Vec3;

    /// `n` unit boxes along x at 0, 1, 2, …
    fn row(n: usize) -> BuildPrims {
        let bounds: Vec<Aabb> = (0..n)
            .map(|i| {
                Aabb::new(
                    Vec3::new(i as f32, 0.0, 0.0),
                    Vec3::new(i as f32 + 1.0, 1.0, 1.0),
                )
            })
            .collect();
        let centroid = bounds.iter().map(|b| b.centre()).collect();
        BuildPrims { bounds, centroid }
    }

    #[test]
    fn binary_median_of_16_is_balanced() {
        // 001 §1.3: 16 primitives, one per leaf: depth 4, 15 internal nodes.
        let p = row(16);
        let t = binary(&p, 1);
        t.validate(&p, 2).unwrap();
        let inner = t
            .nodes
            .iter()
            .filter(|n| matches!(n.kind, BuildKind::Inner { .. }))
            .count();
        assert_eq!(inner, 15);
        assert_eq!(t.nodes.len() - inner, 16);
        // The root's left half is primitives 0..8 (sorted on x at depth 0).
        let left = t.children(0)[0];
        assert_eq!(t.nodes[left as usize].bounds.hi.x, 8.0);
    }

    #[test]
    fn nway_median_groups_and_empty_slots() {
        // 001 §1.3: 16 primitives, 4-ary, one per leaf: depth 2, 5 internal nodes.
        let p = row(16);
        let t = nway(&p, 1, 4);
        t.validate(&p, 4).unwrap();
        let inner: Vec<_> = t
            .nodes
            .iter()
            .filter(|n| matches!(n.kind, BuildKind::Inner { .. }))
            .collect();
        assert_eq!(inner.len(), 5);
        // 5 primitives in 4 groups: 1, 1, 1, 2 (truncated cuts 0, 1, 2, 3, 5).
        let p = row(5);
        let t = nway(&p, 1, 4);
        t.validate(&p, 4).unwrap();
        let sizes: Vec<u32> = t
            .children(0)
            .iter()
            .map(|&c| match t.nodes[c as usize].kind {
                BuildKind::Leaf { count, .. } => count,
                BuildKind::Inner { .. } => 2,
            })
            .collect();
        assert_eq!(sizes, vec![1, 1, 1, 2]);
        // 2 primitives, 8-ary: only two non-empty groups.
        let p = row(2);
        let t = nway(&p, 1, 8);
        assert_eq!(t.children(0).len(), 2);
    }
}
