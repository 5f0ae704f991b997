//! `embree`: Intel Embree 4, the cross-check and the performance anchor.
//!
//! Embree answers on the same primitives as every other engine: the prepared triangles of
//! [`Geometry`](crate::geometry::Geometry) natively (one `RTC_GEOMETRY_TYPE_TRIANGLE` geometry,
//! geomID 0), spheres and open cones/cylinders as one user geometry (geomID 1) whose callbacks
//! call the shared kernels of [`crate::geometry::kernels`]. A map per geometry turns Embree's
//! primID back into the scene's object index.
//!
//! Rays go through the raw `rtcIntersect1` / `rtcOccluded1` of embree4-sys: the embree4-rs
//! wrapper checks the device error after every ray, which costs up to 31% of Embree's speed.
//! embree4-rs is not used for set-up either: its `Device` cannot take a configuration string
//! (it passes it without a terminating NUL) and neither it nor its `Scene` expose the raw handles
//! that the raw calls need. The few set-up calls are wrapped here instead (`raw.rs`).
//!
//! Settings (`key=value`):
//! - `threads` (default 1): Embree's build threads (`threads=N` in the device configuration;
//!   0 lets Embree use every core). Tracing runs on the caller's threads either way.
//! - `quality` (default `medium`, Embree's default): `low`, `medium` or `high` (`rtcSetSceneBuildQuality`).
//! - `robust` (default `off`): `on` sets `RTC_SCENE_FLAG_ROBUST` (Embree's watertight-ish
//!   triangle test and robust traversal); `on|off` (also `true|false`).
//! - `compact` (default false): `RTC_SCENE_FLAG_COMPACT`.
//! - `isa` (default: the best the CPU has): `sse2`, `sse4.2`, `avx`, `avx2` or `avx512`.
//! - `verbose` (default 0): Embree's verbosity (1 prints the device and the BVH chosen, on stdout).
//! - `api` (default `single`): `single` traces ray by ray (`rtcIntersect1`/`rtcOccluded1`);
//!   `packet8` / `packet16` hand consecutive rays of a batch to `rtcIntersect8/16` and
//!   `rtcOccluded8/16` (Embree's packet traversal; a short last packet is masked), the fair
//!   partner for packet tracers. The answers are the same queries' answers.
//!
//! Memory: [`Engine::structure_bytes`] is what Embree holds after the build, as its memory monitor
//! (`rtcSetDeviceMemoryMonitorFunction`) reports it — the BVH with its leaves (which copy the
//! triangles) and the vertex and index buffers Embree was given — plus this engine's own
//! primID → object maps and its copy of the spheres and cones. `build_stats` breaks it down and
//! adds the peak during the build.
//!
//! Without the cargo feature `embree` the engine is listed but unavailable.

use crate::engine::{BuildInput, Engine, EngineError, EngineInfo, Settings};

#[cfg(feature = "embree")]
mod api;
mod config;
#[cfg(feature = "embree")]
mod engine;
#[cfg(feature = "embree")]
mod raw;
#[cfg(feature = "embree")]
mod user;

pub use config::{Api, EmbreeConfig, Quality};

/// The registry entry of the `embree` engine.
pub fn info() -> EngineInfo {
    EngineInfo {
        name: "embree",
        description: "Intel Embree 4 (raw rtcIntersect1/rtcOccluded1; spheres and cones as user geometry on the shared kernels): the cross-check and the performance anchor",
        available,
        build,
    }
}

#[cfg(feature = "embree")]
fn available() -> Result<(), String> {
    static AVAILABLE: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    AVAILABLE
        .get_or_init(|| raw::Device::shared(&EmbreeConfig::default().device_config()).map(|_| ()))
        .clone()
}

#[cfg(not(feature = "embree"))]
fn available() -> Result<(), String> {
    Err("built without the embree feature".into())
}

#[cfg(feature = "embree")]
fn build(input: &BuildInput, settings: Settings) -> Result<Box<dyn Engine>, EngineError> {
    let config = EmbreeConfig::from_settings(settings)?;
    Ok(Box::new(engine::EmbreeEngine::build(input, &config)?))
}

#[cfg(not(feature = "embree"))]
fn build(_input: &BuildInput, settings: Settings) -> Result<Box<dyn Engine>, EngineError> {
    EmbreeConfig::from_settings(settings)?;
    Err(EngineError::Unavailable {
        engine: "embree".into(),
        reason: "built without the embree feature".into(),
    })
}

/// Embree's version as `major.minor.patch` (for the results' environment), or why there is none.
pub fn version() -> Result<String, String> {
    #[cfg(feature = "embree")]
    {
        // The engines' default device (see `raw::Device::shared`): making and releasing a
        // device of another configuration here would lift TBB's thread limit.
        raw::Device::shared(&EmbreeConfig::default().device_config()).map(|d| d.version())
    }
    #[cfg(not(feature = "embree"))]
    {
        Err("built without the embree feature".into())
    }
}

#[cfg(test)]
mod tests;
