//! `breadth-first`: Nakamaru's out-of-core breadth-first ray tracer, the basic method of seed
//! 000 chapter 3 (Nakamaru and Ohno 1997) with the improved method's separate bounding-box and
//! geometry files and lazy geometry loading (§4.2.1–4.2.2, "S" and "G").
//!
//! Rays, not objects, are registered in a uniform grid; the scene is streamed from disk once per
//! pass, sequentially, so its size never makes the engine thrash. Files, one concept each:
//! [`config`] (settings), [`voxels`] (the marked grid and face flags, Algorithm 3.4, and the
//! rays registered per voxel in a pass),
//! [`intersect`] (passes, registration, the sweep: Algorithm 3.5), [`spill`] (the temporary
//! store of an in-memory scene). The resumable walk each ray keeps between passes is the shared
//! 3D-DDA ([`crate::geometry::dda`]), the `grid` engine's, so both engines visit the same cells.
//!
//! Built from a `BuildInput` (an in-memory scene) it first writes the scene as a store
//! ([`crate::store`]) in its spill directory; [`BreadthFirst::open`] builds it from a store on
//! disk. In memory it answers one band of pixel rows per call (`batch=band`, the in-memory
//! engines' bands), or a whole generation (`batch=generation`, [`config::Batch`]).
//!
//! Settings (`key=value`):
//!
//! | key | values | default | what |
//! |---|---|---|---|
//! | `memory` | bytes (`32MiB`, `1GiB` …) | `1GiB` | everything the engine holds: grid, rays in memory, registrations, file buffers (a band traced while another thread's is swept holds rays, registrations and buffers of its own within this budget, over the same grid: [`BreadthFirst`]) |
//! | `registration` | `fixed:N`, `thesis`, `inverse`, `inverse:N` | `inverse` | candidate voxels per ray per pass ([`config::Registration`]) |
//! | `spill` | a directory | the system temp dir | where the store of an in-memory scene is written (removed on drop) |
//! | `buffer` | bytes | `64KiB` | each file buffer (a compressed split store's readers hold one 128 KiB block, its compressed bytes and the block index instead: `store_reader_bytes`) |
//! | `progress` | `on`, `off` | `off` | one line on stderr after every pass: the pass, the rays it held, the cap if any, the seconds since the engine opened |
//! | `max_passes` | count | `0` (none) | stop after N passes over all trace calls ([`cap`]): counters and times are those passes'; `bf_pass_cap_reached` > 0 says the run stopped so, and its image is no answer |
//! | `triangle` | `watertight`, `moller` | `watertight` | the shared triangle kernel |
//! | `verify` | `full`, `records` | `full` | `full`: a store opened is read once and every record checked ([`crate::store::StoreHeader::verify`]) before preprocessing, outside the I/O counters (reported as `verify_bytes_read`, `verify_s`); `records`: only the records the algorithm reads are checked |
//! | `layout` | `split`, `basic` | `split` | the store layout read: `basic` = one file of (box, object) records read whole on every sweep and in shading (seed 000 Ch.3, Algorithms 3.4–3.6); `split` = box and geometry files apart (Ch.4 "S"). A store of the other layout is refused |
//! | `lazy` | `on`, `off` | `on` (split), `off` (basic) | read an object's geometry only when a ray hits its box (Ch.4 "G"); `off` reads every object's geometry in every sweep. `on` needs `split` |
//! | `boundary` | `on`, `off` | `on` | register rays only where they enter a voxel boundary (§3.2); `off`: in every marked voxel |
//! | `prevskip` | `on`, `off` | `on` | the previous-voxel skip (§3.3) |
//! | `refill` | `on`, `off` | `on` | refill memory with new rays every pass (§3.3); `off`: a batch of rays is finished before the next is read (Algorithm 3.3) |
//! | `count` | `prims`, `objects` | `prims` | the n of ⌊n^(1/3) + 0.5⌋: primitives, or objects as Rayshade counted (the grid engine's `count`) |
//! | `res` | cells per axis | ⌊n^(1/3) + 0.5⌋ | a given cubic resolution (Fig. 3.2 ran 20 and 40) |
//! | `rays` | a count | what the budget holds | at most this many rays in memory |
//! | `spill_codec` | `none`, `gzip` | `none` | the out-of-core workload's spill files (rays, hit records, shadow rays) gzip-compressed (level 1) |
//! | `secondary` | `on`, `off` | `on` | the out-of-core workload traces reflection and refraction rays, or eye and shadow rays only (`off`; seed 000's rings80) |
//! | `hierarchy` | `on`, `off` | `off` | sweep through the store's bounding-box hierarchy, skipping whole subtrees no ray needs (Ch.4 "B", §4.2.2; [`hierarchy`]); built at preprocessing (and counted in it) when the store has none of these constants. Needs `split` |
//! | `bh_s`, `bh_m`, `bh_l`, `bh_t` | numbers | the thesis's: 3, 1000, 4, t = 0.5 for balls/gears/tree, else 1.0 | the hierarchy's constants ([`crate::store::hierarchy`]) |
//! | `cache` | `warm`, `cold` | `warm` | `cold`: the store's files are dropped from the page cache (`posix_fadvise DONTNEED`) after preprocessing and after every sweep, so each sweep reads the disk |
//! | `grid` | `cuberoot`, `single`, `two-level` | `cuberoot` | the grid rays are registered in: the basic method's in-memory grid (⌊n^(1/3) + 0.5⌋, fitted to half the budget); `single`: in memory at Klimaszewski's resolution capped at `cap` (the thesis's "-l"); `two-level`: the high-resolution grid of §4.3 ([`hires`]) |
//! | `cap` | cells per axis | 128 (`single`), none (`two-level`) | cap on Klimaszewski's resolution |
//! | `upper`, `lower` | cells per axis | 256, 4 | R_u and R_l of §4.3.3's rule (`two-level`) |
//! | `pool` | a count | what 1/16 of `memory` holds | lower grids in the pool (`two-level`) |
//! | `block` | bytes | 1/8 of `memory` | one X-slab block of the on-disk grid (`two-level`) |
//! | `subspace` | voxels per side | what 1/4 of `memory` holds | a cubic preprocessing subspace (`two-level`) |
//! | `hrgrid` | `build`, `reuse`, `resume` | `build` | make the on-disk grid `hrgrid.bin` in the store at preprocessing, or open the one there; `resume`: make it keeping `hrgrid.progress.json` after each subspace, and take up an interrupted or finished build of the same grid (its subspaces and seconds from the record: `hr_build_resumed_subspaces`, `hr_build_prior_s`, both counted in `hr_build_s` and `preprocess_s`) |
//! | `hrgrid_subspaces` | a count | none | build only the first K subspaces of the on-disk grid, the rest left empty: a timing model of a build longer than one sitting, whose answers are not the scene's; needs `hrgrid=build` and `max_passes`, and the partial grid is removed from the store once opened (`hr_subspaces` built of `hr_subspaces_total`, `hr_build_partial`) |
//! | `batch` | `band`, `generation` | `band` | what one call of an in-memory run holds: the caller's band of pixel rows (a few thousand rays; the caller holds no more), or a whole generation (seed 000's procedure, Algorithm 3.6; caller and engine hold every ray of the generation). The out-of-core workload fills the budget either way ([`config::Batch`]) |
//! | `floor` | `out`, `in` | `out` | floor and backdrop polygons (the `grid` engine's test, on bounding boxes) in a group of their own, tested for every ray as it enters memory, and the grid fitted to the rest (§1.2: the thesis did so for balls and tree) |
//!
//! Counters: `rays`, `primitive_tests`, `primitive_hits`, `box_tests` (ray–bounding-box tests
//! of the sweep), `mailbox_skips`, `cells_visited` (voxels walked); in `extra`: `bf_passes`
//! (scene sweeps), `bf_floor_tests` (primitive tests of the floor group; `box_tests` +
//! `bf_floor_tests` are the ray–object tests the grid engine counts as `primitive_tests`),
//! `bf_geometry_records_read` (geometry records read in sweeps), `bf_pass_NNN_rays` (rays in memory at pass NNN, summed over calls: the
//! surviving rays per pass), `bf_registrations`, `bf_prev_voxel_skips`, `bf_geometry_loads`,
//! and the exact I/O of the calls: `io_bytes_read` (on disk: compressed bytes for a compressed
//! store), `io_codec_bytes` (uncompressed bytes out of the codec; 0 for a plain store),
//! `io_read_calls`, `io_seeks`. With `hierarchy=on`, per level K (0: the objects' boxes)
//! `bh_level_K_read`, and for K ≥ 1 `bh_level_K_skipped` (boxes whose subtree was passed),
//! `bh_level_K_objects_skipped`, `bh_level_K_ray_tests`; `bh_objects_skipped` in all; in the
//! build stats `bh_levels`, `bh_level_K_boxes`, `bh_build_s` (0 when the store had it).
//! With `grid=two-level` ([`hires`]): `hr_traversals`, `hr_blocks_read`, `hr_voxels_read`,
//! `hr_grid_bytes_read`, `hr_grid_read_calls`, `hr_grid_seeks` (the on-disk grid's reads, also in
//! `io_*`), `hr_lower_registrations` and `hr_direct_registrations` (rays sent directly to the
//! upper grid), `hr_lower_grids_used` (summed over passes), `hr_direct_misses` (direct
//! registrations a box's range check turned away); in the build stats the plan (`res_*`,
//! `hr_upper_*`, `hr_lower`, `hr_levels`, `hr_pool`, `hr_block_slices`) and the preprocessing
//! (`hr_subspace_side`, `hr_subspaces`, `hr_build_boxes_read`, `hr_build_nodes_culled`,
//! `hr_build_objects_culled`, `hr_build_bytes_written`, `hr_build_s`).

