//! Settings of the `breadth-first` engine, parsed from `key=value` strings.

pub use super::bytes::Bytes;
use crate::engine::{EngineError, Settings};
use crate::geometry::TriangleTest;
use std::path::PathBuf;
use std::str::FromStr;

/// How many candidate voxels each ray is registered in per pass (seed 000 §3.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Registration {
    /// The same count every pass (`fixed:N`; Table 3.1 used 1, so that the engine makes the
    /// intersection tests Rayshade makes).
    Fixed(u32),
    /// ⌈r/10 + 0.5⌉ every pass, r the grid's resolution per axis (`thesis`; the Ch.3 scaling runs).
    Thesis,
    /// ⌈r/10 + 0.5⌉ to start, then inversely proportional to the rays in memory, so the memory
    /// freed by finished rays goes to those still running (`inverse`; §3.2, dynamic count).
    Inverse,
    /// As `inverse`, starting from N (`inverse:N`; Fig. 3.2b started at 1 for r = 20, 2 for 40).
    InverseFrom(u32),
}

impl FromStr for Registration {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "thesis" => Ok(Registration::Thesis),
            "inverse" => Ok(Registration::Inverse),
            _ => {
                let bad = || "expected fixed:N or inverse:N (N ≥ 1), thesis or inverse".to_string();
                if let Some(n) = s.strip_prefix("inverse:") {
                    return match n.parse::<u32>() {
                        Ok(n) if n >= 1 => Ok(Registration::InverseFrom(n)),
                        _ => Err(bad()),
                    };
                }
                match s.strip_prefix("fixed:").map(str::parse::<u32>) {
                    Some(Ok(n)) if n >= 1 => Ok(Registration::Fixed(n)),
                    _ => Err(bad()),
                }
            }
        }
    }
}

impl Registration {
    /// ⌈r/10 + 0.5⌉ as seed 000 prints it.
    pub fn thesis_count(res: u32) -> u32 {
        (res as f64 / 10.0 + 0.5).ceil() as u32
    }

