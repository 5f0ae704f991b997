//! Packets against Embree's packets on coherent generations:
//! `cargo bench -p rtbench-engines --bench packets -- [SCENE[:SF] ...] [--size N] [--pairs P]
//! [--engines LABEL,...] [--tessellate RES] [--set KEY=VALUE ...]` (`--engines`: only the engines
//! whose label starts with one of these, e.g. `"embree single,bvh4 single"`; bvh8 single is always
//! built, it makes the shadow rays; `--tessellate`: the scenes as triangles, SPD `-t RES`;
//! `--set`: a setting of bvh8's packet engines, e.g. `packet_cull=off`; `--set-single`: a
//! setting of bvh4 single and bvh8 single, e.g. `sah_block=8`).
//!
//! Two generations of each scene, as the SPD workload makes them but grouped so that a batch is
//! coherent: the eye rays through the (size+1)² pixel corners, row by row, and the shadow rays
//! from the eye rays' hit points to one light at a time (the first light's rays, then the
//! second's, …). Every engine answers the same batches of 4,096 rays. Each pair traces one
//! generation with both engines back to back (the order alternating), so that load from other
//! processes falls on both sides of a ratio; the ratio is Embree's time over the engine's
//! (> 1: faster than Embree), the median of the pairs with its min and max. Answers are
//! compared ray by ray with the engine's own single-ray traversal (hits: same object and t,
//! occlusion: same bool) and with Embree (object agreement). With `--once` every engine traces
//! each generation once, untimed, for instruction counts per entry point:
//! `valgrind --tool=callgrind target/release/deps/packets-* gears --once --size 256`, then
//! `callgrind_annotate --inclusive=yes` (bvh8: `packet::x86::closest_impl` / `any_impl`,
//! `avx8_closest_impl` / `avx8_any_impl`; Embree: `rtcIntersect1/8/16`, `rtcOccluded1/8/16`;
//! the first eye trace (bvh8 single) is done twice, to make the shadow rays).

use rtbench_engines::geometry::Geometry;
use rtbench_engines::{build_engine, BuildInput, Counters, Engine, Hit, Ray};
use rtbench_scenes::generate_scene;
use rtbench_scenes::spd::{Options, Program};
use std::sync::Arc;
use std::time::Instant;

const BATCH: usize = 4096;

/// (label, engine, settings).
type Setup = (
    &'static str,
    &'static str,
    &'static [(&'static str, &'static str)],
);

/// The engines compared.
const ENGINES: &[Setup] = &[
    ("bvh8 single", "bvh8", &[]),
    ("bvh8 packet8", "bvh8", &[("packet", "8")]),
    ("bvh8 packet16", "bvh8", &[("packet", "16")]),
    ("embree single", "embree", &[("threads", "1")]),
    (
        "embree packet8",
        "embree",
        &[("threads", "1"), ("api", "packet8")],
    ),
    (
        "embree packet16",
        "embree",
        &[("threads", "1"), ("api", "packet16")],
    ),
    ("bvh4 single", "bvh4", &[]),
];

/// The pairs timed: (engine, Embree yardstick), indices into `ENGINES`.
const PAIRS: &[(usize, usize)] = &[(1, 4), (2, 5), (0, 3), (1, 0), (6, 3)];

fn eye_rays(scene: &rtbench_scenes::Scene, size: u32) -> Vec<Ray> {
    // The workload's camera (harness/src/workload/camera.rs, `Camera::corner_ray`): the eye
    // rays through the (size+1)² pixel corners, row by row from the top.
    let v = &scene.view;
    let eye = v.from.as_vec3();
    let forward = (v.at - v.from).normalize().as_vec3();
    let right = forward.cross(v.up.as_vec3()).normalize();
    let up = right.cross(forward).normalize();
    let half = (v.angle.to_radians() / 2.0).tan() as f32;
    let (right, up) = (right * half, up * half);
    let span = (size.max(2) - 1) as f32;
    let mut rays = Vec::with_capacity(((size + 1) * (size + 1)) as usize);
    for j in 0..=size {
        for i in 0..=size {
            let x = (2.0 * i as f32 - size as f32) / span;
            let y = (size as f32 - 2.0 * j as f32) / span;
            let d = (forward + right * x + up * y).normalize();
            rays.push(Ray::new(eye, d, v.hither.max(0.0) as f32, f32::INFINITY));
        }
    }
    rays
}

