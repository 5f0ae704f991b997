//! `grid`: a Rayshade-style uniform grid (seed 000 chapter 3, seed 002): one grid over the
//! scene's bounds, primitives registered in the cells they reach, rays walked through the cells
//! by 3D-DDA (Amanatides and Woo 1987) with mailboxes, and Rayshade's two extras as switches.
//!
//! Files, one concept each: [`config`] (settings), [`resolution`] (how many cells), [`overlap`]
//! (primitive–cell tests for exact insertion), [`build`] (the compact layout), [`mailbox`],
//! [`shadow_cache`], [`traverse`] (3D-DDA, closest and any hit).
//!
//! Settings (`key=value`):
//!
//! | key | values | default | what |
//! |---|---|---|---|
//! | `res` | `cuberoot`, `woo`, `klimaszewski`, `X,Y,Z` | `cuberoot` | cells per axis ([`resolution`]) |
//! | `density` | number > 0 | 1 | cells per primitive, for `woo` and `klimaszewski` only |
//! | `count` | `prims`, `objects` | `prims` | the n of the policies: grid primitives, or scene objects as Rayshade counted |
//! | `insert` | `bbox`, `exact` | `bbox` | cells a primitive's bounding box reaches (Rayshade), or its surface ([`overlap`]) |
//! | `mailbox` | `true`, `false` | `true` | test each primitive once per ray |
//! | `preset` | `rss`, `rss-r` | `rss` | `rss`: shadow cache and voxel culling on, as Rayshade ships; `rss-r`: both off (seed 000 §3.4) |
//! | `shadow_cache` | `true`, `false` | the preset's | last blocker per light first ([`shadow_cache`]) |
//! | `voxel_cull` | `true`, `false` | the preset's | per-voxel ray–box culling (Snyder and Barr 1987) |
//! | `floor` | `in`, `out` | `in` | `out` keeps floor/backdrop polygons out of the grid (SPD rule 11; [`build::floor_objects`]) |
//! | `triangle` | `watertight`, `moller` | `watertight` | the shared triangle kernel |
//!
//! Counters (Havran's statistics): `cells_visited` (N_TS, so steps per ray = cells_visited /
//! rays), `empty_cells_visited`, `primitive_tests` (tests per ray), `primitive_hits`,
//! `mailbox_skips`, `shadow_cache_hits`, `box_tests` (voxel culling's tests), and in `extra`
//! `voxel_culled` and `shadow_cache_misses` when those switches are on. Build statistics:
//! `cells` (N_V), `empty_cells` (N_EV), `references` (N_OIV), `res_x|y|z`, `n`,
//! `grid_primitives`, `floor_primitives`, `references_per_primitive`, `mailbox_bytes_per_thread`,
//! `build_s`.

pub mod build;
pub mod config;
pub mod mailbox;
pub mod overlap;
pub mod paging;
pub mod resolution;
pub mod shadow_cache;
pub mod traverse;

#[cfg(test)]
mod tests;

use crate::engine::{BuildInput, Counters, Engine, EngineError, EngineInfo, Settings};
use crate::geometry::Geometry;
use crate::ray::{Hit, Ray};
use build::Cells;
use config::GridConfig;
use glam::Vec3;
use mailbox::{Mailbox, MailboxPool};
use shadow_cache::ShadowCache;
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

/// The registry entry of the `grid` engine.
pub fn info() -> EngineInfo {
    EngineInfo {
        name: "grid",
        description: "Rayshade-style uniform grid: 3D-DDA, mailboxes, optional shadow cache and \
                      per-voxel ray-box culling (seeds 000, 002)",
        available: || Ok(()),
        build: build_engine,
    }
}

fn build_engine(input: &BuildInput, settings: Settings) -> Result<Box<dyn Engine>, EngineError> {
    let config = GridConfig::from_settings(settings)?;
    Ok(Box::new(Grid::build(input, config)?))
}

/// A built uniform grid over one scene's prepared primitives.
pub struct Grid {
    geometry: Arc<Geometry>,
    config: GridConfig,
    cells: Cells,
    /// Primitives tested outside the grid (`floor=out`).
    floor: Vec<u32>,
    /// Each primitive's bounding box, for voxel culling (empty when it is off).
    prim_bounds: Vec<[Vec3; 2]>,
    mailboxes: MailboxPool,
    stats: BTreeMap<String, f64>,
}

impl Grid {
    pub fn build(input: &BuildInput, config: GridConfig) -> Result<Grid, EngineError> {
        let t = Instant::now();
        let geometry = input.geometry.clone();
        let built = build::build(&input.scene, &geometry, &config)?;
        let prim_bounds = if config.voxel_cull {
            geometry
                .prims
                .iter()
                .map(|p| {
                    let (a, b) = p.bounds();
                    [a, b]
                })
                .collect()
        } else {
            Vec::new()
        };
        let mailboxes = MailboxPool::new(if config.mailbox {
            geometry.prims.len()
        } else {
            0
        });
        let build_s = t.elapsed().as_secs_f64();
        let cells = built.cells;
        let mut stats = BTreeMap::new();
        let refs = cells.refs.len() as f64;
        stats.insert("cells".into(), cells.count() as f64);
        stats.insert("empty_cells".into(), cells.empty_count() as f64);
        stats.insert("references".into(), refs);
        stats.insert("res_x".into(), cells.lattice.res[0] as f64);
        stats.insert("res_y".into(), cells.lattice.res[1] as f64);
        stats.insert("res_z".into(), cells.lattice.res[2] as f64);
        stats.insert("n".into(), built.n as f64);
        stats.insert("grid_primitives".into(), built.grid_prims as f64);
        stats.insert("floor_primitives".into(), built.floor.len() as f64);
        stats.insert(
            "references_per_primitive".into(),
            refs / (built.grid_prims.max(1) as f64),
        );
        stats.insert(
            "mailbox_bytes_per_thread".into(),
            mailboxes.bytes_each() as f64,
        );
        stats.insert("build_s".into(), build_s);
        Ok(Grid {
            geometry,
            config,
            cells,
            floor: built.floor,
            prim_bounds,
            mailboxes,
            stats,
        })
    }