pub mod bytes;
pub mod cap;
pub mod config;
pub mod hierarchy;
pub mod hires;
pub mod intersect;
pub mod slot;
pub mod spill;
pub mod tree;
pub mod voxels;

#[cfg(test)]
mod cap_tests;
#[cfg(test)]
mod hierarchy_tests;
#[cfg(test)]
mod hires_tests;
#[cfg(test)]
mod layout_tests;
#[cfg(test)]
mod tests;

use crate::engine::{BuildInput, Counters, Engine, EngineError, EngineInfo, Settings};
use crate::grid::build::{FLOOR_FLAT, FLOOR_SPAN};
use crate::ray::{Hit, Ray};
use crate::store::{
    Hierarchy, IoCounters, ObjectRecord, SceneReader, StoreHeader, StoreWriter, Surface,
};
use config::{BreadthFirstConfig, Count, Floor, Registration};
use glam::Vec3;
use hires::config::GridKind;
use intersect::Work;
use spill::SpillDir;
use std::collections::BTreeMap;
use std::io;
use std::path::Path;
use std::sync::{Arc, Mutex, TryLockError};
use std::time::Instant;
use voxels::{Voxels, PREALLOCATE};

pub fn info() -> EngineInfo {
    EngineInfo {
        name: "breadth-first",
        description: "Nakamaru's out-of-core breadth-first ray tracer: rays registered in a \
                      uniform grid, the scene streamed from disk once per pass (seed 000)",
        available: || Ok(()),
        build: build_engine,
    }
}

