//! `object-space`: the (Mπ)² object-space parallel machine of seed 003 (Yamauchi 1997), simulated.
//! Object space is cut into a uniform grid of subspaces; subspaces are given to processing
//! elements (PEs) on a 1D, 2D or 3D torus; a ray travels as a packet from subspace to subspace,
//! and from PE to neighbouring PE, until it hits something or leaves the space.
//!
//! The engine answers queries for real (the shared kernels, in every subspace the ray visits,
//! so hits equal the other engines') and meanwhile times them on the simulated machine: each
//! batch the harness gives is one wave of rays injected at once, simulated on its own; the
//! clocks of the waves add up. 003's own ray-tracing pass (at most 3 reflections, no shadow
//! rays, intensity packets into the frame buffer) is traced by the harness (`rtbench reproduce
//! yamauchi-*`) with [`ObjectSpace::execute`] and timed with [`sim::simulate`].
//!
//! Files: [`config`] (settings, Table 4 costs), [`machine`] (torus, allocations), [`trace`] (what execution records), [`sim`] (the event simulation of the ray-tracing pass),
//! [`radiosity`] (003's radiosity pass on the machine, and a single-process reference),
//! [`framebuffer`] (GFB and the cached frame buffer system), [`queueing`] (003's analytic
//! model of the CFBS and a random-arrival simulation of it). The walk from subspace to subspace
//! (003 §2.4: "the next subspace is computed with 3DDDA" [Fujimoto et al., ARTS]) is the shared
//! 3D-DDA, [`crate::geometry::dda`].
//!
//! Settings (`key=value`):
//!
//! | key | values | default | what |
//! |---|---|---|---|
//! | `subspaces` | `S` or `X,Y,Z` | `32` | subspaces per axis (003: 32³) |
//! | `pes` | `N`, `NxM`, `NxMxK` | `16` | PEs per axis of a 1D, 2D or 3D torus; each must divide the subspaces on its axis |
//! | `allocation` | `block`, `distributed`, `skewed` | `skewed` | subspace → PE (003 eqs. 7–10; skewed on 1D and 2D only) |
//! | `rp_blocks` | 1–4096 | 1 | ray-processing blocks per PE (dynamic load balancing) |
//! | `frame_buffer` | `direct`, `cfbs:M`, `wb:M` | `direct` | intensity packets straight to the GFB, or through an M-ary tree of caches or of write buffers |
//! | `cost.<name>` | clocks > 0 | Table 4/5 | `primary` 4379, `triangle` 1028, `sphere` 1737, `cone` 2446, `intensity` 349, `dda_init` 3151, `dda` 1106, `secondary` 1818, `packet` 164, `hop` 164, `fb_hit` 12, `fb_miss` 7, `fb_dirty` 4, `gfb` 14, `fb_link` 8, `fb_block_link` 64 |
//! | `triangle` | `watertight`, `moller` | `watertight` | the shared triangle kernel |
//!
//! Counters: `rays`, `cells_visited` (subspaces visited), `empty_cells_visited`,
//! `primitive_tests` (a primitive in several subspaces is tested again in each: PEs keep no
//! per-ray memory), `primitive_hits`; in `extra` the simulation's `sim_clocks` (summed over
//! waves), `sim_busy_clocks`, `sim_rp_clocks` (image time × RP blocks, for utilisation),
//! `sim_events`, `sim_packets`, `sim_hops`, `sim_waves`.

pub mod config;
pub mod fbpath;
pub mod framebuffer;
pub mod machine;
pub mod queueing;
pub mod radiosity;
pub mod sim;
pub mod trace;

#[cfg(test)]
mod tests;

use crate::engine::{BuildInput, Counters, Engine, EngineError, EngineInfo, Settings};
use crate::geometry::dda;
use crate::geometry::kernels::f32::WatertightRay;
use crate::geometry::{Geometry, Prim};
use crate::grid::build::{self, Cells};
use crate::grid::config::{GridConfig, Resolution};
use crate::ray::{Hit, Ray};
use config::ObjectSpaceConfig;
use std::collections::BTreeMap;
use std::sync::Arc;
use trace::{Segment, Trace, TracedRay, NO_PIXEL};

