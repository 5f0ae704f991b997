//! Intersection, seed 000's Algorithm 3.5: rays are registered in their next candidate voxels,
//! the scene is swept once per pass, and passes repeat until every ray's hit is complete.
//!
//! - A voxel is a *candidate* for a ray when it is marked and either it is the ray's first voxel
//!   in the grid, or the ray entered it through a face flagged as lying on a voxel boundary
//!   (§3.2, "registration at voxel boundaries"). The thesis's second case (a ray starting inside
//!   a voxel boundary is registered just before it first crosses a boundary face) is taken here
//!   as the first voxel itself: both make the ray meet every box it starts in, and the first
//!   voxel is known without walking. Every box of voxels the walk reaches is then reached at a
//!   candidate: the walk is face-connected and the box convex.
//! - A ray's hit is *complete* once it lies in voxels already walked and swept, or the ray left
//!   the grid (§3.1). After registering k candidates the walk is covered up to the exit of the
//!   last one; between passes the walk continues through non-candidate voxels (all their boxes
//!   were met before) until the next candidate, stopping early if the hit lies there.
//! - In the sweep each object's box of voxels is visited; for each ray registered there the
//!   per-ray mailbox (last object tested) and the previous-voxel test (the ray's last voxel of
//!   the previous pass lies in this box: tested then) skip repeated tests (§3.3), then the
//!   ray–box test, and only then is the geometry read, forward only (§4.2.2, "G").
//! - Memory is refilled with new rays at the start of every pass, and the registration count is
//!   set from the rays in memory (§3.3).
//! - Hit records leave in completion order through `out(ray id, hit)`; the caller files them by
//!   ray id (the thesis's sort by ray id).

use super::slot::{face_bit_of, BoxRay, Slot, Tally};
use super::voxels::{push_within, Registrations, Voxels, MARKED};
use crate::engine::Counters;
use crate::geometry::dda::{Dda, START};
use crate::geometry::kernels::f32::WatertightRay;
use crate::geometry::TriangleTest;
use crate::ray::{Hit, Ray};
use crate::store::{BboxRecord, IoCounters, ObjectRecord, SceneReader};
use std::io;
use std::sync::Arc;

/// What the engine works with during a call: the grid, the rays in memory and their
/// registrations, and the two files.
pub struct Work {
    /// The marked grid, read only once preprocessing has marked it: shared by the engine's
    /// works (one per thread tracing at once, [`super::BreadthFirst`]).
    pub(super) voxels: Arc<Voxels>,
    /// The rays registered in each voxel this pass.
    pub(super) registered: Registrations,
    pub(super) regs_capacity: usize,
    pub(super) slots: Vec<Slot>,
    /// Rays in memory at most.
    pub(super) capacity: usize,
    pub(super) initial_count: u32,
    pub(super) inverse: bool,
    /// The switches of §3.2–3.3 (each on by default).
    pub(super) boundary: bool,
    pub(super) prev_skip: bool,
    pub(super) refill: bool,
    pub(super) scene: SceneReader,
    pub(super) record: ObjectRecord,
    /// The floor group: (object id, its record), held in memory.
    pub(super) floor: Arc<Vec<(u32, ObjectRecord)>>,
    /// Primitive tests of the floor group not yet in the counters (`bf_floor_tests`): counted
    /// here and added once per call, as a lookup of that key per test cost more than the test.
    pub(super) floor_tests: u64,
    /// Largest absolute coordinate of the scene: the conservative slab test's rounding bound.
    pub(super) extent: f32,
    /// The bounding-box hierarchy's level files (`hierarchy=on`; §4.2.2 "B").
    pub(super) tree: Option<super::tree::Tree>,
    /// Drop the store from the page cache after every sweep (`cache=cold`).
    pub(super) cold: bool,
    /// The high-resolution grid (`grid=two-level`, §4.3): its flags on disk, rays registered in
    /// its two-level grid; `voxels` then holds the grid's frame only, and `registered` nothing.
    pub(super) hires: Option<super::hires::HiRes>,
    /// The pass cap (`max_passes`, [`super::cap`]) and the passes made so far, over all calls.
    pub(super) max_passes: Option<u64>,
    pub(super) passes_done: u64,
    /// When the engine opened, for the `progress=on` line after every pass.
    pub(super) progress: Option<std::time::Instant>,
}

