//! The results files of `rtbench run` / `rtbench sweep`, as reports read them.
//!
//! A results directory holds `env.json` (one [`Environment`]) and `results.jsonl`: one [`RunRecord`]
//! per line, one line per (engine, scene, SF, configuration, threads). `rtbench run` rewrites the
//! file atomically (temp file, then rename) after each run, so it is always whole. Reports are made
//! from these files alone.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Where and with what a run was measured.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Environment {
    pub cpu_model: String,
    pub cpu_flags: Vec<String>,
    pub cores_logical: usize,
    pub cores_physical: Option<usize>,
    pub memory_bytes: u64,
    pub os: String,
    pub kernel: String,
    pub hostname: String,
    pub rustc: String,
    pub git_commit: String,
    pub git_dirty: bool,
    pub embree_version: Option<String>,
    pub rtbench_version: String,
    pub started_at: String,
}

/// min / median / max of repeated measurements, and every sample.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Spread {
    pub min: f64,
    pub median: f64,
    pub max: f64,
    pub samples: Vec<f64>,
    /// For ratios measured in pairs (a paired ratio to Embree, a speed-up): their median with its
    /// 95 % interval and the number of pairs ([`crate::interval::of_ratios`]). Absent
    /// for times, and with fewer than two pairs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interval: Option<crate::interval::Interval>,
}

/// What one timed span measured ([`Sample`]s of a run's repeats are kept whole, so that every
/// statistic can be recomputed from the results).
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Sample {
    /// Wall seconds.
    pub wall_s: f64,
    /// CPU seconds of the threads that did the work (the pool's threads, summed): not Embree's
    /// TBB workers, which spin on after a build.
    pub thread_cpu_s: f64,
    /// CPU seconds of the whole process.
    pub process_cpu_s: f64,
    /// Page faults of the process during the span: minor (no I/O) and major (I/O).
    pub minor_faults: u64,
    pub major_faults: u64,
    /// Context switches of the process during the span, voluntary (it blocked or slept) and
    /// involuntary (it was preempted): how much the machine's other load took the CPUs away.
    #[serde(default)]
    pub context_switches: u64,
}

impl Spread {
    pub fn of(samples: &[f64]) -> Spread {
        let mut s = samples.to_vec();
        s.sort_by(|a, b| a.total_cmp(b));
        if s.is_empty() {
            return Spread::default();
        }
        let median = if s.len() % 2 == 1 {
            s[s.len() / 2]
        } else {
            (s[s.len() / 2 - 1] + s[s.len() / 2]) / 2.0
        };
        Spread {
            min: s[0],
            median,
            max: s[s.len() - 1],
            samples: samples.to_vec(),
            interval: None,
        }
    }

    /// [`Spread::of`] ratios measured in pairs, with the interval of their median.
    pub fn of_ratios(samples: &[f64]) -> Spread {
        Spread {
            interval: crate::interval::of_ratios(samples),
            ..Spread::of(samples)
        }
    }

    /// Robust relative noise of the samples: 1.4826 × median absolute deviation / median (an
    /// estimate of σ/median that one outlying repeat does not move).
    pub fn rel_noise(&self) -> f64 {
        if self.median <= 0.0 || self.samples.len() < 2 {
            return 0.0;
        }
        let mut dev: Vec<f64> = self
            .samples
            .iter()
            .map(|x| (x - self.median).abs())
            .collect();
        dev.sort_by(|a, b| a.total_cmp(b));
        let n = dev.len();
        let mad = if n % 2 == 1 {
            dev[n / 2]
        } else {
            (dev[n / 2 - 1] + dev[n / 2]) / 2.0
        };
        1.4826 * mad / self.median
    }
}

/// The scene a run traced.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct SceneInfo {
    /// `balls4`, `mount6-jenkins`, `balls4-tess3`, or a file's name and the first 12 hex digits
    /// of its content hash (`bunny.obj-3f9a1c2b7d4e`).
    pub name: String,
    pub program: Option<String>,
    pub sf: Option<u32>,
    pub tessellate: Option<u32>,
    pub objects: u64,
    /// Primitives the engines see (polygons cut into triangles).
    pub primitives: u64,
    /// A scene file's path as given, and the SHA-256 of its content (with a glTF's buffers).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sha256: Option<String>,
}

/// Timings of the phases, in seconds, over the repeats.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Timings {
    /// Scene generation (once).
    pub generate: f64,
    /// Preprocessing: the engine's build (plus the shared geometry preparation).
    pub build: Spread,
    /// Tracing the whole workload, and within it the engine's queries and the shading.
    pub trace: Spread,
    pub intersect: Spread,
    pub shade: Spread,
    /// CPU seconds of the trace (all threads; getrusage). Steadier than wall time on a shared
    /// machine: `compare` uses it when present. Absent in older results.
    #[serde(default)]
    pub trace_cpu: Spread,
}

impl Timings {
    /// The trace time `compare` uses: CPU time when recorded, else wall time.
    pub fn trace_for_compare(&self) -> &Spread {
        if self.trace_cpu.samples.is_empty() {
            &self.trace
        } else {
            &self.trace_cpu
        }
    }
}

/// The run's answers against Embree's on the same rays.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct CheckResult {
    pub against: String,
    pub rays: u64,
    pub hit_agreement: f64,
    /// Closest hits naming the same object, without the tie rule (absent in older results).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub primitive_agreement: Option<f64>,
    pub t_rel_err_median: f64,
    pub t_rel_err_p99: f64,
    pub t_rel_err_max: f64,
    /// `None` when the images are identical (infinite PSNR).
    pub image_psnr_db: Option<f64>,
}