fn err(reason: String) -> EngineError {
    EngineError::Build {
        engine: "breadth-first".into(),
        reason,
    }
}

fn build_engine(input: &BuildInput, settings: Settings) -> Result<Box<dyn Engine>, EngineError> {
    let config = BreadthFirstConfig::from_settings(settings)?;
    Ok(Box::new(BreadthFirst::from_scene(input, config)?))
}

/// The `grid` engine's floor test ([`crate::grid::build::floor_objects`]) on a bounding box:
/// spanning [`FLOOR_SPAN`] of the scene along two axes, and flat across the third.
fn is_floor_box(lo: Vec3, hi: Vec3, scene_extent: Vec3) -> bool {
    let e = hi - lo;
    let spans = (0..3)
        .filter(|&i| scene_extent[i] > 0.0 && e[i] as f64 >= FLOOR_SPAN * scene_extent[i] as f64)
        .count();
    spans >= 2 && e.min_element() as f64 <= FLOOR_FLAT * e.max_element() as f64
}

/// What a work is made of besides its readers: the marked grid and the floor group (shared,
/// read only), the hierarchy's files, and the sizes the budget gave.
struct WorkParts {
    extent: f32,
    voxels: Arc<Voxels>,
    floor: Arc<Vec<(u32, ObjectRecord)>>,
    tree: Option<Hierarchy>,
    capacity: usize,
    initial: u32,
}

impl WorkParts {
    fn work(
        &self,
        config: &BreadthFirstConfig,
        scene: SceneReader,
        tree: Option<tree::Tree>,
        hires: Option<hires::HiRes>,
    ) -> Work {
        let regs_capacity = self.capacity * self.initial as usize;
        Work {
            extent: self.extent,
            registered: if hires.is_some() {
                voxels::Registrations::new(0, 0)
            } else {
                voxels::Registrations::new(self.voxels.count(), regs_capacity)
            },
            voxels: Arc::clone(&self.voxels),
            regs_capacity,
            slots: Vec::with_capacity(self.capacity.min(PREALLOCATE)),
            capacity: self.capacity,
            initial_count: self.initial,
            inverse: matches!(
                config.registration,
                Registration::Inverse | Registration::InverseFrom(_)
            ),
            boundary: config.boundary,
            prev_skip: config.prev_skip,
            refill: config.refill,
            scene,
            record: ObjectRecord::default(),
            floor: Arc::clone(&self.floor),
            floor_tests: 0,
            tree,
            cold: config.cold,
            hires,
            max_passes: config.max_passes,
            passes_done: 0,
            progress: config.progress.then(std::time::Instant::now),
        }
    }

    /// Another work over the same grid, with readers of its own.
    fn twin(&self, header: &StoreHeader, config: &BreadthFirstConfig) -> io::Result<Work> {
        let scene = SceneReader::open(header, config.buffer as usize, config.lazy)?;
        let tree = match &self.tree {
            Some(info) => Some(tree::Tree::open(info.clone(), config.buffer as usize)?),
            None => None,
        };
        Ok(self.work(config, scene, tree, None))
    }
}

