//! Wald 2007's binned SAH split search.

use super::{blocks, split_cost, Range, Split, Splitter};
use crate::bvh::tree::{extend_par, BuildPrims, PARALLEL_MIN};
use crate::geometry::aabb::Aabb;
use crate::geometry::Geometry;
use glam::Vec3A;

/// A box in SIMD registers (glam's `Vec3A`): the binned builder's inner loops grow boxes
/// millions of times, and `Vec3A`'s min/max are single SSE instructions.
/// Also the spatial builder's box ([`super::spatial`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Box3A {
    pub(super) lo: Vec3A,
    pub(super) hi: Vec3A,
}

impl Box3A {
    pub(super) const EMPTY: Box3A = Box3A {
        lo: Vec3A::INFINITY,
        hi: Vec3A::NEG_INFINITY,
    };

    #[inline(always)]
    pub(super) fn grow(&mut self, b: &Box3A) {
        self.lo = self.lo.min(b.lo);
        self.hi = self.hi.max(b.hi);
    }

    #[inline(always)]
    pub(super) fn grow_point(&mut self, p: Vec3A) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }

    /// The box centre, computed as `BuildPrims` does (`Aabb::centre`).
    #[inline(always)]
    pub(super) fn centre(&self) -> Vec3A {
        (self.lo + self.hi) * 0.5
    }

    #[inline(always)]
    pub(super) fn half_area(&self) -> f32 {
        let e = (self.hi - self.lo).max(Vec3A::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    pub(super) fn aabb(&self) -> Aabb {
        Aabb::new(self.lo.into(), self.hi.into())
    }

    #[inline(always)]
    pub(super) fn new(lo: Vec3A, hi: Vec3A) -> Box3A {
        Box3A { lo, hi }
    }

    #[inline(always)]
    pub(super) fn is_empty(&self) -> bool {
        self.lo.cmpgt(self.hi).any()
    }

    #[inline(always)]
    pub(super) fn union(&self, o: &Box3A) -> Box3A {
        let mut b = *self;
        b.grow(o);
        b
    }

    pub(super) fn largest_axis(&self) -> usize {
        self.aabb().largest_axis()
    }
}

/// Wald 2007's binned SAH: the centroid bounds of the range are cut into `bins` equal bins per
/// axis; one pass over the primitives counts and bounds them per bin on all three axes, and the
/// `bins − 1` planes between bins are evaluated with a prefix/suffix sweep over the bins. The
/// range is then partitioned in place, which also gives both sides' bounds. Primitive boxes
/// are kept contiguous (Embree's `PrimRef`), with their indices alongside.
pub struct Binned<'a> {
    /// The boxes and indices of positions `off..off + boxes.len()` of the primitive order (all
    /// of it, or one side of a [`Binned::fork`]: a part of its parent's, borrowed).
    boxes: Store<'a, Box3A>,
    ids: Store<'a, u32>,
    off: usize,
    nb: usize,
    /// Indexed by a `u8` bin number, so no bounds check is needed in the binning loop.
    bins: Box<[[Bin; 3]; 256]>,
    /// The bin numbers of one axis's filled bins, and the area and count of the right side of
    /// the plane before each, indexed by a `u8`.
    filled: Box<[u8; 256]>,
    right_area: Box<[f32; 256]>,
    right_count: Box<[u32; 256]>,
    /// The SAH counts primitives in blocks of this many ([`super::blocks`]; 1: one by one).
    block: usize,
}

/// A splitter's boxes or indices: its own, or a part of its parent's (a fork's side, split
/// in place without copying: the copies and their page faults were a pass on one thread per
/// fork).
enum Store<'a, T> {
    Owned(Vec<T>),
    Part(&'a mut [T]),
}

impl<T> std::ops::Deref for Store<'_, T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        match self {
            Store::Owned(v) => v,
            Store::Part(p) => p,
        }
    }
}

impl<T> std::ops::DerefMut for Store<'_, T> {
    fn deref_mut(&mut self) -> &mut [T] {
        match self {
            Store::Owned(v) => v,
            Store::Part(p) => p,
        }
    }
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Box3A,
    count: u32,
}

