//! Binary tree → N-wide tree, the common way (Embree's BVHN builders; Dammertz, Hanika and
//! Keller 2008's QBVH; Wald, Benthin and Boulos 2008): a wide node starts with its binary
//! node's two children and keeps replacing the child of largest surface area by that child's
//! own two children until it has N children. Opening the largest box first keeps apart the
//! children a ray is most likely to enter, which is what a greedy SAH choice does.
//!
//! Leaves follow Embree's `minLeafSize` rule: a child subtree of at most `leaf` primitives
//! becomes one leaf (its primitives are contiguous in the binary tree's order, as every builder
//! here keeps subtrees contiguous). Children bigger than that are opened first; slots still
//! free are then used to open leaf-sized subtrees too, since a SIMD node tests all N boxes for
//! the price of one and every slot filled this way saves primitive tests. With `leaf = 1` the
//! leaves are the binary tree's own (001). The binary tree is therefore built down to one
//! primitive per leaf; merging small subtrees here, rather than stopping the binary build early,
//! lets wide nodes fill their N slots.

use super::tree::{BuildKind, BuildTree, MAX_WIDTH};

/// How leaves are formed.
#[derive(Clone, Copy)]
pub struct Leaves<'a> {
    /// Most primitives per leaf.
    pub leaf: usize,
    /// Spend free slots on splitting leaf-sized subtrees (worth it when each primitive is tested
    /// on its own; not with triangle packets, which test a whole leaf of up to 4 triangles for
    /// the price of one, see `leaf.rs`).
    pub split_leaves: bool,
    /// With triangle packets: `scalar_before[i]` counts the primitives at order positions
    /// `< i` that are not triangles. A subtree holding one of those is tested primitive by
    /// primitive, so it becomes a leaf only when it has a single primitive (curved SPD
    /// primitives thus get 001's one-per-leaf tree, triangles Embree's packets).
    pub scalar_before: Option<&'a [u32]>,
}

impl Leaves<'_> {
    fn is_leaf(&self, (first, count): (u32, u32)) -> bool {
        if count as usize > self.leaf {
            return false;
        }
        match self.scalar_before {
            Some(s) if count > 1 => s[(first + count) as usize] == s[first as usize],
            _ => true,
        }
    }
}

pub fn collapse(bin: &BuildTree, width: usize, leaves: Leaves) -> BuildTree {
    collapse_threads(bin, width, leaves, 1)
}

/// (first, count) of the primitives under each node.
fn spans(bin: &BuildTree, i: u32, span: &mut [(u32, u32)]) -> (u32, u32) {
    let s = match bin.nodes[i as usize].kind {
        BuildKind::Leaf { first, count } => (first, count),
        BuildKind::Inner { children, len } => {
            let (mut first, mut count) = (u32::MAX, 0);
            for &c in &children[..len as usize] {
                let (f, n) = spans(bin, c, span);
                first = first.min(f);
                count += n;
            }
            (first, count)
        }
    };
    span[i as usize] = s;
    s
}

/// The wide node binary node `i` becomes: `None` for a leaf, else its children (binary
/// nodes) in their slots.
fn kids_of(
    bin: &BuildTree,
    span: &[(u32, u32)],
    i: u32,
    width: usize,
    leaves: &Leaves,
) -> Option<([u32; MAX_WIDTH], usize)> {
    let n = &bin.nodes[i as usize];
    let mut kids = [0u32; MAX_WIDTH];
    let mut len = match n.kind {
        BuildKind::Inner { children, len } if !leaves.is_leaf(span[i as usize]) => {
            kids[..len as usize].copy_from_slice(&children[..len as usize]);
            len as usize
        }
        _ => return None,
    };
    while len < width {
        // The child to open: a subtree too big for a leaf before a leaf-sized one, then the
        // largest surface area; only if its children fit in the slots left.
        let best = kids[..len]
            .iter()
            .enumerate()
            .filter(|&(_, &k)| {
                matches!(bin.nodes[k as usize].kind, BuildKind::Inner { len: l, .. }
                    if len - 1 + l as usize <= width)
            })
            .map(|(slot, &k)| {
                let big = !leaves.is_leaf(span[k as usize]);
                (slot, big, bin.nodes[k as usize].bounds.half_area())
            })
            .filter(|&(_, big, _)| big || leaves.split_leaves)
            .max_by(|a, b| a.1.cmp(&b.1).then(a.2.total_cmp(&b.2)));
        let Some((slot, _, _)) = best else { break };
        let grand = bin.children(kids[slot]);
        let g = grand.len();
        kids.copy_within(slot + 1..len, slot + g);
        kids[slot..slot + g].copy_from_slice(grand);
        len += g - 1;
    }
    Some((kids, len))
}

fn node(
    bin: &BuildTree,
    span: &[(u32, u32)],
    i: u32,
    width: usize,
    leaves: &Leaves,
    out: &mut BuildTree,
) -> u32 {
    let n = &bin.nodes[i as usize];
    let Some((kids, len)) = kids_of(bin, span, i, width, leaves) else {
        let (first, count) = span[i as usize];
        return out.push(n.bounds, BuildKind::Leaf { first, count });
    };
    let me = out.push(n.bounds, n.kind);
    let mut wide = [0u32; MAX_WIDTH];
    for (slot, &k) in kids[..len].iter().enumerate() {
        wide[slot] = node(bin, span, k, width, leaves, out);
    }
    out.nodes[me as usize].kind = BuildKind::Inner {
        children: wide,
        len: len as u8,
    };
    me
}

