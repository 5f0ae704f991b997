//! Rays per second of one engine variant on the SPD workload of two triangle scenes (teapot 6:
//! patches; gears 2: concave polygons cut into triangles), where the triangle test is what the
//! kernel variants change. The best of three renders of each scene is kept; one engine at a time.

use super::Variant;
use crate::error::Result;
use crate::workload::trace;
use rtbench_engines::{build_engine, BuildInput};
use rtbench_scenes::spd::{Options, Program};
use serde_json::{json, Value};

/// Image size of the speed renders.
pub const SIZE: u32 = 96;
const REPEATS: usize = 3;

/// The scenes speed is measured on.
pub fn scenes() -> Vec<(Program, u32)> {
    vec![(Program::Teapot, 6), (Program::Gears, 2)]
}

pub fn options(p: Program, sf: u32) -> Options {
    Options {
        size_factor: sf,
        ..Options::standard(p)
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Speed {
    pub rays: u64,
    /// Sum over the scenes of the best query time.
    pub intersect_s: f64,
}

impl Speed {
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / self.intersect_s.max(1e-12) / 1e6
    }
    pub fn to_json(self) -> Value {
        json!({"rays": self.rays, "intersect_s": self.intersect_s, "mrays_per_s": self.mrays_per_s()})
    }
}

pub fn measure(v: &Variant, inputs: &[BuildInput]) -> Result<Speed> {
    let mut s = Speed::default();
    for input in inputs {
        let engine = build_engine(&v.engine, input, v.settings.clone())?;
        let mut best = f64::INFINITY;
        let mut rays = 0;
        for _ in 0..REPEATS {
            let r = trace::render(&input.scene, engine.as_ref(), SIZE, None);
            best = best.min(r.intersect_s);
            rays = r.stats.total;
        }
        s.rays += rays;
        s.intersect_s += best;
    }
    Ok(s)
}