/// Shadow rays from each eye hit to one light after another (offset along the ray so the
/// origin is just in front of the surface it hit).
fn shadow_rays(scene: &rtbench_scenes::Scene, eye: &[Ray], hits: &[Hit]) -> Vec<Ray> {
    let mut out = Vec::new();
    for l in &scene.lights {
        let lp = l.position.as_vec3();
        for (r, h) in eye.iter().zip(hits) {
            if !h.is_hit() {
                continue;
            }
            let p = r.at(h.t * (1.0 - 1e-4));
            let to = lp - p;
            let dist = to.length();
            out.push(Ray::new(p, to / dist, 0.0, dist * (1.0 - 1e-6)));
        }
    }
    out
}

fn closest(e: &dyn Engine, rays: &[Ray], c: &mut Counters) -> Vec<Hit> {
    let mut hits = vec![Hit::MISS; rays.len()];
    for (r, h) in rays.chunks(BATCH).zip(hits.chunks_mut(BATCH)) {
        e.intersect(r, h, c);
    }
    hits
}

fn any(e: &dyn Engine, rays: &[Ray], c: &mut Counters) -> Vec<bool> {
    let mut out = vec![false; rays.len()];
    for (r, o) in rays.chunks(BATCH).zip(out.chunks_mut(BATCH)) {
        e.occluded(r, o, c);
    }
    out
}

fn seconds(f: impl FnOnce()) -> f64 {
    let t = Instant::now();
    f();
    t.elapsed().as_secs_f64()
}

fn median(mut v: Vec<f64>) -> (f64, f64, f64) {
    v.sort_by(f64::total_cmp);
    (v[v.len() / 2], v[0], v[v.len() - 1])
}