impl Bin {
    const EMPTY: Bin = Bin {
        bounds: Box3A::EMPTY,
        count: 0,
    };
}

/// Wald 2007's map from a centre to its bin on each axis: `⌊(c − lo)·scale⌋` clamped to
/// `[0, last]`. The clamp is done on floats before the one SSE2 conversion (`cvttps2dq`);
/// truncating then clamping gives the same bins (both are monotone and `last` is a whole
/// number), and a NaN goes to bin 0 either way. glam's `as_uvec3` converted lane by lane with
/// Rust's saturating casts, 23% of the build's instructions with the clamp (callgrind).
/// Also the spatial builder's object split search ([`super::spatial`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct BinMap {
    lo: Vec3A,
    pub(super) scale: Vec3A,
    last: Vec3A,
}

impl BinMap {
    /// `nb` equal bins per axis over the centroid bounds `cb`.
    pub(super) fn new(cb: &Aabb, nb: usize) -> BinMap {
        let ext = Vec3A::from(cb.extent());
        // Bins per unit length on each axis; 0 on a flat axis puts everything in bin 0, where
        // no plane has primitives on both sides.
        let scale = Vec3A::select(
            ext.cmpgt(Vec3A::ZERO),
            Vec3A::splat(nb as f32 * (1.0 - 1e-6)) / ext,
            Vec3A::ZERO,
        );
        BinMap {
            lo: Vec3A::from(cb.lo),
            scale,
            last: Vec3A::splat((nb - 1) as f32),
        }
    }

    #[inline(always)]
    pub(super) fn bin_of(&self, c: Vec3A) -> [u32; 4] {
        let t = ((c - self.lo) * self.scale).max(Vec3A::ZERO).min(self.last);
        truncate(t)
    }
}

/// The lanes of `t` (each in `[0, 255]`, the unused fourth lane too) truncated to integers.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn truncate(t: Vec3A) -> [u32; 4] {
    use std::arch::x86_64::{__m128i, _mm_cvttps_epi32};
    // SAFETY: SSE2 is part of every x86_64 target; `__m128i` and `[u32; 4]` have the same
    // size and every bit pattern is valid for both.
    unsafe { std::mem::transmute::<__m128i, [u32; 4]>(_mm_cvttps_epi32(t.into())) }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn truncate(t: Vec3A) -> [u32; 4] {
    [t.x as u32, t.y as u32, t.z as u32, 0]
}

impl From<&Aabb> for Box3A {
    fn from(b: &Aabb) -> Box3A {
        Box3A {
            lo: b.lo.into(),
            hi: b.hi.into(),
        }
    }
}

impl<'a> Binned<'a> {
    /// A splitter over `boxes` and `ids`, positions `off..` of the primitive order, with
    /// `bins` bins per axis (2 to 256) and empty scratch.
    fn over(
        boxes: Store<'a, Box3A>,
        ids: Store<'a, u32>,
        off: usize,
        bins: usize,
        block: usize,
    ) -> Binned<'a> {
        Binned {
            boxes,
            ids,
            off,
            nb: bins.clamp(2, 256),
            bins: Box::new([[Bin::EMPTY; 3]; 256]),
            filled: Box::new([0; 256]),
            right_area: Box::new([0.0; 256]),
            right_count: Box::new([0; 256]),
            block,
        }
    }
}