    /// The count of the first pass, which sizes the registration memory.
    pub fn initial(&self, res: u32) -> u32 {
        match *self {
            Registration::Fixed(n) | Registration::InverseFrom(n) => n,
            Registration::Thesis | Registration::Inverse => Self::thesis_count(res),
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct BreadthFirstConfig {
    /// Everything the engine holds: grid, ray slots, registrations, I/O buffers.
    pub memory: u64,
    /// Where the store of an in-memory scene is written (a fresh subdirectory, removed on drop).
    pub spill: Option<PathBuf>,
    pub registration: Registration,
    /// Bytes of each file buffer (bbox and geometry file).
    pub buffer: u64,
    pub triangle: TriangleTest,
    /// Floor and backdrop polygons in their own group, out of the grid (seed 000 §1.2: "for
    /// balls and tree the base plate was excluded"), or in it.
    pub floor: Floor,
    /// Check every record of a store when it is opened (`verify=full`, the default), not only
    /// those the algorithm reads (`verify=records`).
    pub verify: bool,
    /// The store layout this engine reads (a store of the other layout is refused): `basic`,
    /// one file of (box, object) records read whole (Ch.3), or `split` (Ch.4's "S").
    pub layout: Layout,
    /// Read an object's geometry only when a ray hits its box (Ch.4's "G"; split layout only).
    pub lazy: bool,
    /// Register rays only at voxel-boundary entries (§3.2); off: in every marked voxel.
    pub boundary: bool,
    /// Skip an object when the ray's last voxel of the previous pass lies in its box (§3.3).
    pub prev_skip: bool,
    /// Refill memory with new rays at every pass (§3.3); off: a batch of rays runs until all are
    /// done before the next is read (Algorithm 3.3).
    pub refill: bool,
    /// What sizes the grid: the primitives, or the objects as Rayshade counted them.
    pub count: Count,
    /// Cells per axis, given (`res=N`: N³), in place of ⌊n^(1/3) + 0.5⌋.
    pub res: Option<u32>,
    /// At most this many rays in memory (`rays=N`), below what the budget allows.
    pub max_rays: Option<u64>,
    /// How the out-of-core workload stores its spill files (`spill_codec=none|gzip`).
    pub spill_codec: Codec,
    /// The out-of-core workload traces reflection and refraction rays (`secondary=on`), or
    /// eye and shadow rays only (`off`; seed 000 ran rings80 so, Fig. 3.9).
    pub secondary: bool,
    /// Sweep through the store's bounding-box hierarchy, built at preprocessing when the store
    /// has none of these constants (`hierarchy=on`; Ch.4's "B").
    pub hierarchy: bool,
    /// The hierarchy's constants given (`bh_s`, `bh_m`, `bh_l`, `bh_t`); the rest the thesis's.
    pub bh: BhConstants,
    /// Drop the store's files from the page cache after preprocessing and after every sweep
    /// (`cache=cold`), so that each sweep reads the disk as on the thesis's 256 MB machine.
    pub cold: bool,
    /// The grid rays are registered in (`grid=cuberoot|single|two-level` and its constants;
    /// seed 000 §4.3).
    pub grid: super::hires::config::GridKind,
    /// Stop after this many passes (`max_passes=N`, [`super::cap`]); the run is then marked
    /// incomplete (`bf_pass_cap_reached`) and its image is no answer.
    pub max_passes: Option<u64>,
    /// One line on stderr after every pass (`progress=on`): a 10^9-object run takes hours.
    pub progress: bool,
    /// What one call of an in-memory run holds (`batch=band|generation`).
    pub batch: Batch,
}

/// What one call of the in-memory workload hands the engine ([`crate::Engine::batch_hint`]).
///
/// A whole generation is the thesis's procedure (Algorithm 3.6: every ray of a depth in one
/// breadth-first trace); in core it makes the caller hold the whole generation too (its rays,
/// paths and shadow rays: about 100 MB at 512² on balls4), and the engine as many rays as the
/// generation has. A band of pixel rows, as the in-memory engines get, holds a few thousand
/// rays at once; each call still sweeps the scene once per pass for all of its rays. The out-of-core
/// workload ([`super::BreadthFirst::trace_stream`]) is not split either way: it fills the
/// budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Batch {
    /// The caller's bands of pixel rows, one call per band and query (the default).
    Band,
    /// Whole generations, one call per generation and query (seed 000's procedure in core).
    Generation,
}

/// Hierarchy constants set by the user (`None`: the thesis's for the scene).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BhConstants {
    pub s: Option<f64>,
    pub m: Option<u64>,
    pub l: Option<u32>,
    pub t: Option<f64>,
}

impl BhConstants {
    /// The constants for a store of the scene `name`.
    pub fn resolve(&self, name: &str) -> crate::store::Constants {
        let d = crate::store::Constants::thesis(name);
        crate::store::Constants {
            s: self.s.unwrap_or(d.s),
            m: self.m.unwrap_or(d.m),
            l: self.l.unwrap_or(d.l),
            t: self.t.unwrap_or(d.t),
        }
    }
}

pub use crate::store::Codec;

pub use crate::grid::config::Count;
pub use crate::store::Layout;

fn on_off(s: &mut Settings, key: &'static str) -> Result<bool, EngineError> {
    let v: String = s.get(key, "on".to_string())?;
    match v.as_str() {
        "on" => Ok(true),
        "off" => Ok(false),
        v => Err(bad(key, v, "on or off")),
    }
}

pub use crate::grid::config::Floor;

/// An optional number: absent → `None`; present, it must parse and pass `ok`.
fn opt_num<T: FromStr>(
    s: &mut Settings,
    key: &'static str,
    ok: impl Fn(&T) -> bool,
    what: &str,
) -> Result<Option<T>, EngineError> {
    let v: String = s.get(key, String::new())?;
    if v.is_empty() {
        return Ok(None);
    }
    match v.parse::<T>() {
        Ok(x) if ok(&x) => Ok(Some(x)),
        _ => Err(bad(key, &v, what)),
    }
}
pub const DEFAULT_MEMORY: u64 = 1 << 30;
pub const DEFAULT_BUFFER: u64 = 1 << 16;

/// MemTotal + SwapTotal of `/proc/meminfo`, in bytes (None where it cannot be read): no memory
/// budget above it can be allocated, so none is accepted.
pub fn machine_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let kb = |key: &str| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        line.split_whitespace().nth(1)?.parse().ok()
    };
    Some((kb("MemTotal:")? + kb("SwapTotal:").unwrap_or(0)).saturating_mul(1024))
}

fn bad(key: &str, value: &str, reason: &str) -> EngineError {
    EngineError::BadValue {
        engine: "breadth-first".into(),
        key: key.into(),
        value: value.into(),
        reason: reason.into(),
    }
}