impl Work {
    pub(super) fn io(&self) -> IoCounters {
        let mut io = self.scene.io();
        if let Some(t) = &self.tree {
            io.add(&t.io());
        }
        if let Some(h) = &self.hires {
            io.add(&h.grid.io);
        }
        io
    }

    /// Drops every file this engine reads from the page cache.
    pub(super) fn drop_cache(&self) {
        self.scene.drop_cache();
        if let Some(t) = &self.tree {
            t.drop_cache();
        }
        if let Some(h) = &self.hires {
            h.grid.drop_cache();
        }
    }
}

/// With `boundary` off every marked voxel is a candidate.
#[inline]
fn is_candidate(g: &Voxels, d: &Dda, boundary: bool) -> bool {
    let f = g.flags[g.lattice.index(d.voxel())];
    // `entered` is 2·axis + side, the numbering of `face_bit(axis, side)`.
    f & MARKED != 0 && (!boundary || d.entered == START || f & face_bit_of(d.entered) != 0)
}

/// Walks to the ray's first candidate voxel; false when it has none.
fn first_candidate(g: &Voxels, d: &mut Dda, boundary: bool, c: &mut Counters) -> bool {
    loop {
        c.cells_visited += 1;
        if is_candidate(g, d, boundary) {
            return true;
        }
        if !d.advance(g.lattice.res) {
            return false;
        }
    }
}

/// One object of the sweep, as each ray registered where its box reaches meets it.
struct Visit {
    id: u32,
    /// The box of voxels the object's box reaches: its first voxel and its extent − 1.
    a: [u32; 3],
    span: [u32; 3],
    /// The object's box, padded as the grid pads it ([`BoxRay::planes`]).
    planes: [f32; 6],
    any: bool,
    prev_skip: bool,
}

impl Visit {
    /// Whether the ray must meet the object's geometry: not for an any-hit ray already answered,
    /// the mailbox (§3.3: the object was tested for this ray in another voxel), the previous-voxel
    /// skip (§3.3: the ray's last voxel of the previous pass is in the object's box of voxels, so
    /// it was tested then), or a missed box.
    #[inline(always)]
    fn needs(&self, s: &mut Slot, c: &mut Counters, t: &mut Tally) -> bool {
        if self.any && s.has_hit {
            return false;
        }
        if s.mailbox == self.id {
            c.mailbox_skips += 1;
            return false;
        }
        s.mailbox = self.id;
        // One unsigned comparison per axis, without branches: a voxel below `a` wraps round past
        // the span, and "none" (u32::MAX) is past every span.
        let p = s.prev;
        let inside = (p[0].wrapping_sub(self.a[0]) <= self.span[0])
            & (p[1].wrapping_sub(self.a[1]) <= self.span[1])
            & (p[2].wrapping_sub(self.a[2]) <= self.span[2]);
        if self.prev_skip & inside {
            t.prev_skips += 1;
            return false;
        }
        c.box_tests += 1;
        s.boxray.hits(&self.planes, s.best_t)
    }
}