/// The registry entry of the `object-space` engine.
pub fn info() -> EngineInfo {
    EngineInfo {
        name: "object-space",
        description: "(M\u{3c0})\u{b2} object-space parallel machine, simulated: subspaces on \
                      processing elements of a torus, rays as packets (seed 003)",
        available: || Ok(()),
        build: build_engine,
    }
}

fn build_engine(input: &BuildInput, settings: Settings) -> Result<Box<dyn Engine>, EngineError> {
    let config = ObjectSpaceConfig::from_settings(settings)?;
    Ok(Box::new(ObjectSpace::build(input, config)?))
}

/// The subspace grid with its primitives, the machine, and the owner of every subspace.
pub struct ObjectSpace {
    geometry: Arc<Geometry>,
    config: ObjectSpaceConfig,
    subspaces: Cells,
    /// Table 4's test cost of each primitive, by its kind.
    test_cost: Vec<u32>,
    owner: Vec<u32>,
}

impl ObjectSpace {
    /// Registers every primitive in each subspace its (padded) bounding box overlaps, using the
    /// grid engine's builder at the configured resolution.
    pub fn build(
        input: &BuildInput,
        config: ObjectSpaceConfig,
    ) -> Result<ObjectSpace, EngineError> {
        let grid = GridConfig {
            resolution: Resolution::Explicit(config.subspaces),
            ..GridConfig::default()
        };
        let built =
            build::build(&input.scene, &input.geometry, &grid).map_err(|e| EngineError::Build {
                engine: "object-space".into(),
                reason: e.to_string(),
            })?;
        // A scene with nothing to register gets one empty cell: every ray misses before walking.
        let subspaces = built.cells;
        let c = &config.costs;
        let test_cost = input
            .geometry
            .prims
            .iter()
            .map(|p| match p {
                Prim::Triangle(_) => c.triangle,
                Prim::Sphere { .. } => c.sphere,
                Prim::Cone { .. } => c.cone,
            })
            .collect();
        let owner = config.machine.owner_map(config.subspaces);
        Ok(ObjectSpace {
            geometry: input.geometry.clone(),
            config,
            subspaces,
            test_cost,
            owner,
        })
    }

    pub fn config(&self) -> &ObjectSpaceConfig {
        &self.config
    }

    /// The subspace grid's box and resolution.
    pub fn lattice(&self) -> &dda::Lattice {
        &self.subspaces.lattice
    }

    /// The PE of every subspace under the configured machine.
    pub fn owner(&self) -> &[u32] {
        &self.owner
    }

    /// Clocks of testing every primitive of subspace `s` (Table 4's per-test costs): the work
    /// of any ray's visit that does not stop at its first blocker.
    pub fn subspace_work(&self, s: usize) -> u32 {
        self.subspaces
            .prims_in(s)
            .iter()
            .fold(0u32, |w, &p| w.saturating_add(self.test_cost[p as usize]))
    }

    /// Whether `p` lies inside the subspace grid's box.
    pub fn inside(&self, p: glam::Vec3) -> bool {
        let g = &self.subspaces;
        !g.refs.is_empty() && p.cmpge(g.lattice.lo).all() && p.cmple(g.lattice.hi).all()
    }

