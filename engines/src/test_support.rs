//! Scaffolding the engines' unit tests share (it was copied into four test files): an SPD scene
//! as build input, settings from `key=value` pairs, reproducible rays around a scene, and an
//! engine's answers to them.

use crate::engine::{BuildInput, Counters, Engine};
use crate::geometry::Geometry;
use crate::ray::{Hit, Ray};
use glam::Vec3;
use rtbench_scenes::generate_scene;
use rtbench_scenes::spd::{Options, Program};
use std::sync::Arc;

/// SPD `program` at size factor `sf`, with its standard options, as an engine's build input.
pub fn spd(program: Program, sf: u32) -> BuildInput {
    let scene = generate_scene(
        program,
        &Options {
            size_factor: sf,
            ..Options::standard(program)
        },
    )
    .unwrap();
    BuildInput {
        geometry: Arc::new(Geometry::from_scene(&scene)),
        scene: Arc::new(scene),
    }
}

/// Settings as the command line gives them.
pub fn kv(pairs: &[(&str, &str)]) -> Vec<(String, String)> {
    pairs
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

/// `n` closest-hit rays from points around the scene (its box grown 1.5× about its centre)
/// towards points in it, and `n` any-hit segments between two points in it; drawn from an LCG
/// started at `seed`, so the same rays every run.
pub fn rays_around(g: &Geometry, n: usize, seed: u64) -> (Vec<Ray>, Vec<Ray>) {
    let (lo, hi) = (g.bounds_min, g.bounds_max);
    let mut s = seed;
    let mut unit = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut pt = |a: Vec3, b: Vec3| a + (b - a) * Vec3::new(unit(), unit(), unit());
    let c = (lo + hi) * 0.5;
    let h = (hi - lo) * 0.5;
    let (mut closest, mut any) = (Vec::new(), Vec::new());
    for _ in 0..n {
        let o = pt(c - h * 1.5, c + h * 1.5);
        let t = pt(lo, hi);
        closest.push(Ray::new(o, (t - o).normalize(), 0.0, f32::INFINITY));
        let a = pt(lo, hi);
        let d = pt(lo, hi) - a;
        any.push(Ray::new(a, d / d.length(), 0.0, d.length()));
    }
    (closest, any)
}

/// The hits of `e` for the closest-hit rays `r.0` and its occlusion answers for `r.1`.
pub fn answers(
    e: &dyn Engine,
    r: &(Vec<Ray>, Vec<Ray>),
    c: &mut Counters,
) -> (Vec<Hit>, Vec<bool>) {
    let mut hits = vec![Hit::MISS; r.0.len()];
    let mut occ = vec![false; r.1.len()];
    e.intersect(&r.0, &mut hits, c);
    e.occluded(&r.1, &mut occ, c);
    (hits, occ)
}

/// Builds `engine` with `settings` on `input`, answers `r` and asserts the answers are `want`'s
/// (the same object at the same t, the same occlusion) and that the engine did not fail; the
/// engine and its counters are returned for the caller's own checks.
pub fn same_answers(
    engine: &str,
    input: &BuildInput,
    settings: &[(&str, &str)],
    r: &(Vec<Ray>, Vec<Ray>),
    want: &(Vec<Hit>, Vec<bool>),
) -> (Box<dyn Engine>, Counters) {
    let e = crate::build_engine(engine, input, kv(settings)).unwrap();
    let mut c = Counters::default();
    let got = answers(e.as_ref(), r, &mut c);
    assert!(e.failure().is_none(), "{settings:?}: {:?}", e.failure());
    let same = got
        .0
        .iter()
        .zip(&want.0)
        .all(|(a, b)| a.object == b.object && a.t == b.t);
    assert!(same && got.1 == want.1, "{settings:?}: answers differ");
    (e, c)
}