impl Work {
    /// Answers all of `rays` (closest hit, or any hit with `any`), calling `out` once per ray.
    pub fn trace(
        &mut self,
        rays: &mut dyn Iterator<Item = (u32, Ray)>,
        any: bool,
        test: TriangleTest,
        out: &mut dyn FnMut(u32, Hit),
        c: &mut Counters,
    ) -> io::Result<()> {
        if self.hires.is_some() {
            return self.trace_hires(rays, any, test, out, c);
        }
        let mut input_left = true;
        let mut pass = 0usize;
        loop {
            if self.capped(rays, out, c) {
                return Ok(());
            }
            // Refill the free slots (Algorithm 3.5, "while memory not full of rays"); without
            // refill only once the batch in memory is done (Algorithm 3.3).
            let may_read = self.refill || self.slots.is_empty();
            while may_read && input_left && self.slots.len() < self.capacity {
                let Some((id, ray)) = rays.next() else {
                    input_left = false;
                    break;
                };
                match self.admit(id, ray, any, test, c) {
                    Err(best) => out(id, best),
                    Ok(mut slot) => {
                        let g = &self.voxels;
                        if first_candidate(g, &mut slot.dda, self.boundary, c) {
                            push_within(&mut self.slots, slot, self.capacity);
                        } else {
                            out(id, slot.best);
                        }
                    }
                }
            }
            if self.slots.is_empty() {
                return Ok(());
            }
            pass += 1;
            *c.extra
                .entry(format!("bf_pass_{pass:03}_rays"))
                .or_insert(0) += self.slots.len() as u64;
            let count = self.registration_count(self.slots.len());
            self.register(count, c);
            self.sweep(any, test, c)?;
            self.end_pass(c);
            self.finish_pass(any, out, c);
        }
    }

