use super::{binary, wide_same_axis, Binned, Splitter, Sweep};
use crate::bvh::tree::{BuildKind, BuildPrims};
use crate::geometry::aabb::Aabb;
use glam::Vec3;

fn prims(boxes: &[(Vec3, Vec3)]) -> BuildPrims {
    let bounds: Vec<Aabb> = boxes.iter().map(|&(l, h)| Aabb::new(l, h)).collect();
    let centroid = bounds.iter().map(|b| b.centre()).collect();
    BuildPrims { bounds, centroid }
}

/// Two clusters of small boxes far apart on y: the first split must separate them.
fn clusters() -> BuildPrims {
    let mut v = Vec::new();
    for i in 0..10 {
        let x = i as f32 * 0.1;
        v.push((Vec3::new(x, 0.0, 0.0), Vec3::new(x + 0.05, 0.05, 0.05)));
        v.push((Vec3::new(x, 100.0, 0.0), Vec3::new(x + 0.05, 100.05, 0.05)));
    }
    prims(&v)
}

#[test]
fn sweep_and_binned_separate_clusters() {
    let p = clusters();
    for t in [binary(Sweep::new(&p), 1), binary(Binned::new(&p, 16), 1)] {
        t.validate(&p, 2).unwrap();
        let c = t.children(0);
        assert_eq!(c.len(), 2);
        for &ci in c {
            let b = t.nodes[ci as usize].bounds;
            assert!(b.hi.y - b.lo.y < 1.0, "a child spans both clusters: {b:?}");
        }
        // One primitive per leaf with leaf = 1 (001): 2n − 1 nodes.
        assert_eq!(t.nodes.len(), 2 * p.len() - 1);
    }
}

#[test]
fn sweep_finds_the_exact_optimum() {
    // Four unit boxes at x = 0, 1, 2 and 10: the best cut is before the far one.
    let p = prims(
        &[0.0, 1.0, 2.0, 10.0].map(|x| (Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0))),
    );
    let mut s = Sweep::new(&p);
    let root = s.root();
    let sp = s.split(&root, None, false);
    assert_eq!((sp.left.end, sp.axis), (3, 0));
    // Eq. 3.4 by hand: left box 3×1×1 (half area 7), right 1×1×1 (3), parent 11×1×1 (23).
    let want = 2.0 + (7.0 * 3.0 + 3.0 * 1.0) / 23.0;
    assert!((sp.cost - want).abs() < 1e-5, "{} vs {want}", sp.cost);
}

#[test]
fn leaves_grow_up_to_leaf_size_when_cheaper() {
    let p = clusters();
    let t = binary(Binned::new(&p, 32), 4);
    t.validate(&p, 2).unwrap();
    let max_leaf = t
        .nodes
        .iter()
        .filter_map(|n| match n.kind {
            BuildKind::Leaf { count, .. } => Some(count),
            _ => None,
        })
        .max()
        .unwrap();
    assert!((2..=4).contains(&max_leaf));
}

#[test]
fn same_axis_wide_children_are_ordered_on_one_axis() {
    let p = prims(
        &(0..64)
            .map(|i| {
                let x = (i % 8) as f32 * 2.0;
                let y = (i / 8) as f32 * 2.0;
                (Vec3::new(x, y, 0.0), Vec3::new(x + 1.0, y + 1.0, 1.0))
            })
            .collect::<Vec<_>>(),
    );
    for width in [4, 8] {
        let t = wide_same_axis(Sweep::new(&p), 1, width);
        t.validate(&p, width).unwrap();
        let c = t.children(0);
        assert_eq!(c.len(), width);
        // Children follow each other along one axis without overlap.
        let b: Vec<Aabb> = c.iter().map(|&i| t.nodes[i as usize].bounds).collect();
        let along = |a: usize| b.windows(2).all(|w| w[0].hi[a] <= w[1].lo[a]);
        assert!(along(0) || along(1), "{b:?}");
    }
}

/// Embree's leaf rule: twelve coincident boxes are one leaf (three blocks of 4 cost less than
/// any split, whose halves keep the whole box); a primitive that is not packable never shares a
/// leaf; distant clusters are still split.
#[test]
fn block_leaves_follow_the_sah_in_blocks() {
    use super::{binary_blocks, BlockLeaves};
    let same = prims(&vec![(Vec3::ZERO, Vec3::ONE); 12]);
    let all = vec![true; 12];
    let rule = BlockLeaves {
        min: 4,
        max: 16,
        block: 4,
        packable: &all,
    };
    let t = binary_blocks(Binned::new(&same, 32).with_block(4), &rule);
    t.validate(&same, 2).unwrap();
    assert_eq!(t.nodes.len(), 1, "one leaf of 12");
    let mut one_scalar = all.clone();
    one_scalar[5] = false;
    let rule = BlockLeaves {
        packable: &one_scalar,
        ..rule
    };
    let t = binary_blocks(Binned::new(&same, 32).with_block(4), &rule);
    t.validate(&same, 2).unwrap();
    for n in &t.nodes {
        if let BuildKind::Leaf { first, count } = n.kind {
            let ids = &t.order[first as usize..(first + count) as usize];
            assert!(count == 1 || !ids.contains(&5), "primitive 5 shares a leaf");
        }
    }
    let c = clusters();
    let all = vec![true; c.len()];
    let rule = BlockLeaves {
        packable: &all,
        ..rule
    };
    let t = binary_blocks(Binned::new(&c, 32).with_block(4), &rule);
    t.validate(&c, 2).unwrap();
    assert_eq!(t.children(0).len(), 2, "the clusters are split");
}