impl Binned<'static> {
    pub fn new(prims: &BuildPrims, bins: usize) -> Binned<'static> {
        let boxes = prims.bounds.iter().map(Box3A::from).collect();
        let ids = (0..prims.len() as u32).collect();
        Binned::over(Store::Owned(boxes), Store::Owned(ids), 0, bins, 1)
    }

    /// [`Binned::new`] over `BuildPrims::new(geometry)`'s boxes, made straight from the
    /// geometry on `threads` threads (contiguous parts; the same boxes and order), without the
    /// primitive boxes and centres of [`BuildPrims`] in between: 29 MB and a pass fewer on
    /// balls4 tessellated.
    pub fn of_geometry(geometry: &Geometry, bins: usize, threads: usize) -> Binned<'static> {
        let n = geometry.prims.len();
        let threads = if n < 2 * PARALLEL_MIN { 1 } else { threads };
        let (mut boxes, mut ids) = (Vec::new(), Vec::new());
        extend_par(&mut boxes, n, threads, |i| {
            let (lo, hi) = geometry.prims[i].bounds();
            Box3A::from(&Aabb::new(lo, hi))
        });
        extend_par(&mut ids, n, threads, |i| i as u32);
        Binned::over(Store::Owned(boxes), Store::Owned(ids), 0, bins, 1)
    }

    /// The same search with the SAH counting primitives in blocks of `block` (Embree's
    /// `sahBlockSize`), for leaves whose primitives are tested `block` at a time.
    pub fn with_block(mut self, block: usize) -> Binned<'static> {
        assert!(block.is_power_of_two(), "block {block}");
        self.block = block;
        self
    }
}

impl Binned<'_> {
    /// Both sides of position `mid` as splitters of their own, borrowing this one's boxes and
    /// indices in place, so that a range on each side can be split on its own thread
    /// ([`super::binary::binary_blocks_threads`]); when both are dropped, this splitter holds
    /// what they did to its positions.
    pub fn fork(&mut self, mid: usize) -> (Binned<'_>, Binned<'_>) {
        let at = mid - self.off;
        let (off, nb, block) = (self.off, self.nb, self.block);
        let (bl, br) = self.boxes.split_at_mut(at);
        let (il, ir) = self.ids.split_at_mut(at);
        let side =
            |boxes, ids, off| Binned::over(Store::Part(boxes), Store::Part(ids), off, nb, block);
        (side(bl, il, off), side(br, ir, mid))
    }

    fn range(&self, start: usize, end: usize) -> Range {
        let mut bounds = Box3A::EMPTY;
        let mut centroids = Box3A::EMPTY;
        for p in &self.boxes[start - self.off..end - self.off] {
            bounds.grow(p);
            centroids.grow_point(p.centre());
        }
        Range {
            start,
            end,
            bounds: bounds.aabb(),
            centroids: centroids.aabb(),
        }
    }

    fn median(&mut self, r: &Range, axis: usize) -> Split {
        let k = r.len() / 2;
        // Select on (centre, index) pairs, then reorder boxes and indices to match.
        let start = r.start - self.off;
        let mut keyed: Vec<(f32, u32, Box3A)> = (start..r.end - self.off)
            .map(|i| (self.boxes[i].centre()[axis], self.ids[i], self.boxes[i]))
            .collect();
        keyed.select_nth_unstable_by(k, |x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        for (i, (_, id, b)) in keyed.into_iter().enumerate() {
            self.ids[start + i] = id;
            self.boxes[start + i] = b;
        }
        let mid = r.start + k;
        Split {
            left: self.range(r.start, mid),
            right: self.range(mid, r.end),
            axis,
            cost: f32::INFINITY,
        }
    }
}

/// Counts and bounds the centres of `boxes` into `bins` on all three axes.
#[inline(always)]
fn bin_into(bins: &mut [[Bin; 3]; 256], boxes: &[Box3A], map: &BinMap) {
    for p in boxes {
        let k = map.bin_of(p.centre());
        for a in 0..3 {
            // k < nb ≤ 256: the u8 is the bin itself, and indexes the 256 bins unchecked.
            let bin = &mut bins[k[a] as u8 as usize][a];
            bin.bounds.grow(p);
            bin.count += 1;
        }
    }
}