fn main() {
    let mut scenes: Vec<(Program, Option<u32>)> = Vec::new();
    let mut size = 512u32;
    let mut pairs = 7usize;
    // `--once`: every engine traces each generation once, untimed and unchecked (for counting
    // instructions per entry point under callgrind).
    let mut once = false;
    // `--tessellate RES`: the scenes tessellated (SPD `-t RES`; 001's setting, `kimura-simd`,
    // is RES 3), so every engine traces triangles only.
    let mut tessellate: Option<u32> = None;
    // `--engines L1,L2`: only the engines whose label starts with one of these (bvh8 single,
    // which makes the shadow rays and the reference answers, is always built).
    let mut only: Option<Vec<String>> = None;
    // `--set KEY=VALUE`: added to the settings of bvh8's packet engines.
    let mut extra: Vec<(String, String)> = Vec::new();
    // `--set-single KEY=VALUE`: added to the settings of bvh4 single and bvh8 single (a tree
    // setting tried on both widths).
    let mut single: Vec<(String, String)> = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--size" => size = args.next().and_then(|s| s.parse().ok()).expect("--size N"),
            "--pairs" => pairs = args.next().and_then(|s| s.parse().ok()).expect("--pairs P"),
            "--bench" => {}
            "--once" => once = true,
            "--tessellate" => {
                tessellate = Some(
                    args.next()
                        .and_then(|s| s.parse().ok())
                        .expect("--tessellate RES"),
                )
            }
            "--set" => {
                let kv = args.next().expect("--set KEY=VALUE");
                let (k, v) = kv.split_once('=').expect("--set KEY=VALUE");
                extra.push((k.to_string(), v.to_string()));
            }
            "--set-single" => {
                let kv = args.next().expect("--set-single KEY=VALUE");
                let (k, v) = kv.split_once('=').expect("--set-single KEY=VALUE");
                single.push((k.to_string(), v.to_string()));
            }
            "--engines" => {
                let l = args.next().expect("--engines LABEL,LABEL");
                only = Some(l.split(',').map(str::to_string).collect());
            }
            s if !s.starts_with('-') => {
                let (name, sf) = match s.split_once(':') {
                    Some((n, f)) => (n, Some(f.parse().expect("SCENE:SF"))),
                    None => (s, None),
                };
                scenes.push((name.parse().expect("an SPD program"), sf));
            }
            _ => {}
        }
    }
    if scenes.is_empty() {
        scenes = vec![(Program::Gears, None), (Program::Tetra, None)];
    }
    for (program, sf) in scenes {
        let mut opts = Options::standard(program);
        if let Some(sf) = sf {
            opts.size_factor = sf;
        }
        opts.tessellate = tessellate;
        let scene = Arc::new(generate_scene(program, &opts).expect("scene"));
        let geometry = Arc::new(Geometry::from_scene(&scene));
        let input = BuildInput {
            scene: scene.clone(),
            geometry,
        };
        let wanted = |k: usize| {
            k == 0
                || only
                    .as_ref()
                    .is_none_or(|o| o.iter().any(|p| ENGINES[k].0.starts_with(p.as_str())))
        };
        let engines: Vec<Option<Box<dyn Engine>>> = ENGINES
            .iter()
            .enumerate()
            .map(|(k, (label, name, set))| {
                wanted(k).then(|| {
                    let mut s: Vec<(String, String)> = set
                        .iter()
                        .map(|(k, v)| (k.to_string(), v.to_string()))
                        .collect();
                    if *name == "bvh8" && label.contains("packet") {
                        s.extend(extra.iter().cloned());
                    }
                    if name.starts_with("bvh") && label.contains("single") {
                        s.extend(single.iter().cloned());
                    }
                    build_engine(name, &input, s).expect("engine")
                })
            })
            .collect();
        let first = engines[0].as_ref().expect("bvh8 single").as_ref();
        let eye = eye_rays(&scene, size);
        let eye_hits = closest(first, &eye, &mut Counters::default());
        let shadow = shadow_rays(&scene, &eye, &eye_hits);
        let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
        println!(
            "{} sf {}{}: {} eye rays ({} hit), {} shadow rays to {} lights one at a time; load {}",
            program.name(),
            opts.size_factor,
            tessellate.map_or(String::new(), |t| format!(" tessellated {t}")),
            eye.len(),
            eye_hits.iter().filter(|h| h.is_hit()).count(),
            shadow.len(),
            scene.lights.len(),
            load.split_whitespace()
                .take(3)
                .collect::<Vec<_>>()
                .join(" ")
        );
        if once {
            for e in engines.iter().flatten() {
                std::hint::black_box(closest(e.as_ref(), &eye, &mut Counters::default()));
                std::hint::black_box(any(e.as_ref(), &shadow, &mut Counters::default()));
            }
            continue;
        }
        // Answers: every engine against bvh8's single-ray traversal (bvh8 single itself too:
        // its line gives its counters).
        let shadow_want = any(first, &shadow, &mut Counters::default());
        for (k, (label, _, _)) in ENGINES.iter().enumerate() {
            let Some(e) = engines[k].as_deref() else {
                continue;
            };
            let mut ce = Counters::default();
            let h = closest(e, &eye, &mut ce);
            let same_object = h
                .iter()
                .zip(&eye_hits)
                .filter(|(a, b)| a.is_hit() == b.is_hit() && (!a.is_hit() || a.object == b.object))
                .count();
            let same_t = h
                .iter()
                .zip(&eye_hits)
                .filter(|(a, b)| a.object == b.object && a.t.to_bits() == b.t.to_bits())
                .count();
            let mut cs = Counters::default();
            let o = any(e, &shadow, &mut cs);
            let same_occ = o.iter().zip(&shadow_want).filter(|(a, b)| a == b).count();
            println!(
                "  {label:<16} eye: same object {same_object}/{n}, same object and t bits {same_t}/{n}; shadow: same answer {same_occ}/{m}",
                n = eye.len(),
                m = shadow.len()
            );
            // Exact counters per ray (nodes visited, box tests, primitive tests), the
            // noise-free side of a tree or traversal change.
            let per = |c: &Counters| {
                let r = c.rays.max(1) as f64;
                format!(
                    "nodes {:.4}, boxes {:.4}, prims {:.4}",
                    c.nodes_visited as f64 / r,
                    c.box_tests as f64 / r,
                    c.primitive_tests as f64 / r
                )
            };
            println!(
                "  {label:<16} per eye ray: {}; per shadow ray: {}",
                per(&ce),
                per(&cs)
            );
        }
        for (gen, is_eye) in [("eye", true), ("shadow", false)] {
            for &(a, b) in PAIRS {
                if engines[a].is_none() || engines[b].is_none() {
                    continue;
                }
                let mut ratios = Vec::with_capacity(pairs);
                for p in 0..pairs {
                    let time = |k: usize| {
                        let e = engines[k].as_deref().expect("built");
                        let mut c = Counters::default();
                        seconds(|| {
                            if is_eye {
                                std::hint::black_box(closest(e, &eye, &mut c));
                            } else {
                                std::hint::black_box(any(e, &shadow, &mut c));
                            }
                        })
                    };
                    let (ta, tb) = if p % 2 == 0 {
                        let ta = time(a);
                        (ta, time(b))
                    } else {
                        let tb = time(b);
                        (time(a), tb)
                    };
                    ratios.push(tb / ta);
                }
                let (m, lo, hi) = median(ratios);
                println!(
                    "  {gen:<6} {:<15} vs {:<15} speed {m:.3} (min {lo:.3}, max {hi:.3}, {pairs} pairs)",
                    ENGINES[a].0, ENGINES[b].0
                );
            }
        }
    }
}
