//! Building the grid: which primitives go in (the floor may stay out), the grid's box and
//! resolution, and the compact cell layout.
//!
//! Layout (Lagae and Dutré 2008, "Compact, fast and robust grids for ray tracing"): one array
//! `offsets` of cells + 1 entries and one flat array `refs` of primitive indices; the primitives
//! of cell c are `refs[offsets[c]..offsets[c + 1]]`, in primitive order. No vector per cell. It
//! is filled in two passes over the primitives (count, then place), so the only memory beyond the
//! result is one bit per (primitive, candidate cell) in exact insertion, to avoid repeating the
//! overlap tests.
//!
//! Robustness: traversal works in `f32`, so a hit exactly on a cell wall may be reported a hair
//! inside the neighbour. Every primitive is therefore registered in the cells its bounding box
//! (or surface) reaches after growing it by [`Cells::pad`], a few units of rounding of the scene's
//! coordinates plus a small fraction of a cell. The grid's box is grown by the same amount, which
//! also gives flat scenes a non-zero thickness.

use super::config::{Count, Floor, GridConfig, Insertion, Resolution};
use super::overlap;
use super::resolution::{self, MAX_CELLS};
use crate::engine::EngineError;
use crate::geometry::dda::Lattice;
use crate::geometry::Geometry;
use glam::{DVec3, Vec3};
use rtbench_scenes::{Scene, Shape};

/// A floor polygon spans at least this fraction of the scene's bounds along two axes.
pub const FLOOR_SPAN: f64 = 0.9;
/// ... and is flat across the third: thinner than this fraction of its own width.
pub const FLOOR_FLAT: f64 = 0.01;

/// Relative padding of cells against `f32` rounding, per unit of the largest coordinate.
pub(crate) const PAD_COORD: f32 = 4e-6;
/// Padding as a fraction of a cell's side.
pub(crate) const PAD_CELL: f32 = 1e-5;

/// The uniform grid itself: its box, its resolution and its compact cell lists.
#[derive(Clone, Debug, Default)]
pub struct Cells {
    /// The grid's box, resolution and cell size.
    pub lattice: Lattice,
    /// `offsets[c]..offsets[c + 1]` is cell c's range of `refs`; cell (x, y, z) is
    /// c = x + res_x·(y + res_y·z).
    pub offsets: Vec<u32>,
    /// Indices into `Geometry::prims`.
    pub refs: Vec<u32>,
    /// How far primitive boxes (and the grid's box) are grown against rounding, per axis.
    pub pad: Vec3,
}

impl Cells {
    pub fn count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    pub fn empty_count(&self) -> usize {
        self.offsets.windows(2).filter(|w| w[0] == w[1]).count()
    }

    pub fn bytes(&self) -> u64 {
        ((self.offsets.len() + self.refs.len()) * 4) as u64
    }

    /// Primitives registered in cell `c`.
    pub fn prims_in(&self, c: usize) -> &[u32] {
        let (a, b) = self.span(c);
        &self.refs[a..b]
    }

    /// Cell `c`'s range of `refs`, as `(offsets[c], offsets[c + 1])`: equal ends for an empty
    /// cell, which the walk tells so before it forms the slice (the slice's two bounds checks
    /// are left to the cells that have primitives) and reads through one window, one bounds
    /// check where two indexings were two (−1.8 % instructions on mount6, callgrind, 128²).
    #[inline(always)]
    pub fn span(&self, c: usize) -> (usize, usize) {
        let o = &self.offsets[c..c + 2];
        (o[0] as usize, o[1] as usize)
    }

    /// [`Cells::span`] without its bounds check, for the walk, whose cells are the lattice's by
    /// construction: with [`Cells::refs_unchecked`], −2.7 % instructions on mount6 (callgrind,
    /// 128²), the checks' registers freed for the walk.
    ///
    /// # Safety
    /// `c` is below [`Cells::count`].
    #[inline(always)]
    pub(crate) unsafe fn span_unchecked(&self, c: usize) -> (usize, usize) {
        debug_assert!(c + 1 < self.offsets.len());
        // SAFETY: `c + 1 < offsets.len()` (the caller's promise).
        unsafe {
            (
                *self.offsets.get_unchecked(c) as usize,
                *self.offsets.get_unchecked(c + 1) as usize,
            )
        }
    }