/// [`bin_into`] on `threads` threads, each binning a contiguous part of `boxes` into bins of
/// its own, then merged into `bins` (the first `nb` of each axis). A bin's count is a sum and
/// its box a union (min and max, exact), whichever thread saw which box, so the bins, and the
/// split chosen from them, are the one-thread search's (for boxes without NaN: the scenes'
/// coordinates are finite, `rtbench_scenes::validate`).
fn bin_threads(
    bins: &mut [[Bin; 3]; 256],
    boxes: &[Box3A],
    map: &BinMap,
    nb: usize,
    threads: usize,
) {
    let part = boxes.len().div_ceil(threads);
    let parts: Vec<Box<[[Bin; 3]; 256]>> = std::thread::scope(|scope| {
        let handles: Vec<_> = boxes
            .chunks(part)
            .map(|chunk| {
                scope.spawn(move || {
                    let mut own = Box::new([[Bin::EMPTY; 3]; 256]);
                    bin_into(&mut own, chunk, map);
                    own
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a binning thread panicked"))
            .collect()
    });
    for own in &parts {
        for (row, mine) in bins[..nb].iter_mut().zip(&own[..nb]) {
            for (b, m) in row.iter_mut().zip(mine) {
                b.bounds.grow(&m.bounds);
                b.count += m.count;
            }
        }
    }
}

impl Binned<'_> {
    /// [`Splitter::split`] with the binning pass (48 instructions per primitive) on `threads` threads when the range is large: for the top split of a
    /// parallel build, where every other thread would wait (`binary_blocks_threads`). The
    /// split is the one-thread search's ([`bin_threads`]).
    pub fn split_threads(
        &mut self,
        r: &Range,
        axis: Option<usize>,
        median: bool,
        threads: usize,
    ) -> Split {
        self.split_on(r, axis, median, threads)
    }

    /// The split search; `threads` 1 from [`Splitter::split`], a constant once inlined, so the
    /// one-thread build's code is as before.
    #[inline(always)]
    fn split_on(&mut self, r: &Range, axis: Option<usize>, median: bool, threads: usize) -> Split {
        debug_assert!(r.len() >= 2);
        let cb = r.centroids;
        if median {
            return self.median(r, axis.unwrap_or_else(|| cb.largest_axis()));
        }
        // Small ranges use fewer bins: 2n bins separate n centres about as well as 32, and
        // clearing and sweeping 3 × 32 bins would dominate the millions of splits near the
        // leaves.
        let nb = self.nb.min(2 * r.len());
        let map = BinMap::new(&cb, nb);
        let (start, end) = (r.start - self.off, r.end - self.off);
        // Every bin is empty between splits (the sweeps below empty the ones they used), so
        // no clearing pass is needed.
        if threads > 1 && r.len() >= 2 * PARALLEL_MIN {
            bin_threads(&mut self.bins, &self.boxes[start..end], &map, nb, threads);
        } else {
            bin_into(&mut self.bins, &self.boxes[start..end], &map);
        }
        let bins: &mut [[Bin; 3]; 256] = &mut self.bins;
        // An empty bin leaves both sides' boxes and counts as they were, so the plane after it
        // costs exactly what the plane before it does and never wins (ties keep the first
        // plane): the sweeps run over the filled bins only, `filled[..m]` in order. Small
        // ranges get 2n bins, at least half of them empty, and on balls3 tessellated the
        // average split has 6.4 filled bins of 24 per axis (callgrind).
        let mut best: Option<(usize, u32, f32)> = None; // (axis, plane, Σ A·N)
        for a in 0..3 {
            let filled = &mut self.filled;
            let mut m = 0;
            for (k, row) in bins[..nb].iter().enumerate() {
                // m ≤ k < 256: the u8 indexes unchecked.
                filled[m as u8 as usize] = k as u8;
                m += (row[a].count != 0) as usize;
            }
            if axis.is_none_or(|x| x == a) {
                // Planes between filled bins i − 1 and i (plane number filled[i − 1] + 1):
                // the right side's area and count from a sweep down, the left side's on the
                // way up.
                let mut acc = Box3A::EMPTY;
                let mut count = 0;
                for i in (1..m).rev() {
                    let bin = &bins[filled[i] as usize][a];
                    acc.grow(&bin.bounds);
                    count += bin.count;
                    self.right_area[i as u8 as usize] = acc.half_area();
                    self.right_count[i as u8 as usize] = count;
                }
                let mut l = Box3A::EMPTY;
                let mut lc = 0;
                for i in 1..m {
                    let k = filled[i - 1];
                    let bin = &bins[k as usize][a];
                    l.grow(&bin.bounds);
                    lc += bin.count;
                    let rc = self.right_count[i as u8 as usize];
                    let (lb, rb) = (
                        blocks(lc as usize, self.block) as u32,
                        blocks(rc as usize, self.block) as u32,
                    );
                    let c =
                        l.half_area() * lb as f32 + self.right_area[i as u8 as usize] * rb as f32;
                    if best.is_none_or(|b| c < b.2) {
                        best = Some((a, k as u32 + 1, c));
                    }
                }
            }
            for &k in &filled[..m] {
                bins[k as usize][a] = Bin::EMPTY;
            }
        }
        let Some((a, plane, c)) = best else {
            // All centres coincide (on the allowed axes): any equal-count split.
            return self.median(r, axis.unwrap_or_else(|| cb.largest_axis()));
        };
        // Partition in place, bounding both sides on the way. A centre goes left when its bin
        // is below `plane` (1 ≤ plane ≤ nb − 1), that is when `(c − lo)·scale ≥ plane` fails
        // on axis `a`: the clamp to [0, nb − 1] and the truncation cannot move a value across
        // a whole number in that range, and a NaN (bin 0) fails the comparison too. One
        // compare and a sign mask instead of the bin number.
        let at_plane = Vec3A::splat(plane as f32);
        let axis_bit = 1 << a;
        let boxes = &mut self.boxes[start..end];
        let ids = &mut self.ids[start..end];
        let (mut i, mut j) = (0, boxes.len());
        let (mut lb, mut lcb, mut rb, mut rcb) =
            (Box3A::EMPTY, Box3A::EMPTY, Box3A::EMPTY, Box3A::EMPTY);
        while i < j {
            let p = boxes[i];
            let centre = p.centre();
            let t = (centre - map.lo) * map.scale;
            if t.cmpge(at_plane).bitmask() & axis_bit == 0 {
                lb.grow(&p);
                lcb.grow_point(centre);
                i += 1;
            } else {
                rb.grow(&p);
                rcb.grow_point(centre);
                j -= 1;
                // The swap with `p` already in registers.
                boxes[i] = boxes[j];
                boxes[j] = p;
                ids.swap(i, j);
            }
        }
        let mid = r.start + i;
        Split {
            left: Range {
                start: r.start,
                end: mid,
                bounds: lb.aabb(),
                centroids: lcb.aabb(),
            },
            right: Range {
                start: mid,
                end: r.end,
                bounds: rb.aabb(),
                centroids: rcb.aabb(),
            },
            axis: a,
            cost: split_cost(c, r.bounds.half_area()),
        }
    }
}

impl Splitter for Binned<'_> {
    fn root(&self) -> Range {
        self.range(self.off, self.off + self.boxes.len())
    }

    fn split(&mut self, r: &Range, axis: Option<usize>, median: bool) -> Split {
        self.split_on(r, axis, median, 1)
    }

    fn ids(&self, r: &Range) -> &[u32] {
        &self.ids[r.start - self.off..r.end - self.off]
    }

    fn into_order(self) -> Vec<u32> {
        debug_assert_eq!(self.off, 0, "the order of a fork");
        match self.ids {
            Store::Owned(v) => v,
            Store::Part(p) => p.to_vec(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Boxes in a few tight clusters (so most bins are empty), with repeated centres.
    fn clustered(n: usize, seed: u64) -> BuildPrims {
        let mut x = seed;
        let mut next = || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 40) as f32) / (1u64 << 24) as f32
        };
        let bounds: Vec<Aabb> = (0..n)
            .map(|i| {
                let cluster = Vec3::new((i % 3) as f32 * 10.0, (i % 5) as f32 * 3.0, 0.0);
                let jitter = if i % 4 == 0 {
                    Vec3::ZERO
                } else {
                    Vec3::new(next(), next(), next())
                };
                let lo = cluster + jitter;
                Aabb::new(lo, lo + Vec3::new(next(), next(), next()) * 0.5)
            })
            .collect();
        let centroid = bounds.iter().map(|b| b.centre()).collect();
        BuildPrims { bounds, centroid }
    }

    /// Every plane of every axis evaluated from scratch, in the order the sweeps visit them:
    /// (axis, left ids sorted, cost).
    fn brute_force(p: &BuildPrims, r: &Range, nb: usize, block: usize) -> (usize, Vec<u32>, f32) {
        let map = BinMap::new(&r.centroids, nb);
        let boxes: Vec<Box3A> = p.bounds.iter().map(Box3A::from).collect();
        let mut best: Option<(usize, u32, f32)> = None;
        for a in 0..3 {
            for plane in 1..nb as u32 {
                let (mut l, mut r, mut lc, mut rc) = (Box3A::EMPTY, Box3A::EMPTY, 0, 0);
                for b in &boxes {
                    if map.bin_of(b.centre())[a] < plane {
                        l.grow(b);
                        lc += 1;
                    } else {
                        r.grow(b);
                        rc += 1;
                    }
                }
                if lc > 0 && rc > 0 {
                    let (lb, rb) = (blocks(lc, block), blocks(rc, block));
                    let c = l.half_area() * lb as f32 + r.half_area() * rb as f32;
                    if best.is_none_or(|b| c < b.2) {
                        best = Some((a, plane, c));
                    }
                }
            }
        }
        let (a, plane, c) = best.expect("a plane with both sides filled");
        let left = (0..boxes.len() as u32)
            .filter(|&i| map.bin_of(boxes[i as usize].centre())[a] < plane)
            .collect();
        (a, left, split_cost(c, r.bounds.half_area()))
    }

    /// The split search (filled bins only, the partition's compare against the plane) chooses
    /// the plane a search of every plane does, with the same cost to the bit, on ranges whose
    /// bins are mostly empty, with 2n bins (small ranges) and with 32.
    #[test]
    fn split_equals_every_plane_searched() {
        for (n, seed) in [(3, 1), (7, 2), (16, 3), (40, 4), (300, 5)] {
            for block in [1, 4] {
                let p = clustered(n, seed);
                let mut s = Binned::new(&p, 32).with_block(block);
                let root = s.root();
                let (axis, want_left, want_cost) = brute_force(&p, &root, 32.min(2 * n), block);
                let split = s.split(&root, None, false);
                let mut left = s.ids(&split.left).to_vec();
                left.sort_unstable();
                assert_eq!(
                    (split.axis, left, split.cost.to_bits()),
                    (axis, want_left, want_cost.to_bits()),
                    "n {n} block {block}"
                );
                // Both sides bounded as the partition went.
                assert_eq!(split.left.bounds, p.bounds_of(s.ids(&split.left)));
                assert_eq!(split.right.bounds, p.bounds_of(s.ids(&split.right)));
            }
        }
    }

    /// The float clamp before one conversion gives the bins the old clamp after a saturating
    /// conversion gave, at and around every bin edge, beyond both ends, and for NaN.
    #[test]
    fn bins_as_saturating_conversion_gave() {
        let nb: usize = 24;
        let map = BinMap {
            lo: Vec3A::ZERO,
            scale: Vec3A::ONE,
            last: Vec3A::splat((nb - 1) as f32),
        };
        let old = |t: f32| (t.max(0.0) as u32).min(nb as u32 - 1);
        for k in -3..nb as i32 + 3 {
            for t in [
                k as f32,
                (k as f32).next_down(),
                (k as f32).next_up(),
                k as f32 + 0.5,
            ] {
                assert_eq!(map.bin_of(Vec3A::splat(t))[0], old(t), "t {t}");
            }
        }
        for t in [f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30] {
            assert_eq!(map.bin_of(Vec3A::splat(t))[1], old(t), "t {t}");
        }
        assert_eq!(map.bin_of(Vec3A::splat(f32::NAN))[2], 0);
    }
}
