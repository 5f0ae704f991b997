//! The sweep through the bounding-box hierarchy (seed 000 §4.2.2, "B"; Fig. 4.1b): the top
//! level is read whole; a node is descended into only when some ray registered in a voxel its
//! box reaches hits its box, otherwise all its descendants, boxes and geometry, are passed by one
//! forward seek in each level's file (the file of the level below starts the next node's
//! children where they are).
//!
//! The test on a node is the test on an object's box without the per-object skips (the thesis
//! does not spell it out; §1.11 of the digest): a ray that misses a node's box misses every box
//! inside it, and every voxel a child's box reaches is one the node's reaches, so skipping is
//! exact and the image is the one without the hierarchy, to the bit. The mailbox and the
//! previous-voxel skip stay on objects: they say an object was tested, which says nothing about
//! the other objects of a node.
//!
//! Reading checks that each box read lies in its parent's and that siblings' children follow one
//! another: a hierarchy that disagrees with its level below is an error, not a silent miss.

use super::intersect::Work;
use super::slot::{BoxRay, Tally};
use super::tree::{LevelTally, Tree};
use crate::engine::Counters;
use crate::geometry::TriangleTest;
use crate::store::hierarchy::NODE_RECORD;
use crate::store::hierarchy::{disagree, Hierarchy, NodeRecord};
use crate::store::BBOX_RECORD;
use std::io;

impl Work {
    /// The sweep of a pass through the hierarchy, from the top level down.
    pub(super) fn sweep_tree(
        &mut self,
        any: bool,
        test: TriangleTest,
        c: &mut Counters,
        t: &mut Tally,
    ) -> io::Result<()> {
        let mut tree = self.tree.take().expect("a hierarchy");
        let top = tree.levels.len();
        let n = tree.count(top);
        let r = self.visit(&mut tree, top, 0, n, None, any, test, c, t);
        self.tree = Some(tree);
        r
    }

    /// Records `a..z` of level `k` (0: objects), children of `parent`.
    #[allow(clippy::too_many_arguments)]
    fn visit(
        &mut self,
        tree: &mut Tree,
        k: usize,
        a: u64,
        z: u64,
        parent: Option<(u64, NodeRecord)>,
        any: bool,
        test: TriangleTest,
        c: &mut Counters,
        t: &mut Tally,
    ) -> io::Result<()> {
        let outside = |tree: &Tree, i: u64| {
            let (pi, _) = parent.expect("checked with a parent");
            disagree(
                &tree
                    .info
                    .dir
                    .join(crate::store::hierarchy::level_file(k as u32 + 1)),
                pi,
                format!("its box does not hold its child {i}'s"),
            )
        };
        if k == 0 {
            self.scene.skip_to(a as u32, &mut self.record)?;
            for i in a..z {
                let (id, b, read) = self.scene.next(&mut self.record)?.ok_or_else(|| {
                    io::Error::new(
                        io::ErrorKind::InvalidData,
                        "hierarchy names objects past the last",
                    )
                })?;
                tree.tally[0].read += 1;
                t.records += read as u64;
                if parent.is_some_and(|(_, p)| !p.holds(b.lo, b.hi)) {
                    return Err(outside(tree, i));
                }
                if self.floor.binary_search_by_key(&id, |f| f.0).is_ok() {
                    continue;
                }
                self.object(id, &b, read, any, test, c, t)?;
            }
            return Ok(());
        }
        let below_record = if k == 1 { BBOX_RECORD } else { NODE_RECORD };
        let below = tree.count(k - 1);
        tree.levels[k - 1].seek_record(a)?;
        let mut follows: Option<u64> = None;
        for i in a..z {
            let node = tree.levels[k - 1].next_record()?.ok_or_else(|| {
                io::Error::new(
                    io::ErrorKind::InvalidData,
                    "hierarchy: children past the last",
                )
            })?;
            if parent.is_some_and(|(_, p)| !p.holds(node.lo, node.hi)) {
                return Err(outside(tree, i));
            }
            let (ca, cz) = node.child_range(below_record);
            if node.children == 0 || cz > below || follows.is_some_and(|f| f != ca) {
                return Err(disagree(
                    &tree.levels[k - 1].path,
                    i,
                    "its children do not follow the node before it's",
                ));
            }
            follows = Some(cz);
            tree.tally[k].read += 1;
            if self.node_needed(&node, any, &mut tree.tally[k]) {
                self.visit(tree, k - 1, ca, cz, Some((i, node)), any, test, c, t)?;
            } else {
                tree.tally[k].skipped += 1;
                tree.tally[k].objects_skipped += node.objects as u64;
            }
        }
        Ok(())
    }

