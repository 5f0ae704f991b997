//! The fuzzer's mutations (`rtbench_tests::fuzz`) over the harness's own readers of outside data:
//! the history database (what the read commands and `history check` do with it), suite TOML,
//! and shard manifests with their results (what `merge` does with them). A few thousand inputs
//! run in `cargo test`; the large run, one reader at a time:
//! `RTBENCH_FUZZ_N=1000000 cargo test --release -p rtbench --bin rtbench -- --ignored --nocapture fuzz_at_scale`
//! (`RTBENCH_FUZZ_ONLY=history|suite|shard` for one).

use crate::history::{export, Finding, History, Metric, Night};
use rtbench_tests::fuzz::{mutate, Rng};
use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Reader {
    History,
    Suite,
    Shard,
}

impl Reader {
    const ALL: [Reader; 3] = [Reader::History, Reader::Suite, Reader::Shard];
    fn name(self) -> &'static str {
        match self {
            Reader::History => "history",
            Reader::Suite => "suite",
            Reader::Shard => "shard",
        }
    }
}

fn night(commit: &str, metrics: usize) -> Night {
    Night {
        suite: "nightly".into(),
        suite_sha256: "ab".repeat(32),
        started_at: "2026-01-01T00:00:00Z".into(),
        finished_at: "2026-01-01T00:01:00Z".into(),
        git_commit: commit.into(),
        git_dirty: false,
        fingerprint: "fingerprint-日本".into(),
        env_json: r#"{"cpu":"x"}"#.into(),
        wall_s: 61.0,
        note: Some("note".into()),
        metrics: (0..metrics)
            .map(|i| Metric {
                name: format!("ratio:grid tetra{i}@1"),
                kind: "time_ratio".into(),
                unit: "ratio".into(),
                value: 1.0 + i as f64,
                gated: i % 2 == 0,
                samples: vec![1.0, 1.1, 0.9],
            })
            .collect(),
        findings: vec![Finding {
            name: "ratio:grid tetra0@1".into(),
            verdict: "regression".into(),
            baseline: Some(1.0),
            value: Some(1.2),
            change_pct: Some(20.0),
            message: "slower".into(),
        }],
    }
}

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/fuzz/corpus")
}

/// Each seed: (file name, bytes) per file.
fn seeds(r: Reader, work: &Path) -> Vec<Vec<(String, Vec<u8>)>> {
    match r {
        Reader::History => {
            let mut out = Vec::new();
            for (i, commits) in [vec!["abcdef0123"], vec!["日日日日日", "abc"]]
                .iter()
                .enumerate()
            {
                let p = work.join(format!("seed-{i}.sqlite"));
                let mut h = History::open(&p, true).unwrap();
                for (k, c) in commits.iter().enumerate() {
                    h.append(&night(c, 3 + k)).unwrap();
                }
                drop(h);
                out.push(vec![("h.sqlite".into(), std::fs::read(&p).unwrap())]);
            }
            out
        }
        Reader::Suite => {
            let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../suites/nightly.toml");
            let extra = "name = \"s\"\nengines = [\"embree\", \"grid\"]\nvariants = [\"bvh4:simd=off\"]\nscenes = [\"tetra\"]\nsf = [1, 2]\nthreads = [1, \"all\"]\nrepeats = 3\ngate = [\"counters\"]\n[instructions]\nengines = [\"grid\"]\nscenes = [\"tetra\"]\n";
            vec![
                vec![("s.toml".into(), std::fs::read(repo).unwrap())],
                vec![("s.toml".into(), extra.as_bytes().to_vec())],
            ]
        }
        Reader::Shard => {
            let d = corpus().join("shard");
            vec![["shard.json", "results.jsonl"]
                .iter()
                .map(|n| (n.to_string(), std::fs::read(d.join(n)).unwrap()))
                .collect()]
        }
    }
}

fn feed(r: Reader, files: &[(String, Vec<u8>)], dir: &Path) -> bool {
    match r {
        Reader::History => {
            let p = dir.join("h.sqlite");
            for ext in ["-wal", "-shm"] {
                let _ = std::fs::remove_file(dir.join(format!("h.sqlite{ext}")));
            }
            std::fs::write(&p, &files[0].1).unwrap();
            let read = || -> crate::error::Result<()> {
                let h = History::open_read(&p)?;
                let _ = h.problems()?;
                for run in h.runs(None, None)? {
                    let _ = crate::output::head(&run.git_commit, 10);
                    let m = h.metrics(run.id)?;
                    let _ = export::bmf(&m);
                    h.findings(run.id)?;
                    h.env_json(run.id)?;
                }
                export::csv(&h)?;
                Ok(())
            };
            read().is_ok()
        }
        Reader::Suite => {
            let text = String::from_utf8_lossy(&files[0].1);
            crate::nightly::suite::parse("fuzz.toml", &text).is_ok()
        }
        Reader::Shard => {
            for (n, b) in files {
                std::fs::write(dir.join(n), b).unwrap();
            }
            crate::runs::merge::load_shards(&[dir.to_path_buf()])
                .and_then(|s| crate::runs::merge::merged_records(&s))
                .is_ok()
        }
    }
}