    /// A ray entering memory: the floor group is tested first (a near floor hit shortens the
    /// walk), then its walk starts where it enters the grid. `Err(best)`: the ray leaves now
    /// (an any-hit query met the floor, or the segment misses the grid).
    pub(super) fn admit(
        &mut self,
        id: u32,
        ray: Ray,
        any: bool,
        test: TriangleTest,
        c: &mut Counters,
    ) -> Result<Slot, Hit> {
        c.rays += 1;
        if !ray.is_traceable() {
            // As every engine answers it (`Ray::is_traceable`); it also keeps NaN out of the
            // box test's accumulators (`BoxRay::hits`).
            return Err(Hit::MISS);
        }
        let wt = WatertightRay::new(ray.dir);
        let mut best = Hit::MISS;
        let mut seg = ray;
        'floor: for (fid, rec) in self.floor.iter() {
            for prim in &rec.prims {
                c.primitive_tests += 1;
                self.floor_tests += 1;
                if let Some((t, u, v)) = prim.intersect(&seg, test, &wt) {
                    c.primitive_hits += 1;
                    seg.tmax = t;
                    best = Hit {
                        t,
                        object: *fid,
                        u,
                        v,
                    };
                    if any {
                        break 'floor;
                    }
                }
            }
        }
        if any && best.is_hit() {
            return Err(best);
        }
        let Some(dda) = Dda::start(&seg, &self.voxels.lattice) else {
            return Err(best);
        };
        Ok(Slot {
            boxray: BoxRay::new(&ray, self.extent),
            best_t: seg.tmax,
            mailbox: u32::MAX,
            prev: [u32::MAX; 3],
            has_hit: best.is_hit(),
            exhausted: false,
            ray,
            best,
            covered: f32::NEG_INFINITY,
            id,
            last: [u32::MAX; 3],
            wt,
            dda,
        })
    }

    /// Registrations per ray this pass.
    pub(super) fn registration_count(&self, in_memory: usize) -> usize {
        let fixed = self.initial_count as usize;
        if self.inverse {
            (self.regs_capacity / in_memory.max(1)).max(fixed)
        } else {
            fixed
        }
    }

    /// Registers every ray in memory in up to `count` candidate voxels, from the one its walk
    /// stands on.
    fn register(&mut self, count: usize, c: &mut Counters) {
        // A pass whose sweep failed (an I/O error returned to the caller) left its grouping
        // behind; counting on top of it would index past the registrations.
        if self.registered.count() > 0 {
            self.registered.clear();
        }
        let g = &self.voxels;
        let boundary = self.boundary;
        for (si, s) in self.slots.iter_mut().enumerate() {
            let mut k = 0;
            'walk: loop {
                let v = s.dda.voxel();
                self.registered.push(g.lattice.index(v) as u32, si as u32);
                k += 1;
                s.last = v;
                s.covered = s.dda.t_exit();
                if k == count || s.best_t <= s.covered {
                    break;
                }
                // On to the next candidate.
                loop {
                    if !s.dda.advance(g.lattice.res) {
                        s.exhausted = true;
                        break 'walk;
                    }
                    c.cells_visited += 1;
                    if is_candidate(g, &s.dda, boundary) {
                        break;
                    }
                    if s.best_t <= s.dda.t_exit() {
                        s.covered = s.dda.t_exit();
                        break 'walk;
                    }
                }
            }
        }
        *c.extra.entry("bf_registrations".into()).or_insert(0) += self.registered.count() as u64;
        self.registered.group();
    }

    /// One sequential sweep of the bounding-box file (Algorithm 3.5's "for all objects"), or of
    /// the bounding-box hierarchy when the store has one and `hierarchy=on` (§4.2.2, "B").
    pub(super) fn sweep(
        &mut self,
        any: bool,
        test: TriangleTest,
        c: &mut Counters,
    ) -> io::Result<()> {
        self.scene.rewind()?;
        let mut t = Tally::default();
        if self.tree.is_some() {
            self.sweep_tree(any, test, c, &mut t)?;
        } else {
            // The floor group's ids, in stream order.
            let mut next_floor = 0;
            while let Some((id, b, read)) = self.scene.next(&mut self.record)? {
                t.records += read as u64;
                if self.floor.get(next_floor).is_some_and(|f| f.0 == id) {
                    next_floor += 1;
                    continue;
                }
                self.object(id, &b, read, any, test, c, &mut t)?;
            }
        }
        self.registered.clear();
        if let Some(h) = self.hires.as_mut() {
            h.reg.clear();
        }
        if self.cold {
            self.drop_cache();
        }
        *c.extra.entry("bf_prev_voxel_skips".into()).or_insert(0) += t.prev_skips;
        *c.extra.entry("bf_geometry_loads".into()).or_insert(0) += t.loads;
        *c.extra
            .entry("bf_geometry_records_read".into())
            .or_insert(0) += t.records + t.loads;
        Ok(())
    }

    /// The sweep's work on one object (not of the floor group): each ray registered in the
    /// voxels its box reaches, past the mailbox and previous-voxel skips, is tested against the
    /// box, and only then is the geometry read (forward only) and intersected.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn object(
        &mut self,
        id: u32,
        b: &BboxRecord,
        read: bool,
        any: bool,
        test: TriangleTest,
        c: &mut Counters,
        t: &mut Tally,
    ) -> io::Result<()> {
        if !(b.lo.is_finite() && b.hi.is_finite()) {
            return Ok(());
        }
        let g = &self.voxels;
        let (a, z) = g.range(b.lo, b.hi);
        let v = Visit {
            id,
            a,
            span: [0, 1, 2].map(|i| z[i] - a[i]),
            planes: BoxRay::planes(b.lo - g.pad, b.hi + g.pad),
            any,
            prev_skip: self.prev_skip,
        };
        let (slots, scene, record) = (&mut self.slots, &mut self.scene, &mut self.record);
        // Past the box: the geometry, read at the first ray that needs it.
        let mut loaded = read;
        let mut hit = |s: &mut Slot, c: &mut Counters, t: &mut Tally| -> io::Result<()> {
            if !loaded {
                scene.load(b, record)?;
                loaded = true;
                t.loads += 1;
            }
            s.intersect(id, record, any, test, c);
            Ok(())
        };
        if let Some(h) = &self.hires {
            h.reg.for_each(a, z, |slot| {
                let s = &mut slots[slot as usize];
                if v.needs(s, c, t) {
                    hit(s, c, t)?;
                }
                Ok::<bool, io::Error>(false)
            })?;
            return Ok(());
        }
        for cz in a[2]..=z[2] {
            for cy in a[1]..=z[1] {
                let row = g.lattice.index([0, cy, cz]);
                for &slot in self
                    .registered
                    .run(row + a[0] as usize, row + z[0] as usize)
                {
                    let s = &mut slots[slot as usize];
                    if v.needs(s, c, t) {
                        hit(s, c, t)?;
                    }
                }
            }
        }
        Ok(())
    }

    /// Algorithm 3.5's last loop: rays whose hit is complete leave; the others walk to the first
    /// candidate of the next pass.
    fn finish_pass(&mut self, any: bool, out: &mut dyn FnMut(u32, Hit), c: &mut Counters) {
        let g = &self.voxels;
        let boundary = self.boundary;
        let mut i = 0;
        while i < self.slots.len() {
            let s = &mut self.slots[i];
            s.prev = s.last;
            let mut done = (any && s.best.is_hit()) || s.exhausted || s.best_t <= s.covered;
            if !done {
                loop {
                    if !s.dda.advance(g.lattice.res) {
                        done = true;
                        break;
                    }
                    c.cells_visited += 1;
                    if is_candidate(g, &s.dda, boundary) {
                        break;
                    }
                    if s.best_t <= s.dda.t_exit() {
                        done = true;
                        break;
                    }
                }
            }
            if done {
                out(s.id, s.best);
                self.slots.swap_remove(i);
            } else {
                i += 1;
            }
        }
    }
}

