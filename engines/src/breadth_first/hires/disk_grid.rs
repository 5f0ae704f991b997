//! The on-disk voxel grid of seed 000 §4.3: one byte per voxel (the basic method's mark and six
//! face bits, [`crate::breadth_first::voxels`]), in a file ordered x-major (x slowest, z fastest)
//! so that an X-slab block (Algorithm 4.6) is one sequential read.
//!
//! - **Preprocessing by subspaces** (§4.3.1, Fig. 4.2): the grid is made one cubic subspace at a
//!   time, each with one pass over the bounding boxes; with the hierarchy ("B") a node whose
//!   voxels miss the subspace is passed with all its descendants. Subspaces are cubes, not slabs,
//!   so that long boxes are culled more often (the thesis's reason).
//! - The file, `hrgrid.bin` in the store's directory: a 64-byte header (magic, resolution, the
//!   grid's box, floor objects, CRC-32 of `header.json` and of the header itself), then the flags.
//!   It is written as `hrgrid.bin.tmp` and renamed when whole; a failed build removes the
//!   temporary, so no half-written grid is ever left. A file whose length disagrees with its
//!   header is refused when opened, and a read past its end fails, naming the file.

use super::super::tree::Tree;
use super::super::voxels::{face_bit, Voxels, MARKED};
use crate::store::hierarchy::NODE_RECORD;
use crate::store::{IoCounters, ObjectRecord, SceneReader, BBOX_RECORD, HEADER_FILE};
use glam::Vec3;
use std::fs::File;
use std::io;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};

pub const FILE_NAME: &str = "hrgrid.bin";
const MAGIC: &[u8; 8] = b"RTBHRG01";
pub const HEADER: u64 = 64;

/// What one build counted.
#[derive(Clone, Copy, Debug, Default)]
pub struct BuildStats {
    pub subspaces: u64,
    pub side: u32,
    /// Object boxes read over all subspace passes, and boxes (of any level) whose subtree was
    /// passed because its voxels miss the subspace.
    pub boxes_read: u64,
    pub nodes_culled: u64,
    pub objects_culled: u64,
    pub marked: u64,
    pub io: IoCounters,
    /// `hrgrid=resume`: subspaces an earlier, interrupted invocation had finished (all of them
    /// when it had finished the grid), and the build seconds it had spent on them.
    pub resumed: u64,
    pub prior_s: f64,
    /// The grid's subspaces, and whether the build stopped short of them (`hrgrid_subspaces`).
    pub total: u64,
    pub partial: bool,
}

/// `hrgrid=resume`'s record, `hrgrid.progress.json` beside the grid: written after each
/// subspace is on disk, so that a build of hours (rings368's 27 subspaces each read the
/// 35 GB store: ~4 h) goes on where a killed invocation stopped, and kept when the grid is
/// whole, so that an invocation killed in its passes does not make the grid again. It binds
/// to one grid: the header's checksum (resolution, bounds, floor group, store), the subspace
/// side and whether the hierarchy culled.
#[derive(serde::Serialize, serde::Deserialize, Clone, Copy, Debug, PartialEq)]
struct Progress {
    header_crc: u32,
    side: u32,
    hierarchy: bool,
    total: u64,
    done: u64,
    seconds: f64,
    boxes_read: u64,
    nodes_culled: u64,
    objects_culled: u64,
    marked: u64,
    bytes_written: u64,
    write_calls: u64,
}

pub const PROGRESS_FILE: &str = "hrgrid.progress.json";

impl Progress {
    fn read(path: &Path) -> Option<Progress> {
        serde_json::from_slice(&std::fs::read(path).ok()?).ok()
    }

    /// Written whole or not at all, after the grid's bytes are synced.
    fn write(&self, path: &Path) -> io::Result<()> {
        crate::store::write_atomic(path, &serde_json::to_vec(self).map_err(io::Error::other)?)
    }

    fn restore(&self, st: &mut BuildStats) {
        st.subspaces = self.done;
        st.boxes_read = self.boxes_read;
        st.nodes_culled = self.nodes_culled;
        st.objects_culled = self.objects_culled;
        st.marked = self.marked;
        st.io.bytes_written = self.bytes_written;
        st.io.write_calls = self.write_calls;
        st.resumed = self.done;
        st.prior_s = self.seconds;
    }
}

pub struct DiskGrid {
    file: File,
    pub path: PathBuf,
    pub res: [u32; 3],
    pub io: IoCounters,
    /// End of the last read (a read elsewhere is a seek).
    last_end: u64,
}

