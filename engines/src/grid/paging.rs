//! The grid engine's page-access stream (seed 000 §3.4: Rayshade thrashes once its grid and
//! objects outgrow physical memory). The grid's arrays are laid out one after another, each
//! starting on a page, as the process holds them: the cell offsets, the reference list, the
//! prepared primitives, the primitives' scene objects and the mailbox stamps. A ray's query is
//! replayed as [`Grid::closest`] and [`Grid::any`] make it (rss-r semantics: mailboxes, no shadow
//! cache, no per-voxel culling, so the stream does not depend on earlier rays), and every array
//! element it reads or writes is reported as its page number. Feeding the stream to Mattson's
//! stack algorithm gives the page faults for every memory size at once.

use super::Grid;
use crate::geometry::kernels::f32::WatertightRay;
use crate::geometry::Prim;
use crate::ray::Ray;

/// Page size of the model.
pub const PAGE: u64 = 4096;

/// Where each array starts, in bytes from 0, each on a page boundary.
#[derive(Clone, Copy, Debug)]
pub struct Layout {
    offsets: u64,
    refs: u64,
    prims: u64,
    prim_object: u64,
    mailbox: u64,
    /// Total bytes (the grid's memory in the model, rounded to pages).
    pub bytes: u64,
}

fn pages(bytes: u64) -> u64 {
    bytes.div_ceil(PAGE) * PAGE
}

/// Where a query's reads land, as page numbers: in the grid's own arrays ([`Layout`]), or in
/// another program's memory image of the same grid (seed 000's rayshade-ss, whose objects, voxel
/// pointers and list nodes the harness lays out as Rayshade allocates them).
pub trait PageMap {
    /// Cell `cell`'s entry (c = x + res_x·(y + res_y·z)).
    fn cell(&self, cell: usize) -> u64;
    /// Entry `index` of the cells' reference list.
    fn reference(&self, index: u64) -> u64;
    /// Primitive `prim`'s mailbox stamp.
    fn mailbox(&self, prim: u32) -> u64;
    /// Primitive `prim`'s geometry, read by the intersection test.
    fn prim(&self, prim: u32) -> u64;
    /// Primitive `prim`'s scene object, read on a hit.
    fn object(&self, prim: u32) -> u64;
}

impl PageMap for Layout {
    fn cell(&self, cell: usize) -> u64 {
        (self.offsets + cell as u64 * 4) / PAGE
    }
    fn reference(&self, index: u64) -> u64 {
        (self.refs + index * 4) / PAGE
    }
    fn mailbox(&self, prim: u32) -> u64 {
        (self.mailbox + prim as u64 * 4) / PAGE
    }
    fn prim(&self, prim: u32) -> u64 {
        (self.prims + prim as u64 * std::mem::size_of::<Prim>() as u64) / PAGE
    }
    fn object(&self, prim: u32) -> u64 {
        (self.prim_object + prim as u64 * 4) / PAGE
    }
}

impl Grid {
    /// The model's memory layout of this grid.
    pub fn layout(&self) -> Layout {
        let n = self.geometry.prims.len() as u64;
        let offsets = 0;
        let refs = offsets + pages(self.cells.offsets.len() as u64 * 4);
        let prims = refs + pages(self.cells.refs.len() as u64 * 4);
        let prim_object = prims + pages(n * std::mem::size_of::<Prim>() as u64);
        let mailbox = prim_object + pages(n * 4);
        Layout {
            offsets,
            refs,
            prims,
            prim_object,
            mailbox,
            bytes: mailbox + pages(n * 4),
        }
    }

    /// Replays one query (`any`: any hit, else closest) and reports the page of every access.
    /// `stamps`: one per primitive, `ray_no` this query's number (the mailbox's state).
    pub fn page_accesses(
        &self,
        ray: &Ray,
        any: bool,
        layout: &dyn PageMap,
        stamps: &mut [u32],
        ray_no: u32,
        out: &mut dyn FnMut(u64),
    ) {
        let prims = &self.geometry.prims;
        let test = self.config.triangle;
        let wt = WatertightRay::new(ray.dir);
        let mut r = *ray;
        let mut hit = false;
        let visit_prim = |p: u32, r: &mut Ray, out: &mut dyn FnMut(u64)| -> bool {
            out(layout.prim(p));
            match prims[p as usize].intersect(r, test, &wt) {
                Some((t, _, _)) => {
                    if !any {
                        r.tmax = t;
                    }
                    out(layout.object(p));
                    true
                }
                None => false,
            }
        };
        for &p in &self.floor {
            if visit_prim(p, &mut r, out) {
                hit = true;
                if any {
                    return;
                }
            }
        }
        if self.cells.refs.is_empty() {
            return;
        }
        let g = &self.cells;
        let segment = r;
        self.walk(&segment, |cell, _, t_exit| {
            out(layout.cell(cell));
            let (a, b) = (g.offsets[cell] as u64, g.offsets[cell + 1] as u64);
            for i in a..b {
                out(layout.reference(i));
                let p = g.refs[i as usize];
                if self.config.mailbox {
                    out(layout.mailbox(p));
                    if stamps[p as usize] == ray_no {
                        continue;
                    }
                    stamps[p as usize] = ray_no;
                }
                if visit_prim(p, &mut r, out) {
                    hit = true;
                    if any {
                        return true;
                    }
                }
            }
            !any && hit && r.tmax <= t_exit
        });
    }
}
