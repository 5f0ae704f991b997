//! The `object-space` engine's typed settings, parsed from `key=value` strings (the table of
//! keys is in the module docs of [`super`]).

use super::machine::{Allocation, Machine};
use crate::engine::{EngineError, Settings};
use crate::geometry::TriangleTest;

/// 003's Table 4 unit costs and Table 5's frame-buffer costs, in simulation clocks (1 clock =
/// 25 ns = one byte on a 40 MB/s link; 003 §4.2.1). Every cost is a whole number of clocks
/// above 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Costs {
    /// Generation of an initial (primary) ray, by the FRGU.
    pub primary: u32,
    /// One ray–primitive test, by primitive kind. 003 gives a range, 1028–2446 clocks, without
    /// saying what sets the value; we take the low end for triangles (its scene was patches),
    /// the high end for cones and the middle for spheres.
    pub triangle: u32,
    pub sphere: u32,
    pub cone: u32,
    /// Intensity calculation at a hit (ICU).
    pub intensity: u32,
    /// Next subspace by 3D-DDA, on the ray's first step (with set-up) and afterwards.
    pub dda_init: u32,
    pub dda: u32,
    /// Generation of one secondary ray (SRGU).
    pub secondary: u32,
    /// Making a ray packet to send on (NIU), and sending it one hop to a neighbour.
    pub packet: u32,
    pub hop: u32,
    /// Frame-buffer cache hit; miss is `fb_miss + fb_dirty × dirty pixels` (Table 5).
    pub fb_hit: u32,
    pub fb_miss: u32,
    pub fb_dirty: u32,
    /// Direct access to the global frame buffer without caches (Table 5).
    pub gfb: u32,
    /// Sending one intensity packet (7 bytes) to the first cache stage, and one cache block up a
    /// later stage (Table 3: T_C1 = 8, T_Ci = 64).
    pub fb_link: u32,
    pub fb_block_link: u32,
}

impl Default for Costs {
    fn default() -> Self {
        Costs {
            primary: 4379,
            triangle: 1028,
            sphere: 1737,
            cone: 2446,
            intensity: 349,
            dda_init: 3151,
            dda: 1106,
            secondary: 1818,
            packet: 164,
            hop: 164,
            fb_hit: 12,
            fb_miss: 7,
            fb_dirty: 4,
            gfb: 14,
            fb_link: 8,
            fb_block_link: 64,
        }
    }
}

/// Where intensity packets go (003 §3.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameBuffer {
    /// Straight to the global frame buffer, one shared server (Table 5: 14 clocks each).
    Direct,
    /// The cached frame buffer system: an m-ary tree of frame-buffer caches.
    Cached { m: u32 },
    /// The same tree with write buffers in place of the caches (003 §4.3.2's third case): they
    /// queue packets and pass each on, adding nothing up ([`super::fbpath`]).
    WriteBuffer { m: u32 },
}

impl std::str::FromStr for FrameBuffer {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "direct" => Ok(FrameBuffer::Direct),
            _ => match (
                s.strip_prefix("cfbs:").map(str::parse::<u32>),
                s.strip_prefix("wb:").map(str::parse::<u32>),
            ) {
                (Some(Ok(m)), _) if m >= 2 => Ok(FrameBuffer::Cached { m }),
                (_, Some(Ok(m))) if m >= 2 => Ok(FrameBuffer::WriteBuffer { m }),
                _ => Err("expected direct, cfbs:M or wb:M (an m-ary tree of caches or write buffers, M at least 2)".into()),
            },
        }
    }
}

/// The typed configuration of one `object-space` engine.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectSpaceConfig {
    /// Subspaces per axis (003: 32³ = 32768).
    pub subspaces: [u32; 3],
    pub machine: Machine,
    pub costs: Costs,
    pub frame_buffer: FrameBuffer,
    pub triangle: TriangleTest,
}

impl Default for ObjectSpaceConfig {
    fn default() -> Self {
        ObjectSpaceConfig {
            subspaces: [32; 3],
            machine: Machine {
                pes: [16, 1, 1],
                dims: 1,
                allocation: Allocation::Skewed,
                rp_blocks: 1,
            },
            costs: Costs::default(),
            frame_buffer: FrameBuffer::Direct,
            triangle: TriangleTest::Watertight,
        }
    }
}

fn bad(key: &str, value: &str, reason: &str) -> EngineError {
    EngineError::BadValue {
        engine: "object-space".into(),
        key: key.into(),
        value: value.into(),
        reason: reason.into(),
    }
}

/// `S` or `X,Y,Z`, each from 1.
fn parse_subspaces(s: &str) -> Result<[u32; 3], EngineError> {
    let err = || {
        bad(
            "subspaces",
            s,
            "expected S or X,Y,Z (subspaces per axis, from 1)",
        )
    };
    let parts: Vec<u32> = s
        .split(',')
        .map(|p| p.trim().parse::<u32>().map_err(|_| err()))
        .collect::<Result<_, _>>()?;
    let r = match parts.as_slice() {
        [n] => [*n; 3],
        [x, y, z] => [*x, *y, *z],
        _ => return Err(err()),
    };
    if r.contains(&0) {
        return Err(err());
    }
    if r.iter().map(|&v| v as u64).product::<u64>() > 1 << 24 {
        return Err(bad("subspaces", s, "more than 2^24 subspaces"));
    }
    Ok(r)
}

