//! The bounding-box hierarchy of a split store (seed 000 §4.2.2, "B"; Fig. 4.1b), built by
//! streaming: each level is made in one sequential pass over the level below by merging
//! neighbours in stream order, never holding a level in memory.
//!
//! Merging one level (M boxes below): T = (s / M^(1/3))²; the next box joins the current group
//! while the area of their union over the area of the scene's box stays ≤ T, otherwise it starts a
//! new group. Levels are made one above another; when the level below has M ≤ m boxes or the
//! level about to be made is the l-th, it is made with t in place of T and is the top. The top
//! level's boxes are the groups of the scene (§4.2.2: "the top-level boxes define the groups").
//! Defaults are the thesis's experiments' (§4.4): s = 3, m = 1,000, l = 4, t = 0.5 for balls,
//! gears and tree (two top boxes), 1.0 otherwise (one).
//!
//! Files, beside `bbox.bin` (level 0, the objects):
//! - `bbox-K.bin` for level K = 1 … L: 16-byte header (magic `RTHIER\0\0`, u32 version, u32
//!   level), then one [`NODE_RECORD`]-byte record per node, in stream order: its box (6 × f32,
//!   the union of its children's), the **end offset of its children** in the file of level K − 1
//!   (u64: one forward seek there skips the whole subtree), the number of its children (u32),
//!   the objects below it (u32), and a CRC-32 (u32) of (level u32, index u64, the record's first
//!   40 bytes).
//! - `hierarchy.json`: the constants, the record count of each level, and the CRC-32 of
//!   `header.json` it was built for. Written last (renamed into place): a store has a hierarchy
//!   when, and only when, this file is present and names its header.
//!
//! Reading checks the records' checksums, that the children of a node are the records right after
//! those of the node before it, and that each box read holds its children's (a hierarchy that
//! disagrees with its level below is refused, never trusted: it would skip objects silently).

use super::io::{IoCounters, IoFile};
use super::read::{BboxReader, StoreHeader};
use super::{Layout, BBOX_RECORD, FILE_HEADER, HEADER_FILE, VERSION};
use glam::Vec3;
use serde_json::json;
use std::io;
use std::path::{Path, PathBuf};

pub const HIERARCHY_FILE: &str = "hierarchy.json";
pub const HIERARCHY_MAGIC: &[u8; 8] = b"RTHIER\0\0";
/// Bytes of a node record: 6 × f32, u64, u32, u32, u32 checksum.
pub const NODE_RECORD: usize = 44;
/// At most this many levels above the objects (the thesis's l = 4 makes at most 4).
pub const MAX_LEVELS: u32 = 16;

/// The file of level `k` (1-based; level 0 is `bbox.bin`).
pub fn level_file(k: u32) -> String {
    format!("bbox-{k}.bin")
}

/// The hierarchy's constants (§4.2.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constants {
    /// T = (s / M^(1/3))²: at the lowest level a box about s voxels on a side.
    pub s: f64,
    /// The top is made once the level below has at most m boxes …
    pub m: u64,
    /// … or the level about to be made is the l-th.
    pub l: u32,
    /// The top level's area-ratio threshold.
    pub t: f64,
}

impl Constants {
    /// The thesis's constants for a scene named `name` (§4.4): t = 0.5 for balls, gears and tree.
    pub fn thesis(name: &str) -> Constants {
        let two_tops = ["balls", "gears", "tree"].iter().any(|p| {
            name.strip_prefix(p)
                .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()))
        });
        Constants {
            s: 3.0,
            m: 1000,
            l: 4,
            t: if two_tops { 0.5 } else { 1.0 },
        }
    }
}

/// One node of a level file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeRecord {
    pub lo: Vec3,
    pub hi: Vec3,
    /// Byte offset, in the file of the level below, just past this node's last child.
    pub end: u64,
    pub children: u32,
    pub objects: u32,
}

impl NodeRecord {
    /// Index (in the level below) of the first child and one past the last.
    pub fn child_range(&self, below_record: usize) -> (u64, u64) {
        let end = (self.end.saturating_sub(FILE_HEADER)) / below_record as u64;
        (end.saturating_sub(self.children as u64), end)
    }

