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
        layout: &Layout,
        stamps: &mut [u32],
        ray_no: u32,
        out: &mut dyn FnMut(u64),
    ) {
        let prims = &self.geometry.prims;
        let test = self.config.triangle;
        let wt = WatertightRay::new(ray.dir);
        let psize = std::mem::size_of::<Prim>() as u64;
        let mut r = *ray;
        let mut hit = false;
        let visit_prim = |p: u32, r: &mut Ray, out: &mut dyn FnMut(u64)| -> bool {
            out((layout.prims + p as u64 * psize) / PAGE);
            match prims[p as usize].intersect(r, test, &wt) {
                Some((t, _, _)) => {
                    if !any {
                        r.tmax = t;
                    }
                    out((layout.prim_object + p as u64 * 4) / PAGE);
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
            out((layout.offsets + cell as u64 * 4) / PAGE);
            let (a, b) = (g.offsets[cell] as u64, g.offsets[cell + 1] as u64);
            for i in a..b {
                out((layout.refs + i * 4) / PAGE);
                let p = g.refs[i as usize];
                if self.config.mailbox {
                    out((layout.mailbox + p as u64 * 4) / PAGE);
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
