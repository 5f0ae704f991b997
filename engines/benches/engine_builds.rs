//! Build times against Embree's, side by side (issue 20, acceptance 4):
//! `cargo bench -p rtbench-engines --bench engine_builds -- [SCENE[:SF] ...] [--rounds R]`.
//!
//! Each round builds every engine below once over the same prepared geometry, in an order that
//! rotates from round to round, so that load from other processes falls on all of them; each
//! build's wall time is the engine's whole build (`build_engine`: Embree's device, scene and
//! BVH; bvh8's primitive boxes, tree, collapse and leaf layout). Printed per engine: the median
//! and range of the rounds, and per round the ratio of bvh8's time to Embree's at the same
//! thread count (≤ 1.5 is the acceptance). Scenes as the harness's `--tessellate` makes them
//! (resolution 3; balls4: 797,150 triangles).

use rtbench_engines::geometry::Geometry;
use rtbench_engines::{build_engine, BuildInput};
use rtbench_scenes::generate_scene;
use rtbench_scenes::spd::{Options, Program};
use std::sync::Arc;
use std::time::Instant;

/// (label, engine, settings).
type Setup = (
    &'static str,
    &'static str,
    &'static [(&'static str, &'static str)],
);

/// The builds compared.
const ENGINES: &[Setup] = &[
    ("embree 1 thread", "embree", &[("threads", "1")]),
    ("bvh8 1 thread", "bvh8", &[]),
    ("embree 2 threads", "embree", &[("threads", "2")]),
    ("bvh8 2 threads", "bvh8", &[("build_threads", "2")]),
];

fn main() {
    let mut scenes: Vec<(Program, Option<u32>)> = Vec::new();
    let mut rounds = 5usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--rounds" => {
                rounds = args
                    .next()
                    .and_then(|s| s.parse().ok())
                    .expect("--rounds R")
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
        scenes = vec![(Program::Balls, None)];
    }
    for (program, sf) in scenes {
        let mut opts = Options {
            tessellate: Some(3),
            ..Options::standard(program)
        };
        if let Some(sf) = sf {
            opts.size_factor = sf;
        }
        let scene = Arc::new(generate_scene(program, &opts).expect("scene"));
        let geometry = Arc::new(Geometry::from_scene(&scene));
        let input = BuildInput {
            scene: scene.clone(),
            geometry: geometry.clone(),
        };
        let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
        println!(
            "{} sf {} tessellated: {} primitives; {rounds} rounds; load before {}",
            program.name(),
            opts.size_factor,
            geometry.prims.len(),
            load.split_whitespace()
                .take(3)
                .collect::<Vec<_>>()
                .join(" ")
        );
        let mut times = vec![Vec::new(); ENGINES.len()];
        for round in 0..rounds {
            for k in 0..ENGINES.len() {
                let e = (k + round) % ENGINES.len();
                let (_, name, set) = ENGINES[e];
                let s = set.iter().map(|(k, v)| (k.to_string(), v.to_string()));
                let t = Instant::now();
                let engine = build_engine(name, &input, s.collect()).expect("engine");
                times[e].push(t.elapsed().as_secs_f64());
                drop(engine);
            }
            println!(
                "  round {}: {}; bvh8/embree 1 thread {:.2}, 2 threads {:.2}",
                round + 1,
                ENGINES
                    .iter()
                    .zip(&times)
                    .map(|((l, _, _), t)| format!("{l} {:.3} s", t[round]))
                    .collect::<Vec<_>>()
                    .join(", "),
                times[1][round] / times[0][round],
                times[3][round] / times[2][round],
            );
        }
        for ((label, _, _), t) in ENGINES.iter().zip(&times) {
            let mut s = t.clone();
            s.sort_by(f64::total_cmp);
            println!(
                "  {label:<17} median {:.3} s (min {:.3}, max {:.3})",
                s[s.len() / 2],
                s[0],
                s[s.len() - 1]
            );
        }
        let mut r1: Vec<f64> = (0..rounds).map(|r| times[1][r] / times[0][r]).collect();
        let mut r2: Vec<f64> = (0..rounds).map(|r| times[3][r] / times[2][r]).collect();
        r1.sort_by(f64::total_cmp);
        r2.sort_by(f64::total_cmp);
        println!(
            "  bvh8 / embree, median of rounds: 1 thread {:.2} (min {:.2}, max {:.2}), 2 threads {:.2} (min {:.2}, max {:.2})",
            r1[rounds / 2], r1[0], r1[rounds - 1], r2[rounds / 2], r2[0], r2[rounds - 1]
        );
        let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
        println!(
            "  load after {}",
            load.split_whitespace()
                .take(3)
                .collect::<Vec<_>>()
                .join(" ")
        );
    }
}
