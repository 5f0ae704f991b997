//! Eric Haines' Standard Procedural Databases (SPD 3.14), ported from the C programs so that they
//! print the same records in the same order with the same numbers.
//!
//! Each program is one file with `generate(out, size_factor)` (the C `main` after option parsing)
//! and `object_count(size_factor)` (the number of primitives of its curved output, `None` when it
//! does not fit 64 bits). Generators stream through [`Output`], the port of the C library's
//! `lib_output_*` layer, into any [`Sink`].

pub mod output;
pub mod tessellate;
pub mod vec;

pub mod balls;
pub mod gears;
pub mod jacks;
pub mod lattice;
pub mod mount;
pub mod rings;
pub mod shells;
pub mod sombrero;
pub mod teapot;
pub mod tetra;
pub mod tree;

use crate::sink::Sink;
pub use output::{CurveFormat, Output};
use std::fmt;
use std::str::FromStr;

/// SPD 3.14's default tessellation resolution (`OUTPUT_RESOLUTION` in lib.h).
pub const DEFAULT_RESOLUTION: u32 = 3;

/// The eleven SPD programs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Program {
    Balls,
    Gears,
    Mount,
    Rings,
    Teapot,
    Tetra,
    Tree,
    Lattice,
    Shells,
    Jacks,
    Sombrero,
}

impl Program {
    pub const ALL: [Program; 11] = [
        Program::Balls,
        Program::Gears,
        Program::Mount,
        Program::Rings,
        Program::Teapot,
        Program::Tetra,
        Program::Tree,
        Program::Lattice,
        Program::Shells,
        Program::Jacks,
        Program::Sombrero,
    ];

    /// The seven programs of the SPD's published timings and ray statistics.
    pub const STANDARD: [Program; 7] = [
        Program::Balls,
        Program::Gears,
        Program::Mount,
        Program::Rings,
        Program::Teapot,
        Program::Tetra,
        Program::Tree,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Program::Balls => "balls",
            Program::Gears => "gears",
            Program::Mount => "mount",
            Program::Rings => "rings",
            Program::Teapot => "teapot",
            Program::Tetra => "tetra",
            Program::Tree => "tree",
            Program::Lattice => "lattice",
            Program::Shells => "shells",
            Program::Jacks => "jacks",
            Program::Sombrero => "sombrero",
        }
    }

    /// The standard size factor: the one of the SPD tables (teapot: 12, although SPD 3.14's
    /// built-in default is 6).
    pub fn standard_sf(self) -> u32 {
        match self {
            Program::Balls => 4,
            Program::Gears => 4,
            Program::Mount => 6,
            Program::Rings => 7,
            Program::Teapot => 12,
            Program::Tetra => 6,
            Program::Tree => 11,
            Program::Lattice => 12,
            Program::Shells => 5,
            Program::Jacks => 1,
            Program::Sombrero => 1,
        }
    }

    pub fn description(self) -> &'static str {
        match self {
            Program::Balls => "sphereflake: spheres on spheres, a mirrored fractal, and a floor",
            Program::Gears => "interlocking gears of concave 144-gon faces, glass and mirrored",
            Program::Mount => "fractal mountain of triangles with four glass spheres",
            Program::Rings => "pentagonal rings of spheres and cylinders",
            Program::Teapot => "the Utah teapot as triangle patches on a checkerboard",
            Program::Tetra => "Sierpinski tetrahedron of triangles",
            Program::Tree => "a branching tree of cones and spheres",
            Program::Lattice => "a lattice of spheres joined by cylinders",
            Program::Shells => "a spiral shell of spheres",
            Program::Jacks => "a recursive cluster of jacks (spheres and cylinders)",
            Program::Sombrero => "a height field (sombrero function) as triangles",
        }
    }

    /// Primitives in the curved (`-r 1`) output at this size factor; `None` when the count does
    /// not fit 64 bits.
    pub fn object_count(self, size_factor: u32) -> Option<u64> {
        let sf = size_factor as u64;
        match self {
            Program::Balls => balls::object_count(sf),
            Program::Gears => gears::object_count(sf),
            Program::Mount => mount::object_count(sf),
            Program::Rings => rings::object_count(sf),
            Program::Teapot => teapot::object_count(sf),
            Program::Tetra => tetra::object_count(sf),
            Program::Tree => tree::object_count(sf),
            Program::Lattice => lattice::object_count(sf),
            Program::Shells => shells::object_count(sf),
            Program::Jacks => jacks::object_count(sf),
            Program::Sombrero => sombrero::object_count(sf),
        }
    }
}