/// `N` (1D), `NxM` (2D) or `NxMxK` (3D), each from 1.
fn parse_pes(s: &str) -> Result<([u32; 3], u8), EngineError> {
    let err = |why: &str| bad("pes", s, why);
    let parts: Vec<u32> = s
        .split('x')
        .map(|p| p.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|_| err("expected N, NxM or NxMxK (PEs per torus axis)"))?;
    if parts.contains(&0) {
        return Err(err("zero processing elements"));
    }
    match parts.as_slice() {
        [n] => Ok(([*n, 1, 1], 1)),
        [x, y] => Ok(([*x, *y, 1], 2)),
        [x, y, z] => Ok(([*x, *y, *z], 3)),
        _ => Err(err("expected N, NxM or NxMxK (PEs per torus axis)")),
    }
}

impl ObjectSpaceConfig {
    /// Reads every key the engine knows, rejects the rest, and checks that the PE grid divides
    /// the subspaces along each axis and that every cost is above 0.
    pub fn from_settings(mut s: Settings) -> Result<ObjectSpaceConfig, EngineError> {
        let d = ObjectSpaceConfig::default();
        let subspaces_text: String = s.get("subspaces", "32".to_string())?;
        let pes_text: String = s.get("pes", "16".to_string())?;
        let allocation: Allocation = s.get("allocation", d.machine.allocation)?;
        let rp_blocks_text: String = s.get("rp_blocks", "1".to_string())?;
        let frame_buffer = s.get("frame_buffer", d.frame_buffer)?;
        let triangle = s.get("triangle", d.triangle)?;
        let mut costs = d.costs;
        {
            let c = &mut costs;
            let slots: [(&'static str, &mut u32); 16] = [
                ("cost.primary", &mut c.primary),
                ("cost.triangle", &mut c.triangle),
                ("cost.sphere", &mut c.sphere),
                ("cost.cone", &mut c.cone),
                ("cost.intensity", &mut c.intensity),
                ("cost.dda_init", &mut c.dda_init),
                ("cost.dda", &mut c.dda),
                ("cost.secondary", &mut c.secondary),
                ("cost.packet", &mut c.packet),
                ("cost.hop", &mut c.hop),
                ("cost.fb_hit", &mut c.fb_hit),
                ("cost.fb_miss", &mut c.fb_miss),
                ("cost.fb_dirty", &mut c.fb_dirty),
                ("cost.gfb", &mut c.gfb),
                ("cost.fb_link", &mut c.fb_link),
                ("cost.fb_block_link", &mut c.fb_block_link),
            ];
            for (key, slot) in slots {
                let text: String = s.get(key, String::new())?;
                if text.is_empty() {
                    continue;
                }
                *slot = match text.parse::<i64>() {
                    Ok(v) if v > 0 && v <= 1 << 30 => v as u32,
                    Ok(_) => return Err(bad(key, &text, "a cost must be above 0 clocks")),
                    Err(_) => {
                        return Err(bad(key, &text, "expected a whole number of clocks above 0"))
                    }
                };
            }
        }
        s.finish()?;

        let subspaces = parse_subspaces(&subspaces_text)?;
        let (pes, dims) = parse_pes(&pes_text)?;
        for i in 0..3 {
            if subspaces[i] % pes[i] != 0 {
                return Err(bad(
                    "pes",
                    &pes_text,
                    &format!(
                        "the PE grid does not divide the subspaces: {} PEs along axis {} but {} \
                         subspaces",
                        pes[i],
                        ["x", "y", "z"][i],
                        subspaces[i]
                    ),
                ));
            }
        }
        if allocation == Allocation::Skewed && dims == 3 {
            return Err(bad(
                "allocation",
                "skewed",
                "skewed allocation is defined for 1D and 2D machines only (003 eqs. 9, 10)",
            ));
        }
        let rp_blocks = match rp_blocks_text.parse::<i64>() {
            Ok(v) if (1..=4096).contains(&v) => v as u32,
            _ => {
                return Err(bad(
                    "rp_blocks",
                    &rp_blocks_text,
                    "expected ray-processing blocks per PE, from 1 to 4096",
                ))
            }
        };
        if pes.iter().map(|&v| v as u64).product::<u64>() * rp_blocks as u64 > 1 << 22 {
            return Err(bad(
                "pes",
                &pes_text,
                "more than 2^22 ray-processing blocks",
            ));
        }
        Ok(ObjectSpaceConfig {
            subspaces,
            machine: Machine {
                pes,
                dims,
                allocation,
                rp_blocks,
            },
            costs,
            frame_buffer,
            triangle,
        })
    }
}
