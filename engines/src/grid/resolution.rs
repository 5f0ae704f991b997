//! Grid resolution policies: how many cells along each axis, from the grid's box and the number
//! of primitives n in it.
//!
//! - `cuberoot`: ⌊n^(1/3) + 0.5⌋ cells on every axis, whatever the box's shape. This is the rule
//!   seed 000 used for Rayshade and sray alike (§3.4, "the resolution of one side of the grid is
//!   ⌊n^(1/3) + 0.5⌋").
//! - `woo`: Woo 1992 (Graphics Gems III): cells as near to cubes as the box allows and about
//!   D·n of them, so along axis i there are round(d_i · (D·n / V)^(1/3)) cells (d the box's
//!   sides, V its volume). D is Havran's grid density (cells per primitive).
//! - `klimaszewski`: Klimaszewski and Sederberg 1997 build *heterogeneous* grids, whose cells need
//!   not be cubes. Our reading (the paper's exact formula was not available to us, so this is
//!   stated as ours): again about D·n cells, but each cell is shaped like the primitives' mean
//!   bounding box, so that a cell holds about the same extent of primitive along every axis: cell
//!   side c_i = s·e_i with e_i the mean extent along axis i, and s chosen so that
//!   Π d_i / c_i = D·n. Mean extents are kept within 1:16 of each other so that flat,
//!   axis-aligned primitives do not make cells arbitrarily thin.
//!
//! Axes along which the box is flat (a planar scene) get one cell, and the density is spread over
//! the remaining axes. Every policy is capped at [`MAX_CELLS`] cells.

use super::config::Resolution;

/// The most cells any policy may produce: 2^26 cells take 256 MiB of offsets.
pub const MAX_CELLS: u64 = 1 << 26;

/// An axis this much shorter than the longest counts as flat.
const FLAT: f64 = 1e-9;

/// Widest ratio allowed between the mean primitive extents that shape a Klimaszewski cell.
const MAX_ASPECT: f64 = 16.0;

/// Cells along x, y and z for `policy`, for a box of sides `extent` holding `n` primitives whose
/// bounding boxes have mean sides `mean_prim_extent`. Explicit resolutions are returned as given
/// (the caller checks them against [`MAX_CELLS`]).
pub fn cells_per_axis(
    policy: Resolution,
    extent: [f64; 3],
    n: usize,
    density: f64,
    mean_prim_extent: [f64; 3],
) -> [u32; 3] {
    let n = n.max(1) as f64;
    let r = match policy {
        Resolution::Explicit(r) => return r,
        Resolution::CubeRoot => {
            let k = (n.cbrt() + 0.5).floor().max(1.0);
            [k; 3]
        }
        Resolution::Woo => shaped(extent, [1.0; 3], density * n),
        Resolution::Klimaszewski => {
            let emax = mean_prim_extent.iter().cloned().fold(0.0, f64::max);
            if emax <= 0.0 || !emax.is_finite() {
                // Points only: no shape to follow, fall back to cubes.
                shaped(extent, [1.0; 3], density * n)
            } else {
                let e = mean_prim_extent.map(|e| e.max(emax / MAX_ASPECT));
                shaped(extent, e, density * n)
            }
        }
    };
    cap(r.map(|v| v.clamp(1.0, u32::MAX as f64) as u32))
}

/// Klimaszewski's resolution (our reading, above) without the [`MAX_CELLS`] cap: the
/// breadth-first engine's on-disk grid (seed 000 §4.3) is not bound by memory.
pub fn klimaszewski_uncapped(
    extent: [f64; 3],
    n: usize,
    density: f64,
    mean_prim_extent: [f64; 3],
) -> [u32; 3] {
    let cells = density * n.max(1) as f64;
    let emax = mean_prim_extent.iter().cloned().fold(0.0, f64::max);
    let r = if emax <= 0.0 || !emax.is_finite() {
        shaped(extent, [1.0; 3], cells)
    } else {
        shaped(
            extent,
            mean_prim_extent.map(|e| e.max(emax / MAX_ASPECT)),
            cells,
        )
    };
    r.map(|v| v.clamp(1.0, u32::MAX as f64) as u32)
}

/// About `cells` cells over a box of sides `extent`, each cell's sides proportional to `shape`:
/// along axis i, round(d_i / (s·shape_i)) cells with s such that the product is `cells`.
fn shaped(extent: [f64; 3], shape: [f64; 3], cells: f64) -> [f64; 3] {
    let dmax = extent.iter().cloned().fold(0.0, f64::max);
    let live: Vec<usize> = (0..3)
        .filter(|&i| dmax > 0.0 && extent[i] > FLAT * dmax)
        .collect();
    let mut r = [1.0; 3];
    if live.is_empty() {
        return r;
    }
    // Π_i d_i / (s·shape_i) = cells over the non-flat axes  ⇒  s^m = Π(d_i/shape_i) / cells.
    let prod: f64 = live.iter().map(|&i| extent[i] / shape[i]).product();
    let s = (prod / cells).powf(1.0 / live.len() as f64);
    for &i in &live {
        r[i] = (extent[i] / (shape[i] * s)).round().max(1.0);
    }
    r
}

/// Scales a resolution down, keeping its proportions, until it has at most [`MAX_CELLS`] cells.
fn cap(mut r: [u32; 3]) -> [u32; 3] {
    while total(r) > MAX_CELLS {
        let f = (MAX_CELLS as f64 / total(r) as f64).cbrt();
        r = r.map(|v| ((v as f64 * f).floor() as u32).max(1));
    }
    r
}

/// Number of cells of a resolution.
pub fn total(r: [u32; 3]) -> u64 {
    r.iter().map(|&v| v as u64).product()
}
