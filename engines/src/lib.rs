//! rtbench-engines: every accelerator of rtbench behind one interface ([`Engine`]), and the
//! one shared set of ray–primitive kernels they all call ([`geometry`]).
//!
//! ```
//! use rtbench_engines::{build_engine, BuildInput, Counters, Hit, Ray, geometry::Geometry};
//! use rtbench_scenes::{generate_scene, spd::{Options, Program}};
//! use std::sync::Arc;
//! let scene = Arc::new(generate_scene(Program::Tetra, &Options { size_factor: 1, ..Options::standard(Program::Tetra) }).unwrap());
//! let input = BuildInput { geometry: Arc::new(Geometry::from_scene(&scene)), scene };
//! let engine = build_engine("reference", &input, vec![]).unwrap();
//! let ray = Ray::new(glam::Vec3::new(0.0, 0.0, -5.0), glam::Vec3::Z, 0.0, f32::INFINITY);
//! let mut hits = [Hit::MISS];
//! engine.intersect(&[ray], &mut hits, &mut Counters::default());
//! assert!(hits[0].is_hit());
//! ```

pub mod breadth_first;
pub mod bvh;
pub mod embree;
pub mod engine;
pub mod geometry;
pub mod grid;
pub mod object_space;
pub mod obvhs_engine;
pub mod plugin;
pub mod ray;
pub mod reference;
pub mod store;
#[cfg(test)]
mod test_support;
pub mod testing;
pub mod tinybvh;
pub mod usage;

pub use engine::{BuildInput, Counters, Engine, EngineError, EngineInfo, Settings};
pub use geometry::TriangleTest;
pub use ray::{Hit, Ray};

/// Every engine rtbench knows, available here or not.
pub fn registry() -> Vec<EngineInfo> {
    let mut v = vec![
        reference::info(),
        breadth_first::info(),
        embree::info(),
        grid::info(),
        bvh::info2(),
        bvh::info4(),
        bvh::info8(),
        obvhs_engine::info(),
        tinybvh::info(),
        object_space::info(),
        plugin::info(),
    ];
    if testing::enabled() {
        v.extend(test_infos());
    }
    v
}

/// The engines for rtbench's own tests ([`testing`]); the wrappers build their inner engine
/// with [`build_engine`].
fn test_infos() -> Vec<EngineInfo> {
    vec![
        EngineInfo {
            name: "test-slow",
            description: "test only: another engine, slowed by RTBENCH_TEST_SLOWDOWN",
            available: || Ok(()),
            build: |input, s| testing::build_slow(input, s, build_engine),
        },
        EngineInfo {
            name: "test-panic",
            description: "test only: panics in its first query",
            available: || Ok(()),
            build: testing::build_panic,
        },
        EngineInfo {
            name: "test-hog",
            description: "test only: allocates `bytes` bytes at build",
            available: || Ok(()),
            build: |input, s| testing::build_hog(input, s, build_engine),
        },
    ]
}

/// Finds an engine by name, checks it is available, and builds it with `key=value` settings.
pub fn build_engine(
    name: &str,
    input: &BuildInput,
    settings: Vec<(String, String)>,
) -> Result<Box<dyn Engine>, EngineError> {
    let info = registry()
        .into_iter()
        .find(|e| e.name == name)
        .ok_or_else(|| EngineError::Unknown(name.to_string()))?;
    (info.available)().map_err(|reason| EngineError::Unavailable {
        engine: name.to_string(),
        reason,
    })?;
    (info.build)(input, Settings::new(name, settings))
}