pub struct BreadthFirst {
    config: BreadthFirstConfig,
    header: StoreHeader,
    /// The work of the out-of-core workload and of every in-memory call that finds it free.
    work: Mutex<Work>,
    /// Works made for in-memory calls that came while `work` was busy (another thread's band),
    /// kept for the next such call: threads trace at once, each with its own rays in memory,
    /// registrations and file readers, over the one grid.
    spares: Mutex<Vec<Work>>,
    /// What such a work is made from; `None` where calls take turns on `work`.
    parts: Option<WorkParts>,
    failure: Mutex<Option<String>>,
    stats: BTreeMap<String, f64>,
    structure_bytes: u64,
    /// The temporary store of an in-memory scene; dropped (removed) with the engine.
    _spill: Option<SpillDir>,
}

impl BreadthFirst {
    /// Writes the scene as a store in the spill directory, then opens it.
    pub fn from_scene(
        input: &BuildInput,
        config: BreadthFirstConfig,
    ) -> Result<BreadthFirst, EngineError> {
        let t = Instant::now();
        let spill = SpillDir::create(config.spill.as_deref()).map_err(err)?;
        let io = StoreWriter::create_layout(spill.path(), &input.scene.name, config.layout)
            .and_then(|w| w.write_scene(&input.scene))
            .map_err(|e| {
                err(format!(
                    "{}: cannot write the scene store: {e}",
                    spill.shown()
                ))
            })?;
        let store_s = t.elapsed().as_secs_f64();
        // Just written by this process: its records are checked as the algorithm reads them.
        let mut e = Self::open(
            spill.path(),
            BreadthFirstConfig {
                verify: false,
                ..config
            },
        )?;
        e.stats.insert("store_write_s".into(), store_s);
        e.stats
            .insert("store_bytes_written".into(), io.bytes_written as f64);
        e._spill = Some(spill);
        Ok(e)
    }