    /// `refs[a..b]` without its bounds check.
    ///
    /// # Safety
    /// `(a, b)` is a cell's [`Cells::span`] of cells as [`build`] lays them out: `offsets`
    /// ascends and ends at `refs.len()`, so `a <= b <= refs.len()`.
    #[inline(always)]
    pub(crate) unsafe fn refs_unchecked(&self, (a, b): (usize, usize)) -> &[u32] {
        debug_assert!(a <= b && b <= self.refs.len());
        // SAFETY: `a <= b <= refs.len()` (the caller's promise).
        unsafe { self.refs.get_unchecked(a..b) }
    }
}

/// What the build decided, besides the cells.
pub struct Built {
    pub cells: Cells,
    /// Primitives kept out of the grid (`floor=out`), tested on their own.
    pub floor: Vec<u32>,
    /// The `n` the resolution policy was given.
    pub n: usize,
    pub grid_prims: usize,
}

fn build_err(reason: String) -> EngineError {
    EngineError::Build {
        engine: "grid".into(),
        reason,
    }
}

/// Scene objects that are floor or backdrop polygons: a polygon lying across one axis (flat to
/// [`FLOOR_FLAT`] of its width) whose bounding box spans at least [`FLOOR_SPAN`] of the scene's
/// bounds along the two others. In the SPD these are balls', gears' and tree's ground and rings'
/// wall, each spanning the whole scene; teapot's checkerboard is many small squares and tetra's
/// faces are slanted, so neither qualifies.
pub fn floor_objects(scene: &Scene, geometry: &Geometry) -> Vec<bool> {
    let extent = (geometry.bounds_max - geometry.bounds_min).as_dvec3();
    scene
        .objects
        .iter()
        .map(|o| match &o.shape {
            Shape::Polygon(_) => {
                let e = o.shape.bounds().extent();
                let (thin, wide) = (e.min_element(), e.max_element());
                let spans = (0..3)
                    .filter(|&i| extent[i] > 0.0 && e[i] >= FLOOR_SPAN * extent[i])
                    .count();
                spans >= 2 && thin <= FLOOR_FLAT * wide
            }
            _ => false,
        })
        .collect()
}

