//! Spatial splits (Stich, Friedrich and Dietrich 2009, "Spatial Splits in Bounding Volume
//! Hierarchies", §3–§4; as Embree's spatial-split builder, `BVHBuilderFastSpatialSAH`):
//! a node may cut space instead of its list of triangles, so a long triangle crossing the cut
//! is referenced on both sides, each reference bounded by its own part of the triangle. Long
//! thin triangles (gears' ear-clipped faces, a teapot's seams) then no longer stretch the boxes
//! of their neighbours.
//!
//! At each node the binned object split (Wald 2007, as [`super::Binned`]) is searched first;
//! where its two boxes overlap by more than `alpha` of the root's area, the spatial split is
//! searched too: the node's box is cut into equal bins per axis, each reference clipped into
//! the bins it spans (entering the first, leaving the last), and the planes between bins costed
//! as the object split's are. Straddling references go to one side only where that costs less
//! than splitting them ("reference unsplitting", §4.4). Duplicates are bounded by a budget of
//! extra references shared out down the tree in proportion to the references of each side.
//!
//! The tree is the binary tree of [`super::binary_blocks`] (Embree's leaf rule, SAH counts in
//! blocks), for collapsing into a wide tree; its order holds a triangle once per reference.
//! Triangles only: spheres and cones are not clipped.

use super::binary::FORK_MIN;
use super::binned::{BinMap as CentreMap, Box3A as Bx};
use super::{blocks, split_cost, BlockLeaves};
use crate::bvh::config::{T_AABB, T_TRI};
use crate::bvh::tree::{BuildKind, BuildTree, MAX_WIDTH, SAH_MEDIAN_DEPTH};
use crate::geometry::{Geometry, Prim};
use glam::Vec3A;

/// Bins per axis of the spatial search (Embree's fast spatial builder uses 16).
const SPATIAL_BINS: usize = 16;

/// Stich et al.'s α: the least overlap of the object split's two boxes, as a fraction of the
/// root's area, for which a spatial split is searched.
const ALPHA: f32 = 1e-5;

/// The least overlap of the object split's two boxes as a fraction of the node's own area for
/// which a spatial split is searched (Embree's threshold): below it the two sides hardly share
/// space, and a spatial split seldom pays for its search.
const NODE_OVERLAP: f32 = 0.1;

/// One reference: a triangle and the box of its part on this side of every cut above.
#[derive(Clone, Copy, Debug)]
struct Ref {
    b: Bx,
    id: u32,
}

/// What the spatial builder is given besides the geometry.
#[derive(Clone, Copy, Debug)]
pub struct SpatialSettings {
    /// Bins per axis of the object split search.
    pub bins: usize,
    /// Extra references allowed, as a fraction of the triangles.
    pub budget: f32,
    /// The fewest references of a node whose spatial splits are searched: a search clips
    /// every reference into the bins it spans, on three axes, which for small nodes costs more
    /// build time than their splits save in tracing.
    pub min_refs: usize,
}

/// A binary tree over `geometry`'s triangles with spatial splits, leaves by `rule`, built on
/// `threads` threads: the two sides of each of the top `⌈log2 threads⌉ + 2` levels of splits
/// (not counting splits with a side below [`FORK_MIN`] references) are built at once, the
/// right side on a thread of its own into a tree of its own, appended after the left side
/// where the one-thread build puts it. A side's subtree depends only on its references, its
/// depth and its share of the budget, so the tree is the same node for node at any count
/// (test `bvh::tests::threads_build_the_same_tree`).
pub fn spatial_blocks(
    geometry: &Geometry,
    rule: &BlockLeaves,
    s: SpatialSettings,
    threads: usize,
) -> BuildTree {
    let tris: Vec<[Vec3A; 3]> = geometry
        .prims
        .iter()
        .map(|p| match p {
            Prim::Triangle(v) => v.map(Vec3A::from),
            // Not a triangle: a point box never split (callers pass triangle scenes only).
            other => {
                let (lo, hi) = other.bounds();
                [lo.into(), hi.into(), hi.into()]
            }
        })
        .collect();
    let refs: Vec<Ref> = geometry
        .prims
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (lo, hi) = p.bounds();
            Ref {
                b: Bx::new(lo.into(), hi.into()),
                id: i as u32,
            }
        })
        .collect();
    let mut bounds = Bx::EMPTY;
    for r in &refs {
        bounds.grow(&r.b);
    }
    let n = refs.len();
    let mut b = Build::new(
        Params {
            tris: &tris,
            rule,
            bins: s.bins.clamp(2, 256),
            min_overlap: ALPHA * bounds.half_area(),
            min_refs: s.min_refs,
        },
        n,
    );
    let budget = (s.budget.max(0.0) * n as f32) as usize;
    let forks = if threads > 1 {
        threads.next_power_of_two().trailing_zeros() as usize + 2
    } else {
        0
    };
    if n > 0 {
        b.node(refs, bounds, 0, budget, forks);
    }
    b.tree
}