    /// Opens a store and preprocesses it (Algorithm 3.4: one sweep of the bounding-box file
    /// marking voxels and boundary faces).
    pub fn open(dir: &Path, config: BreadthFirstConfig) -> Result<BreadthFirst, EngineError> {
        let t = Instant::now();
        let header = StoreHeader::read(dir).map_err(|e| err(e.to_string()))?;
        if header.layout != config.layout {
            return Err(err(format!(
                "{}: a store of the {} layout, and this engine reads layout={} (set layout={})",
                dir.display(),
                header.layout.name(),
                config.layout.name(),
                header.layout.name()
            )));
        }
        let open_err = |e: std::io::Error| err(format!("{}: {e}", dir.display()));
        let verify = if config.verify {
            let t = Instant::now();
            let bytes = header.verify().map_err(open_err)?;
            Some((bytes, t.elapsed().as_secs_f64()))
        } else {
            None
        };
        // Ch.4's "B": the hierarchy, built now (inside preprocessing) when the store lacks it.
        let mut bh_stats = BTreeMap::new();
        let mut tree = if config.hierarchy {
            let constants = config.bh.resolve(&header.name);
            let (info, built) =
                hierarchy::prepare(&header, constants, config.buffer as usize).map_err(open_err)?;
            bh_stats.insert(
                "bh_build_s".into(),
                built.as_ref().map_or(0.0, |b| b.seconds),
            );
            if let Some(b) = &built {
                bh_stats.insert("bh_build_bytes_read".into(), b.io.bytes_read as f64);
                bh_stats.insert("bh_build_bytes_written".into(), b.io.bytes_written as f64);
            }
            if config.verify {
                let t = Instant::now();
                let bytes = info.verify(config.buffer as usize).map_err(open_err)?;
                bh_stats.insert("bh_verify_bytes_read".into(), bytes as f64);
                bh_stats.insert("bh_verify_s".into(), t.elapsed().as_secs_f64());
            }
            bh_stats.insert("bh_levels".into(), info.height() as f64);
            for (k, n) in info.levels.iter().enumerate() {
                bh_stats.insert(format!("bh_level_{}_boxes", k + 1), *n as f64);
            }
            bh_stats.insert("bh_s".into(), constants.s);
            bh_stats.insert("bh_m".into(), constants.m as f64);
            bh_stats.insert("bh_l".into(), constants.l as f64);
            bh_stats.insert("bh_t".into(), constants.t);
            Some(tree::Tree::open(info, config.buffer as usize).map_err(open_err)?)
        } else {
            None
        };
        let mut scene =
            SceneReader::open(&header, config.buffer as usize, config.lazy).map_err(open_err)?;
        // The floor group, and the box and primitive count of the rest (one sweep).
        let (mut floor, mut bounds, mut grid_prims) =
            (Vec::new(), header.bounds, header.primitives);
        // The mean box extent, which shapes Klimaszewski's cells (`grid=single|two-level`).
        let (mut extent_sum, mut extent_n) = (glam::DVec3::ZERO, 0u64);
        if config.floor == Floor::Out {
            let ext = header.bounds[1] - header.bounds[0];
            let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            let mut rec = ObjectRecord::default();
            while let Some((id, b, loaded)) = scene.next(&mut rec).map_err(open_err)? {
                if is_floor_box(b.lo, b.hi, ext) {
                    if !loaded {
                        scene.load(&b, &mut rec).map_err(open_err)?;
                    }
                    if matches!(rec.surface, Some(Surface::Flat { .. })) {
                        grid_prims -= rec.prims.len() as u64;
                        floor.push((id, std::mem::take(&mut rec)));
                        continue;
                    }
                }
                lo = lo.min(b.lo);
                hi = hi.max(b.hi);
                if b.lo.is_finite() && b.hi.is_finite() {
                    extent_sum += (b.hi - b.lo).as_dvec3();
                    extent_n += 1;
                }
            }
            bounds = [lo, hi];
            scene.rewind().map_err(open_err)?;
        }
        let grid_n = match config.count {
            Count::Prims => grid_prims,
            Count::Objects => header.objects - floor.len() as u64,
        };
        let klim = !matches!(config.grid, GridKind::CubeRoot);
        if klim && config.floor == Floor::In {
            let mut rec = ObjectRecord::default();
            while let Some((_, b, _)) = scene.next(&mut rec).map_err(open_err)? {
                if b.lo.is_finite() && b.hi.is_finite() {
                    extent_sum += (b.hi - b.lo).as_dvec3();
                    extent_n += 1;
                }
            }
            scene.rewind().map_err(open_err)?;
        }
        let mean_extent = (extent_sum / extent_n.max(1) as f64).to_array();
        let klimaszewski = |ext: [f64; 3]| {
            crate::grid::resolution::klimaszewski_uncapped(ext, grid_n as usize, 1.0, mean_extent)
        };
        let mut plan = None;
        let mut hr_stats = BTreeMap::new();
        let mut prior_s = 0.0;
        // The grid takes about one voxel per primitive (5 bytes each: flags and where its rays
        // begin in the registrations grouped by voxel).
        // Where that would pass half the memory budget, it is made coarser to fit in half, so
        // the rest stays for rays (seed 000 §1.2 sizes its grid to the machine's memory too).
        let voxel_target = grid_n.min(config.memory / 2 / 5).max(1);
        let mut voxels = match config.grid {
            GridKind::CubeRoot => Voxels::with_res(bounds, voxel_target, config.res),
            GridKind::Single { cap } => Voxels::shaped(bounds, grid_n.max(1), |ext| {
                klimaszewski(ext).map(|r| r.min(cap))
            }),
            GridKind::TwoLevel(tl) => Voxels::frame(bounds, grid_n.max(1), |ext| {
                let p = hires::config::plan(klimaszewski(ext), &tl);
                plan = Some(p);
                p.res
            }),
        };
        let res3 = voxels.lattice.res;
        let nvox = res3.iter().map(|&r| r as u64).product::<u64>();
        let (grid_bytes, reg_bytes) = match (config.grid, plan) {
            (GridKind::TwoLevel(tl), Some(p)) => {
                let pool = tl.pool.unwrap_or_else(|| {
                    (config.memory / 16 / (4 * (p.lower as u64).pow(3)).max(1)).max(1)
                });
                let block = tl.block.unwrap_or(config.memory / 8);
                hr_stats.insert("hr_pool".into(), pool as f64);
                hr_stats.insert("hr_block_bytes".into(), block as f64);
                (
                    hires::two_level::TwoLevel::bytes(p.upper, p.lower, pool)
                        + hires::blocks::Blocks::bytes(res3, block),
                    hires::reg_bytes(),
                )
            }
            _ => (nvox * 5, voxels::reg_bytes()),
        };
        if grid_bytes > config.memory {
            return Err(err(format!(
                "memory={} B is too small for the grid: {} B ({:?} cells; set cap= or a lower upper=)",
                config.memory, grid_bytes, res3
            )));
        }
        // The scene files' buffers (a compressed split store's readers hold a block, its
        // compressed bytes and the block index instead of `buffer`).
        let buffers = scene.held_bytes()
            + tree
                .as_ref()
                .map_or(0, |t| t.levels.len() as u64 * config.buffer);
        let initial = config.registration.initial(voxels.max_res());
        let per_ray = slot::slot_bytes()
            + initial as u64 * reg_bytes
            + if plan.is_some() {
                hires::walk_bytes()
            } else {
                0
            };
        let left = config.memory.saturating_sub(grid_bytes + buffers);
        let capacity = (left / per_ray).min(config.max_rays.unwrap_or(u64::MAX)) as usize;
        if capacity == 0 {
            return Err(err(format!(
                "memory={} B is too small: the grid ({} voxels) and buffers take {} B, and one \
                 ray {} B more",
                config.memory,
                nvox,
                grid_bytes + buffers,
                per_ray
            )));
        }
        let floor_ids: Vec<u32> = floor.iter().map(|f| f.0).collect();
        let hires = match (config.grid, plan) {
            (GridKind::TwoLevel(tl), Some(p)) => {
                let tb = Instant::now();
                if !tl.reuse {
                    // The subspace: a cube whose flags fit in 1/4 of the budget (§4.3.1).
                    let side = tl.subspace.unwrap_or_else(|| {
                        ((config.memory / 4) as f64).cbrt().floor().max(1.0) as u32
                    });
                    let st = hires::disk_grid::DiskGrid::build(
                        dir,
                        &voxels,
                        side,
                        &mut scene,
                        tree.as_mut(),
                        &floor_ids,
                        tl.resume,
                        tl.max_subspaces,
                    )
                    .map_err(|e| err(e.to_string()))?;
                    prior_s = st.prior_s;
                    hr_stats.insert("hr_build_resumed_subspaces".into(), st.resumed as f64);
                    hr_stats.insert("hr_build_prior_s".into(), st.prior_s);
                    hr_stats.insert("hr_subspace_side".into(), st.side as f64);
                    hr_stats.insert("hr_subspaces".into(), st.subspaces as f64);
                    hr_stats.insert("hr_subspaces_total".into(), st.total as f64);
                    hr_stats.insert("hr_build_partial".into(), f64::from(u8::from(st.partial)));
                    hr_stats.insert("hr_build_boxes_read".into(), st.boxes_read as f64);
                    hr_stats.insert("hr_build_nodes_culled".into(), st.nodes_culled as f64);
                    hr_stats.insert("hr_build_objects_culled".into(), st.objects_culled as f64);
                    hr_stats.insert("hr_build_bytes_written".into(), st.io.bytes_written as f64);
                    hr_stats.insert("hr_build_write_calls".into(), st.io.write_calls as f64);
                    hr_stats.insert("marked_voxels".into(), st.marked as f64);
                }
                hr_stats.insert("hr_build_s".into(), prior_s + tb.elapsed().as_secs_f64());
                let grid = hires::disk_grid::DiskGrid::open(dir, &voxels, floor.len() as u64)
                    .map_err(|e| err(e.to_string()))?;
                if tl.max_subspaces.is_some() {
                    // A partial grid (`hrgrid_subspaces`) is held open and never left where
                    // `hrgrid=reuse` or `resume` would take it.
                    let path = dir.join(hires::disk_grid::FILE_NAME);
                    std::fs::remove_file(&path)
                        .map_err(|e| err(format!("{}: {e}", path.display())))?;
                }
                hr_stats.insert(
                    "hr_grid_file_bytes".into(),
                    (hires::disk_grid::HEADER + hires::disk_grid::flag_bytes(res3)) as f64,
                );
                hr_stats.insert("hr_levels".into(), if p.lower > 1 { 2.0 } else { 1.0 });
                hr_stats.insert("hr_lower".into(), p.lower as f64);
                for (i, a) in ["x", "y", "z"].iter().enumerate() {
                    hr_stats.insert(format!("hr_upper_{a}"), p.upper[i] as f64);
                }
                let pool = hr_stats["hr_pool"] as usize;
                let block = hr_stats["hr_block_bytes"] as u64;
                let blocks = hires::blocks::Blocks::new(res3, block);
                hr_stats.insert("hr_block_slices".into(), blocks.width as f64);
                Some(hires::HiRes {
                    grid,
                    reg: hires::two_level::TwoLevel::new(p.upper, p.lower, pool),
                    blocks,
                    walks: Vec::with_capacity(capacity.min(PREALLOCATE)),
                    cands: Vec::new(),
                    io_reported: Default::default(),
                })
            }
            _ => {
                let mut next_floor = floor.iter().map(|f| f.0).peekable();
                let mut rec = ObjectRecord::default();
                while let Some((id, b, _)) = scene.next(&mut rec).map_err(open_err)? {
                    if next_floor.next_if_eq(&id).is_none() {
                        voxels.mark(b.lo, b.hi);
                    }
                }
                hr_stats.insert("marked_voxels".into(), voxels.marked_count() as f64);
                None
            }
        };
        let pre_io = scene.take_io();
        if config.cold {
            scene.drop_cache();
            if let Some(t) = &tree {
                t.drop_cache();
            }
        }
        // With `hrgrid=resume`, the grid's subspaces an earlier invocation built count here too.
        let preprocess_s = prior_s + t.elapsed().as_secs_f64();

        let mut stats = bh_stats;
        stats.extend(hr_stats);
        stats.insert("preprocess_s".into(), preprocess_s);
        stats.insert("res_x".into(), voxels.lattice.res[0] as f64);
        stats.insert("res_y".into(), voxels.lattice.res[1] as f64);
        stats.insert("res_z".into(), voxels.lattice.res[2] as f64);
        stats.insert("voxels".into(), nvox as f64);
        stats.insert("objects".into(), header.objects as f64);
        stats.insert("primitives".into(), header.primitives as f64);
        stats.insert("memory_budget_bytes".into(), config.memory as f64);
        stats.insert("rays_in_memory".into(), capacity as f64);
        stats.insert("registration_initial".into(), initial as f64);
        stats.insert("bytes_per_ray".into(), per_ray as f64);
        stats.insert("preprocess_bytes_read".into(), pre_io.bytes_read as f64);
        stats.insert("preprocess_read_calls".into(), pre_io.read_calls as f64);
        stats.insert("preprocess_codec_bytes".into(), pre_io.codec_bytes as f64);
        stats.insert("store_stored_bytes".into(), header.disk_bytes() as f64);
        stats.insert("store_reader_bytes".into(), scene.held_bytes() as f64);
        stats.insert(
            "store_plain_bytes".into(),
            (header.geometry_bytes + header.bbox_bytes) as f64,
        );
        stats.insert("floor_objects".into(), floor.len() as f64);
        stats.insert("grid_n".into(), grid_n as f64);
        if let Some((bytes, secs)) = verify {
            stats.insert("verify_bytes_read".into(), bytes as f64);
            stats.insert("verify_s".into(), secs);
        }
        let extent = header.bounds[0]
            .abs()
            .max(header.bounds[1].abs())
            .max_element();
        let parts = WorkParts {
            extent: if extent.is_finite() { extent } else { 0.0 },
            voxels: Arc::new(voxels),
            floor: Arc::new(floor),
            tree: tree.as_ref().map(|t| t.info.clone()),
            capacity,
            initial,
        };
        // A work of its own for each thread tracing at once, except where a count runs over
        // all calls (the pass cap and its progress lines) or the grid is the on-disk one (its
        // block buffer and lower-grid pool are most of the budget).
        let twins = hires.is_none() && config.max_passes.is_none() && !config.progress;
        let work = parts.work(&config, scene, tree, hires);
        Ok(BreadthFirst {
            config,
            header,
            work: Mutex::new(work),
            spares: Mutex::new(Vec::new()),
            parts: twins.then_some(parts),
            failure: Mutex::new(None),
            stats,
            structure_bytes: grid_bytes,
            _spill: None,
        })
    }