impl fmt::Display for Program {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Program {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Program::ALL
            .iter()
            .copied()
            .find(|p| p.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Program::ALL.iter().map(|p| p.name()).collect();
                format!("unknown SPD program '{s}' (known: {})", names.join(", "))
            })
    }
}

/// mount's two hash functions (mount.c: the original, kept for old results, and Bob Jenkins',
/// `JENKINS_HASH`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MountHash {
    #[default]
    Original,
    Jenkins,
}

impl FromStr for MountHash {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "original" => Ok(MountHash::Original),
            "jenkins" => Ok(MountHash::Jenkins),
            _ => Err(format!("unknown hash '{s}' (known: original, jenkins)")),
        }
    }
}

/// What the C programs take on their command line (besides `-r`, always NFF here).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Options {
    pub size_factor: u32,
    /// `-t [RES]`: tessellated output at this resolution.
    pub tessellate: Option<u32>,
    pub hash: MountHash,
}

impl Options {
    pub fn standard(program: Program) -> Options {
        Options {
            size_factor: program.standard_sf(),
            tessellate: None,
            hash: MountHash::Original,
        }
    }
}

/// Why a generator was not run.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum SpdError {
    #[error("size factor must be at least 1, got {0}")]
    SizeFactorZero(u32),
    #[error("{program} at size factor {sf} has more than 2^64 objects")]
    CountOverflow { program: Program, sf: u32 },
    #[error("tessellation resolution must be at least 1, got {0}")]
    BadResolution(u32),
}

/// Checks the options as the C program would (SF ≥ 1, resolution ≥ 1) and that the object
/// count fits 64 bits.
pub fn validate(program: Program, opts: &Options) -> Result<u64, SpdError> {
    if opts.size_factor == 0 {
        return Err(SpdError::SizeFactorZero(0));
    }
    if let Some(0) = opts.tessellate {
        return Err(SpdError::BadResolution(0));
    }
    program
        .object_count(opts.size_factor)
        .ok_or(SpdError::CountOverflow {
            program,
            sf: opts.size_factor,
        })
}

/// Runs one SPD program into `sink`: the records its C original prints with `-r 1` (NFF), or
/// with `-t RES` when `opts.tessellate` is set.
pub fn generate(program: Program, opts: &Options, sink: &mut dyn Sink) -> Result<(), SpdError> {
    validate(program, opts)?;
    let (format, res) = match opts.tessellate {
        Some(r) => (CurveFormat::Patches, r),
        None => (CurveFormat::Curves, DEFAULT_RESOLUTION),
    };
    let mut out = Output::new(sink, format, res);
    let sf = opts.size_factor;
    match program {
        Program::Balls => balls::generate(&mut out, sf),
        Program::Gears => gears::generate(&mut out, sf),
        Program::Mount => mount::generate(&mut out, sf, opts.hash),
        Program::Rings => rings::generate(&mut out, sf),
        Program::Teapot => teapot::generate(&mut out, sf),
        Program::Tetra => tetra::generate(&mut out, sf),
        Program::Tree => tree::generate(&mut out, sf),
        Program::Lattice => lattice::generate(&mut out, sf),
        Program::Shells => shells::generate(&mut out, sf),
        Program::Jacks => jacks::generate(&mut out, sf),
        Program::Sombrero => sombrero::generate(&mut out, sf),
    }
    Ok(())
}