    /// Some ray registered in a voxel the node's box reaches hits the box (within its segment):
    /// the node's subtree must be swept. Walks the voxels, or the registrations when they are
    /// fewer (a top box reaches every voxel).
    fn node_needed(&self, n: &NodeRecord, any: bool, lt: &mut LevelTally) -> bool {
        if !(n.lo.is_finite() && n.hi.is_finite()) || n.lo.cmpgt(n.hi).any() {
            return false;
        }
        let g = &self.voxels;
        let (a, z) = g.range(n.lo, n.hi);
        let planes = BoxRay::planes(n.lo - g.pad, n.hi + g.pad);
        let mut hits = |slot: u32| {
            let s = &self.slots[slot as usize];
            if any && s.best.is_hit() {
                return false;
            }
            lt.ray_tests += 1;
            s.boxray.hits(&planes, s.best_t)
        };
        if let Some(h) = &self.hires {
            // The two-level registration grid (§4.3.3).
            return h
                .reg
                .for_each(a, z, |slot| Ok::<bool, ()>(hits(slot)))
                .unwrap_or(false);
        }
        let cells: u64 = (0..3).map(|i| (z[i] - a[i] + 1) as u64).product();
        if cells > self.registered.count() as u64 {
            let [rx, ry, _] = g.lattice.res;
            return self.registered.regs.iter().any(|reg| {
                let v = reg.voxel;
                let p = [v % rx, (v / rx) % ry, v / (rx * ry)];
                (0..3).all(|i| p[i] >= a[i] && p[i] <= z[i]) && hits(reg.slot)
            });
        }
        for cz in a[2]..=z[2] {
            for cy in a[1]..=z[1] {
                let row = g.lattice.index([0, cy, cz]);
                let run = self
                    .registered
                    .run(row + a[0] as usize, row + z[0] as usize);
                if run.iter().any(|&slot| hits(slot)) {
                    return true;
                }
            }
        }
        false
    }
}

/// The counters of the hierarchy into `extra`: per level K, `bh_level_K_read`,
/// `bh_level_K_skipped`, `bh_level_K_objects_skipped`, `bh_level_K_ray_tests`; and
/// `bh_objects_skipped` (objects passed without reading their boxes, all levels).
pub fn report(tree: &mut Tree, c: &mut Counters) {
    let mut skipped = 0;
    for (k, l) in tree.tally.iter_mut().enumerate() {
        let e = &mut c.extra;
        *e.entry(format!("bh_level_{k}_read")).or_insert(0) += l.read;
        if k > 0 {
            *e.entry(format!("bh_level_{k}_skipped")).or_insert(0) += l.skipped;
            *e.entry(format!("bh_level_{k}_objects_skipped"))
                .or_insert(0) += l.objects_skipped;
            *e.entry(format!("bh_level_{k}_ray_tests")).or_insert(0) += l.ray_tests;
        }
        skipped += l.objects_skipped;
        *l = LevelTally::default();
    }
    *c.extra.entry("bh_objects_skipped".into()).or_insert(0) += skipped;
}

/// Opens (building when absent or built with other constants) the hierarchy of `h` for the
/// engine; returns the tree and, when it was built now, what building took.
pub fn prepare(
    h: &crate::store::StoreHeader,
    constants: crate::store::Constants,
    buffer: usize,
) -> io::Result<(Hierarchy, Option<crate::store::hierarchy::BuildStats>)> {
    if let Some(info) = Hierarchy::open(h, Some(constants))? {
        return Ok((info, None));
    }
    let stats = Hierarchy::build(h, constants, buffer).map_err(|e| {
        io::Error::new(
            e.kind(),
            format!("cannot build the bounding-box hierarchy: {e}"),
        )
    })?;
    let info = Hierarchy::open(h, Some(constants))?.ok_or_else(|| {
        io::Error::other(format!(
            "{}: hierarchy built but not found",
            h.dir.display()
        ))
    })?;
    Ok((info, Some(stats)))
}
