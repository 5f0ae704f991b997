//! The bounding-box hierarchy in use (seed 000 §4.2.2, "B"): one reader per level and the counts
//! of each level; the sweep through it is `hierarchy.rs`.

use crate::store::hierarchy::{Hierarchy, LevelReader};
use crate::store::IoCounters;
use std::io;

/// Counts of one level, over all sweeps.
#[derive(Clone, Copy, Debug, Default)]
pub struct LevelTally {
    /// Boxes read, boxes whose subtree was passed, objects below those.
    pub read: u64,
    pub skipped: u64,
    pub objects_skipped: u64,
    /// Ray–box tests made on this level's nodes.
    pub ray_tests: u64,
}

/// The hierarchy in use: one reader per level (index K − 1 for level K) and its counts.
pub struct Tree {
    pub info: Hierarchy,
    pub levels: Vec<LevelReader>,
    /// Index K for level K (0: the objects' boxes read by the sweep).
    pub tally: Vec<LevelTally>,
}

impl Tree {
    pub fn open(info: Hierarchy, buffer: usize) -> io::Result<Tree> {
        let levels = info
            .levels
            .iter()
            .enumerate()
            .map(|(i, &n)| LevelReader::open(&info.dir, i as u32 + 1, n, buffer))
            .collect::<io::Result<Vec<_>>>()?;
        let tally = vec![LevelTally::default(); levels.len() + 1];
        Ok(Tree {
            info,
            levels,
            tally,
        })
    }

    pub fn io(&self) -> IoCounters {
        let mut io = IoCounters::default();
        for l in &self.levels {
            io.add(&l.file.io);
        }
        io
    }

    pub fn drop_cache(&self) {
        for l in &self.levels {
            l.file.drop_cache();
        }
    }

    /// Records of level `k` (0: objects).
    pub(super) fn count(&self, k: usize) -> u64 {
        if k == 0 {
            self.info.objects
        } else {
            self.info.levels[k - 1]
        }
    }
}
