//! Synthetic results directories for the tests: RunRecords as `rtbench run` writes them.

#![allow(dead_code)]

use rtbench_reports::{run_key, CheckResult, Environment, RunRecord, SceneInfo, Spread, Timings};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// A directory under the system's temp dir, removed on drop.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(name: &str) -> TempDir {
        static N: AtomicUsize = AtomicUsize::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        let p =
            std::env::temp_dir().join(format!("rtbench-reports-{name}-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).unwrap();
        TempDir(p)
    }
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Three repeats around `median` with relative spread `spread` ((max − min) / median).
pub fn samples(median: f64, spread: f64) -> Spread {
    Spread::of(&[
        median * (1.0 - spread / 2.0),
        median,
        median * (1.0 + spread / 2.0),
    ])
}

/// An ok run of `engine` on `program` at `sf`, one thread, tracing in `trace` seconds (median, 2% spread).
pub fn run(engine: &str, program: &str, sf: u32, trace: f64) -> RunRecord {
    let scene = format!("{program}{sf}");
    let settings = BTreeMap::new();
    let rays_total = 1_000_000u64 * sf as u64;
    let trace = samples(trace, 0.02);
    let mut counters = BTreeMap::new();
    counters.insert(
        "nodes_visited".to_string(),
        1000 * sf as u64 + engine.len() as u64,
    );
    counters.insert("primitive_tests".to_string(), 500 * sf as u64);
    let check = (engine != "embree").then(|| CheckResult {
        against: "embree".to_string(),
        rays: rays_total,
        hit_agreement: if engine == "grid" { 1.0 } else { 0.99998 },
        primitive_agreement: None,
        t_rel_err_median: 1e-8,
        t_rel_err_p99: if engine == "grid" { 0.0 } else { 2e-6 },
        t_rel_err_max: 1e-4,
        image_psnr_db: if engine == "grid" { None } else { Some(48.26) },
    });
    RunRecord {
        key: run_key(engine, &settings, &scene, 1),
        status: "ok".to_string(),
        reason: None,
        engine: engine.to_string(),
        settings,
        scene: SceneInfo {
            name: scene,
            program: Some(program.to_string()),
            sf: Some(sf),
            tessellate: None,
            objects: 10u64.pow(sf),
            primitives: 10u64.pow(sf),
            file: None,
            sha256: None,
        },
        threads: 1,
        repeats: 3,
        size: 513,
        rays: None,
        rays_total,
        time_s: Timings {
            generate: 0.01,
            build: samples(0.05 * sf as f64, 0.04),
            intersect: samples(trace.median * 0.8, 0.02),
            shade: samples(trace.median * 0.2, 0.02),
            trace_cpu: Spread::default(),
            trace: trace.clone(),
        },
        mrays_per_s: rays_total as f64 / trace.median / 1e6,
        structure_bytes: 1_000_000 * sf as u64 * (1 + engine.len() as u64),
        peak_rss_bytes: 50_000_000 + 3_000_000 * sf as u64,
        counters,
        build_stats: BTreeMap::new(),
        check,
        paired_ratio: None,
        thread_scaling: None,
        image_sha256: Some("00ff".to_string()),
        samples: Vec::new(),
        ratio_to_embree: None,
        rounds: Vec::new(),
        wall_s: 1.0,
        finished_at: "2026-11-21T10:00:00Z".to_string(),
        machine: None,
    }
}

/// A run that failed for `reason`.
pub fn failed(engine: &str, program: &str, sf: u32, reason: &str) -> RunRecord {
    let mut r = run(engine, program, sf, 0.0);
    r.status = "failed".to_string();
    r.reason = Some(reason.to_string());
    r.time_s = Timings::default();
    r.mrays_per_s = 0.0;
    r.counters.clear();
    r.check = None;
    r
}

pub fn environment() -> Environment {
    Environment {
        cpu_model: "Synthetic CPU 9000".to_string(),
        cpu_flags: vec!["avx2".to_string()],
        cores_logical: 2,
        cores_physical: Some(1),
        memory_bytes: 24_000_000_000,
        os: "Debian 12".to_string(),
        kernel: "6.1".to_string(),
        hostname: "test".to_string(),
        rustc: "rustc 1.95.0".to_string(),
        git_commit: "abc1234".to_string(),
        git_dirty: false,
        embree_version: Some("4.3.3".to_string()),
        rtbench_version: "0.1.0".to_string(),
        started_at: "2026-11-21T10:00:00Z".to_string(),
    }
}

/// Writes `results.jsonl` (one record a line) and `env.json` into `dir`.
pub fn write_set(dir: &Path, records: &[RunRecord]) {
    let lines: Vec<String> = records
        .iter()
        .map(|r| serde_json::to_string(r).unwrap())
        .collect();
    std::fs::write(dir.join("results.jsonl"), lines.join("\n") + "\n").unwrap();
    std::fs::write(
        dir.join("env.json"),
        serde_json::to_string_pretty(&environment()).unwrap(),
    )
    .unwrap();
}