    pub fn header(&self) -> &StoreHeader {
        &self.header
    }

    pub fn config(&self) -> &BreadthFirstConfig {
        &self.config
    }

    /// The rays the engine holds in memory at once within its budget (`rays_in_memory`): the
    /// out-of-core workload shades that many rays per sweep of the store (Algorithm 3.6, "while
    /// memory not full of rays").
    pub fn ray_capacity(&self) -> usize {
        self.work.lock().unwrap_or_else(|p| p.into_inner()).capacity
    }

    /// Answers `rays` (ids are their positions) through `out`; the shared body of `intersect`
    /// and `occluded`, and the entry of the out-of-core workload.
    pub fn trace_stream(
        &self,
        rays: &mut dyn Iterator<Item = (u32, Ray)>,
        any: bool,
        out: &mut dyn FnMut(u32, Hit),
        c: &mut Counters,
    ) -> std::io::Result<()> {
        let mut w = self.work.lock().unwrap_or_else(|p| p.into_inner());
        Self::trace_work(
            &mut w,
            self.config.triangle,
            rays,
            any,
            out,
            c,
            IoCounters::default(),
        )
    }

    /// [`Self::trace_stream`] on the engine's work, already locked; `opened` is what opening
    /// its readers for this call read, counted with the call's own reads.
    fn trace_work(
        w: &mut Work,
        triangle: crate::geometry::TriangleTest,
        rays: &mut dyn Iterator<Item = (u32, Ray)>,
        any: bool,
        out: &mut dyn FnMut(u32, Hit),
        c: &mut Counters,
        opened: IoCounters,
    ) -> std::io::Result<()> {
        let mut before = w.io();
        before.sub(&opened);
        let r = w.trace(rays, any, triangle, out, c);
        let floor_tests = std::mem::take(&mut w.floor_tests);
        if floor_tests > 0 {
            *c.extra.entry("bf_floor_tests".into()).or_insert(0) += floor_tests;
        }
        if let Some(t) = w.tree.as_mut() {
            hierarchy::report(t, c);
        }
        // Rays left in memory by an error are dropped: their answers are MISS.
        w.slots.clear();
        let after = w.io();
        if let Some(h) = w.hires.as_mut() {
            hires::report(h, c);
        }
        let e = &mut c.extra;
        *e.entry("io_bytes_read".into()).or_insert(0) += after.bytes_read - before.bytes_read;
        *e.entry("io_read_calls".into()).or_insert(0) += after.read_calls - before.read_calls;
        *e.entry("io_seeks".into()).or_insert(0) += after.seeks - before.seeks;
        *e.entry("io_codec_bytes".into()).or_insert(0) += after.codec_bytes - before.codec_bytes;
        r
    }

