//! The SPD workload: camera, surfaces, and the wavefront tracer.

pub mod camera;
pub mod crosscheck;
pub mod frustum;
pub mod out_of_core;
pub mod surface;
pub mod tiles;
pub mod trace;
pub mod view_file;

use crate::error::{input, Result};
use crate::source::Source;
use rtbench_engines::geometry::Geometry;
use rtbench_engines::{build_engine, BuildInput, Engine};
use std::sync::Arc;
use std::time::Instant;

/// A scene ready for engines, with how long getting it ready took.
pub struct Prepared {
    pub input: BuildInput,
    pub generate_s: f64,
    pub prepare_s: f64,
}

pub fn prepare(src: &Source) -> Result<Prepared> {
    let t = Instant::now();
    let mut scene = src.load()?;
    // The objects were collected one by one into a growing vector; its spare capacity (up to
    // half of it: 0.6 MiB of gears4's 1.3 MiB) would stay resident through build and trace.
    scene.objects.shrink_to_fit();
    if scene.objects.is_empty() {
        return Err(input(format!("{}: the scene has no objects", src.label())));
    }
    let generate_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let geometry = Geometry::from_scene(&scene);
    let prepare_s = t.elapsed().as_secs_f64();
    Ok(Prepared {
        input: BuildInput {
            scene: Arc::new(scene),
            geometry: Arc::new(geometry),
        },
        generate_s,
        prepare_s,
    })
}

/// `--json` owns stdout: a setting that makes a library print there (Embree's `verbose`, which
/// writes on stdout from C++) is refused with it.
pub fn check_json_settings(json: bool, settings: &[(String, String)]) -> Result<()> {
    if let Some((_, v)) = settings
        .iter()
        .find(|(k, v)| json && k == "verbose" && v != "0")
    {
        return Err(input(format!(
            "--set verbose={v}: Embree prints on stdout, which --json owns (drop one of them)"
        )));
    }
    Ok(())
}

/// Parses `--set key=value` arguments.
pub fn parse_settings(set: &[String]) -> Result<Vec<(String, String)>> {
    set.iter()
        .map(|s| match s.split_once('=') {
            Some((k, v)) if !k.is_empty() => Ok((k.trim().to_string(), v.trim().to_string())),
            _ => Err(input(format!("--set '{s}': expected key=value"))),
        })
        .collect()
}

/// Builds an engine and times the build (the SPD's preprocessing, with scene preparation).
pub fn build(
    name: &str,
    input: &BuildInput,
    settings: Vec<(String, String)>,
) -> Result<(Box<dyn Engine>, f64)> {
    // `--engine plugin:PATH[:key=value…]` (render, check): the same entry as in `--engines`.
    let (name, settings) = if name.starts_with("plugin:") {
        let mut e = crate::select::engines(Some(name), "--engine")?;
        let (n, mut s) = e.remove(0);
        s.extend(settings);
        (n, s)
    } else {
        (name.to_string(), settings)
    };
    let t = Instant::now();
    let e = build_engine(&name, input, settings)?;
    Ok((e, t.elapsed().as_secs_f64()))
}

/// Bytes the workload holds per pixel corner, at least: measured 80 (in-memory engines) to 210
/// (breadth-first) at --size 2048 (corners, rays, hits, paths, shading records), rounded up.
pub const BYTES_PER_CORNER: u64 = 256;

/// Bytes an in-memory run holds per scene object, at least: measured 330 (embree, spheres) to
/// 1,640 (bvh8, gears' polygons) at 0.1 to 1 million objects; the lower figure, rounded down.
pub const BYTES_PER_OBJECT: u64 = 300;

fn gib(b: u64) -> String {
    format!("{:.1} GiB", b as f64 / (1u64 << 30) as f64)
}

/// `--size`: from 1 to 16384, and an image whose workload fits in the memory available.
pub fn check_size(size: u32) -> Result<()> {
    if !(1..=16384).contains(&size) {
        return Err(input(format!("--size {size}: must be from 1 to 16384")));
    }
    let corners = (size as u64 + 1).pow(2);
    let need = corners * BYTES_PER_CORNER;
    if let Some(have) = crate::measure::memory::memory_available().filter(|&have| need > have) {
        return Err(input(format!(
            "--size {size}: the workload needs at least {} ({BYTES_PER_CORNER} B per pixel \
             corner), {} is available",
            gib(need),
            gib(have)
        )));
    }
    Ok(())
}

/// A generated scene about to be held in memory fits in the memory available, by the estimate
/// [`BYTES_PER_OBJECT`] (`--sf 40` of tree ran the machine out of memory); `force` skips this.
pub fn check_scene_fits(src: &Source, force: bool) -> Result<()> {
    let Source::Program(p, o) = src else {
        return Ok(());
    };
    if force {
        return Ok(());
    }
    let objects = p.object_count(o.size_factor).unwrap_or(u64::MAX);
    let need = objects.saturating_mul(BYTES_PER_OBJECT);
    if let Some(have) = crate::measure::memory::memory_available().filter(|&have| need > have) {
        return Err(input(format!(
            "{}: {objects} objects need at least {} in memory, {} is available (--force to \
             try anyway)",
            src.label(),
            gib(need),
            gib(have)
        )));
    }
    Ok(())
}