    /// The grid's cells (for tests and reports).
    pub fn cells(&self) -> &Cells {
        &self.cells
    }

    /// Primitives kept out of the grid.
    pub fn floor(&self) -> &[u32] {
        &self.floor
    }

    pub fn config(&self) -> &GridConfig {
        &self.config
    }
}

/// Counts kept in locals during a batch and added to `Counters` once at its end.
#[derive(Default)]
pub struct Local {
    pub(super) culled: u64,
    pub(super) cache_misses: u64,
}

impl Local {
    pub fn flush(&self, c: &mut Counters, cull: bool, cache: bool) {
        if cull {
            *c.extra.entry("voxel_culled".into()).or_insert(0) += self.culled;
        }
        if cache {
            *c.extra.entry("shadow_cache_misses".into()).or_insert(0) += self.cache_misses;
        }
    }
}

impl Grid {
    /// Answers a batch of closest-hit queries with the walk's switches made constants.
    fn intersect_with<const MB: bool, const CULL: bool>(
        &self,
        rays: &[Ray],
        hits: &mut [Hit],
        mb: &mut Mailbox,
        c: &mut Counters,
        l: &mut Local,
    ) {
        for (r, h) in rays.iter().zip(hits.iter_mut()) {
            *h = self.closest::<MB, CULL>(r, mb, c, l);
        }
    }

    /// Answers a batch of any-hit queries with the walk's switches made constants.
    fn occluded_with<const MB: bool, const CULL: bool>(
        &self,
        rays: &[Ray],
        occluded: &mut [bool],
        mb: &mut Mailbox,
        c: &mut Counters,
        l: &mut Local,
    ) {
        let mut cache = ShadowCache::default();
        for (r, o) in rays.iter().zip(occluded.iter_mut()) {
            let cache = self.config.shadow_cache.then_some(&mut cache);
            *o = self.any::<MB, CULL>(r, mb, cache, c, l);
        }
    }
}

impl Engine for Grid {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], c: &mut Counters) {
        // With mailboxes off the pool's mailboxes hold no stamps, and none is read.
        let mut mb = self.mailboxes.take();
        let mut l = Local::default();
        let cull = !self.prim_bounds.is_empty();
        match (self.config.mailbox, cull) {
            (true, true) => self.intersect_with::<true, true>(rays, hits, &mut mb, c, &mut l),
            (true, false) => self.intersect_with::<true, false>(rays, hits, &mut mb, c, &mut l),
            (false, true) => self.intersect_with::<false, true>(rays, hits, &mut mb, c, &mut l),
            (false, false) => self.intersect_with::<false, false>(rays, hits, &mut mb, c, &mut l),
        }
        l.flush(c, self.config.voxel_cull, false);
        self.mailboxes.give(mb);
    }

    fn occluded(&self, rays: &[Ray], occluded: &mut [bool], c: &mut Counters) {
        let mut mb = self.mailboxes.take();
        let mut l = Local::default();
        let cull = !self.prim_bounds.is_empty();
        match (self.config.mailbox, cull) {
            (true, true) => self.occluded_with::<true, true>(rays, occluded, &mut mb, c, &mut l),
            (true, false) => self.occluded_with::<true, false>(rays, occluded, &mut mb, c, &mut l),
            (false, true) => self.occluded_with::<false, true>(rays, occluded, &mut mb, c, &mut l),
            (false, false) => {
                self.occluded_with::<false, false>(rays, occluded, &mut mb, c, &mut l)
            }
        }
        l.flush(c, self.config.voxel_cull, self.config.shadow_cache);
        self.mailboxes.give(mb);
    }

    fn structure_bytes(&self) -> u64 {
        self.cells.bytes()
            + (self.floor.len() * 4) as u64
            + (self.prim_bounds.len() * std::mem::size_of::<[Vec3; 2]>()) as u64
    }

    fn build_stats(&self) -> BTreeMap<String, f64> {
        let mut s = self.stats.clone();
        // The grid proper (offsets over the cells and the flat reference list: 4 bytes each) and
        // what per-voxel culling adds (one box per primitive), apart: the first is what seed 000
        // and Havran count.
        s.insert("cell_structure_bytes".into(), self.cells.bytes() as f64);
        s.insert(
            "culling_box_bytes".into(),
            (self.prim_bounds.len() * std::mem::size_of::<[Vec3; 2]>()) as f64,
        );
        s
    }
}
