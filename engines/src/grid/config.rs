//! The `grid` engine's typed settings, parsed from `key=value` strings (see the module docs of
//! [`super`] for the table of keys).

use crate::engine::{EngineError, Settings};
use crate::geometry::TriangleTest;
use std::str::FromStr;

/// How many cells the grid has along each axis (see [`super::resolution`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Resolution {
    /// ⌊n^(1/3) + 0.5⌋ cells on every axis: Rayshade as run in seed 000 §3.4.
    CubeRoot,
    /// Woo 1992: about `density`·n cells, as cubic as the box allows.
    Woo,
    /// Klimaszewski 1997: about `density`·n cells, shaped like the primitives (heterogeneous).
    Klimaszewski,
    /// Given by the user.
    Explicit([u32; 3]),
}

impl FromStr for Resolution {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "cuberoot" => Ok(Resolution::CubeRoot),
            "woo" => Ok(Resolution::Woo),
            "klimaszewski" => Ok(Resolution::Klimaszewski),
            _ => {
                let parts: Vec<&str> = s.split(',').map(str::trim).collect();
                let bad = || {
                    format!(
                        "expected cuberoot, woo, klimaszewski or X,Y,Z (three cell counts from 1), \
                         got '{s}'"
                    )
                };
                if parts.len() != 3 {
                    return Err(bad());
                }
                let mut r = [0u32; 3];
                for (slot, p) in r.iter_mut().zip(&parts) {
                    *slot = p.parse::<u32>().map_err(|_| bad())?;
                    if *slot == 0 {
                        return Err(bad());
                    }
                }
                Ok(Resolution::Explicit(r))
            }
        }
    }
}

/// Which cells a primitive is registered in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Insertion {
    /// Every cell its bounding box overlaps (Rayshade's `engrid`; seed 000 §1.3).
    BoundingBox,
    /// Only the cells its surface may touch: triangle–box separating axes, sphere surface–box,
    /// a conservative cone–box test ([`super::overlap`]).
    Exact,
}

impl FromStr for Insertion {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "bbox" => Ok(Insertion::BoundingBox),
            "exact" => Ok(Insertion::Exact),
            _ => Err("expected bbox or exact".into()),
        }
    }
}

/// Where the floor (backdrop) polygon goes: SPD rule 11 allows keeping it out of the structure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Floor {
    /// In the grid like everything else.
    In,
    /// Out of the grid, tested on its own before the grid (seed 000 §3.4: "the base plate was
    /// excluded" for balls and tree).
    Out,
}

impl FromStr for Floor {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "in" => Ok(Floor::In),
            "out" => Ok(Floor::Out),
            _ => Err("expected in or out".into()),
        }
    }
}

/// What `n` is in the resolution formulas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Count {
    /// The primitives placed in the grid (polygons count once per triangle).
    Prims,
    /// The scene objects (NFF records) placed in the grid, as Rayshade counted them (seed 000
    /// §3.4: n objects).
    Objects,
}

impl FromStr for Count {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "prims" => Ok(Count::Prims),
            "objects" => Ok(Count::Objects),
            _ => Err("expected prims or objects".into()),
        }
    }
}

/// Rayshade's two extras together (seed 000 §3.4): `rss` is rayshade-ss (shadow cache and
/// per-voxel ray–box culling on, as Rayshade ships, and the default), `rss-r` is rayshade-ss-r
/// (both off).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    Rss,
    RssR,
}

impl FromStr for Preset {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "rss" => Ok(Preset::Rss),
            "rss-r" => Ok(Preset::RssR),
            _ => Err("expected rss or rss-r".into()),
        }
    }
}

/// The typed configuration of one `grid` engine.
#[derive(Clone, Debug, PartialEq)]
pub struct GridConfig {
    pub resolution: Resolution,
    /// Cells per primitive for `woo` and `klimaszewski` (Havran's grid density).
    pub density: f64,
    pub count: Count,
    pub insertion: Insertion,
    pub mailbox: bool,
    pub shadow_cache: bool,
    pub voxel_cull: bool,
    pub floor: Floor,
    pub triangle: TriangleTest,
}

/// Density used by `woo` and `klimaszewski` when none is given: one cell per primitive, the
/// density the n^(1/3) rule gives for a cubic box.
pub const DEFAULT_DENSITY: f64 = 1.0;

impl Default for GridConfig {
    fn default() -> Self {
        GridConfig {
            resolution: Resolution::CubeRoot,
            density: DEFAULT_DENSITY,
            count: Count::Prims,
            insertion: Insertion::BoundingBox,
            mailbox: true,
            shadow_cache: true,
            voxel_cull: true,
            floor: Floor::In,
            triangle: TriangleTest::Watertight,
        }
    }
}

fn bad(key: &str, value: &str, reason: &str) -> EngineError {
    EngineError::BadValue {
        engine: "grid".into(),
        key: key.into(),
        value: value.into(),
        reason: reason.into(),
    }
}

impl GridConfig {
    /// Reads every key the grid knows, then rejects the rest. `preset` sets `shadow_cache` and
    /// `voxel_cull` together; either key given on its own overrides the preset.
    pub fn from_settings(mut s: Settings) -> Result<GridConfig, EngineError> {
        let d = GridConfig::default();
        let resolution = s.get("res", d.resolution)?;
        // Read as text so that a density given to a policy that has none is an error, not ignored.
        let density_text: String = s.get("density", String::new())?;
        let count = s.get("count", d.count)?;
        let insertion = s.get("insert", d.insertion)?;
        let mailbox = s.get("mailbox", d.mailbox)?;
        let preset: Option<Preset> = match s.get("preset", String::new())?.as_str() {
            "" => None,
            p => Some(p.parse().map_err(|e: String| bad("preset", p, &e))?),
        };
        let (cache0, cull0) = match preset {
            Some(Preset::Rss) => (true, true),
            Some(Preset::RssR) => (false, false),
            None => (d.shadow_cache, d.voxel_cull),
        };
        let shadow_cache = s.get("shadow_cache", cache0)?;
        let voxel_cull = s.get("voxel_cull", cull0)?;
        let floor = s.get("floor", d.floor)?;
        let triangle = s.get("triangle", d.triangle)?;
        s.finish()?;

        let density = if density_text.is_empty() {
            d.density
        } else {
            if !matches!(resolution, Resolution::Woo | Resolution::Klimaszewski) {
                return Err(bad(
                    "density",
                    &density_text,
                    "only res=woo and res=klimaszewski take a density",
                ));
            }
            match density_text.parse::<f64>() {
                Ok(v) if v.is_finite() && v > 0.0 => v,
                _ => {
                    return Err(bad(
                        "density",
                        &density_text,
                        "expected a number of cells per primitive above 0",
                    ))
                }
            }
        };
        Ok(GridConfig {
            resolution,
            density,
            count,
            insertion,
            mailbox,
            shadow_cache,
            voxel_cull,
            floor,
            triangle,
        })
    }
}