/// What every node of one build reads.
#[derive(Clone, Copy)]
struct Params<'a> {
    tris: &'a [[Vec3A; 3]],
    rule: &'a BlockLeaves<'a>,
    bins: usize,
    min_overlap: f32,
    min_refs: usize,
}

/// A build's settings, its search scratch and the tree it makes (one per thread).
struct Build<'a> {
    p: Params<'a>,
    /// The object search's bins: per axis 256, indexed by a `u8` bin number (no bounds check),
    /// all empty between searches.
    scratch: Box<[[(Bx, usize); 256]; 3]>,
    /// The object search's filled bins of one axis, and the right side (area, count) of the
    /// plane before each (written before read: a fresh array was 4 KB zeroed per node).
    filled: Box<[u8; 256]>,
    right: Box<[(f32, usize); 256]>,
    tree: BuildTree,
}

/// Where a split cuts: an object split between two bins of the centres (the right side's
/// first), or a spatial split at a plane.
#[derive(Clone, Copy, Debug)]
enum Cut {
    Object { map: CentreMap, first: usize },
    Spatial { plane: f32 },
}

/// A split found by a search: its SAH numerator (`A_L·N_L + A_R·N_R` in blocks), the sides'
/// boxes, the right side's count, and where it cuts.
#[derive(Clone, Copy, Debug)]
struct Found {
    weighted: f32,
    axis: usize,
    cut: Cut,
    lb: Bx,
    rb: Bx,
    nr: usize,
}

