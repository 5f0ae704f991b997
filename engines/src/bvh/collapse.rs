//! Binary tree → N-wide tree, the common way (Embree's BVHN builders; Dammertz, Hanika and
//! Keller 2008's QBVH; Wald, Benthin and Boulos 2008): a wide node starts with its binary
//! node's two children and keeps replacing the inner child of largest surface area by that
//! child's own two children until it has N children or only leaves remain. Opening the largest
//! box first keeps the children that a ray is most likely to enter apart, which is what a
//! greedy SAH choice does. Leaves keep their primitive ranges.

use super::tree::{BuildKind, BuildTree, MAX_WIDTH};

pub fn collapse(bin: &BuildTree, width: usize) -> BuildTree {
    assert!((2..=MAX_WIDTH).contains(&width));
    let mut out = BuildTree {
        nodes: Vec::with_capacity(bin.nodes.len() / (width - 1) + 1),
        order: bin.order.clone(),
    };
    node(bin, 0, width, &mut out);
    out
}

fn node(bin: &BuildTree, i: u32, width: usize, out: &mut BuildTree) -> u32 {
    let n = &bin.nodes[i as usize];
    let BuildKind::Inner { children, len } = n.kind else {
        return out.push(n.bounds, n.kind);
    };
    let mut kids: Vec<u32> = children[..len as usize].to_vec();
    while kids.len() < width {
        // The inner child of largest area whose children still fit.
        let best = kids
            .iter()
            .enumerate()
            .filter_map(|(slot, &k)| match bin.nodes[k as usize].kind {
                BuildKind::Inner { len, .. } if kids.len() - 1 + len as usize <= width => {
                    Some((slot, bin.nodes[k as usize].bounds.half_area()))
                }
                _ => None,
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((slot, _)) = best else { break };
        let opened = kids[slot];
        let grand = bin.children(opened).to_vec();
        kids.splice(slot..slot + 1, grand);
    }
    let me = out.push(n.bounds, n.kind);
    let mut wide = [0u32; MAX_WIDTH];
    for (slot, &k) in kids.iter().enumerate() {
        wide[slot] = node(bin, k, width, out);
    }
    out.nodes[me as usize].kind = BuildKind::Inner {
        children: wide,
        len: kids.len() as u8,
    };
    me
}

#[cfg(test)]
mod tests {
    use super::super::build_median;
    use super::super::tree::BuildPrims;
    use super::*;
    use crate::geometry::aabb::Aabb;
    use glam::Vec3;

    #[test]
    fn collapsing_a_balanced_binary_tree() {
        // 16 primitives, one per leaf: binary depth 4 → 4-wide depth 2 with 5 inner nodes and
        // no empty slot; 8-wide: 9 inner nodes (the root's 8 children hold 2 leaves each).
        let bounds: Vec<Aabb> = (0..16)
            .map(|i| {
                Aabb::new(
                    Vec3::new(i as f32, 0.0, 0.0),
                    Vec3::new(i as f32 + 0.5, 1.0, 1.0),
                )
            })
            .collect();
        let p = BuildPrims {
            centroid: bounds.iter().map(|b| b.centre()).collect(),
            bounds,
        };
        let bin = build_median::binary(&p, 1);
        let inner = |t: &BuildTree| {
            t.nodes
                .iter()
                .filter(|n| matches!(n.kind, BuildKind::Inner { .. }))
                .count()
        };
        let w4 = collapse(&bin, 4);
        w4.validate(&p, 4).unwrap();
        assert_eq!(inner(&w4), 5);
        assert!(w4.children(0).len() == 4);
        let w8 = collapse(&bin, 8);
        w8.validate(&p, 8).unwrap();
        assert_eq!(inner(&w8), 9);
        assert_eq!(w8.children(0).len(), 8);
        let w2 = collapse(&bin, 2);
        assert_eq!(w2.nodes.len(), bin.nodes.len());
    }
}
