//! SAH builders: the split search (exact full sweep, 001 §1.5; or binned, Wald 2007) and the two
//! ways of making a tree from it (binary; or 001's N-ary "stepwise construction").
//!
//! The binary split cost is 001's Eq. 3.4 (from Wald, Boulos and Shirley 2007):
//! `2·T_AABB + (A(S1)/A(S))·N(S1)·T_tri + (A(S2)/A(S))·N(S2)·T_tri`. 001 splits down to one
//! primitive per leaf; with `leaf > 1` a node of at most `leaf` primitives becomes a leaf when
//! `N(S)·T_tri` is no more than its best split (the usual SAH termination).

use super::config::{T_AABB, T_TRI};
use super::tree::{BuildKind, BuildPrims, BuildTree, MAX_WIDTH, SAH_MEDIAN_DEPTH};
use crate::geometry::aabb::Aabb;

/// A chosen split of a primitive range: `[start, mid)` left, `[mid, end)` right.
#[derive(Clone, Copy, Debug)]
pub struct Split {
    pub mid: usize,
    pub axis: usize,
    /// Eq. 3.4's cost of the split.
    pub cost: f32,
}

/// Finds and applies splits of primitive ranges. Ranges are of one order of the primitives
/// that the splitter keeps (and hands over with [`Splitter::into_order`]).
pub trait Splitter {
    /// Bounds of the primitives of `[start, end)`.
    fn bounds(&self, start: usize, end: usize) -> Aabb;
    /// Best split of `[start, end)` (`end − start ≥ 2`), on `axis` only when given; with
    /// `median`, the object median on the axis of greatest centroid extent instead. The range
    /// is reordered to match.
    fn split(&mut self, start: usize, end: usize, axis: Option<usize>, median: bool) -> Split;
    fn into_order(self) -> Vec<u32>;
}

/// Eq. 3.4 from `A(S1)·N(S1) + A(S2)·N(S2)` (what the searches minimise) and `A(S)`.
fn split_cost(weighted_area: f32, parent_area: f32) -> f32 {
    let inv = if parent_area > 0.0 {
        1.0 / parent_area
    } else {
        0.0
    };
    2.0 * T_AABB + weighted_area * inv * T_TRI
}

/// Axes to search: the one given, or all three.
fn axes(axis: Option<usize>) -> std::ops::Range<usize> {
    match axis {
        Some(a) => a..a + 1,
        None => 0..3,
    }
}

// ---------------------------------------------------------------------------------------------
// Exact full sweep (001 §1.5)

/// 001's SAH search: for each axis, every position between primitives sorted by box centre, with
/// prefix and suffix boxes swept in O(n). The primitives are sorted once per axis and the three
/// orders partitioned stably at each split (Wald, Boulos and Shirley 2007), so a level costs
/// O(n) instead of a sort.
pub struct Sweep<'a> {
    prims: &'a BuildPrims,
    sorted: [Vec<u32>; 3],
    goes_left: Vec<bool>,
    scratch: Vec<u32>,
    right_area: Vec<f32>,
}

impl<'a> Sweep<'a> {
    pub fn new(prims: &'a BuildPrims) -> Sweep<'a> {
        let sorted = [0, 1, 2].map(|a| {
            let mut v: Vec<u32> = (0..prims.len() as u32).collect();
            v.sort_unstable_by(|&x, &y| prims.cmp(x, y, a));
            v
        });
        Sweep {
            prims,
            sorted,
            goes_left: vec![false; prims.len()],
            scratch: Vec::with_capacity(prims.len()),
            right_area: vec![0.0; prims.len()],
        }
    }

    /// Makes every axis order of `[start, end)` put the primitives of `sorted[axis][start..mid]`
    /// first, keeping each side sorted.
    fn partition(&mut self, start: usize, mid: usize, end: usize, axis: usize) {
        for &p in &self.sorted[axis][start..mid] {
            self.goes_left[p as usize] = true;
        }
        for &p in &self.sorted[axis][mid..end] {
            self.goes_left[p as usize] = false;
        }
        for a in (0..3).filter(|&a| a != axis) {
            let s = &mut self.sorted[a][start..end];
            self.scratch.clear();
            let mut w = 0;
            for i in 0..s.len() {
                let p = s[i];
                if self.goes_left[p as usize] {
                    s[w] = p;
                    w += 1;
                } else {
                    self.scratch.push(p);
                }
            }
            s[w..].copy_from_slice(&self.scratch);
        }
    }
}

impl Splitter for Sweep<'_> {
    fn bounds(&self, start: usize, end: usize) -> Aabb {
        self.prims.bounds_of(&self.sorted[0][start..end])
    }

