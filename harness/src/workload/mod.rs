//! The SPD workload: camera, surfaces, and the wavefront tracer.

pub mod camera;
pub mod crosscheck;
pub mod footprint;
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
/// (breadth-first with `batch=generation`; its default, `batch=band`, holds far less) at
/// --size 2048 (corners, rays, hits, paths, shading records), rounded up.
pub const BYTES_PER_CORNER: u64 = 256;

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

/// A generated scene about to be held in memory, and the structures of `engines` over it, fit in
/// the memory available (RAM and the address-space limit), by the estimate of [`footprint`];
/// `force` skips this (`--sf 40` of tree ran the machine out of memory, `--tessellate 1000`
/// and an address-space limit aborted).
pub fn check_scene_fits(src: &Source, engines: &[&str], force: bool) -> Result<()> {
    let Source::Program(p, o) = src else {
        return Ok(());
    };
    if force {
        return Ok(());
    }
    let f = footprint::Census::of(*p, o);
    let need = f.bytes(engines);
    if let Some(have) = crate::measure::memory::memory_available().filter(|&have| need > have) {
        return Err(input(format!(
            "{}: {} objects ({} primitives to build over) need about {} in memory with {}, {} is \
             available (--force to try anyway)",
            src.label(),
            f.objects,
            f.primitives(),
            gib(need),
            engines.join(" and "),
            gib(have)
        )));
    }
    Ok(())
}

/// Feature sizes below this share of the scene's scale (its largest coordinate, the camera's
/// included) are not resolved by the `f32` engines: f32 keeps 24 bits, so at 1e5 a feature
/// spans fewer than 200 representable steps and hit tests on it come apart from the `f64`
/// reference (a triangle of ±1e-5 seen from 5 units; a cone whose radii differ by 10^6).
pub const F32_FEATURE_RATIO: f64 = 1e5;

/// A one-line warning when the scene holds a feature the `f32` engines cannot represent at the
/// scene's scale ([`F32_FEATURE_RATIO`]); render and check print it.
pub fn precision_warning(scene: &rtbench_scenes::Scene) -> Option<String> {
    use rtbench_scenes::Shape;
    let mut scale = scene.view.from.abs().max_element();
    let mut smallest = f64::INFINITY;
    for o in &scene.objects {
        let b = o.shape.bounds();
        scale = scale
            .max(b.min.abs().max_element())
            .max(b.max.abs().max_element());
        let feature = match &o.shape {
            Shape::Sphere { radius, .. } => *radius,
            Shape::Cone {
                base,
                base_radius,
                apex,
                apex_radius,
            } => {
                let radii = [*base_radius, *apex_radius]
                    .into_iter()
                    .filter(|r| *r > 0.0)
                    .fold(f64::INFINITY, f64::min);
                radii.min((*apex - *base).length())
            }
            // A polygon's size, not its shortest edge: a sliver is still where it is.
            Shape::Polygon(_) | Shape::Patch { .. } => {
                let d = (b.max - b.min).length();
                if d > 0.0 {
                    d
                } else {
                    f64::INFINITY
                }
            }
        };
        smallest = smallest.min(feature);
    }
    (smallest.is_finite() && smallest > 0.0 && scale / smallest > F32_FEATURE_RATIO).then(|| {
        format!(
            "{}: a feature of {smallest:.3e} at a scale of {scale:.3e} (ratio {:.1e} > {F32_FEATURE_RATIO:e}): the f32 engines cannot resolve it and may miss hits the f64 reference sees",
            scene.name,
            scale / smallest
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(objects: Vec<rtbench_scenes::Shape>) -> rtbench_scenes::Scene {
        let mut s = rtbench_scenes::generate_scene(
            rtbench_scenes::spd::Program::Tetra,
            &rtbench_scenes::spd::Options::standard(rtbench_scenes::spd::Program::Tetra),
        )
        .unwrap();
        s.objects = objects
            .into_iter()
            .map(|shape| rtbench_scenes::Object { material: 0, shape })
            .collect();
        s
    }

    /// Features the f32 engines cannot resolve are named; ordinary scenes pass silently.
    #[test]
    fn tiny_features_are_warned_of() {
        use glam::DVec3;
        use rtbench_scenes::Shape;
        let tri = |r: f64| {
            Shape::Polygon(vec![
                DVec3::new(-r, -r, 0.0),
                DVec3::new(r, -r, 0.0),
                DVec3::new(0.0, r, 0.0),
            ])
        };
        assert!(precision_warning(&scene(vec![tri(1.0)])).is_none());
        assert!(precision_warning(&scene(vec![tri(1e-5)])).is_some());
        assert!(precision_warning(&scene(vec![tri(1e-20)])).is_some());
        let cone = Shape::Cone {
            base: DVec3::ZERO,
            base_radius: 1.0,
            apex: DVec3::new(0.0, 1.0, 0.0),
            apex_radius: 1e-6,
        };
        assert!(precision_warning(&scene(vec![cone])).is_some());
        let tetra = rtbench_scenes::generate_scene(
            rtbench_scenes::spd::Program::Tetra,
            &rtbench_scenes::spd::Options::standard(rtbench_scenes::spd::Program::Tetra),
        )
        .unwrap();
        assert!(precision_warning(&tetra).is_none());
    }
}