    /// The box holds `lo..hi` (an empty box, lo > hi, is held by any).
    pub fn holds(&self, lo: Vec3, hi: Vec3) -> bool {
        lo.cmpgt(hi).any() || (lo.cmpge(self.lo).all() && hi.cmple(self.hi).all())
    }
}

fn bad(path: &Path, what: impl std::fmt::Display) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{}: {what}", path.display()),
    )
}

fn checksum(level: u32, index: u64, rec: &[u8]) -> u32 {
    let mut h = crc32fast::Hasher::new();
    h.update(&level.to_le_bytes());
    h.update(&index.to_le_bytes());
    h.update(rec);
    h.finalize()
}

pub(crate) fn encode(level: u32, index: u64, n: &NodeRecord) -> [u8; NODE_RECORD] {
    let mut b = [0u8; NODE_RECORD];
    for (i, x) in
        n.lo.to_array()
            .into_iter()
            .chain(n.hi.to_array())
            .enumerate()
    {
        b[i * 4..i * 4 + 4].copy_from_slice(&x.to_le_bytes());
    }
    b[24..32].copy_from_slice(&n.end.to_le_bytes());
    b[32..36].copy_from_slice(&n.children.to_le_bytes());
    b[36..40].copy_from_slice(&n.objects.to_le_bytes());
    let crc = checksum(level, index, &b[..40]);
    b[40..].copy_from_slice(&crc.to_le_bytes());
    b
}

fn decode(level: u32, index: u64, b: &[u8; NODE_RECORD], path: &Path) -> io::Result<NodeRecord> {
    if checksum(level, index, &b[..40]) != u32::from_le_bytes(b[40..].try_into().unwrap()) {
        return Err(bad(path, format!("record {index}: checksum mismatch")));
    }
    let f = |i: usize| f32::from_le_bytes(b[i * 4..i * 4 + 4].try_into().unwrap());
    let u = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap());
    Ok(NodeRecord {
        lo: Vec3::new(f(0), f(1), f(2)),
        hi: Vec3::new(f(3), f(4), f(5)),
        end: u64::from_le_bytes(b[24..32].try_into().unwrap()),
        children: u(32),
        objects: u(36),
    })
}

/// `hierarchy.json`, parsed and checked against the store and the level files' sizes.
#[derive(Clone, Debug, PartialEq)]
pub struct Hierarchy {
    pub dir: PathBuf,
    pub constants: Constants,
    /// Records of level 1 … L (the last is the top).
    pub levels: Vec<u64>,
    pub objects: u64,
}

/// The CRC-32 of a store's `header.json` (what a hierarchy is tied to).
fn header_crc(dir: &Path) -> io::Result<u32> {
    let text = std::fs::read(dir.join(HEADER_FILE))?;
    Ok(crc32fast::hash(&text))
}

/// Area of a box's surface (0 for an empty box).
fn area(lo: Vec3, hi: Vec3) -> f64 {
    let e = (hi - lo).as_dvec3();
    if e.min_element() < 0.0 {
        return 0.0;
    }
    2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
}

/// What building took.
#[derive(Clone, Debug, Default)]
pub struct BuildStats {
    pub levels: Vec<u64>,
    pub io: IoCounters,
    pub seconds: f64,
}