    fn split(&mut self, start: usize, end: usize, axis: Option<usize>, median: bool) -> Split {
        let n = end - start;
        debug_assert!(n >= 2);
        let (axis, mid, cost) = if median {
            let cb = self.prims.centroid_bounds_of(&self.sorted[0][start..end]);
            let a = axis.unwrap_or_else(|| cb.largest_axis());
            (a, n / 2, f32::INFINITY)
        } else {
            let mut best = (0, 1, f32::INFINITY);
            let mut parent = 0.0;
            for a in axes(axis) {
                let s = &self.sorted[a][start..end];
                let mut b = Aabb::EMPTY;
                for i in (1..n).rev() {
                    b.grow(&self.prims.bounds[s[i] as usize]);
                    self.right_area[i] = b.half_area();
                }
                b.grow(&self.prims.bounds[s[0] as usize]);
                parent = b.half_area();
                let mut l = Aabb::EMPTY;
                for i in 1..n {
                    l.grow(&self.prims.bounds[s[i - 1] as usize]);
                    // Eq. 3.4 without its constant part and the division by A(S), which are
                    // the same for every candidate.
                    let c = l.half_area() * i as f32 + self.right_area[i] * (n - i) as f32;
                    if c < best.2 {
                        best = (a, i, c);
                    }
                }
            }
            (best.0, best.1, split_cost(best.2, parent))
        };
        self.partition(start, start + mid, end, axis);
        Split {
            mid: start + mid,
            axis,
            cost,
        }
    }

    fn into_order(self) -> Vec<u32> {
        let [order, _, _] = self.sorted;
        order
    }
}

// ---------------------------------------------------------------------------------------------
// Binned (Wald 2007)

/// Wald 2007's binned SAH: the centroid bounds of the range are cut into `bins` equal bins per
/// axis; primitives are counted and bounded per bin in one pass, and the `bins − 1` planes
/// between bins are evaluated with a prefix/suffix sweep over the bins. The range is then
/// partitioned in place.
pub struct Binned<'a> {
    prims: &'a BuildPrims,
    order: Vec<u32>,
    bins: Vec<Bin>,
    right_area: Vec<f32>,
    right_count: Vec<usize>,
}

impl<'a> Binned<'a> {
    pub fn new(prims: &'a BuildPrims, bins: usize) -> Binned<'a> {
        let nb = bins.clamp(2, 256);
        Binned {
            prims,
            order: (0..prims.len() as u32).collect(),
            bins: vec![Bin::EMPTY; nb],
            right_area: vec![0.0; nb],
            right_count: vec![0; nb],
        }
    }
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Aabb,
    count: usize,
}

impl Bin {
    const EMPTY: Bin = Bin {
        bounds: Aabb::EMPTY,
        count: 0,
    };
}

impl Splitter for Binned<'_> {
    fn bounds(&self, start: usize, end: usize) -> Aabb {
        self.prims.bounds_of(&self.order[start..end])
    }

