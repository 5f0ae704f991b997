//! The tinybvh plugin is built once (examples/tinybvh/build.sh) if it is not there yet; every
//! layout is built, queried against the reference engine and dropped, on SPD scenes, on an empty
//! scene and on rays that cannot hit.

use super::*;
use crate::engine::{Counters, Engine};
use crate::geometry::Geometry;
use crate::ray::{Hit, Ray};
use glam::Vec3;
use rtbench_scenes::generate_scene;
use rtbench_scenes::spd::{Options, Program};
use rtbench_scenes::Scene;
use std::path::Path;
use std::sync::{Arc, OnceLock};

/// Builds the plugin where the engine looks for it, once per test binary.
fn ensure_built() {
    static BUILT: OnceLock<()> = OnceLock::new();
    BUILT.get_or_init(|| {
        if library().is_ok() {
            return;
        }
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/tinybvh/build.sh");
        let status = std::process::Command::new("bash")
            .arg(&script)
            .status()
            .expect("bash runs");
        assert!(status.success(), "examples/tinybvh/build.sh failed");
        library().expect("the plugin is where the engine looks after build.sh");
    });
}

fn input(program: Program, size_factor: u32) -> BuildInput {
    let scene = Arc::new(
        generate_scene(
            program,
            &Options {
                size_factor,
                ..Options::standard(program)
            },
        )
        .unwrap(),
    );
    BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene,
    }
}

fn tinybvh(input: &BuildInput, pairs: &[(&str, &str)]) -> Result<Box<dyn Engine>, EngineError> {
    let pairs = pairs
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    build(input, Settings::new("tinybvh", pairs))
}

/// Rays from outside through the scene, every other one a segment ending inside it, and some
/// starting at tmin > 0.
fn fan(input: &BuildInput) -> Vec<Ray> {
    let g = &input.geometry;
    let c = (g.bounds_min + g.bounds_max) * 0.5;
    let r = (g.bounds_max - g.bounds_min).length();
    (0..400)
        .map(|i| {
            let a = i as f32 * 0.137;
            let o = c + Vec3::new(a.cos(), 0.3 + 0.2 * (a * 3.0).sin(), a.sin()) * r;
            let target = c + Vec3::new((a * 7.0).sin(), (a * 5.0).cos(), (a * 3.0).sin()) * 0.3 * r;
            // Not unit length: t is rtbench's parameter, not a distance.
            let d = (target - o) * 0.5;
            let tmax = if i % 2 == 0 { f32::INFINITY } else { 2.2 };
            let tmin = if i % 3 == 0 { 0.5 } else { 0.0 };
            Ray::new(o, d, tmin, tmax)
        })
        .collect()
}

#[test]
fn every_layout_agrees_with_the_reference_and_drops_cleanly() {
    ensure_built();
    // Triangles and polygons only (tetra, gears), and spheres and cylinders tessellated (tree).
    for (program, sf, exact) in [
        (Program::Tetra, 3, true),
        (Program::Gears, 1, true),
        (Program::Tree, 3, false),
    ] {
        let inp = input(program, sf);
        let rays = fan(&inp);
        let refe =
            (crate::reference::info().build)(&inp, Settings::new("reference", vec![])).unwrap();
        let mut want = vec![Hit::MISS; rays.len()];
        refe.intersect(&rays, &mut want, &mut Counters::default());
        let want_hits = want.iter().filter(|h| h.is_hit()).count();
        assert!(want_hits > 50, "{program}{sf}: {want_hits} hits");
        for layout in LAYOUTS {
            for quality in ["default", "hq"] {
                let e = tinybvh(&inp, &[("layout", layout), ("quality", quality)]).unwrap();
                let mut got = vec![Hit::MISS; rays.len()];
                let mut cnt = Counters::default();
                e.intersect(&rays, &mut got, &mut cnt);
                assert_eq!(cnt.rays, rays.len() as u64);
                assert_eq!(e.failure(), None, "{layout}");
                let mut occ = vec![false; rays.len()];
                e.occluded(&rays, &mut occ, &mut Counters::default());
                let agree = got
                    .iter()
                    .zip(&want)
                    .filter(|(a, b)| {
                        a.is_hit() == b.is_hit()
                            && (!a.is_hit()
                                || a.object == b.object
                                || (a.t - b.t).abs() <= 1e-4 * b.t)
                    })
                    .count();
                // Tessellated spheres and cylinders differ from the true surfaces near their
                // silhouettes; triangles and polygons are the same surfaces.
                let slack = if exact { 2 } else { rays.len() / 20 };
                assert!(
                    agree + slack >= rays.len(),
                    "{layout}/{quality} on {program}{sf}: {agree} of {} agree",
                    rays.len()
                );
                for (k, (o, h)) in occ.iter().zip(&got).enumerate() {
                    assert_eq!(*o, h.is_hit(), "{layout}/{quality}: ray {k} {:?}", rays[k]);
                }
                for (h, r) in got.iter().zip(&rays) {
                    if h.is_hit() {
                        assert!(h.t > r.tmin && h.t < r.tmax, "{layout}: {h:?} for {r:?}");
                    }
                }
                assert!(e.structure_bytes() > 0);
                drop(e);
            }
        }
    }
}