    /// The scene's readers opened again, and what opening them read (the bounding-box
    /// hierarchy's and the high-resolution grid's files keep their readers).
    fn fresh_readers(
        w: &mut Work,
        header: &StoreHeader,
        config: &BreadthFirstConfig,
    ) -> std::io::Result<IoCounters> {
        w.scene = SceneReader::open(header, config.buffer as usize, config.lazy)?;
        Ok(w.scene.io())
    }

    fn answer<T>(
        &self,
        rays: &[Ray],
        out: &mut [T],
        any: bool,
        c: &mut Counters,
        put: impl Fn(&mut T, Hit),
    ) {
        let fail = |e: String| {
            let mut f = self.failure.lock().unwrap_or_else(|p| p.into_inner());
            f.get_or_insert(e);
        };
        let own = match self.work.try_lock() {
            Ok(w) => Ok(w),
            Err(TryLockError::Poisoned(p)) => Ok(p.into_inner()),
            Err(TryLockError::WouldBlock) => Err(()),
        };
        if let (Err(()), Some(parts)) = (&own, &self.parts) {
            // Another thread traces on `work`: this call takes a spare, or makes one.
            let spare = self.spares.lock().unwrap_or_else(|p| p.into_inner()).pop();
            let mut w = match spare.map_or_else(|| parts.twin(&self.header, &self.config), Ok) {
                Ok(w) => w,
                Err(e) => return fail(format!("breadth-first: opening the scene store: {e}")),
            };
            self.answer_on(&mut w, rays, out, any, c, put, &fail);
            self.spares
                .lock()
                .unwrap_or_else(|p| p.into_inner())
                .push(w);
            return;
        }
        let mut w = own.unwrap_or_else(|()| self.work.lock().unwrap_or_else(|p| p.into_inner()));
        self.answer_on(&mut w, rays, out, any, c, put, &fail);
    }

