//! 001's exact full-sweep SAH split search (§1.5).

use super::{axes, blocks, split_cost, Range, Split, Splitter};
use crate::bvh::tree::BuildPrims;
use crate::geometry::aabb::Aabb;

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
    /// The SAH counts primitives in blocks of this many ([`super::blocks`]; 1: one by one).
    block: usize,
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
            block: 1,
        }
    }

    /// The same search with the SAH counting primitives in blocks of `block` (Embree's
    /// `sahBlockSize`), for leaves whose primitives are tested `block` at a time.
    pub fn with_block(mut self, block: usize) -> Sweep<'a> {
        assert!(block.is_power_of_two(), "block {block}");
        self.block = block;
        self
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
    fn root(&self) -> Range {
        range_of(self.prims, &self.sorted[0], 0, self.prims.len())
    }

    fn split(&mut self, r: &Range, axis: Option<usize>, median: bool) -> Split {
        let (start, end, n) = (r.start, r.end, r.len());
        debug_assert!(n >= 2);
        let (axis, mid, cost) = if median {
            let a = axis.unwrap_or_else(|| r.centroids.largest_axis());
            (a, n / 2, f32::INFINITY)
        } else {
            let mut best = (0, 1, f32::INFINITY);
            for a in axes(axis) {
                let s = &self.sorted[a][start..end];
                let mut b = Aabb::EMPTY;
                for i in (1..n).rev() {
                    b.grow(&self.prims.bounds[s[i] as usize]);
                    self.right_area[i] = b.half_area();
                }
                let mut l = Aabb::EMPTY;
                for i in 1..n {
                    l.grow(&self.prims.bounds[s[i - 1] as usize]);
                    // Eq. 3.4 without its constant part and the division by A(S), which are
                    // the same for every candidate.
                    let (lb, rb) = (blocks(i, self.block), blocks(n - i, self.block));
                    let c = l.half_area() * lb as f32 + self.right_area[i] * rb as f32;
                    if c < best.2 {
                        best = (a, i, c);
                    }
                }
            }
            (best.0, best.1, split_cost(best.2, r.bounds.half_area()))
        };
        self.partition(start, start + mid, end, axis);
        Split {
            left: range_of(self.prims, &self.sorted[0], start, start + mid),
            right: range_of(self.prims, &self.sorted[0], start + mid, end),
            axis,
            cost,
        }
    }

    fn ids(&self, r: &Range) -> &[u32] {
        &self.sorted[0][r.start..r.end]
    }

    fn into_order(self) -> Vec<u32> {
        let [order, _, _] = self.sorted;
        order
    }
}

/// The range `[start, end)` of `ids` with its bounds, in one pass.
fn range_of(prims: &BuildPrims, ids: &[u32], start: usize, end: usize) -> Range {
    let mut bounds = Aabb::EMPTY;
    let mut centroids = Aabb::EMPTY;
    for &i in &ids[start..end] {
        bounds.grow(&prims.bounds[i as usize]);
        centroids.grow_point(prims.centroid[i as usize]);
    }
    Range {
        start,
        end,
        bounds,
        centroids,
    }
}