    /// Traces one ray through the subspaces, appending a [`Segment`] per subspace visited:
    /// the closest hit, or with `any` the first blocker found (as a hit). In each subspace the
    /// ray tests every primitive registered there against its segment so far; the nearest hit
    /// is carried along in the packet and the walk stops in the subspace that contains it.
    pub fn execute(&self, ray: &Ray, any: bool, segs: &mut Vec<Segment>, c: &mut Counters) -> Hit {
        c.rays += 1;
        let g = &self.subspaces;
        let prims = &self.geometry.prims;
        if g.refs.is_empty() {
            return Hit::MISS;
        }
        let wt = WatertightRay::new(ray.dir);
        let test = self.config.triangle;
        let mut r = *ray;
        let mut best = u32::MAX;
        let (mut bu, mut bv) = (0.0, 0.0);
        dda::walk(&g.lattice, ray, |_, cell, _, t_exit| {
            let s = cell as u32;
            c.cells_visited += 1;
            let list = g.prims_in(s as usize);
            if list.is_empty() {
                c.empty_cells_visited += 1;
            }
            let mut work = 0u32;
            let mut done = false;
            for &p in list {
                work = work.saturating_add(self.test_cost[p as usize]);
                c.primitive_tests += 1;
                if let Some((t, u, v)) = prims[p as usize].intersect(&r, test, &wt) {
                    c.primitive_hits += 1;
                    (r.tmax, best, bu, bv) = (t, p, u, v);
                    if any {
                        done = true;
                        break;
                    }
                }
            }
            segs.push(Segment { subspace: s, work });
            done || r.tmax <= t_exit
        });
        if best == u32::MAX {
            Hit::MISS
        } else {
            Hit {
                t: r.tmax,
                object: self.geometry.prim_object[best as usize],
                u: bu,
                v: bv,
            }
        }
    }

    /// Traces a batch as one wave of root rays and simulates it on the configured machine.
    fn wave(&self, rays: &[Ray], any: bool, mut answer: impl FnMut(usize, Hit), c: &mut Counters) {
        let mut trace = Trace::default();
        for (i, ray) in rays.iter().enumerate() {
            let start = trace.segs.len() as u32;
            let h = self.execute(ray, any, &mut trace.segs, c);
            trace.rays.push(TracedRay {
                seg_start: start,
                seg_count: trace.segs.len() as u32 - start,
                first_child: 0,
                children: 0,
                pixel: NO_PIXEL,
                root: true,
                initial: !self.inside(ray.origin),
                hit: h.is_hit(),
            });
            answer(i, h);
        }
        let cfg = &self.config;
        let s = sim::simulate(
            &trace,
            &cfg.machine,
            &self.owner,
            &cfg.costs,
            cfg.frame_buffer,
            1,
        );
        let mut add = |k: &str, v: u64| *c.extra.entry(k.into()).or_insert(0) += v;
        add("sim_clocks", s.clocks);
        add("sim_busy_clocks", s.busy);
        add("sim_rp_clocks", s.clocks * s.pes * s.rp_blocks);
        add("sim_events", s.events);
        add("sim_packets", s.packets);
        add("sim_hops", s.hops);
        add("sim_waves", 1);
    }
}

impl Engine for ObjectSpace {
    fn intersect(&self, rays: &[Ray], hits: &mut [Hit], c: &mut Counters) {
        self.wave(rays, false, |i, h| hits[i] = h, c);
    }

    fn occluded(&self, rays: &[Ray], occluded: &mut [bool], c: &mut Counters) {
        self.wave(rays, true, |i, h| occluded[i] = h.is_hit(), c);
    }

    fn structure_bytes(&self) -> u64 {
        self.subspaces.bytes() + (self.owner.len() * 4 + self.test_cost.len() * 4) as u64
    }

    fn build_stats(&self) -> BTreeMap<String, f64> {
        let m = &self.config.machine;
        let mut s = BTreeMap::new();
        s.insert("subspaces".into(), self.owner.len() as f64);
        s.insert(
            "empty_subspaces".into(),
            self.subspaces.empty_count() as f64,
        );
        s.insert("references".into(), self.subspaces.refs.len() as f64);
        s.insert("pes".into(), m.pe_count() as f64);
        s.insert("pe_dims".into(), m.dims as f64);
        s.insert("rp_blocks_per_pe".into(), m.rp_blocks as f64);
        s
    }
}