impl<'a> Build<'a> {
    /// A build with empty scratch and a tree reserved for about `n` references.
    fn new(p: Params<'a>, n: usize) -> Build<'a> {
        Build {
            p,
            scratch: Box::new([[(Bx::EMPTY, 0); 256]; 3]),
            filled: Box::new([0; 256]),
            right: Box::new([(0.0, 0); 256]),
            tree: BuildTree {
                nodes: Vec::with_capacity(2 * n / p.rule.min.max(1) + 1),
                order: Vec::with_capacity(n + n / 4),
            },
        }
    }

    fn leaf(&mut self, refs: &[Ref], bounds: Bx) -> u32 {
        let first = self.tree.order.len() as u32;
        self.tree.order.extend(refs.iter().map(|r| r.id));
        self.tree.push(
            bounds.aabb(),
            BuildKind::Leaf {
                first,
                count: refs.len() as u32,
            },
        )
    }

    /// The subtree of `refs` in `bounds`, its splits sharing `budget` extra references; its
    /// top `forks` levels of splits build their two sides at once.
    fn node(
        &mut self,
        mut refs: Vec<Ref>,
        bounds: Bx,
        depth: usize,
        budget: usize,
        forks: usize,
    ) -> u32 {
        let n = refs.len();
        if n == 1 || n <= self.p.rule.min {
            return self.leaf(&refs, bounds);
        }
        let block = self.p.rule.block;
        let median = depth >= SAH_MEDIAN_DEPTH;
        let mut best = if median { None } else { self.object(&refs) };
        if !median {
            let overlap = best.map_or(f32::INFINITY, |f| overlap_area(&f.lb, &f.rb));
            if budget > 0
                && n >= self.p.min_refs
                && overlap > self.p.min_overlap
                && overlap >= NODE_OVERLAP * bounds.half_area()
            {
                if let Some(sp) = self.spatial(&refs, &bounds) {
                    if best.is_none_or(|o| sp.weighted < o.weighted) {
                        best = Some(sp);
                    }
                }
            }
        }
        let weighted = best.map_or(f32::INFINITY, |f| f.weighted);
        let cost = split_cost(weighted, bounds.half_area());
        let leaf_cost = blocks(n, block) as f32 * T_TRI;
        if n <= self.p.rule.max && leaf_cost <= cost - T_AABB {
            return self.leaf(&refs, bounds);
        }
        let (left, right) = match best {
            Some(Found {
                cut: Cut::Spatial { plane },
                axis,
                nr,
                ..
            }) => self.partition_spatial(refs, axis, plane, nr),
            Some(Found {
                cut: Cut::Object { map, first },
                axis,
                nr,
                ..
            }) => {
                // The left side stays in the node's vector, in order.
                let mut right = Vec::with_capacity(nr);
                refs.retain(|r| {
                    let left = (map.bin_of(r.b.centre())[axis] as usize) < first;
                    if !left {
                        right.push(*r);
                    }
                    left
                });
                (refs, right)
            }
            None => {
                // No plane separates the centres (or below the SAH's depth): the object median
                // on the axis of the centres' greatest extent.
                let mut cb = Bx::EMPTY;
                for r in &refs {
                    cb.grow_point(r.b.centre());
                }
                let axis = cb.largest_axis();
                let mid = n / 2;
                refs.select_nth_unstable_by(mid, |a, b| {
                    a.b.centre()[axis].total_cmp(&b.b.centre()[axis])
                });
                let r = refs.split_off(mid);
                (refs, r)
            }
        };
        let (left, right) = if left.is_empty() || right.is_empty() {
            let mut all = left;
            all.extend(right);
            let r = all.split_off(all.len() / 2);
            (all, r)
        } else {
            (left, right)
        };
        let extra = (left.len() + right.len()).saturating_sub(n);
        let rest = budget.saturating_sub(extra);
        let total = (left.len() + right.len()) as f64;
        let lbudget = (rest as f64 * left.len() as f64 / total) as usize;
        let rbudget = rest - lbudget;
        let lb = union(&left);
        let rb = union(&right);
        let me = self
            .tree
            .push(bounds.aabb(), BuildKind::Leaf { first: 0, count: 0 });
        let mut children = [0; MAX_WIDTH];
        if forks > 0 && left.len().min(right.len()) >= FORK_MIN {
            let mut other = Build::new(self.p, right.len());
            let sub = std::thread::scope(|scope| {
                let h = scope.spawn(move || {
                    other.node(right, rb, depth + 1, rbudget, forks - 1);
                    other.tree
                });
                children[0] = self.node(left, lb, depth + 1, lbudget, forks - 1);
                h.join().expect("a build thread panicked")
            });
            let shift = self.tree.order.len() as u32;
            children[1] = self.tree.append_shifted(&sub.nodes, shift, 1);
            self.tree.order.extend_from_slice(&sub.order);
        } else {
            // (A side too small for a thread: the other may still fork below.)
            children[0] = self.node(left, lb, depth + 1, lbudget, forks);
            children[1] = self.node(right, rb, depth + 1, rbudget, forks);
        }
        self.tree.nodes[me as usize].kind = BuildKind::Inner { children, len: 2 };
        me
    }

    /// The best object split (binned centres, [`super::Binned`]'s map: the three axes'
    /// bins in one SSE computation), or `None` when the centres coincide. One pass bins the
    /// references on all three axes.
    fn object(&mut self, refs: &[Ref]) -> Option<Found> {
        let block = self.p.rule.block;
        let nb = self.p.bins;
        let mut cb = Bx::EMPTY;
        for r in refs {
            cb.grow_point(r.b.centre());
        }
        let map = CentreMap::new(&cb.aabb(), nb);
        // Every bin is empty between searches (each axis's used bins are emptied below).
        let bins = &mut *self.scratch;
        for r in refs {
            let k = map.bin_of(r.b.centre());
            for (a, bins) in bins.iter_mut().enumerate() {
                // k < nb ≤ 256: the u8 is the bin itself, and indexes the 256 bins unchecked.
                let bin = &mut bins[k[a] as u8 as usize];
                bin.0.grow(&r.b);
                bin.1 += 1;
            }
        }
        let (filled, right) = (&mut *self.filled, &mut *self.right);
        let mut best: Option<Found> = None;
        for (axis, bins) in bins.iter_mut().enumerate() {
            // The filled bins, `filled[..m]` in order. An empty bin leaves both sides' boxes
            // and counts as they were, so the plane after it costs what the plane before it
            // does and never wins (ties keep the first plane): the sweeps run over the filled
            // bins only, as `Binned`'s do.
            let mut m = 0;
            for (k, bin) in bins[..nb].iter().enumerate() {
                // m ≤ k < 256: the u8 indexes unchecked.
                filled[m as u8 as usize] = k as u8;
                m += (bin.1 != 0) as usize;
            }
            if map.scale[axis] != 0.0 {
                // The plane after filled bin i − 1: the right side's area and count from a
                // sweep down, the left side's on the way up.
                let mut acc = Bx::EMPTY;
                let mut count = 0;
                for i in (1..m).rev() {
                    let bin = &bins[filled[i] as usize];
                    acc.grow(&bin.0);
                    count += bin.1;
                    right[i as u8 as usize] = (acc.half_area(), count);
                }
                let mut l = Bx::EMPTY;
                let mut lc = 0;
                let mut won = None;
                for i in 1..m {
                    let bin = &bins[filled[i - 1] as usize];
                    l.grow(&bin.0);
                    lc += bin.1;
                    let (ar, rc) = right[i as u8 as usize];
                    let weighted =
                        l.half_area() * blocks(lc, block) as f32 + ar * blocks(rc, block) as f32;
                    if best.is_none_or(|b| weighted < b.weighted) {
                        let first = filled[i - 1] as usize + 1;
                        won = Some(first);
                        best = Some(Found {
                            weighted,
                            axis,
                            cut: Cut::Object { map, first },
                            lb: l,
                            rb: Bx::EMPTY,
                            nr: rc,
                        });
                    }
                }
                if let (Some(first), Some(f)) = (won, best.as_mut()) {
                    f.rb = union_bins(&bins[first..nb]);
                }
            }
            for &k in &filled[..m] {
                bins[k as usize] = (Bx::EMPTY, 0);
            }
        }
        best
    }

    /// The best spatial split of the node's box `bounds`, or `None` when it is flat.
    fn spatial(&self, refs: &[Ref], bounds: &Bx) -> Option<Found> {
        const NB: usize = SPATIAL_BINS;
        // The node's longest axis only: on gears4 searching all three gave a tree of about the
        // same node visits and triangle tests (within 1 %) at three times the search's cost.
        let axis = bounds.largest_axis();
        let map = PlaneMap::new(bounds.lo[axis], bounds.hi[axis], NB);
        if map.scale == 0.0 {
            return None;
        }
        // Per bin: the box of the parts in it with the references entering it (a left side
        // counts those), and the same box with the references leaving it (a right side's).
        let mut enter = [(Bx::EMPTY, 0usize); NB];
        let mut leave = [0usize; NB];
        for r in refs {
            let first = map.bin(r.b.lo[axis]);
            let last = map.bin(r.b.hi[axis]);
            enter[first].1 += 1;
            leave[last] += 1;
            if first == last {
                enter[first].0.grow(&r.b);
            } else {
                parts(
                    &self.p.tris[r.id as usize],
                    &r.b,
                    axis,
                    &map,
                    first,
                    last,
                    |k, b| enter[k].0.grow(b),
                );
            }
        }
        let leaving: [(Bx, usize); NB] = std::array::from_fn(|k| (enter[k].0, leave[k]));
        let mut right = [(0.0f32, 0usize); NB];
        let mut found = None;
        sweep(
            &enter,
            &leaving,
            &mut right,
            self.p.rule.block,
            |k, weighted, _, nr| {
                if found.is_none_or(|(_, w, _)| weighted < w) {
                    found = Some((k, weighted, nr));
                }
            },
        );
        found.map(|(k, weighted, nr)| Found {
            weighted,
            axis,
            cut: Cut::Spatial {
                plane: map.plane(k),
            },
            lb: union_bins(&enter[..k]),
            rb: union_bins(&enter[k..]),
            nr,
        })
    }

    /// The references of a spatial split's two sides: whole where they lie on one side,
    /// else kept whole on the cheaper side or split (Stich et al. §4.4). The left side is
    /// made in the node's vector (it holds at most one reference of each of the node's).
    fn partition_spatial(
        &self,
        mut left: Vec<Ref>,
        axis: usize,
        pos: f32,
        nr: usize,
    ) -> (Vec<Ref>, Vec<Ref>) {
        let mut right = Vec::with_capacity(nr);
        let mut straddle = Vec::new();
        let (mut lb, mut rb) = (Bx::EMPTY, Bx::EMPTY);
        left.retain(|r| {
            if r.b.hi[axis] <= pos {
                lb.grow(&r.b);
                true
            } else {
                if r.b.lo[axis] >= pos {
                    rb.grow(&r.b);
                    right.push(*r);
                } else {
                    straddle.push(*r);
                }
                false
            }
        });
        let (mut nl, mut nr) = (
            (left.len() + straddle.len()) as f32,
            (right.len() + straddle.len()) as f32,
        );
        // The straddlers' parts on each side, for the unsplitting costs.
        let parts: Vec<(Bx, Bx)> = straddle
            .iter()
            .map(|r| clip(&self.p.tris[r.id as usize], &r.b, axis, pos))
            .collect();
        for (l, r) in &parts {
            lb.grow(l);
            rb.grow(r);
        }
        for (r, (pl, pr)) in straddle.into_iter().zip(parts) {
            let (al, ar) = (lb.half_area(), rb.half_area());
            let split = al * nl + ar * nr;
            let whole_left = lb.union(&r.b).half_area() * nl + ar * (nr - 1.0);
            let whole_right = al * (nl - 1.0) + rb.union(&r.b).half_area() * nr;
            if whole_left < split && whole_left <= whole_right {
                lb.grow(&r.b);
                nr -= 1.0;
                left.push(r);
            } else if whole_right < split {
                rb.grow(&r.b);
                nl -= 1.0;
                right.push(r);
            } else {
                if !pl.is_empty() {
                    left.push(Ref { b: pl, id: r.id });
                }
                if !pr.is_empty() {
                    right.push(Ref { b: pr, id: r.id });
                }
            }
        }
        (left, right)
    }
}

/// The spatial search's equal bins over `[lo, hi]` on one axis, and the planes between them.
#[derive(Clone, Copy, Debug)]
struct PlaneMap {
    lo: f32,
    scale: f32,
    width: f32,
    last: usize,
}

impl PlaneMap {
    fn new(lo: f32, hi: f32, nb: usize) -> PlaneMap {
        let ext = hi - lo;
        let ok = ext > 0.0 && ext.is_finite();
        PlaneMap {
            lo,
            scale: if ok {
                nb as f32 * (1.0 - 1e-6) / ext
            } else {
                0.0
            },
            width: if ok { ext / nb as f32 } else { 0.0 },
            last: nb - 1,
        }
    }