impl BreadthFirstConfig {
    pub fn from_settings(mut s: Settings) -> Result<BreadthFirstConfig, EngineError> {
        let memory = s.get("memory", Bytes(DEFAULT_MEMORY))?.0;
        let spill: String = s.get("spill", String::new())?;
        let registration = s.get("registration", Registration::Inverse)?;
        let buffer = s.get("buffer", Bytes(DEFAULT_BUFFER))?.0;
        let triangle = s.get("triangle", TriangleTest::Watertight)?;
        let floor = s.get("floor", Floor::Out)?;
        let verify: String = s.get("verify", "full".to_string())?;
        let verify = match verify.as_str() {
            "full" => true,
            "records" => false,
            v => return Err(bad("verify", v, "full or records")),
        };
        let layout = s.get("layout", Layout::Split)?;
        let lazy: String = s.get("lazy", String::new())?;
        let lazy = match (lazy.as_str(), layout) {
            ("" | "on", Layout::Split) => true,
            ("off", _) | ("", Layout::Basic) => false,
            ("on", Layout::Basic) => {
                return Err(bad(
                    "lazy",
                    "on",
                    "layout=basic reads every object whole; lazy=on needs layout=split",
                ))
            }
            (v, _) => return Err(bad("lazy", v, "on or off")),
        };
        let boundary = on_off(&mut s, "boundary")?;
        let prev_skip = on_off(&mut s, "prevskip")?;
        let refill = on_off(&mut s, "refill")?;
        let count = s.get("count", Count::Prims)?;
        let res: u32 = s.get("res", 0u32)?;
        if (res as u64).pow(3).saturating_mul(5) > memory {
            return Err(bad(
                "res",
                &res.to_string(),
                "the grid (5 bytes per voxel) would pass the memory budget",
            ));
        }
        let max_rays: u64 = s.get("rays", 0u64)?;
        let max_passes: u64 = s.get("max_passes", 0u64)?;
        let progress = match s.get("progress", "off".to_string())?.as_str() {
            "on" => true,
            "off" => false,
            v => return Err(bad("progress", v, "on or off")),
        };
        let spill_codec: String = s.get("spill_codec", "none".to_string())?;
        let spill_codec = match spill_codec.as_str() {
            "none" => Codec::None,
            // Fast: spill files are written and read once.
            "gzip" => Codec::Gzip(1),
            "zstd" => Codec::Zstd(1),
            v => return Err(bad("spill_codec", v, "none, gzip or zstd")),
        };
        let secondary = on_off(&mut s, "secondary")?;
        let hierarchy: String = s.get("hierarchy", "off".to_string())?;
        let hierarchy =
            match (hierarchy.as_str(), layout) {
                ("off", _) => false,
                ("on", Layout::Split) => true,
                ("on", Layout::Basic) => return Err(bad(
                    "hierarchy",
                    "on",
                    "the bounding-box hierarchy skips records of bbox.bin; it needs layout=split",
                )),
                (v, _) => return Err(bad("hierarchy", v, "on or off")),
            };
        let bh = BhConstants {
            s: opt_num(
                &mut s,
                "bh_s",
                |v: &f64| *v > 0.0 && v.is_finite(),
                "a positive number",
            )?,
            m: opt_num(&mut s, "bh_m", |_: &u64| true, "a count")?,
            l: opt_num(
                &mut s,
                "bh_l",
                |v: &u32| (1..=crate::store::hierarchy::MAX_LEVELS).contains(v),
                "levels, 1 to 16",
            )?,
            t: opt_num(
                &mut s,
                "bh_t",
                |v: &f64| *v > 0.0 && v.is_finite(),
                "a positive number",
            )?,
        };
        let cache: String = s.get("cache", "warm".to_string())?;
        let cold = match cache.as_str() {
            "warm" => false,
            "cold" => true,
            v => return Err(bad("cache", v, "warm or cold")),
        };
        let batch = match s.get("batch", "band".to_string())?.as_str() {
            "band" => Batch::Band,
            "generation" => Batch::Generation,
            v => return Err(bad("batch", v, "band or generation")),
        };
        let grid = super::hires::config::GridKind::from_settings(&mut s)?;
        s.finish()?;
        if let super::hires::config::GridKind::TwoLevel(tl) = &grid {
            if let (Some(k), 0) = (tl.max_subspaces, max_passes) {
                return Err(bad(
                    "hrgrid_subspaces",
                    &k.to_string(),
                    "a partial grid's answers are not the scene's: it needs max_passes (whose runs claim no image)",
                ));
            }
        }
        if buffer < 64 {
            return Err(bad("buffer", &buffer.to_string(), "at least 64 bytes"));
        }
        if let Some(machine) = machine_memory() {
            if memory > machine {
                return Err(bad(
                    "memory",
                    &format!("{memory}B"),
                    &format!("more than this machine's memory and swap ({machine} B)"),
                ));
            }
        }
        if let Some(left) = crate::usage::address_space_left() {
            if memory > left {
                return Err(bad(
                    "memory",
                    &format!("{memory}B"),
                    &format!("more than the address space left under this process's limit (ulimit -v: {left} B)"),
                ));
            }
        }
        if buffer.saturating_mul(2) > memory {
            return Err(bad(
                "memory",
                &format!("{memory}B"),
                &format!("too small for the two file buffers of buffer={buffer}B"),
            ));
        }
        Ok(BreadthFirstConfig {
            memory,
            spill: (!spill.is_empty()).then(|| PathBuf::from(spill)),
            registration,
            buffer,
            triangle,
            floor,
            verify,
            layout,
            lazy,
            boundary,
            prev_skip,
            refill,
            count,
            res: (res > 0).then_some(res),
            max_rays: (max_rays > 0).then_some(max_rays),
            max_passes: (max_passes > 0).then_some(max_passes),
            progress,
            spill_codec,
            secondary,
            hierarchy,
            bh,
            cold,
            grid,
            batch,
        })
    }
}