pub fn build(
    scene: &Scene,
    geometry: &Geometry,
    config: &GridConfig,
) -> Result<Built, EngineError> {
    let nprims = geometry.prims.len();
    if nprims > u32::MAX as usize {
        return Err(build_err(format!(
            "{nprims} primitives: more than 32-bit indices can address"
        )));
    }
    // Split off the floor.
    let is_floor = match config.floor {
        Floor::In => vec![false; scene.objects.len()],
        Floor::Out => floor_objects(scene, geometry),
    };
    let mut floor = Vec::new();
    let mut inside = Vec::with_capacity(nprims);
    for (i, &o) in geometry.prim_object.iter().enumerate() {
        if is_floor.get(o as usize).copied().unwrap_or(false) {
            floor.push(i as u32);
        } else {
            inside.push(i as u32);
        }
    }

    // The grid's box and the primitives' mean extents (for Klimaszewski).
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    let mut extent_sum = DVec3::ZERO;
    let bounds: Vec<(Vec3, Vec3)> = inside
        .iter()
        .map(|&p| geometry.prims[p as usize].bounds())
        .collect();
    for &(a, b) in &bounds {
        lo = lo.min(a);
        hi = hi.max(b);
        extent_sum += (b - a).as_dvec3();
    }
    if inside.is_empty() {
        return Ok(Built {
            cells: Cells {
                lattice: Lattice {
                    res: [1; 3],
                    ..Lattice::default()
                },
                offsets: vec![0, 0],
                ..Cells::default()
            },
            floor,
            n: 0,
            grid_prims: 0,
        });
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return Err(build_err(
            "a primitive has non-finite bounds (NaN or infinite coordinates)".into(),
        ));
    }
    let magnitude = lo.abs().max(hi.abs()).max_element();
    let pad0 = PAD_COORD * magnitude + PAD_CELL * (hi - lo).max_element() + f32::MIN_POSITIVE;
    lo -= Vec3::splat(pad0);
    hi += Vec3::splat(pad0);

    let n = match config.count {
        Count::Prims => inside.len(),
        // Primitives come in object order, so objects are the runs of equal `prim_object`.
        Count::Objects => {
            let mut last = u32::MAX;
            let mut k = 0;
            for &p in &inside {
                let o = geometry.prim_object[p as usize];
                if o != last {
                    k += 1;
                    last = o;
                }
            }
            k
        }
    };
    let extent = (hi - lo).as_dvec3().to_array();
    let mean = (extent_sum / inside.len() as f64).to_array();
    let res = resolution::cells_per_axis(config.resolution, extent, n, config.density, mean);
    if let Resolution::Explicit(r) = config.resolution {
        // The walk reads a cell's offsets unchecked (`Cells::span_unchecked`): every cell of the
        // lattice must be one of `offsets`', which a zero axis (no cells, yet the clamp of
        // `Lattice::cell_of` wraps) would break. The parser refuses it; a config built in code
        // is refused here.
        if r.contains(&0) {
            return Err(build_err(format!(
                "res={},{},{}: an axis without cells",
                r[0], r[1], r[2]
            )));
        }
        if resolution::total(r) > MAX_CELLS {
            return Err(build_err(format!(
                "res={},{},{}: {} cells, more than the {} allowed",
                r[0],
                r[1],
                r[2],
                resolution::total(r),
                MAX_CELLS
            )));
        }
    }
    let lattice = Lattice::new(lo, hi, res);
    let cell = lattice.cell;
    let pad = Vec3::splat(PAD_COORD * magnitude) + cell * PAD_CELL;
    let ncells = resolution::total(res) as usize;

    let mut cells = Cells {
        lattice,
        offsets: Vec::new(),
        refs: Vec::new(),
        pad,
    };

    // The range of cells a primitive's padded bounding box reaches.
    let range = |b: &(Vec3, Vec3)| -> ([u32; 3], [u32; 3]) {
        (
            cells.lattice.cell_of(b.0 - pad),
            cells.lattice.cell_of(b.1 + pad),
        )
    };
    let exact = config.insertion == Insertion::Exact;
    let (lo64, cell64, pad64) = (lo.as_dvec3(), cell.as_dvec3(), pad.as_dvec3());
    let keep = |p: u32, c: [u32; 3]| -> bool {
        let cl = lo64 + DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * cell64;
        overlap::prim_box(&geometry.prims[p as usize], cl - pad64, cl + cell64 + pad64)
    };

    // Pass 1: count each cell's references (and remember the exact tests' answers).
    let mut counts = vec![0u32; ncells + 1];
    let mut answers = BitList::default();
    for (&p, b) in inside.iter().zip(&bounds) {
        let (a, z) = range(b);
        let single = a == z;
        for_each_cell(a, z, |c| {
            let k = !exact || single || keep(p, c);
            if exact && !single {
                answers.push(k);
            }
            if k {
                counts[cells.lattice.index(c)] += 1;
            }
        });
    }
    // Prefix sums: counts become offsets.
    let mut total: u64 = 0;
    for v in counts.iter_mut() {
        let here = *v as u64;
        *v = total as u32;
        total += here;
        if total > u32::MAX as u64 {
            return Err(build_err(format!(
                "more than {} references: too many for 32-bit offsets",
                u32::MAX
            )));
        }
    }
    // Pass 2: place the references; `fill` walks each cell's slots from its offset.
    let mut refs = vec![0u32; total as usize];
    let mut fill: Vec<u32> = counts[..ncells].to_vec();
    let mut k = 0usize;
    for (&p, b) in inside.iter().zip(&bounds) {
        let (a, z) = range(b);
        let single = a == z;
        for_each_cell(a, z, |c| {
            let keep = if exact && !single {
                k += 1;
                answers.get(k - 1)
            } else {
                true
            };
            if keep {
                let i = cells.lattice.index(c);
                refs[fill[i] as usize] = p;
                fill[i] += 1;
            }
        });
    }
    counts[ncells] = total as u32;
    cells.offsets = counts;
    cells.refs = refs;
    Ok(Built {
        cells,
        floor,
        n,
        grid_prims: inside.len(),
    })
}

/// Calls `f` for every cell of the box of cells `a..=z`, x fastest.
fn for_each_cell(a: [u32; 3], z: [u32; 3], mut f: impl FnMut([u32; 3])) {
    for cz in a[2]..=z[2] {
        for cy in a[1]..=z[1] {
            for cx in a[0]..=z[0] {
                f([cx, cy, cz]);
            }
        }
    }
}

/// A growable list of bits.
#[derive(Default)]
struct BitList {
    words: Vec<u64>,
    len: usize,
}

impl BitList {
    fn push(&mut self, b: bool) {
        if self.len & 63 == 0 {
            self.words.push(0);
        }
        if b {
            self.words[self.len / 64] |= 1 << (self.len % 64);
        }
        self.len += 1;
    }

    fn get(&self, i: usize) -> bool {
        self.words[i / 64] >> (i % 64) & 1 == 1
    }
}