impl Hierarchy {
    /// The hierarchy of the store `h`, when it has one built with `constants`; `None` when it has
    /// none (or one of other constants). A hierarchy file that is there and wrong is an error.
    pub fn open(h: &StoreHeader, constants: Option<Constants>) -> io::Result<Option<Hierarchy>> {
        let path = h.dir.join(HIERARCHY_FILE);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(io::Error::new(e.kind(), format!("{}: {e}", path.display()))),
        };
        let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad(&path, e))?;
        if v["format"] != "rtbench-hierarchy" || v["version"].as_u64() != Some(VERSION as u64) {
            return Err(bad(
                &path,
                "not a hierarchy of this rtbench (format, version)",
            ));
        }
        let num = |k: &str| {
            v[k].as_f64()
                .ok_or_else(|| bad(&path, format!("'{k}' is not a number")))
        };
        let c = Constants {
            s: num("s")?,
            m: v["m"].as_u64().ok_or_else(|| bad(&path, "'m'"))?,
            l: v["l"]
                .as_u64()
                .and_then(|l| u32::try_from(l).ok())
                .ok_or_else(|| bad(&path, "'l'"))?,
            t: num("t")?,
        };
        if v["store_crc"].as_u64() != Some(header_crc(&h.dir)? as u64) {
            return Err(bad(
                &path,
                "built for another header.json (checksum): rebuild it",
            ));
        }
        let levels: Vec<u64> = v["levels"]
            .as_array()
            .ok_or_else(|| bad(&path, "'levels'"))?
            .iter()
            .map(|x| x.as_u64().ok_or_else(|| bad(&path, "'levels'")))
            .collect::<io::Result<_>>()?;
        if levels.is_empty() || levels.len() > MAX_LEVELS as usize {
            return Err(bad(
                &path,
                format!("{} levels (1 … {MAX_LEVELS})", levels.len()),
            ));
        }
        for (i, &n) in levels.iter().enumerate() {
            let k = i as u32 + 1;
            let f = h.dir.join(level_file(k));
            let size = std::fs::metadata(&f)
                .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", f.display())))?
                .len();
            let want = FILE_HEADER + n * NODE_RECORD as u64;
            if size != want {
                return Err(bad(
                    &f,
                    format!("{size} bytes, hierarchy.json says {n} records ({want} bytes)"),
                ));
            }
        }
        if constants.is_some_and(|want| want != c) {
            return Ok(None);
        }
        Ok(Some(Hierarchy {
            dir: h.dir.clone(),
            constants: c,
            levels,
            objects: h.objects,
        }))
    }

    /// Number of levels above the objects.
    pub fn height(&self) -> u32 {
        self.levels.len() as u32
    }

    /// Builds the hierarchy of the split store `h` (replacing any), level by level, each in one
    /// sequential pass over the level below. Each file is written under a temporary name and
    /// renamed; `hierarchy.json` last. On any error (a full disk) what was written is removed.
    pub fn build(h: &StoreHeader, c: Constants, buffer: usize) -> io::Result<BuildStats> {
        if h.layout != Layout::Split {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "{}: a bounding-box hierarchy needs a split store",
                    h.dir.display()
                ),
            ));
        }
        if !(c.s > 0.0
            && c.s.is_finite()
            && c.t > 0.0
            && c.t.is_finite()
            && c.l >= 1
            && c.l <= MAX_LEVELS)
        {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "hierarchy constants s={} t={} l={}: s, t > 0, 1 ≤ l ≤ {MAX_LEVELS}",
                    c.s, c.t, c.l
                ),
            ));
        }
        let t0 = std::time::Instant::now();
        // No stale hierarchy is believed while this one is made.
        match std::fs::remove_file(h.dir.join(HIERARCHY_FILE)) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => return Err(e),
            _ => {}
        }
        let mut stats = BuildStats::default();
        let mut made: Vec<PathBuf> = Vec::new();
        let r = Self::build_levels(h, c, buffer, &mut stats, &mut made);
        if let Err(e) = r {
            for f in &made {
                let _ = std::fs::remove_file(f);
            }
            return Err(e);
        }
        stats.seconds = t0.elapsed().as_secs_f64();
        Ok(stats)
    }

    fn build_levels(
        h: &StoreHeader,
        c: Constants,
        buffer: usize,
        stats: &mut BuildStats,
        made: &mut Vec<PathBuf>,
    ) -> io::Result<()> {
        let a_all = area(h.bounds[0], h.bounds[1]).max(f64::MIN_POSITIVE);
        let tmp = |name: &str| h.dir.join(format!(".{name}.tmp-{}", std::process::id()));
        let mut below = h.objects;
        let mut k = 1u32;
        loop {
            let top = below <= c.m || k >= c.l;
            let threshold = if top {
                c.t
            } else {
                (c.s / (below as f64).cbrt()).powi(2)
            };
            let name = level_file(k);
            let tmp_path = tmp(&name);
            made.push(tmp_path.clone());
            let mut out = IoFile::create(&tmp_path, buffer)?;
            let mut header = [0u8; FILE_HEADER as usize];
            header[..8].copy_from_slice(HIERARCHY_MAGIC);
            header[8..12].copy_from_slice(&VERSION.to_le_bytes());
            header[12..].copy_from_slice(&k.to_le_bytes());
            out.write_all(&header)?;
            let mut n = 0u64;
            let mut cur: Option<NodeRecord> = None;
            let below_record = if k == 1 { BBOX_RECORD } else { NODE_RECORD } as u64;
            let mut emit = |node: NodeRecord, out: &mut IoFile| -> io::Result<()> {
                out.write_all(&encode(k, n, &node))?;
                n += 1;
                Ok(())
            };
            let mut index = 0u64;
            let mut take = |lo: Vec3, hi: Vec3, objects: u32, out: &mut IoFile| -> io::Result<()> {
                index += 1;
                let end = FILE_HEADER + index * below_record;
                if let Some(g) = cur.as_mut() {
                    let (ml, mh) = (g.lo.min(lo), g.hi.max(hi));
                    if area(ml, mh) / a_all <= threshold {
                        g.lo = ml;
                        g.hi = mh;
                        g.end = end;
                        g.children += 1;
                        g.objects += objects;
                        return Ok(());
                    }
                    emit(*g, out)?;
                }
                cur = Some(NodeRecord {
                    lo,
                    hi,
                    end,
                    children: 1,
                    objects,
                });
                Ok(())
            };
            if k == 1 {
                let mut r = BboxReader::open(&h.dir, h.objects, buffer)?;
                while let Some((_, b)) = r.next_record()? {
                    take(b.lo, b.hi, 1, &mut out)?;
                }
                stats.io.add(&r.file.io);
            } else {
                let mut r = LevelReader::open(&h.dir, k - 1, below, buffer)?;
                while let Some(node) = r.next_record()? {
                    take(node.lo, node.hi, node.objects, &mut out)?;
                }
                stats.io.add(&r.file.io);
            }
            if let Some(g) = cur {
                emit(g, &mut out)?;
            }
            stats.io.add(&out.finish()?);
            std::fs::rename(&tmp_path, h.dir.join(&name))?;
            made.pop();
            made.push(h.dir.join(&name));
            stats.levels.push(n);
            if top || n == 0 {
                break;
            }
            below = n;
            k += 1;
        }
        let text = serde_json::to_string_pretty(&json!({
            "format": "rtbench-hierarchy",
            "version": VERSION,
            "s": c.s, "m": c.m, "l": c.l, "t": c.t,
            "levels": stats.levels,
            "objects": h.objects,
            "store_crc": header_crc(&h.dir)?,
        }))
        .map_err(io::Error::other)?;
        super::write_atomic(&h.dir.join(HIERARCHY_FILE), text.as_bytes())?;
        stats.io.bytes_written += text.len() as u64;
        stats.io.write_calls += 1;
        Ok(())
    }

    /// Reads the whole hierarchy and the bounding-box file once, checking every record: each
    /// level tiles the level below in order, each box holds its children's and the object counts
    /// add up. Returns the bytes read.
    pub fn verify(&self, buffer: usize) -> io::Result<u64> {
        let mut bytes = 0;
        for k in 1..=self.height() {
            let below_n = if k == 1 {
                self.objects
            } else {
                self.levels[k as usize - 2]
            };
            let mut up = LevelReader::open(&self.dir, k, self.levels[k as usize - 1], buffer)?;
            let path = self.dir.join(level_file(k));
            let mut next_child = 0u64;
            let (mut bbox, mut lower) = if k == 1 {
                (
                    Some(BboxReader::open(&self.dir, self.objects, buffer)?),
                    None,
                )
            } else {
                (
                    None,
                    Some(LevelReader::open(&self.dir, k - 1, below_n, buffer)?),
                )
            };
            let below_record = if k == 1 { BBOX_RECORD } else { NODE_RECORD };
            while let Some(node) = up.next_record()? {
                let i = up.next - 1;
                let (a, z) = node.child_range(below_record);
                if a != next_child || z > below_n || node.children == 0 {
                    return Err(disagree(
                        &path,
                        i,
                        "its children do not follow the node before it's",
                    ));
                }
                let mut objects = 0u64;
                for _ in a..z {
                    let (lo, hi, o) = match (&mut bbox, &mut lower) {
                        (Some(b), _) => {
                            let (_, r) = b
                                .next_record()?
                                .ok_or_else(|| disagree(&path, i, "children past the end"))?;
                            (r.lo, r.hi, 1)
                        }
                        (_, Some(l)) => {
                            let r = l
                                .next_record()?
                                .ok_or_else(|| disagree(&path, i, "children past the end"))?;
                            (r.lo, r.hi, r.objects as u64)
                        }
                        _ => unreachable!(),
                    };
                    if !node.holds(lo, hi) {
                        return Err(disagree(&path, i, "its box does not hold a child's"));
                    }
                    objects += o;
                }
                if objects != node.objects as u64 {
                    return Err(disagree(&path, i, "its object count is not its children's"));
                }
                next_child = z;
            }
            if next_child != below_n {
                return Err(disagree(
                    &path,
                    up.next,
                    format!("the level covers {next_child} of {below_n} records below"),
                ));
            }
            bytes += up.file.io.bytes_read;
            bytes += bbox.map_or(0, |b| b.file.io.bytes_read)
                + lower.map_or(0, |l| l.file.io.bytes_read);
        }
        Ok(bytes)
    }
}