    /// `⌊(x − lo)·scale⌋` clamped to `[0, last]`, clamped on floats before the conversion
    /// as [`CentreMap`] does (the same bins: both are monotone and `last` is a whole number):
    /// Rust's saturating cast was the build's costliest line on gears4 (callgrind).
    #[inline(always)]
    fn bin(&self, x: f32) -> usize {
        let t = ((x - self.lo) * self.scale).max(0.0).min(self.last as f32);
        // SAFETY: `t` is finite and in `[0, last]` (`max` of a NaN and 0 is 0), so it is a
        // value the conversion takes exactly.
        unsafe { t.to_int_unchecked::<u32>() as usize }
    }

    /// The coordinate of the plane before bin `k`.
    fn plane(&self, k: usize) -> f32 {
        self.lo + k as f32 * self.width
    }
}

/// Calls `visit(k, A_L·blocks(N_L) + A_R·blocks(N_R), N_L, N_R)` for each plane `k` (1 to
/// nb − 1, before bin k) with references on both sides; bins are (box, count), the left
/// side's counts from `left_bins` and the right side's from `right_bins` (a spatial search
/// counts references entering and leaving; the boxes are the same).
fn sweep(
    left_bins: &[(Bx, usize)],
    right_bins: &[(Bx, usize)],
    right: &mut [(f32, usize)],
    block: usize,
    mut visit: impl FnMut(usize, f32, usize, usize),
) {
    let nb = left_bins.len();
    let mut b = Bx::EMPTY;
    let mut c = 0;
    for k in (1..nb).rev() {
        b.grow(&right_bins[k].0);
        c += right_bins[k].1;
        right[k] = (b.half_area(), c);
    }
    let mut b = Bx::EMPTY;
    let mut c = 0;
    for k in 1..nb {
        b.grow(&left_bins[k - 1].0);
        c += left_bins[k - 1].1;
        let (ar, cr) = right[k];
        if c == 0 || cr == 0 {
            continue;
        }
        let weighted = b.half_area() * blocks(c, block) as f32 + ar * blocks(cr, block) as f32;
        visit(k, weighted, c, cr);
    }
}

fn union_bins(bins: &[(Bx, usize)]) -> Bx {
    let mut b = Bx::EMPTY;
    for (x, _) in bins {
        b.grow(x);
    }
    b
}

fn union(refs: &[Ref]) -> Bx {
    let mut b = Bx::EMPTY;
    for r in refs {
        b.grow(&r.b);
    }
    b
}

/// Half the area of the overlap of two boxes (0 when apart).
fn overlap_area(a: &Bx, b: &Bx) -> f32 {
    Bx::new(a.lo.max(b.lo), a.hi.min(b.hi)).half_area()
}

/// The common part of two boxes, or the empty box. Chosen by selects, not a branch: a
/// triangle's part in a bin is empty often and unpredictably (the spatial search's most
/// mispredicted branch on gears4).
#[inline(always)]
fn intersect(a: &Bx, b: &Bx) -> Bx {
    let (lo, hi) = (a.lo.max(b.lo), a.hi.min(b.hi));
    empty_if_inverted(lo, hi)
}

/// The box `lo`–`hi`, or the empty box when `lo` passes `hi` on any axis. The axes' three
/// comparisons are or-ed into every lane by two shuffles (glam's `any` and a splat of the
/// answer went through a general register and back: a fifth of the spatial search on gears4).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn empty_if_inverted(lo: Vec3A, hi: Vec3A) -> Bx {
    use std::arch::x86_64::*;
    // SAFETY: SSE is part of every x86_64 target. The fourth lane is not part of a `Vec3A`'s
    // value, so what is selected there does not matter.
    unsafe {
        let (l, h): (__m128, __m128) = (lo.into(), hi.into());
        let m = _mm_cmpgt_ps(l, h);
        // Lanes x, y, z: (y, z, x) and (z, x, y).
        let any = _mm_or_ps(
            m,
            _mm_or_ps(
                _mm_shuffle_ps::<0b00_00_10_01>(m, m),
                _mm_shuffle_ps::<0b00_01_00_10>(m, m),
            ),
        );
        let pick =
            |empty: __m128, v: __m128| _mm_or_ps(_mm_and_ps(any, empty), _mm_andnot_ps(any, v));
        Bx::new(
            pick(_mm_set1_ps(f32::INFINITY), l).into(),
            pick(_mm_set1_ps(f32::NEG_INFINITY), h).into(),
        )
    }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn empty_if_inverted(lo: Vec3A, hi: Vec3A) -> Bx {
    let empty = glam::BVec3A::splat(lo.cmpgt(hi).any());
    Bx::new(
        Vec3A::select(empty, Vec3A::INFINITY, lo),
        Vec3A::select(empty, Vec3A::NEG_INFINITY, hi),
    )
}

/// Calls `visit(k, part)` with the box of triangle `t`'s part in each bin `k` from `first` to
/// `last` of `map` on `axis`, each cut to the reference's box `b`. The triangle's section by a
/// plane is a segment from its longest edge (in `axis`) to one of the two others, so each bin's
/// part is bounded by the sections at its two walls and the vertices between them: one section
/// per plane crossed, where clipping the triangle at each plane in turn went over its three
/// edges for each (most of the build's time on gears4).
fn parts(
    t: &[Vec3A; 3],
    b: &Bx,
    axis: usize,
    map: &PlaneMap,
    first: usize,
    last: usize,
    visit: impl FnMut(usize, &Bx),
) {
    match axis {
        0 => parts_on::<0>(t, b, map, first, last, visit),
        1 => parts_on::<1>(t, b, map, first, last, visit),
        _ => parts_on::<2>(t, b, map, first, last, visit),
    }
}

/// Coordinate `A` of `v` (a constant lane).
#[inline(always)]
fn at<const A: usize>(v: Vec3A) -> f32 {
    match A {
        0 => v.x,
        1 => v.y,
        _ => v.z,
    }
}

/// The point of segment `p`–`q` at coordinate `x` on axis `A` (`p` when the segment is flat
/// on `A`), with that coordinate set to `x` exactly.
#[inline(always)]
fn crossing<const A: usize>(p: Vec3A, q: Vec3A, x: f32) -> Vec3A {
    let d = at::<A>(q) - at::<A>(p);
    let mut s = if d > 0.0 {
        p + (q - p) * ((x - at::<A>(p)) / d)
    } else {
        p
    };
    s[A] = x;
    s
}

/// [`parts`] on axis `A` (a constant, so the coordinate picks are fixed lanes).
#[inline(always)]
fn parts_on<const A: usize>(
    t: &[Vec3A; 3],
    b: &Bx,
    map: &PlaneMap,
    first: usize,
    last: usize,
    mut visit: impl FnMut(usize, &Bx),
) {
    // The vertices in order along A: a, m, c.
    let [mut a, mut m, mut c] = *t;
    if at::<A>(a) > at::<A>(m) {
        std::mem::swap(&mut a, &mut m);
    }
    if at::<A>(m) > at::<A>(c) {
        std::mem::swap(&mut m, &mut c);
    }
    if at::<A>(a) > at::<A>(m) {
        std::mem::swap(&mut a, &mut m);
    }
    let mid = at::<A>(m);
    // The section at x (a ≤ x ≤ c on A) as a box: from the long edge a–c to a–m or m–c.
    let section = |x: f32| {
        let long = crossing::<A>(a, c, x);
        let short = if x <= mid {
            crossing::<A>(a, m, x)
        } else {
            crossing::<A>(m, c, x)
        };
        Bx::new(long.min(short), long.max(short))
    };
    let lo = at::<A>(b.lo).max(at::<A>(a));
    // (A clipped box may reach past the triangle by a rounding: never below `lo`.)
    let hi = at::<A>(b.hi).min(at::<A>(c)).max(lo);
    let mut from = lo;
    let mut enter = section(lo);
    for k in first..=last {
        let next = if k == last {
            hi
        } else {
            map.plane(k + 1).max(lo).min(hi)
        };
        let leave = section(next);
        let mut part = enter.union(&leave);
        // The end vertices lie on the sections; the middle one is added to the bins it lies
        // in (both, on their common wall: an edge flat on the axis has no single crossing).
        if mid >= from && mid <= next {
            part.grow_point(m);
        }
        visit(k, &intersect(&part, b));
        from = next;
        enter = leave;
    }
}

/// The boxes of triangle `t`'s parts below and above the plane `axis = pos`, each cut to the
/// reference's box `b` (Embree's `splitTriangle`): the vertices on each side and the edges'
/// crossings of the plane.
#[inline]
fn clip(t: &[Vec3A; 3], b: &Bx, axis: usize, pos: f32) -> (Bx, Bx) {
    match axis {
        0 => clip_on::<0>(t, b, pos),
        1 => clip_on::<1>(t, b, pos),
        _ => clip_on::<2>(t, b, pos),
    }
}

/// [`clip`] on axis `A` (a constant, so the coordinate picks are fixed lanes: the build spent
/// most of its time here).
#[inline(always)]
fn clip_on<const A: usize>(t: &[Vec3A; 3], b: &Bx, pos: f32) -> (Bx, Bx) {
    let mut l = Bx::EMPTY;
    let mut r = Bx::EMPTY;
    for i in 0..3 {
        let (v0, v1) = (t[i], t[(i + 1) % 3]);
        let (a0, a1) = (v0[A], v1[A]);
        if a0 <= pos {
            l.grow_point(v0);
        }
        if a0 >= pos {
            r.grow_point(v0);
        }
        if (a0 < pos && pos < a1) || (a1 < pos && pos < a0) {
            let mut p = v0 + (v1 - v0) * ((pos - a0) / (a1 - a0));
            p[A] = pos;
            l.grow_point(p);
            r.grow_point(p);
        }
    }
    (intersect(&l, b), intersect(&r, b))
}