#[test]
fn builds_and_drops_repeatedly() {
    ensure_built();
    let inp = input(Program::Tetra, 2);
    let rays = fan(&inp);
    let mut first: Option<Vec<Hit>> = None;
    for _ in 0..6 {
        let e = tinybvh(&inp, &[]).unwrap();
        let mut got = vec![Hit::MISS; rays.len()];
        e.intersect(&rays, &mut got, &mut Counters::default());
        drop(e);
        match &first {
            None => first = Some(got),
            Some(f) => assert_eq!(f, &got, "rebuilding gives other hits"),
        }
    }
}

#[test]
fn empty_scene_misses_everything() {
    ensure_built();
    let scene = Arc::new(Scene::default());
    let inp = BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene,
    };
    let rays = [
        Ray::new(Vec3::ZERO, Vec3::Z, 0.0, f32::INFINITY),
        Ray::new(Vec3::ONE, -Vec3::X, 0.1, 5.0),
    ];
    for layout in LAYOUTS {
        let e = tinybvh(&inp, &[("layout", layout)]).unwrap();
        let mut got = vec![Hit::MISS; rays.len()];
        let mut occ = vec![true; rays.len()];
        e.intersect(&rays, &mut got, &mut Counters::default());
        e.occluded(&rays, &mut occ, &mut Counters::default());
        assert!(got.iter().all(|h| !h.is_hit()), "{layout}");
        assert!(occ.iter().all(|o| !o), "{layout}");
    }
}

#[test]
fn rays_that_cannot_hit_miss() {
    ensure_built();
    let inp = input(Program::Tetra, 1);
    let (n, i) = (f32::NAN, f32::INFINITY);
    let o = Vec3::new(0.0, 0.0, -5.0);
    let to = (Vec3::ZERO - o).normalize();
    let rays = [
        Ray::new(Vec3::splat(n), to, 0.0, i),
        Ray::new(o, Vec3::splat(n), 0.0, i),
        Ray::new(Vec3::new(i, 0.0, -5.0), to, 0.0, i),
        Ray::new(o, to, n, i),
        Ray::new(o, to, 0.0, n),
        Ray::new(o, to, 3.0, 3.0),
        Ray::new(o, Vec3::ZERO, 0.0, i),
        // Stops before the scene.
        Ray::new(o, to, 0.0, 1e-3),
    ];
    for layout in LAYOUTS {
        let e = tinybvh(&inp, &[("layout", layout)]).unwrap();
        let mut got = vec![Hit::MISS; rays.len()];
        let mut occ = vec![true; rays.len()];
        e.intersect(&rays, &mut got, &mut Counters::default());
        e.occluded(&rays, &mut occ, &mut Counters::default());
        for k in 0..rays.len() {
            assert!(
                !got[k].is_hit(),
                "{layout}: ray {k} {:?} hit {:?}",
                rays[k],
                got[k]
            );
            assert!(!occ[k], "{layout}: ray {k} {:?} occluded", rays[k]);
        }
        assert_eq!(e.failure(), None);
    }
}

#[test]
fn bad_settings_are_refused_by_name() {
    ensure_built();
    let inp = input(Program::Tetra, 1);
    for (pairs, key) in [
        (vec![("layout", "bvh16")], "layout"),
        (vec![("quality", "best")], "quality"),
    ] {
        match tinybvh(&inp, &pairs) {
            Err(EngineError::BadValue { engine, key: k, .. }) => {
                assert_eq!(engine, "tinybvh");
                assert_eq!(k, key);
            }
            other => panic!("{pairs:?}: {:?}", other.err()),
        }
    }
    assert!(matches!(
        tinybvh(&inp, &[("leaf", "4")]),
        Err(EngineError::UnknownKey { .. })
    ));
}