fn header_bytes(res: [u32; 3], bounds: [Vec3; 2], floor: u64, store_crc: u32) -> [u8; 64] {
    let mut b = [0u8; 64];
    b[..8].copy_from_slice(MAGIC);
    for i in 0..3 {
        b[8 + 4 * i..12 + 4 * i].copy_from_slice(&res[i].to_le_bytes());
        b[20 + 4 * i..24 + 4 * i].copy_from_slice(&bounds[0][i].to_le_bytes());
        b[32 + 4 * i..36 + 4 * i].copy_from_slice(&bounds[1][i].to_le_bytes());
    }
    b[44..52].copy_from_slice(&floor.to_le_bytes());
    b[52..56].copy_from_slice(&store_crc.to_le_bytes());
    let crc = crc32fast::hash(&b[..56]);
    b[56..60].copy_from_slice(&crc.to_le_bytes());
    b
}

fn invalid(path: &Path, what: impl std::fmt::Display) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{}: {what}", path.display()),
    )
}

/// Bytes of the flags of a grid of `res`.
pub fn flag_bytes(res: [u32; 3]) -> u64 {
    res.iter().map(|&r| r as u64).product()
}

/// The box sweep of one subspace pass: calls `visit(lo, hi)` for every object box not of the
/// floor group (`floor`: sorted ids) whose voxels may reach the subspace `[s0, s1]`, passing a
/// hierarchy node's subtree when its voxels miss it.
#[allow(clippy::too_many_arguments)]
fn sweep_boxes(
    scene: &mut SceneReader,
    tree: Option<&mut Tree>,
    rec: &mut ObjectRecord,
    floor: &[u32],
    g: &Voxels,
    s0: [u32; 3],
    s1: [u32; 3],
    st: &mut BuildStats,
    visit: &mut dyn FnMut(Vec3, Vec3),
) -> io::Result<()> {
    let reaches = |lo: Vec3, hi: Vec3| {
        let (a, z) = g.range(lo, hi);
        (0..3).all(|i| a[i] <= s1[i] && z[i] >= s0[i])
    };
    scene.rewind()?;
    let Some(tree) = tree else {
        while let Some((id, b, _)) = scene.next(rec)? {
            st.boxes_read += 1;
            if floor.binary_search(&id).is_err() && b.lo.is_finite() && b.hi.is_finite() {
                visit(b.lo, b.hi);
            }
        }
        return Ok(());
    };
    #[allow(clippy::too_many_arguments)]
    fn descend(
        scene: &mut SceneReader,
        tree: &mut Tree,
        rec: &mut ObjectRecord,
        k: usize,
        (a, z): (u64, u64),
        floor: &[u32],
        reaches: &dyn Fn(Vec3, Vec3) -> bool,
        st: &mut BuildStats,
        visit: &mut dyn FnMut(Vec3, Vec3),
    ) -> io::Result<()> {
        if k == 0 {
            scene.skip_to(a as u32, rec)?;
            for _ in a..z {
                let Some((id, b, _)) = scene.next(rec)? else {
                    break;
                };
                st.boxes_read += 1;
                if floor.binary_search(&id).is_err() && b.lo.is_finite() && b.hi.is_finite() {
                    visit(b.lo, b.hi);
                }
            }
            return Ok(());
        }
        let below = if k == 1 { BBOX_RECORD } else { NODE_RECORD };
        tree.levels[k - 1].seek_record(a)?;
        for _ in a..z {
            let Some(n) = tree.levels[k - 1].next_record()? else {
                break;
            };
            let empty = !(n.lo.is_finite() && n.hi.is_finite()) || n.lo.cmpgt(n.hi).any();
            if empty || !reaches(n.lo, n.hi) {
                st.nodes_culled += 1;
                st.objects_culled += n.objects as u64;
                continue;
            }
            let range = n.child_range(below);
            descend(scene, tree, rec, k - 1, range, floor, reaches, st, visit)?;
        }
        Ok(())
    }
    let top = tree.levels.len();
    let n = tree.info.levels[top - 1];
    descend(scene, tree, rec, top, (0, n), floor, &reaches, st, visit)
}