struct Outcome {
    inputs: u64,
    accepted: u64,
    panics: u64,
    first_panic: Option<String>,
    slowest: Duration,
    elapsed: Duration,
}

fn run(r: Reader, n: u64, seed: u64) -> Outcome {
    let work = std::env::temp_dir().join(format!(
        "rtbench-hfuzz-{}-{}-{seed}",
        r.name(),
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    let seeds = seeds(r, &work);
    for s in &seeds {
        assert!(feed(r, s, &work), "{}: a seed does not read", r.name());
    }
    let mut rng = Rng::new(seed);
    let mut o = Outcome {
        inputs: 0,
        accepted: 0,
        panics: 0,
        first_panic: None,
        slowest: Duration::ZERO,
        elapsed: Duration::ZERO,
    };
    let start = Instant::now();
    // Silence only this thread's panics (the fuzz counts them): tests running beside it keep
    // their messages.
    let hook = std::sync::Arc::new(std::panic::take_hook());
    let me = std::thread::current().id();
    let others = hook.clone();
    std::panic::set_hook(Box::new(move |info| {
        if std::thread::current().id() != me {
            others(info)
        }
    }));
    for _ in 0..n {
        let s = &seeds[rng.below(seeds.len())];
        let mut files = s.clone();
        let which = rng.below(files.len());
        files[which].1 = mutate(&files[which].1, &mut rng);
        let t = Instant::now();
        let got = std::panic::catch_unwind(AssertUnwindSafe(|| feed(r, &files, &work)));
        o.slowest = o.slowest.max(t.elapsed());
        o.inputs += 1;
        match got {
            Ok(true) => o.accepted += 1,
            Ok(false) => {}
            Err(p) => {
                o.panics += 1;
                if o.first_panic.is_none() {
                    let msg = p
                        .downcast_ref::<&str>()
                        .map(|s| s.to_string())
                        .or_else(|| p.downcast_ref::<String>().cloned())
                        .unwrap_or_default();
                    let file = work.with_extension("panic");
                    let _ = std::fs::write(&file, &files[which].1);
                    o.first_panic = Some(format!("{msg} (input in {})", file.display()));
                }
            }
        }
    }
    let _ = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| hook(info)));
    o.elapsed = start.elapsed();
    let _ = std::fs::remove_dir_all(&work);
    o
}

fn check(r: Reader, n: u64) {
    let o = run(r, n, 38);
    eprintln!(
        "{:<8} {} inputs in {:.1} s: {} accepted, {} panics, slowest input {:.3} s",
        r.name(),
        o.inputs,
        o.elapsed.as_secs_f64(),
        o.accepted,
        o.panics,
        o.slowest.as_secs_f64()
    );
    assert_eq!(
        o.panics,
        0,
        "{}: first panic: {:?}",
        r.name(),
        o.first_panic
    );
    assert!(
        o.accepted < o.inputs,
        "{}: every mutation accepted",
        r.name()
    );
}

#[test]
fn harness_readers_never_panic() {
    for (r, n) in [
        (Reader::History, 300),
        (Reader::Suite, 3_000),
        (Reader::Shard, 1_000),
    ] {
        check(r, n);
    }
}

// Minutes at 10^6 inputs per reader, so not in every `cargo test` (the small run above is); it runs
// with `RTBENCH_FUZZ_N=1000000 bash scripts/test.sh`, or alone with `RTBENCH_FUZZ_N=1000000 cargo
// test --release -p rtbench --bin rtbench -- --ignored fuzz_at_scale`
// (RTBENCH_FUZZ_ONLY=history|suite|shard for one reader).
#[test]
#[ignore = "the large run: RTBENCH_FUZZ_N inputs per reader (see the comment above)"]
fn fuzz_at_scale() {
    let n: u64 = std::env::var("RTBENCH_FUZZ_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let only = std::env::var("RTBENCH_FUZZ_ONLY").ok();
    for r in Reader::ALL {
        if only.as_deref().is_none_or(|o| o == r.name()) {
            check(r, n);
        }
    }
}