    #[allow(clippy::too_many_arguments)]
    fn answer_on<T>(
        &self,
        w: &mut Work,
        rays: &[Ray],
        out: &mut [T],
        any: bool,
        c: &mut Counters,
        put: impl Fn(&mut T, Hit),
        fail: &dyn Fn(String),
    ) {
        let mut it = rays.iter().enumerate().map(|(i, r)| (i as u32, *r));
        // The calls of an in-memory trace (one per band and query) may come in any order, from
        // several threads, to any of the engine's works. Each starts with the scene's readers as
        // the engine opened them, so what it reads, and its I/O counters, do not depend on where
        // the call before it left the file buffers (the lazy geometry reads end wherever that
        // call's rays ended).
        let r = Self::fresh_readers(w, &self.header, &self.config).and_then(|opened| {
            let mut put = |id: u32, h: Hit| put(&mut out[id as usize], h);
            Self::trace_work(w, self.config.triangle, &mut it, any, &mut put, c, opened)
        });
        if let Err(e) = r {
            fail(format!("breadth-first: reading the scene store: {e}"));
        }
    }
}

impl Engine for BreadthFirst {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], c: &mut Counters) {
        hits.fill(Hit::MISS);
        self.answer(rays, hits, false, c, |h, hit| *h = hit);
    }

    fn occluded(&self, rays: &[Ray], occluded: &mut [bool], c: &mut Counters) {
        occluded.fill(false);
        self.answer(rays, occluded, true, c, |o, hit| *o = hit.is_hit());
    }

    fn structure_bytes(&self) -> u64 {
        self.structure_bytes
    }

    fn batch_hint(&self) -> Option<usize> {
        match self.config.batch {
            // One call per band and query: the band's rays are swept together.
            config::Batch::Band => Some(usize::MAX),
            config::Batch::Generation => None,
        }
    }

    fn failure(&self) -> Option<String> {
        self.failure
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .clone()
    }

    fn build_stats(&self) -> BTreeMap<String, f64> {
        self.stats.clone()
    }
}
