//! SAH builders of seed 001 (Kimura 2007), one file per algorithm, with the shared SAH bits
//! here: the split search is [`sweep`] (exact full sweep, 001 §1.5) or [`binned`] (Wald 2007),
//! and a tree is made from its splits by [`binary`] or by 001's N-ary "stepwise construction"
//! ([`nary`]). [`spatial`] is the binned search with spatial splits (Stich et al. 2009), for
//! scenes of triangles.
//!
//! The binary split cost is 001's Eq. 3.4 (from Wald, Boulos and Shirley 2007):
//! `2·T_AABB + (A(S1)/A(S))·N(S1)·T_tri + (A(S2)/A(S))·N(S2)·T_tri`. 001 splits down to one
//! primitive per leaf; with `leaf > 1` a node of at most `leaf` primitives becomes a leaf when
//! `N(S)·T_tri` is no more than its best split (the usual SAH termination).

pub mod binary;
pub mod binned;
pub mod nary;
pub mod spatial;
pub mod sweep;

#[cfg(test)]
mod tests;

pub use binary::{binary, binary_blocks, binary_blocks_threads, BlockLeaves};
pub use binned::Binned;
pub use nary::wide_same_axis;
pub use spatial::{spatial_blocks, SpatialSettings};
pub use sweep::Sweep;

use super::config::{T_AABB, T_TRI};
use super::tree::BuildKind;
use crate::geometry::aabb::Aabb;

/// A range `[start, end)` of the splitter's primitive order, with the bounds of its
/// primitives and of their centres (passed down so no level recomputes them).
#[derive(Clone, Copy, Debug)]
pub struct Range {
    pub start: usize,
    pub end: usize,
    pub bounds: Aabb,
    pub centroids: Aabb,
}

impl Range {
    pub fn len(&self) -> usize {
        self.end - self.start
    }

    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }
}

/// A chosen split of a range into two non-empty ranges.
#[derive(Clone, Copy, Debug)]
pub struct Split {
    pub left: Range,
    pub right: Range,
    pub axis: usize,
    /// Eq. 3.4's cost of the split (+∞ for a median split, which is not costed).
    pub cost: f32,
}

/// Finds and applies splits of primitive ranges. Ranges are of one order of the primitives
/// that the splitter keeps (and hands over with [`Splitter::into_order`]).
pub trait Splitter {
    /// The range of all primitives.
    fn root(&self) -> Range;
    /// Best split of `r` (`r.len() ≥ 2`), on `axis` only when given; with `median`, the object
    /// median on the axis of greatest centroid extent (or `axis`) instead. The range is
    /// reordered to match.
    fn split(&mut self, r: &Range, axis: Option<usize>, median: bool) -> Split;
    /// The primitives of `r`, in the splitter's current order.
    fn ids(&self, r: &Range) -> &[u32];
    fn into_order(self) -> Vec<u32>;
}

/// Blocks of `block` primitives needed for `n` primitives: the SAH's primitive count when a
/// leaf's primitives are tested `block` at a time (Embree's `sahBlockSize`: a leaf of 1–4
/// triangles costs one `Triangle4` test, 5–8 two). `block = 1` is 001's count. `block` is a
/// power of two (checked by the config), so this is a shift: the binned search evaluates it
/// twice per candidate plane, where a division cost 3% of the build's instructions.
#[inline(always)]
pub fn blocks(n: usize, block: usize) -> usize {
    debug_assert!(block.is_power_of_two());
    (n + block - 1) >> block.trailing_zeros()
}

/// Eq. 3.4 from `A(S1)·N(S1) + A(S2)·N(S2)` (what the searches minimise) and `A(S)`.
pub fn split_cost(weighted_area: f32, parent_area: f32) -> f32 {
    let inv = if parent_area > 0.0 {
        1.0 / parent_area
    } else {
        0.0
    };
    2.0 * T_AABB + weighted_area * inv * T_TRI
}

/// Axes to search: the one given, or all three.
pub fn axes(axis: Option<usize>) -> std::ops::Range<usize> {
    match axis {
        Some(a) => a..a + 1,
        None => 0..3,
    }
}

/// Whether a range of `n` primitives whose best split costs `split_cost` becomes a leaf.
pub fn make_leaf(n: usize, leaf: usize, split_cost: f32) -> bool {
    n == 1 || (n <= leaf && n as f32 * T_TRI <= split_cost)
}

pub fn leaf_kind(r: &Range) -> BuildKind {
    BuildKind::Leaf {
        first: r.start as u32,
        count: r.len() as u32,
    }
}