    fn split(&mut self, start: usize, end: usize, axis: Option<usize>, median: bool) -> Split {
        let n = end - start;
        debug_assert!(n >= 2);
        let ids = &mut self.order[start..end];
        let cb = self.prims.centroid_bounds_of(ids);
        let ext = cb.extent();
        let median_split = |ids: &mut [u32], a: usize| {
            let prims = self.prims;
            ids.select_nth_unstable_by(n / 2, |&x, &y| prims.cmp(x, y, a));
            Split {
                mid: start + n / 2,
                axis: a,
                cost: f32::INFINITY,
            }
        };
        if median {
            return median_split(ids, axis.unwrap_or_else(|| cb.largest_axis()));
        }
        let nb = self.bins.len();
        let (bins, right_area, right_count) =
            (&mut self.bins, &mut self.right_area, &mut self.right_count);
        let mut best: Option<(usize, usize, f32)> = None; // (axis, plane, cost)
        let mut parent = 0.0;
        for a in axes(axis) {
            if ext[a] <= 0.0 {
                continue;
            }
            let scale = nb as f32 * (1.0 - 1e-6) / ext[a];
            let lo = cb.lo[a];
            bins.fill(Bin::EMPTY);
            for &p in ids.iter() {
                let k = (((self.prims.centroid[p as usize][a] - lo) * scale) as usize).min(nb - 1);
                bins[k].bounds.grow(&self.prims.bounds[p as usize]);
                bins[k].count += 1;
            }
            let mut r = Aabb::EMPTY;
            let mut rc = 0;
            for k in (1..nb).rev() {
                r.grow(&bins[k].bounds);
                rc += bins[k].count;
                right_area[k] = r.half_area();
                right_count[k] = rc;
            }
            let mut l = bins[0].bounds;
            let mut lc = bins[0].count;
            parent = l.union(&r).half_area();
            for k in 1..nb {
                if lc > 0 && right_count[k] > 0 {
                    let c = l.half_area() * lc as f32 + right_area[k] * right_count[k] as f32;
                    if best.map_or(true, |b| c < b.2) {
                        best = Some((a, k, c));
                    }
                }
                l.grow(&bins[k].bounds);
                lc += bins[k].count;
            }
        }
        let Some((a, k, c)) = best else {
            // All centres coincide (on the allowed axis): any equal-count split.
            return median_split(ids, axis.unwrap_or_else(|| cb.largest_axis()));
        };
        let scale = nb as f32 * (1.0 - 1e-6) / ext[a];
        let lo = cb.lo[a];
        let centroid = &self.prims.centroid;
        let goes_left =
            |p: u32| (((centroid[p as usize][a] - lo) * scale) as usize).min(nb - 1) < k;
        let mut i = 0;
        let mut j = ids.len();
        while i < j {
            if goes_left(ids[i]) {
                i += 1;
            } else {
                j -= 1;
                ids.swap(i, j);
            }
        }
        Split {
            mid: start + i,
            axis: a,
            cost: split_cost(c, parent),
        }
    }

    fn into_order(self) -> Vec<u32> {
        self.order
    }
}

// ---------------------------------------------------------------------------------------------
// Trees from splits

/// Whether a range of `n` primitives whose best split costs `split_cost` becomes a leaf.
fn make_leaf(n: usize, leaf: usize, split_cost: f32) -> bool {
    n == 1 || (n <= leaf && n as f32 * T_TRI <= split_cost)
}

/// Binary SAH tree (001 with B = 2; Wald, Boulos and Shirley 2007).
pub fn binary<S: Splitter>(mut s: S, n_prims: usize, leaf: usize) -> BuildTree {
    let mut tree = BuildTree {
        nodes: Vec::with_capacity(2 * n_prims + 1),
        order: Vec::new(),
    };
    binary_node(&mut s, &mut tree, 0, n_prims, 0, leaf);
    tree.order = s.into_order();
    tree
}

fn binary_node<S: Splitter>(
    s: &mut S,
    tree: &mut BuildTree,
    start: usize,
    end: usize,
    depth: usize,
    leaf: usize,
) -> u32 {
    let bounds = s.bounds(start, end);
    let n = end - start;
    let leaf_kind = BuildKind::Leaf {
        first: start as u32,
        count: n as u32,
    };
    if n == 1 {
        return tree.push(bounds, leaf_kind);
    }
    let median = depth >= SAH_MEDIAN_DEPTH;
    if median && n <= leaf {
        return tree.push(bounds, leaf_kind);
    }
    let split = s.split(start, end, None, median);
    if make_leaf(n, leaf, split.cost) {
        return tree.push(bounds, leaf_kind);
    }
    let me = tree.push(bounds, leaf_kind);
    let l = binary_node(s, tree, start, split.mid, depth + 1, leaf);
    let r = binary_node(s, tree, split.mid, end, depth + 1, leaf);
    let mut children = [0; MAX_WIDTH];
    children[0] = l;
    children[1] = r;
    tree.nodes[me as usize].kind = BuildKind::Inner { children, len: 2 };
    me
}

/// 001's N-ary SAH tree ("stepwise construction", §1.5, thesis Fig. 3.15), N a power of two:
/// split a node's primitives with the binary SAH over all axes, then split each group again
/// with the SAH on that first split's axis only, log2(N) times; the groups become the children
/// in axis order. A group that would become a leaf is not split further (its slot stays
/// empty, 001's empty nodes).
pub fn wide_same_axis<S: Splitter>(
    mut s: S,
    n_prims: usize,
    leaf: usize,
    width: usize,
) -> BuildTree {
    assert!(width.is_power_of_two() && (2..=MAX_WIDTH).contains(&width));
    let mut tree = BuildTree {
        nodes: Vec::with_capacity(2 * n_prims + 1),
        order: Vec::new(),
    };
    wide_node(&mut s, &mut tree, 0, n_prims, 0, leaf, width);
    tree.order = s.into_order();
    tree
}