/// [`collapse`] with the subtrees under the root's wide node collapsed on `threads` threads:
/// the root's children are cut into `threads` contiguous groups of about equal primitive
/// counts, each group is collapsed into a tree of its own, and the groups are appended in
/// order, so the nodes come out in the one-thread order, node for node. Collapsing was 41–45 ms
/// of a two-thread build of balls4 tessellated on one thread alone.
pub fn collapse_threads(
    bin: &BuildTree,
    width: usize,
    leaves: Leaves,
    threads: usize,
) -> BuildTree {
    assert!((2..=MAX_WIDTH).contains(&width) && leaves.leaf >= 1);
    let mut span = vec![(0u32, 0u32); bin.nodes.len()];
    spans(bin, 0, &mut span);
    let mut out = BuildTree {
        nodes: Vec::with_capacity(bin.nodes.len() / (width - 1) + 1),
        order: bin.order.clone(),
    };
    if threads <= 1 || bin.nodes.len() < 2 * super::tree::PARALLEL_MIN {
        node(bin, &span, 0, width, &leaves, &mut out);
        return out;
    }
    let root = &bin.nodes[0];
    let Some((kids, len)) = kids_of(bin, &span, 0, width, &leaves) else {
        let (first, count) = span[0];
        out.push(root.bounds, BuildKind::Leaf { first, count });
        return out;
    };
    out.push(root.bounds, root.kind);
    // Contiguous groups of the root's children, cut where the primitives so far pass each
    // thread's share.
    let kids = &kids[..len];
    let total: u64 = kids.iter().map(|&k| span[k as usize].1 as u64).sum();
    let mut groups: Vec<&[u32]> = Vec::with_capacity(threads);
    let (mut from, mut acc) = (0usize, 0u64);
    for (j, &k) in kids.iter().enumerate() {
        acc += span[k as usize].1 as u64;
        if acc * threads as u64 >= total * (groups.len() as u64 + 1) || j + 1 == kids.len() {
            groups.push(&kids[from..=j]);
            from = j + 1;
        }
    }
    let span = &span;
    let leaves = &leaves;
    let parts: Vec<(BuildTree, Vec<u32>)> = std::thread::scope(|scope| {
        let handles: Vec<_> = groups
            .iter()
            .map(|&group| {
                scope.spawn(move || {
                    let mut t = BuildTree::default();
                    let roots = group
                        .iter()
                        .map(|&k| node(bin, span, k, width, leaves, &mut t))
                        .collect();
                    (t, roots)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a collapse thread panicked"))
            .collect()
    });
    let mut wide = [0u32; MAX_WIDTH];
    let mut slot = 0;
    for (t, roots) in parts {
        let at = out.append_shifted(&t.nodes, 0, threads);
        for r in roots {
            wide[slot] = r + at;
            slot += 1;
        }
    }
    out.nodes[0].kind = BuildKind::Inner {
        children: wide,
        len: len as u8,
    };
    out
}

#[cfg(test)]
mod tests {
    use super::super::build_median;
    use super::super::tree::BuildPrims;
    use super::*;
    use crate::geometry::aabb::Aabb;
    use glam::Vec3;

    fn plain(leaf: usize) -> Leaves<'static> {
        Leaves {
            leaf,
            split_leaves: true,
            scalar_before: None,
        }
    }

    fn row(n: usize) -> BuildPrims {
        let bounds: Vec<Aabb> = (0..n)
            .map(|i| {
                Aabb::new(
                    Vec3::new(i as f32, 0.0, 0.0),
                    Vec3::new(i as f32 + 0.5, 1.0, 1.0),
                )
            })
            .collect();
        BuildPrims {
            centroid: bounds.iter().map(|b| b.centre()).collect(),
            bounds,
        }
    }

    fn inner(t: &BuildTree) -> usize {
        t.nodes
            .iter()
            .filter(|n| matches!(n.kind, BuildKind::Inner { .. }))
            .count()
    }

    #[test]
    fn collapsing_a_balanced_binary_tree() {
        // 16 primitives, one per leaf: binary depth 4 → 4-wide depth 2 with 5 inner nodes and
        // no empty slot; 8-wide: 9 inner nodes (the root's 8 children hold 2 leaves each).
        let p = row(16);
        let bin = build_median::binary(&p, 1);
        let w4 = collapse(&bin, 4, plain(1));
        w4.validate(&p, 4).unwrap();
        assert_eq!(inner(&w4), 5);
        assert_eq!(w4.children(0).len(), 4);
        let w8 = collapse(&bin, 8, plain(1));
        w8.validate(&p, 8).unwrap();
        assert_eq!(inner(&w8), 9);
        assert_eq!(w8.children(0).len(), 8);
        let w2 = collapse(&bin, 2, plain(1));
        assert_eq!(w2.nodes.len(), bin.nodes.len());
    }

    #[test]
    fn small_subtrees_become_leaves_and_free_slots_split_them() {
        // 24 primitives, 4-wide, leaf 2: the root takes four subtrees of 6; each of those is
        // opened into 3 + 3, then (slots still free) into 1 + 2 + 1 + 2.
        let p = row(24);
        let bin = build_median::binary(&p, 1);
        let w4 = collapse(&bin, 4, plain(2));
        w4.validate(&p, 4).unwrap();
        let mut leaves: Vec<u32> = w4
            .nodes
            .iter()
            .filter_map(|n| match n.kind {
                BuildKind::Leaf { count, .. } => Some(count),
                _ => None,
            })
            .collect();
        leaves.sort();
        assert_eq!(leaves, [vec![1; 8], vec![2; 8]].concat());
        assert_eq!(inner(&w4), 5);
        // With room to spare every leaf ends up with one primitive: 64 primitives, 8-wide.
        let p = row(64);
        let w8 = collapse(&build_median::binary(&p, 1), 8, plain(4));
        w8.validate(&p, 8).unwrap();
        assert_eq!(inner(&w8), 9);
        assert_eq!(w8.nodes.len() - inner(&w8), 64);
    }
}