#[cfg(test)]
mod tie_tests {
    use super::*;
    use crate::geometry::dda::Lattice;
    use crate::geometry::Prim;
    use glam::Vec3;

    /// Of two objects hit at the same t, the one with the smaller id is kept whichever is met
    /// first; a nearer hit still wins over a smaller id, and an object met again keeps its hit.
    #[test]
    fn a_tie_of_equal_t_keeps_the_smaller_object_id_in_either_order() {
        let ray = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z, 1e-4, f32::INFINITY);
        let lattice = Lattice::new(Vec3::splat(-2.0), Vec3::splat(2.0), [2, 2, 2]);
        let slot = Slot {
            boxray: BoxRay::new(&ray, 10.0),
            best_t: ray.tmax,
            mailbox: u32::MAX,
            prev: [u32::MAX; 3],
            has_hit: false,
            exhausted: false,
            ray,
            best: Hit::MISS,
            covered: f32::NEG_INFINITY,
            id: 0,
            last: [u32::MAX; 3],
            wt: WatertightRay::new(ray.dir),
            dda: Dda::start(&ray, &lattice).unwrap(),
        };
        let sphere = |z: f32| ObjectRecord {
            material: 0,
            surface: None,
            prims: vec![Prim::Sphere {
                center: Vec3::new(0.0, 0.0, z),
                radius: 1.0,
            }],
        };
        let (same, nearer) = (sphere(0.0), sphere(-0.5));
        let run = |order: &[(u32, &ObjectRecord)]| {
            let mut s = slot;
            let mut c = Counters::default();
            for (id, rec) in order {
                s.intersect(*id, rec, false, TriangleTest::default(), &mut c);
            }
            (s.best.object, s.best.t)
        };
        let (a, ta) = run(&[(7, &same), (3, &same), (9, &same)]);
        let (b, tb) = run(&[(3, &same), (7, &same), (9, &same)]);
        assert_eq!((a, b), (3, 3));
        assert_eq!(ta, 4.0);
        assert_eq!(ta, tb);
        // A nearer hit wins over a smaller id, before and after.
        assert_eq!(run(&[(3, &same), (8, &nearer)]).0, 8);
        assert_eq!(run(&[(8, &nearer), (3, &same)]).0, 8);
    }
}
