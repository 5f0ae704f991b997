//! Build times against Embree's, side by side:
//! `cargo bench -p rtbench-engines --bench engine_builds -- [SCENE[:SF] ...] [--rounds R]`.
//!
//! Each round builds every engine below once, each build in a child process of its own (Embree
//! keeps one device per thread setting for the process's life, and a live `threads=2` device lets
//! a `threads=1` build use two threads: 1.6–1.8 CPUs in one process), in an
//! order that rotates from round to round, so that load from other processes falls on all of
//! them. Each line also prints the build's CPU time over its wall time. Each
//! build's wall time is the engine's whole build (`build_engine`: Embree's device, scene and
//! BVH; bvh8's primitive boxes, tree, collapse and leaf layout). Printed per engine: the median
//! and range of the rounds, and per round the ratio of bvh8's time to Embree's at the same
//! thread count (≤ 1.5 is the acceptance). Scenes as the harness's `--tessellate` makes them
//! (resolution 3; balls4: 797,150 triangles).

use rtbench_engines::geometry::Geometry;
use rtbench_engines::{build_engine, usage, BuildInput};
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

/// The scene of `program` at `sf` (the standard SF when `None`), tessellated as the harness's
/// `--tessellate 3` makes it, and the engines' input over it.
fn input_of(program: Program, sf: Option<u32>) -> BuildInput {
    let mut opts = Options {
        tessellate: Some(3),
        ..Options::standard(program)
    };
    if let Some(sf) = sf {
        opts.size_factor = sf;
    }
    let scene = Arc::new(generate_scene(program, &opts).expect("scene"));
    let geometry = Arc::new(Geometry::from_scene(&scene));
    BuildInput { scene, geometry }
}

/// One build of `ENGINES[k]` in this process (a child of the bench): prints its wall and CPU
/// seconds and the primitive count.
fn child(k: usize, program: Program, sf: Option<u32>) {
    let input = input_of(program, sf);
    let (_, name, set) = ENGINES[k];
    let s = set.iter().map(|(k, v)| (k.to_string(), v.to_string()));
    let (t, (c, _)) = (Instant::now(), usage::process());
    let engine = build_engine(name, &input, s.collect()).expect("engine");
    let (wall, cpu) = (t.elapsed().as_secs_f64(), usage::process().0 - c);
    drop(engine);
    println!("{wall} {cpu} {}", input.geometry.prims.len());
}

/// `ENGINES[k]` built once in a child process of its own: (wall s, CPU s, primitives).
fn build_in_child(k: usize, scene: &str) -> (f64, f64, usize) {
    let out = std::process::Command::new(std::env::current_exe().expect("the bench's path"))
        .args(["--child", &k.to_string(), scene])
        .output()
        .expect("run the bench as a child");
    assert!(
        out.status.success(),
        "child build of {} failed: {}",
        ENGINES[k].0,
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let f: Vec<&str> = text.split_whitespace().collect();
    (
        f[0].parse().unwrap(),
        f[1].parse().unwrap(),
        f[2].parse().unwrap(),
    )
}

fn load() -> String {
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    load.split_whitespace()
        .take(3)
        .collect::<Vec<_>>()
        .join(" ")
}

fn main() {
    let mut scenes: Vec<(String, Program, Option<u32>)> = Vec::new();
    let mut rounds = 5usize;
    let mut child_of: Option<usize> = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--rounds" => {
                rounds = args
                    .next()
                    .and_then(|s| s.parse().ok())
                    .expect("--rounds R")
            }
            "--child" => child_of = args.next().and_then(|s| s.parse().ok()),
            s if !s.starts_with('-') => {
                let (name, sf) = match s.split_once(':') {
                    Some((n, f)) => (n, Some(f.parse().expect("SCENE:SF"))),
                    None => (s, None),
                };
                scenes.push((s.to_string(), name.parse().expect("an SPD program"), sf));
            }
            _ => {}
        }
    }
    if scenes.is_empty() {
        scenes = vec![("balls".to_string(), Program::Balls, None)];
    }
    if let Some(k) = child_of {
        let (_, program, sf) = &scenes[0];
        return child(k, *program, *sf);
    }
    for (arg, program, sf) in scenes {
        let sf = sf.unwrap_or(Options::standard(program).size_factor);
        println!(
            "{} sf {sf} tessellated: {rounds} rounds, each build in a process of its own; load before {}",
            program.name(),
            load()
        );
        let mut times = vec![Vec::new(); ENGINES.len()];
        let mut cpu = vec![Vec::new(); ENGINES.len()];
        let mut prims = 0;
        for round in 0..rounds {
            for k in 0..ENGINES.len() {
                let e = (k + round) % ENGINES.len();
                let (wall, c, n) = build_in_child(e, &arg);
                times[e].push(wall);
                cpu[e].push(c);
                prims = n;
            }
            println!(
                "  round {}: {}; bvh8/embree 1 thread {:.2}, 2 threads {:.2}",
                round + 1,
                ENGINES
                    .iter()
                    .zip(&times)
                    .zip(&cpu)
                    .map(|(((l, _, _), t), c)| format!(
                        "{l} {:.3} s (CPU {:.2}×)",
                        t[round],
                        c[round] / t[round]
                    ))
                    .collect::<Vec<_>>()
                    .join(", "),
                times[1][round] / times[0][round],
                times[3][round] / times[2][round],
            );
        }
        println!("  {prims} primitives");
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
        println!("  load after {}", load());
    }
}