/// One line of `results.jsonl`.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct RunRecord {
    /// What identifies a run for `--resume` and `compare`: engine, settings, scene, threads.
    pub key: String,
    /// `ok` or `failed`.
    pub status: String,
    /// Why a failed run failed (panic, time limit, memory limit, exit status …).
    pub reason: Option<String>,
    pub engine: String,
    /// The engine's `key=value` settings.
    pub settings: BTreeMap<String, String>,
    pub scene: SceneInfo,
    pub threads: usize,
    pub repeats: u32,
    pub size: u32,
    /// Ray statistics of the workload (as `rtbench render --json` gives them), when ok.
    pub rays: Option<serde_json::Value>,
    pub rays_total: u64,
    pub time_s: Timings,
    /// Rays per second over the median trace time.
    pub mrays_per_s: f64,
    pub structure_bytes: u64,
    pub peak_rss_bytes: u64,
    /// Exact counters (the noise-free signal for regressions).
    pub counters: BTreeMap<String, u64>,
    pub build_stats: BTreeMap<String, f64>,
    pub check: Option<CheckResult>,
    /// Trace CPU time over Embree's, measured in pairs in the same process (`--paired N`):
    /// the engine and Embree trace the workload back to back, alternating which goes first,
    /// so a burst of load from other processes falls on both sides of a ratio. One sample per
    /// pair. `None` when not asked for (and for Embree itself).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paired_ratio: Option<Spread>,
    /// Speed-up over one thread, timed in pairs in the same process (`--paired-threads N`): the
    /// same trace at one thread and at `threads`, back to back, alternating which goes first.
    /// `None` when not asked for, and for one-thread runs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thread_scaling: Option<crate::scaling::ThreadScaling>,
    pub image_sha256: Option<String>,
    /// Every timed repeat of the trace, as measured (wall, CPU, page faults); `time_s.trace` and
    /// `time_s.trace_cpu` are read from these. Empty in older results.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub samples: Vec<Sample>,
    /// Trace CPU time over Embree's on the same scene and threads in this results set: the
    /// quotient of the two runs' geometric means with its 95 % interval (Welch, repeats of both
    /// runs). Set by `rtbench run` and `sweep` once Embree's run is in; absent for Embree and
    /// where Embree did not run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ratio_to_embree: Option<crate::interval::Interval>,
    /// Wall seconds of the whole child process.
    pub wall_s: f64,
    pub finished_at: String,
    /// How the samples split into rounds (`rtbench run --rounds R`, the nightly's rounds): round i
    /// is one process at one time, and its repeats, pairs and thread pairs follow round i − 1's in
    /// `samples`, `paired_ratio` and `thread_scaling`. Intervals and `compare` take the round as
    /// the unit where there are two or more ([`crate::rounds`]). Empty for a run of one process.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rounds: Vec<Round>,
    /// The machine (host name) the run was measured on, set by `rtbench merge` when shards run on
    /// several machines: a run and its Embree anchor always share one. `None` in unsharded results.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
}

/// What one round of a run (one process) measured: how many of the run's samples are its own.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq, Eq)]
pub struct Round {
    /// Timed repeats (in `samples` and every `time_s` spread).
    pub repeats: usize,
    /// Pairs with Embree (in `paired_ratio`).
    #[serde(default)]
    pub pairs: usize,
    /// Pairs of one thread and the run's threads (in `thread_scaling`).
    #[serde(default)]
    pub thread_pairs: usize,
}

impl RunRecord {
    pub fn ok(&self) -> bool {
        self.status == "ok"
    }
}

/// The key of a run: `engine[k=v,…]/scene@threads`.
pub fn run_key(
    engine: &str,
    settings: &BTreeMap<String, String>,
    scene: &str,
    threads: usize,
) -> String {
    let mut k = engine.to_string();
    if !settings.is_empty() {
        let s: Vec<String> = settings.iter().map(|(a, b)| format!("{a}={b}")).collect();
        k.push_str(&format!("[{}]", s.join(",")));
    }
    format!("{k}/{scene}@{threads}")
}

#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    #[error("{path}: cannot read: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}:{line}: not a run record: {message}")]
    Parse {
        path: String,
        line: usize,
        message: String,
    },
}

/// Reads `DIR/results.jsonl`. A missing file is an empty list.
pub fn read_results(dir: &Path) -> Result<Vec<RunRecord>, ReadError> {
    let path = dir.join("results.jsonl");
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => {
            return Err(ReadError::Io {
                path: path.display().to_string(),
                source: e,
            })
        }
    };
    parse_results(&text, &path.display().to_string())
}

/// The run records of a results.jsonl text (`path` names it in errors).
pub fn parse_results(text: &str, path: &str) -> Result<Vec<RunRecord>, ReadError> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            serde_json::from_str(l).map_err(|e| ReadError::Parse {
                path: path.to_string(),
                line: i + 1,
                message: e.to_string(),
            })
        })
        .collect()
}

/// Reads `DIR/env.json`, if there.
pub fn read_environment(dir: &Path) -> Result<Option<Environment>, ReadError> {
    let path = dir.join("env.json");
    match std::fs::read_to_string(&path) {
        Ok(t) => serde_json::from_str(&t)
            .map(Some)
            .map_err(|e| ReadError::Parse {
                path: path.display().to_string(),
                line: 1,
                message: e.to_string(),
            }),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(ReadError::Io {
            path: path.display().to_string(),
            source: e,
        }),
    }
}