/// The error of a hierarchy record that disagrees with its level below.
pub fn disagree(path: &Path, index: u64, what: impl std::fmt::Display) -> io::Error {
    bad(
        path,
        format!("record {index} disagrees with the level below ({what}): rebuild the hierarchy"),
    )
}

/// A level file read forward, with forward seeks to a node's first child.
pub struct LevelReader {
    pub file: IoFile,
    pub path: PathBuf,
    pub level: u32,
    /// Index of the next record.
    pub next: u64,
    pub count: u64,
}

impl LevelReader {
    pub fn open(dir: &Path, level: u32, count: u64, buffer: usize) -> io::Result<LevelReader> {
        let path = dir.join(level_file(level));
        let mut file = IoFile::open(&path, buffer)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
        let mut h = [0u8; FILE_HEADER as usize];
        file.read_exact(&mut h)
            .map_err(|_| bad(&path, "shorter than its header"))?;
        if &h[..8] != HIERARCHY_MAGIC
            || u32::from_le_bytes(h[8..12].try_into().unwrap()) != VERSION
            || u32::from_le_bytes(h[12..].try_into().unwrap()) != level
        {
            return Err(bad(
                &path,
                format!("not level {level} of a hierarchy (magic, version, level)"),
            ));
        }
        Ok(LevelReader {
            file,
            path,
            level,
            next: 0,
            count,
        })
    }

    /// Moves forward to record `index` (one seek at most).
    pub fn seek_record(&mut self, index: u64) -> io::Result<()> {
        if index > self.count {
            return Err(bad(
                &self.path,
                format!("record {index} past the last ({})", self.count),
            ));
        }
        self.file
            .seek_to(FILE_HEADER + index * NODE_RECORD as u64)?;
        self.next = index;
        Ok(())
    }

    pub fn next_record(&mut self) -> io::Result<Option<NodeRecord>> {
        if self.next == self.count {
            return Ok(None);
        }
        let mut b = [0u8; NODE_RECORD];
        self.file.read_exact(&mut b).map_err(|e| {
            if e.kind() == io::ErrorKind::UnexpectedEof {
                bad(&self.path, "truncated")
            } else {
                e
            }
        })?;
        let r = decode(self.level, self.next, &b, &self.path)?;
        self.next += 1;
        Ok(Some(r))
    }
}
