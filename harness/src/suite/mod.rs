//! `rtbench check --suite hard|tessellation`: numerical stability on hard cases, speed against
//! error, and the cost of tessellating curved primitives.
//!
//! - `hard` (`hard.rs`): every available engine (test-only ones aside) in every kernel variant
//!   it accepts (`variants`) on the hard cases of `cases.rs`, scored against f64 answers
//!   (`truth.rs`, `score.rs`); acne of secondary rays under the workload's offset policy on the
//!   cases and on the seven standard scenes (`acne.rs`); rays per second on the SPD workload
//!   against the error (`speed.rs`).
//! - `tessellation` (`tessellation.rs`): balls, rings and tree, curved and at `--tessellate RES`
//!   1…8, image error against the curved render and trace time, per engine.
//!
//! Engines come from the registry, so engines added later are covered without a change here.

mod acne;
mod cases;
pub mod hard;
mod meshes;
mod report;
mod score;
mod speed;
pub mod tessellation;
mod truth;

use crate::error::Result;
use rtbench_engines::geometry::Geometry;
use rtbench_engines::{build_engine, BuildInput, EngineError};
use rtbench_scenes::{Material, Object, Scene, Shape};
use std::sync::Arc;

pub use report::{hard_charts, hard_document, hard_json, tess_charts, tess_document, tess_json};

/// A one-sphere scene to find out which settings an engine takes.
pub fn probe_input() -> BuildInput {
    let scene = Scene {
        materials: vec![Material::default()],
        objects: vec![Object {
            material: 0,
            shape: Shape::Sphere {
                center: glam::DVec3::ZERO,
                radius: 1.0,
            },
        }],
        ..Scene::default()
    };
    BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene: Arc::new(scene),
    }
}

/// One engine with one set of settings.
#[derive(Clone, Debug)]
pub struct Variant {
    pub engine: String,
    pub settings: Vec<(String, String)>,
}

impl Variant {
    /// `bvh4`, `bvh4 triangle=moller`, `embree robust=on`.
    pub fn label(&self) -> String {
        let mut s = self.engine.clone();
        for (k, v) in &self.settings {
            s.push_str(&format!(" {k}={v}"));
        }
        s
    }
}

/// Kernel settings tried on every engine: an engine that takes one is measured with it too.
const ALTERNATIVES: &[(&str, &str)] = &[("triangle", "moller"), ("robust", "on")];

/// The engines to run: `--engine a,b` (each must exist and be available) or every available
/// engine of the registry but the test-only ones and `plugin` (which needs a library).
pub fn engines(arg: Option<&str>) -> Result<Vec<String>> {
    if arg.is_some() {
        return crate::select::engine_names(arg, "--engine");
    }
    // The suites are small: the reference engine runs too.
    Ok(crate::select::default_engines(true))
}

/// Each engine as it comes, and with each alternative kernel setting it accepts (tried by
/// building it on `probe`: an engine that does not know the key or the value is skipped).
pub fn variants(engines: &[String], probe: &BuildInput) -> Result<Vec<Variant>> {
    let mut v = Vec::new();
    for e in engines {
        build_engine(e, probe, vec![])?;
        v.push(Variant {
            engine: e.clone(),
            settings: vec![],
        });
        for (k, val) in ALTERNATIVES {
            let settings = vec![(k.to_string(), val.to_string())];
            match build_engine(e, probe, settings.clone()) {
                Ok(_) => v.push(Variant {
                    engine: e.clone(),
                    settings,
                }),
                Err(EngineError::UnknownKey { .. } | EngineError::BadValue { .. }) => {}
                Err(err) => return Err(err.into()),
            }
        }
    }
    Ok(v)
}