/// Marks, in the subspace buffer `buf` (`[s0, s1]`, z fastest), the voxels and faces of one
/// box's box of voxels: the basic method's marking (Algorithm 3.4), clipped to the subspace.
fn mark(buf: &mut [u8], g: &Voxels, s0: [u32; 3], s1: [u32; 3], lo: Vec3, hi: Vec3) {
    let (a, z) = g.range(lo, hi);
    if (0..3).any(|i| a[i] > s1[i] || z[i] < s0[i]) {
        return;
    }
    let n = [0, 1, 2].map(|i| (s1[i] - s0[i] + 1) as usize);
    for cx in a[0].max(s0[0])..=z[0].min(s1[0]) {
        for cy in a[1].max(s0[1])..=z[1].min(s1[1]) {
            let row = ((cx - s0[0]) as usize * n[1] + (cy - s0[1]) as usize) * n[2];
            for cz in a[2].max(s0[2])..=z[2].min(s1[2]) {
                let mut f = MARKED;
                for (axis, c) in [(0, cx), (1, cy), (2, cz)] {
                    if c == a[axis] {
                        f |= face_bit(axis, false);
                    }
                    if c == z[axis] {
                        f |= face_bit(axis, true);
                    }
                }
                buf[row + (cz - s0[2]) as usize] |= f;
            }
        }
    }
}

/// The CRC-32 of the store's `header.json`, which a grid file is tied to.
fn store_crc(dir: &Path) -> io::Result<u32> {
    Ok(crc32fast::hash(&std::fs::read(dir.join(HEADER_FILE))?))
}