fn wide_node<S: Splitter>(
    s: &mut S,
    tree: &mut BuildTree,
    start: usize,
    end: usize,
    depth: usize,
    leaf: usize,
    width: usize,
) -> u32 {
    let bounds = s.bounds(start, end);
    let n = end - start;
    let leaf_kind = BuildKind::Leaf {
        first: start as u32,
        count: n as u32,
    };
    if n == 1 {
        return tree.push(bounds, leaf_kind);
    }
    // `depth` counts binary levels, so the median fallback bounds the depth as in `binary`.
    let median = depth >= SAH_MEDIAN_DEPTH;
    if median && n <= leaf {
        return tree.push(bounds, leaf_kind);
    }
    let first = s.split(start, end, None, median);
    if make_leaf(n, leaf, first.cost) {
        return tree.push(bounds, leaf_kind);
    }
    let axis = Some(first.axis);
    // Groups as (start, end, still splittable).
    let mut groups: Vec<(usize, usize, bool)> = vec![(start, first.mid, true), (first.mid, end, true)];
    let levels = width.trailing_zeros() as usize;
    for _ in 1..levels {
        let mut next = Vec::with_capacity(2 * groups.len());
        for &(a, b, open) in &groups {
            let m = b - a;
            if !open || m == 1 || (median && m <= leaf) {
                next.push((a, b, false));
                continue;
            }
            let sp = s.split(a, b, axis, median);
            if make_leaf(m, leaf, sp.cost) {
                next.push((a, b, false));
            } else {
                next.push((a, sp.mid, true));
                next.push((sp.mid, b, true));
            }
        }
        groups = next;
    }
    let me = tree.push(bounds, leaf_kind);
    let mut children = [0; MAX_WIDTH];
    for (slot, &(a, b, _)) in groups.iter().enumerate() {
        children[slot] = wide_node(s, tree, a, b, depth + levels, leaf, width);
    }
    tree.nodes[me as usize].kind = BuildKind::Inner {
        children,
        len: groups.len() as u8,
    };
    me
}

#[cfg(test)]
mod tests {
    use super::*;
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
        for t in [
            binary(Sweep::new(&p), p.len(), 1),
            binary(Binned::new(&p, 16), p.len(), 1),
        ] {
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
        let p = prims(&[0.0, 1.0, 2.0, 10.0].map(|x| (Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 1.0, 1.0))));
        let mut s = Sweep::new(&p);
        let sp = s.split(0, 4, None, false);
        assert_eq!((sp.mid, sp.axis), (3, 0));
        // Eq. 3.4 by hand: left box 3×1×1 (half area 7), right 1×1×1 (3), parent 11×1×1 (23).
        let want = 2.0 + (7.0 * 3.0 + 3.0 * 1.0) / 23.0;
        assert!((sp.cost - want).abs() < 1e-5, "{} vs {want}", sp.cost);
    }

    #[test]
    fn leaves_grow_up_to_leaf_size_when_cheaper() {
        let p = clusters();
        let t = binary(Binned::new(&p, 32), p.len(), 4);
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
        let p = prims(&(0..64).map(|i| {
            let x = (i % 8) as f32 * 2.0;
            let y = (i / 8) as f32 * 2.0;
            (Vec3::new(x, y, 0.0), Vec3::new(x + 1.0, y + 1.0, 1.0))
        }).collect::<Vec<_>>());
        for width in [4, 8] {
            let t = wide_same_axis(Sweep::new(&p), p.len(), 1, width);
            t.validate(&p, width).unwrap();
            let c = t.children(0);
            assert_eq!(c.len(), width);
            // Children follow each other along one axis without overlap.
            let b: Vec<Aabb> = c.iter().map(|&i| t.nodes[i as usize].bounds).collect();
            let along = |a: usize| b.windows(2).all(|w| w[0].hi[a] <= w[1].lo[a]);
            assert!(along(0) || along(1), "{b:?}");
        }
    }
}