impl DiskGrid {
    /// Builds the grid of `g` (its lattice and pad; flags not held) in `dir`, subspace by
    /// subspace of `side`³ voxels. On any failure the temporary file is removed. With `resume`
    /// (`hrgrid=resume`) the build keeps [`Progress`] and takes up an interrupted or finished
    /// build of the same grid: the subspaces already on disk are not swept again, and their
    /// counts and seconds come from the record (`resumed`, `prior_s`).
    #[allow(clippy::too_many_arguments)]
    pub fn build(
        dir: &Path,
        g: &Voxels,
        side: u32,
        scene: &mut SceneReader,
        mut tree: Option<&mut Tree>,
        floor: &[u32],
        resume: bool,
        limit: Option<u64>,
    ) -> io::Result<BuildStats> {
        let res = g.lattice.res;
        let path = dir.join(FILE_NAME);
        let tmp = dir.join(format!("{FILE_NAME}.tmp"));
        let progress = dir.join(PROGRESS_FILE);
        let mut st = BuildStats {
            side,
            ..Default::default()
        };
        let head = header_bytes(
            res,
            [g.lattice.lo, g.lattice.hi],
            floor.len() as u64,
            store_crc(dir)?,
        );
        let count = res.map(|r| r.div_ceil(side));
        let total = count.iter().map(|&c| c as u64).product::<u64>();
        st.total = total;
        let mut record = Progress {
            header_crc: u32::from_le_bytes([head[56], head[57], head[58], head[59]]),
            side,
            hierarchy: tree.is_some(),
            total,
            done: 0,
            seconds: 0.0,
            boxes_read: 0,
            nodes_culled: 0,
            objects_culled: 0,
            marked: 0,
            bytes_written: 0,
            write_calls: 0,
        };
        let earlier = Progress::read(&progress).filter(|p| {
            resume
                && (p.header_crc, p.side, p.hierarchy, p.total)
                    == (record.header_crc, side, record.hierarchy, total)
        });
        match earlier {
            Some(p) if p.done == total && path.exists() => {
                p.restore(&mut st);
                return Ok(st);
            }
            Some(p) if p.done < total && tmp.exists() => p.restore(&mut st),
            _ => {
                let _ = std::fs::remove_file(&progress);
            }
        }
        let t0 = std::time::Instant::now();
        let r = (|| -> io::Result<()> {
            let f = if st.resumed > 0 {
                std::fs::OpenOptions::new().write(true).open(&tmp)?
            } else {
                let f = File::create(&tmp)?;
                f.write_all_at(&head, 0)?;
                st.io.write_calls += 1;
                st.io.bytes_written += HEADER;
                f
            };
            let mut rec = ObjectRecord::default();
            let mut buf = Vec::new();
            let mut index = 0u64;
            'all: for bx in 0..count[0] {
                for by in 0..count[1] {
                    for bz in 0..count[2] {
                        index += 1;
                        if index <= st.resumed {
                            continue;
                        }
                        if limit.is_some_and(|k| st.subspaces >= k) {
                            st.partial = true;
                            break 'all;
                        }
                        let s0 = [bx, by, bz].map(|b| b * side);
                        let s1 = [0, 1, 2].map(|i| ((s0[i] + side).min(res[i])) - 1);
                        let n = [0, 1, 2].map(|i| (s1[i] - s0[i] + 1) as usize);
                        buf.clear();
                        buf.resize(n[0] * n[1] * n[2], 0u8);
                        sweep_boxes(
                            scene,
                            tree.as_deref_mut(),
                            &mut rec,
                            floor,
                            g,
                            s0,
                            s1,
                            &mut st,
                            &mut |lo, hi| mark(&mut buf, g, s0, s1, lo, hi),
                        )?;
                        st.subspaces += 1;
                        st.marked += buf.iter().filter(|&&f| f & MARKED != 0).count() as u64;
                        // One write per (x, y) row of the subspace: rows are z-contiguous.
                        for x in 0..n[0] {
                            for y in 0..n[1] {
                                let at = HEADER
                                    + ((s0[0] as u64 + x as u64) * res[1] as u64
                                        + s0[1] as u64
                                        + y as u64)
                                        * res[2] as u64
                                    + s0[2] as u64;
                                let row = (x * n[1] + y) * n[2];
                                f.write_all_at(&buf[row..row + n[2]], at)?;
                                st.io.write_calls += 1;
                                st.io.bytes_written += n[2] as u64;
                            }
                        }
                        if resume {
                            // The record never runs ahead of the bytes on disk.
                            f.sync_data()?;
                            record = Progress {
                                done: index,
                                seconds: st.prior_s + t0.elapsed().as_secs_f64(),
                                boxes_read: st.boxes_read,
                                nodes_culled: st.nodes_culled,
                                objects_culled: st.objects_culled,
                                marked: st.marked,
                                bytes_written: st.io.bytes_written,
                                write_calls: st.io.write_calls,
                                ..record
                            };
                            if index < total {
                                record.write(&progress)?;
                            }
                        }
                    }
                }
            }
            // The whole grid's length (a partial build leaves the rest of its flags empty).
            f.set_len(HEADER + flag_bytes(res))?;
            f.sync_all()?;
            std::fs::rename(&tmp, &path)?;
            if resume {
                // Written after the rename: a record of `total` always has its whole grid.
                record.write(&progress)?;
            }
            Ok(())
        })();
        if let Err(e) = r {
            let _ = std::fs::remove_file(&tmp);
            let _ = std::fs::remove_file(&progress);
            return Err(io::Error::new(
                e.kind(),
                format!("{}: building the on-disk grid: {e}", tmp.display()),
            ));
        }
        Ok(st)
    }

    /// Opens `dir/hrgrid.bin`, which must be the grid of `g` for this store and floor group,
    /// whole.
    pub fn open(dir: &Path, g: &Voxels, floor: u64) -> io::Result<DiskGrid> {
        let path = dir.join(FILE_NAME);
        let file = File::open(&path).map_err(|e| invalid(&path, e))?;
        let res = g.lattice.res;
        let len = file.metadata()?.len();
        let mut head = [0u8; 64];
        if len < HEADER {
            return Err(invalid(&path, format!("{len} bytes: truncated header")));
        }
        file.read_exact_at(&mut head, 0)?;
        let want = header_bytes(res, [g.lattice.lo, g.lattice.hi], floor, store_crc(dir)?);
        if head[..8] != *MAGIC {
            return Err(invalid(&path, "not an rtbench on-disk grid"));
        }
        if head[56..60] != want[56..60] {
            return Err(invalid(
                &path,
                "made for another store, resolution or floor group (hrgrid=build remakes it)",
            ));
        }
        let expect = HEADER + flag_bytes(res);
        if len != expect {
            return Err(invalid(
                &path,
                format!("{len} bytes, its header says {expect}: truncated or grown"),
            ));
        }
        Ok(DiskGrid {
            file,
            path,
            res,
            io: IoCounters::default(),
            last_end: 0,
        })
    }

    /// Bytes of one x-slice (all y and z).
    pub fn slice_bytes(&self) -> u64 {
        self.res[1] as u64 * self.res[2] as u64
    }

    /// Reads x-slices `x0..x1` into `out` (one sequential read).
    pub fn read_slab(&mut self, x0: u32, x1: u32, out: &mut Vec<u8>) -> io::Result<()> {
        let at = HEADER + x0 as u64 * self.slice_bytes();
        let n = (x1 - x0) as u64 * self.slice_bytes();
        out.clear();
        out.resize(n as usize, 0);
        self.file.read_exact_at(out, at).map_err(|e| {
            if e.kind() == io::ErrorKind::UnexpectedEof {
                invalid(&self.path, "truncated while tracing")
            } else {
                invalid(&self.path, e)
            }
        })?;
        if at != self.last_end {
            self.io.seeks += 1;
        }
        self.last_end = at + n;
        self.io.read_calls += 1;
        self.io.bytes_read += n;
        Ok(())
    }

    pub fn drop_cache(&self) {
        use std::os::fd::AsRawFd;
        // SAFETY: a plain system call on a descriptor this value owns.
        unsafe {
            libc::posix_fadvise(self.file.as_raw_fd(), 0, 0, libc::POSIX_FADV_DONTNEED);
        }
    }
}
